/* Reset cause and watchdog at start-up. After a watchdog reset the watchdog stays enabled with
 * its shortest timeout, so it must be turned off before the C runtime's start-up can overrun
 * it: this runs in .init3, before .data and .bss are set up. `used` keeps link-time
 * optimisation from dropping it (nothing calls it). */
#include "reset.h"

#include <avr/io.h>
#include <avr/wdt.h>

#include "protocol_gen.h"

static uint8_t saved_mcusr __attribute__((section(".noinit")));

void reset_save_cause(void) __attribute__((naked, used, section(".init3")));
void reset_save_cause(void)
{
    uint8_t flags = MCUSR;
    if (!flags) /* optiboot clears MCUSR, handing its value over in r2 */
        __asm__ __volatile__("mov %0, r2" : "=r"(flags));
    saved_mcusr = flags;
    MCUSR = 0;
    wdt_disable();
}

uint8_t reset_cause(void)
{
    if (saved_mcusr & _BV(WDRF))
        return PROTO_RESET_CAUSE_WATCHDOG;
    if (saved_mcusr & _BV(BORF))
        return PROTO_RESET_CAUSE_BROWN_OUT;
    if (saved_mcusr & _BV(EXTRF))
        return PROTO_RESET_CAUSE_EXTERNAL;
    if (saved_mcusr & _BV(PORF))
        return PROTO_RESET_CAUSE_POWER_ON;
    return PROTO_RESET_CAUSE_UNKNOWN;
}
