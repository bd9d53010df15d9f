/* Timer0 in CTC mode interrupts at 1 kHz: F_CPU / 64 / (OCR0A + 1) = 16 MHz / 64 / 250. Each tick
 * also runs the core's link-loss guard, so the motor cut never waits for the main loop.
 * Nothing wider than a byte is shared with the main loop: the interrupt keeps its own 32-bit ms
 * count and bumps an 8-bit tick counter, from which clock_ms keeps the main loop's copy of the
 * same count. That holds while clock_ms runs at least every 255 ms, which the watchdog (a pass
 * of the main loop completes within its timeout, and each pass reads the clock) guarantees. */
#include "clock.h"

#include <avr/interrupt.h>
#include <avr/io.h>

#include "../core/robot.h"

static volatile uint8_t ticks; /* one byte: read by the main loop in one instruction */
static uint32_t isr_ms;        /* the interrupt's own */
static uint32_t main_ms;       /* the main loop's own */
static uint8_t seen;           /* ticks when main_ms was last brought up to date */

void clock_init(void)
{
    TCCR0A = _BV(WGM01);
    OCR0A = (uint8_t)(F_CPU / 64 / 1000 - 1);
    TCCR0B = _BV(CS01) | _BV(CS00);
    TIMSK0 = _BV(OCIE0A);
}

ISR(TIMER0_COMPA_vect)
{
    ticks++;
    robot_guard(++isr_ms);
}

uint32_t clock_ms(void)
{
    uint8_t now = ticks;
    main_ms += (uint8_t)(now - seen);
    seen = now;
    return main_ms;
}
