/* Keeps the tase_port library non-empty when no port is built. */
typedef int tase_empty_translation_unit;
