/* What startup.c needs from the application. */
#ifndef BOARD_H
#define BOARD_H

/* SysTick exception: the example's simulated UART receive interrupt. */
void SysTick_Handler(void);

#endif /* BOARD_H */
