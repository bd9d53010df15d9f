/* Timer0 in CTC mode interrupts at 1 kHz: F_CPU / 64 / (OCR0A + 1) = 16 MHz / 64 / 250. Each tick
 * also runs the core's link-loss guard, so the motor cut never waits for the main loop. */
#include "clock.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

#include "../core/robot.h"

static volatile uint32_t ms;

void clock_init(void)
{
    TCCR0A = _BV(WGM01);
    OCR0A = (uint8_t)(F_CPU / 64 / 1000 - 1);
    TCCR0B = _BV(CS01) | _BV(CS00);
    TIMSK0 = _BV(OCIE0A);
}

ISR(TIMER0_COMPA_vect)
{
    uint32_t now = ms + 1;
    ms = now;
    robot_guard(now);
}

uint32_t clock_ms(void)
{
    uint32_t now;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { now = ms; }
    return now;
}
