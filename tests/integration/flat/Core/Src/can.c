/* The application's own CAN peripheral set-up, as STM32CubeMX generates
 * it in Core/Src/can.c: its object is build/can.o, like any other can.c
 * in the project would be. */
#include "can.h"

static unsigned can_bitrate;

unsigned MX_CAN_Init(unsigned bitrate)
{
    can_bitrate = bitrate;
    return can_bitrate;
}
