/* What the two simavr programs share (harness.c runs the firmware ELF for the tests, uno.c is the
 * simulated Uno): the ATmega328P's clock, UART0 wired to the program with its flow control,
 * simavr's sleeping off, the wall clock. Each program includes it once (one translation unit
 * each); host/emulator/build.py rebuilds both when it changes. */
#ifndef SIMAVR_COMMON_H
#define SIMAVR_COMMON_H

#include <stdint.h>
#include <time.h>

#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>

#define F_CPU 16000000UL

/* UART0 seen from outside the chip: bytes go in through `in`; xon is 1 while the UART can take
 * one (simavr's XON/XOFF), so a byte fed only then never overruns it. */
struct uart0 {
    avr_irq_t *in;
    int xon;
};

static void uart0_xon(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq, (void)value;
    ((struct uart0 *)param)->xon = 1;
}

static void uart0_xoff(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq, (void)value;
    ((struct uart0 *)param)->xon = 0;
}

/* Wire UART0: each byte the firmware sends goes to on_tx; simavr's console echo and its sleeping
 * on each empty poll of RXC are off (that sleep slows a program that polls the UART far below
 * real time: shared simavr notes). */
static void uart0_wire(avr_t *avr, struct uart0 *uart, avr_irq_notify_t on_tx)
{
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    uart->in = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            on_tx, NULL);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XON),
                            uart0_xon, uart);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF),
                            uart0_xoff, uart);
}

/* For avr->sleep: simavr's own sleep waits in real time while the AVR sleeps; these programs
 * either run as fast as they can or follow the wall clock with a throttle of their own. */
static void no_sleep(avr_t *avr, avr_cycle_count_t how_long)
{
    (void)avr, (void)how_long;
}

static double wall(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

#endif
