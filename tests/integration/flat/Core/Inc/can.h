#ifndef APP_CAN_H
#define APP_CAN_H
unsigned MX_CAN_Init(unsigned bitrate);
#endif
