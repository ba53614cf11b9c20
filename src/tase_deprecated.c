/*
 * Functions kept for one release after their replacement came, each a
 * call of the replacement (the headers mark them TASE_DEPRECATED_ and say
 * when they go). Nothing else of the library calls them.
 */
#define TASE_ALLOW_DEPRECATED /* defining them is not using them */
#include "tase/frame.h"

/* 0.3.0 -> 0.4.0: the output last, as in every other encoder. */
int tase_frame_encode(uint8_t *out, size_t cap, uint8_t group, uint8_t type, const uint8_t *data,
                      size_t len)
{
    return tase_frame_build(group, type, data, len, out, cap);
}
