/*
 * tools/sim_words.h - the status bytes and words tase-sim reports, built
 * from the model's state with the named bits of tase/flags.h. Header only
 * (static inline), so tests/test_flags.c checks exactly what the simulator
 * sends by decoding it through flags.h.
 */
#ifndef TASE_TOOLS_SIM_WORDS_H
#define TASE_TOOLS_SIM_WORDS_H

#include "sim_model.h"
#include "tase/flags.h"

/* Mode byte of GIMBAL_RATE (4.2.2) and GEOREFERENCE_DATA (4.3.3): bit 0
 * stabilisation, bit 1 / bit 2 the 3AX deployed / retracted (neither while
 * it moves), bits 3-7 the mode. An impulse is a rate command held for a
 * while, so it reports rate feedback. */
static inline uint8_t sim_mode_byte(const sim_model_t *m)
{
    static const uint8_t modes[] = {TASE_MODE_RATE, TASE_MODE_POSITION, TASE_MODE_SPOI,
                                    TASE_MODE_RATE};
    uint8_t b = TASE_MODE_SET_VALUE(0u, modes[m->mode]);
    if (m->stabilised) {
        b |= TASE_MODE_STAB;
    }
    if (m->tax == SIM_3AX_DEPLOYED) {
        b |= TASE_MODE_3AX_DEPLOYED;
    } else if (m->tax == SIM_3AX_RETRACTED) {
        b |= TASE_MODE_3AX_RETRACTED;
    }
    return b;
}

/* Flags byte of a SPOI_CMD sent by the gimbal (4.3.2): "this bit will be
 * set if stabilization is on", "the mode will be recorded here": bit 0
 * stabilisation and the mode in bits 3-7, bits 1-2 clear, whatever the
 * host's flags were. 4.3.2 defines only those two things, so the 3AX bits
 * of the Mode byte are left out: read as the Mode byte or as a bare mode
 * number in bits 1-7, the byte then gives the same mode
 * (docs/PROTOCOL-NOTES.md P4). */
static inline uint8_t sim_spoi_flags(const sim_model_t *m)
{
    return (uint8_t)(sim_mode_byte(m) &
                     ~(unsigned)(TASE_SPOI_3AX_DEPLOYED | TASE_SPOI_3AX_RETRACTED));
}

/* NavHealth of GEOREFERENCE_DATA (4.3.3): every health bit set (the
 * simulated filter is always within bounds), reserved bits 2-5 and 11
 * clear, filter mode "normal" (TASE_NAV_FILTER_NORMAL, 4: PROTOCOL-NOTES
 * P8). */
static inline uint16_t sim_nav_health(void)
{
    return (uint16_t)(TASE_NAV_POSITION | TASE_NAV_VELOCITY | TASE_NAV_HEADING | TASE_NAV_ATTITUDE |
                      TASE_NAV_GYRO_BIAS | TASE_NAV_ACCEL_BIAS | TASE_NAV_MAG_BIAS |
                      TASE_BITS16_SET(0u, 12, 15, TASE_NAV_FILTER_NORMAL));
}

#endif /* TASE_TOOLS_SIM_WORDS_H */
