/* What startup.c and main.c share. */
#ifndef BOARD_H
#define BOARD_H

/* SysTick exception: the example's simulated UART receive interrupt. */
void SysTick_Handler(void);

/* Deepest stack use so far in bytes: the reset handler fills the stack
 * area with a pattern, this finds the lowest word overwritten. */
unsigned long board_stack_used(void);

#endif /* BOARD_H */
