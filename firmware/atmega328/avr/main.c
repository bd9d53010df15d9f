/* ATmega328P entry: set up the AVR layer, then feed received bytes and the clock to the core.
 * Each main-loop pass hands the core at most RX_BYTES_PER_PASS bytes, so every pass ends in
 * bounded time whatever arrives; the watchdog is fed once per complete pass, here and nowhere
 * else. The link-loss cut does not wait for the loop: the timer interrupt runs robot_guard. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <avr/wdt.h>

#include "../config.h"
#include "../core/board.h"
#include "../core/robot.h"
#include "clock.h"
#include "motors.h"
#include "reset.h"
#include "uart.h"

uint8_t board_lock(void)
{
    uint8_t state = SREG;
    cli();
    return state;
}

void board_unlock(uint8_t state)
{
    SREG = state;
}

int main(void)
{
    motors_init(); /* motors off before anything can go wrong */
    clock_init();
    uart_init();
    sei();
    robot_init(reset_cause(), clock_ms());
    reset_watchdog_start();
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        wdt_reset(); /* the one feed: a pass that never completes lets the watchdog bite */
        int16_t byte;
        for (uint8_t n = 0; n < RX_BYTES_PER_PASS && (byte = uart_read()) >= 0; n++)
            robot_rx_byte((uint8_t)byte, clock_ms());
        robot_tick(clock_ms());
        /* sleep until the next interrupt (the 1 ms tick at the latest) */
        cli();
        if (!uart_rx_waiting()) {
            sleep_enable();
            sei();
            sleep_cpu();
            sleep_disable();
        }
        sei();
    }
}
