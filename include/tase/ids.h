/*
 * tase/ids.h - group and packet-type numbers of the spec (section 4).
 *
 * A packet is identified by its (group, type) pair; TASE_ID() packs the
 * pair into one 16-bit value, group in the high byte, for switch
 * statements and tables.
 */
#ifndef TASE_IDS_H
#define TASE_IDS_H

#include "tase/common.h"

/* TASE_ID() converts its arguments to unsigned, so that int arguments
 * pass -Wsign-conversion; in C++98, with arguments that are unsigned int
 * already, g++ -Wuseless-cast calls those conversions useless (as it does
 * TASE_ID_GROUP() / TASE_ID_TYPE() of an unsigned int, and the other
 * macros' conversions, e.g. TASE_GIMBAL_FLAGS(2, 1)): pass uint8_t /
 * uint16_t values, or use the constants below. From C++11 on g++ sees no
 * such cast (tase/common.h: TASE_CAST_). */
#define TASE_ID(group, type)                                                                       \
    TASE_CAST_(uint16_t, (TASE_CAST_(unsigned, group) << 8) | TASE_CAST_(unsigned, type))
/* Private: TASE_ID() of two unsigned literals, for the constants below
 * (TASE_ID()'s conversions of its arguments to unsigned would be useless
 * casts there: g++ -Wuseless-cast in a C++ user's code). */
#define TASE_ID_K_(group, type) TASE_CAST_(uint16_t, ((group)*0x100u) + (type))
#define TASE_ID_GROUP(id) TASE_CAST_(uint8_t, TASE_CAST_(unsigned, id) >> 8)
#define TASE_ID_TYPE(id) TASE_CAST_(uint8_t, 0xFFu & TASE_CAST_(unsigned, id))

/* Groups (spec table 3) */
#define TASE_GROUP_COMMAND 0x00u  /* command and control input */
#define TASE_GROUP_DYNAMICS 0x08u /* rate and attitude information */
#define TASE_GROUP_POSITION 0x10u /* GPS and sensor point of interest */
#define TASE_GROUP_STATUS 0x28u   /* status; no packets defined in v1.0.0 */
#define TASE_GROUP_SETUP 0x48u    /* gimbal setup (echoed, queryable) */

/* Group 0x00 (table 4) */
#define TASE_ID_GIMBAL_CMD TASE_ID_K_(0x00u, 0x80u)
#define TASE_ID_GYRO_ZERO_CMD TASE_ID_K_(0x00u, 0x40u)
#define TASE_ID_CAMERA_CMD TASE_ID_K_(0x00u, 0x41u)
#define TASE_ID_LEGACY_CAMERA_CMD TASE_ID_K_(0x00u, 0x81u)
#define TASE_ID_CAMERA_PASS TASE_ID_K_(0x00u, 0x42u)
#define TASE_ID_RETRACT_DEPLOY_CMD TASE_ID_K_(0x00u, 0x43u)
/* Group 0x08 (table 10) */
#define TASE_ID_GIMBAL_ANGLE TASE_ID_K_(0x08u, 0x10u)
#define TASE_ID_GIMBAL_RATE TASE_ID_K_(0x08u, 0x40u) /* "GIMBAL_TELEMETRY" in table 10 */
#define TASE_ID_HOST_SENSOR TASE_ID_K_(0x08u, 0x41u)
#define TASE_ID_HOST_ATTITUDE TASE_ID_K_(0x08u, 0x42u)
/* Group 0x10 (table 15) */
#define TASE_ID_HOST_GPS_DATA TASE_ID_K_(0x10u, 0x10u)
#define TASE_ID_SPOI_CMD TASE_ID_K_(0x10u, 0x40u)
#define TASE_ID_GEOREFERENCE_DATA TASE_ID_K_(0x10u, 0x41u)
/* Group 0x48 (table 19) */
#define TASE_ID_PACKET_RATE TASE_ID_K_(0x48u, 0x00u)
#define TASE_ID_SENSOR_FILTER TASE_ID_K_(0x48u, 0x01u)
#define TASE_ID_AXIS_SETTING TASE_ID_K_(0x48u, 0x02u)
#define TASE_ID_SYSTEM_VERSION TASE_ID_K_(0x48u, 0x03u)
#define TASE_ID_NAV_SOURCE TASE_ID_K_(0x48u, 0x04u)
#define TASE_ID_CAMERA_TYPE TASE_ID_K_(0x48u, 0x05u)
#define TASE_ID_GPS_LEVER_ARM TASE_ID_K_(0x48u, 0x06u)
#define TASE_ID_CAMERA_ALIGN TASE_ID_K_(0x48u, 0x07u)

#define TASE_PACKET_COUNT 21u

#endif /* TASE_IDS_H */
