/* The application's TASE configuration (tase/config.h), seen by the
 * library's sources and by the application's alike. */
#ifndef APP_TASE_CONFIG_H
#define APP_TASE_CONFIG_H
#define TASE_PORT_WRITE_TIMEOUT_MS 250u
#endif
