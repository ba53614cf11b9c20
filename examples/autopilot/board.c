/* The autopilot example's board layer; see board.h. Register layout of the
 * CMSDK APB UART from ARM DDI0479C (Cortex-M System Design Kit TRM); base
 * address and interrupt numbers from the MPS2 AN385/AN386 memory map. */
#include "board.h"

#define UART0_BASE 0x40004000u
#define UART_DATA (*(volatile uint32_t *)(UART0_BASE + 0x00u))
#define UART_STATE (*(volatile uint32_t *)(UART0_BASE + 0x04u))
#define UART_CTRL (*(volatile uint32_t *)(UART0_BASE + 0x08u))
#define UART_INTSTATUS (*(volatile uint32_t *)(UART0_BASE + 0x0Cu))
#define UART_BAUDDIV (*(volatile uint32_t *)(UART0_BASE + 0x10u))
#define STATE_TXFULL 0x1u
#define STATE_RXFULL 0x2u
#define STATE_RXOVERRUN 0x8u
#define CTRL_TX_EN 0x1u
#define CTRL_RX_EN 0x2u
#define CTRL_RX_INTEN 0x8u
#define INT_RX 0x2u
#define UART0_RX_IRQ 0u /* NVIC line; the TX interrupt is line 1 */

#define TIMER0_CTRL (*(volatile uint32_t *)0x40000000u)
#define TIMER0_VALUE (*(volatile uint32_t *)0x40000004u)
#define TIMER0_RELOAD (*(volatile uint32_t *)0x40000008u)
#define TIMER_EN 0x1u
#define TIMER_HZ BOARD_CPU_HZ

#define NVIC_ISER0 (*(volatile uint32_t *)0xE000E100u)
#define NVIC_ICER0 (*(volatile uint32_t *)0xE000E180u)
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

static tase_bm_uart_t *rx_uart;
static volatile board_stats_t stats;
static volatile uint32_t woken; /* an interrupt since the last board_sleep */
static uint32_t clock_last;     /* TIMER0 value at the last board_millis */
/* timer cycles since board_init, from BOARD_CLOCK_START_MS (a product's
 * clock is not at 0 when a mission starts, and wraps after 49.7 days:
 * the checks start it 4 s before the wrap) */
#ifndef BOARD_CLOCK_START_MS
#define BOARD_CLOCK_START_MS 0u
#endif
static uint64_t clock_cycles = (uint64_t)BOARD_CLOCK_START_MS * (TIMER_HZ / 1000u);

void SysTick_Handler(void)
{
    stats.ticks++;
    woken = 1u;
}

/* Receive interrupt: the UART holds one byte. Clear the interrupt first,
 * then take every byte there is: a byte that arrives after the last read
 * raises the interrupt again. */
void UART0_RX_Handler(void)
{
    uint32_t state;
    stats.rx_irqs++;
    woken = 1u;
    UART_INTSTATUS = INT_RX;
    while (((state = UART_STATE) & STATE_RXFULL) != 0u) {
        if ((state & STATE_RXOVERRUN) != 0u) {
            stats.rx_overruns++;
            UART_STATE = STATE_RXOVERRUN; /* write 1 to clear */
        }
        tase_bm_uart_rx_isr(rx_uart, (uint8_t)UART_DATA);
    }
}

void board_init(tase_bm_uart_t *uart)
{
    rx_uart = uart;
    TIMER0_RELOAD = 0xFFFFFFFFu;
    TIMER0_VALUE = 0xFFFFFFFFu;
    TIMER0_CTRL = TIMER_EN;
    clock_last = TIMER0_VALUE;
    SYST_RVR = BOARD_CPU_HZ / 1000u - 1u;
    SYST_CVR = 0u;
    SYST_CSR = 7u; /* processor clock, interrupt, enable */
    UART_BAUDDIV = BOARD_CPU_HZ / BOARD_BAUD;
    UART_CTRL = CTRL_TX_EN | CTRL_RX_EN | CTRL_RX_INTEN;
    NVIC_ISER0 = 1u << UART0_RX_IRQ;
}

void board_stop(void)
{
    NVIC_ICER0 = 1u << UART0_RX_IRQ;
    UART_CTRL = 0u;
    SYST_CSR = 0u;
}

uint32_t board_millis(void *hw)
{
    uint32_t v = TIMER0_VALUE;
    (void)hw;
    clock_cycles += (uint32_t)(clock_last - v); /* it counts down */
    clock_last = v;
    return (uint32_t)(clock_cycles / (TIMER_HZ / 1000u));
}

int board_uart_tx(void *hw, const uint8_t *data, size_t n)
{
    size_t i;
    (void)hw;
    for (i = 0; i < n; i++) {
        uint32_t start = board_millis(hw);
        while ((UART_STATE & STATE_TXFULL) != 0u) {
            if ((uint32_t)(board_millis(hw) - start) >= BOARD_TX_TIMEOUT_MS) {
                stats.tx_timeouts++;
                return TASE_EIO;
            }
        }
        UART_DATA = data[i];
    }
    return 0;
}

void board_sleep(void)
{
    __asm__ volatile("cpsid i" ::: "memory");
    if (woken == 0u) {
        __asm__ volatile("wfi"); /* a pending interrupt wakes it even masked */
    }
    woken = 0u;
    __asm__ volatile("cpsie i" ::: "memory");
}

board_stats_t board_stats(void)
{
    board_stats_t s;
    s.ticks = stats.ticks;
    s.rx_irqs = stats.rx_irqs;
    s.rx_overruns = stats.rx_overruns;
    s.tx_timeouts = stats.tx_timeouts;
    return s;
}
