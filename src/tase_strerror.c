/* Error strings, in their own translation unit so that firmware which
 * never calls tase_strerror() does not link them. */
#include "tase/common.h"

const char *tase_strerror(int err)
{
    switch (err) {
    case TASE_OK: return "success";
    case TASE_EARG: return "invalid argument";
    case TASE_ENOSPC: return "buffer too small";
    case TASE_ETOOLONG: return "data too long";
    case TASE_ELENGTH: return "wrong data length for packet type";
    case TASE_EUNKNOWN: return "unknown packet, name or tag";
    case TASE_ECHECKSUM: return "checksum mismatch";
    case TASE_EFORMAT: return "malformed input";
    case TASE_ERANGE: return "value out of range";
    case TASE_EAGAIN: return "try again";
    case TASE_ETIMEOUT: return "timed out";
    case TASE_EIO: return "I/O error";
    case TASE_ENODEV: return "no such device or interface";
    case TASE_EDOWN: return "interface is down";
    case TASE_EACCES: return "permission denied";
    case TASE_EBUSY: return "busy";
    case TASE_ENOBUFS: return "transmit queue full";
    case TASE_ETRUNC: return "truncated input";
    case TASE_EUNSUPPORTED: return "not supported";
    case TASE_ESTATE: return "not valid in the current state";
    default: return "unknown error";
    }
}
