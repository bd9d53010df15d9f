/* ATmega328P entry: set up the AVR layer, then feed received bytes and the clock to the core.
 * The watchdog is fed only here: in the main loop and in the receive drain loop. */
#include <avr/interrupt.h>
#include <avr/sleep.h>
#include <avr/wdt.h>

#include "../core/robot.h"
#include "clock.h"
#include "motors.h"
#include "reset.h"
#include "uart.h"

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
        wdt_reset();
        int16_t byte;
        while ((byte = uart_read()) >= 0) {
            wdt_reset(); /* line-rate traffic keeps this loop busy: feed here too */
            robot_rx_byte((uint8_t)byte, clock_ms());
        }
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
