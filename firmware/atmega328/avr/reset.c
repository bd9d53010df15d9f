/* Reset cause and watchdog: told apart even behind a bootloader that clears MCUSR (optiboot 4.4).
 *
 * The cause is worked out in .init3, before the C runtime sets up .data and .bss (after a watchdog
 * reset the watchdog stays on at its shortest timeout and must be stopped first). `used` keeps
 * link-time optimisation from dropping it (nothing calls it). In order:
 *   1. MCUSR, when it says anything: with no bootloader (ISP-flashed) and behind optiboot 8,
 *      which leaves the flags there (clearing only the WDRF of its own timeout).
 *   2. The .noinit record, checked with a magic and a complement, which RAM keeps across resets:
 *      the watchdog interrupt marks it WATCHDOG before the watchdog's reset (a hang), and the
 *      firmware marks it RUNNING at each start. No valid record: RAM was lost, the supply went
 *      away: POWER_ON. A RUNNING record behind a silent MCUSR: the reset pin (the Uno's
 *      auto-reset when a port opens, or its button) or a brown-out that kept RAM; optiboot 4.4
 *      leaves no trace of which, so it is UNKNOWN.
 * r2 is not read: optiboot 4.4 hands nothing over in it, so it holds what this firmware's own
 * code left there, and optiboot 8 puts there what it also leaves in MCUSR. See docs/wiring.md. */
#include "reset.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/wdt.h>

#include "../core/board.h"
#include "protocol_gen.h"

#define RECORD_MAGIC 0x5EA7u
#define MARK_RUNNING 0x52u  /* the firmware started */
#define MARK_WATCHDOG 0x57u /* the watchdog caught a hang; its reset follows */

struct reset_record {
    uint16_t magic;
    uint8_t mark;
    uint8_t mark_complement;
};

static struct reset_record record __attribute__((section(".noinit")));
static uint8_t saved_cause __attribute__((section(".noinit")));

static inline void record_mark(uint8_t mark)
{
    record.magic = RECORD_MAGIC;
    record.mark = mark;
    record.mark_complement = (uint8_t)~mark;
}

static inline uint8_t cause_of(uint8_t flags)
{
    if (flags & _BV(WDRF))
        return PROTO_RESET_CAUSE_WATCHDOG;
    if (flags & _BV(BORF))
        return PROTO_RESET_CAUSE_BROWN_OUT;
    if (flags & _BV(EXTRF))
        return PROTO_RESET_CAUSE_EXTERNAL;
    if (flags & _BV(PORF))
        return PROTO_RESET_CAUSE_POWER_ON;
    return PROTO_RESET_CAUSE_UNKNOWN;
}

void reset_save_cause(void) __attribute__((naked, used, section(".init3")));
void reset_save_cause(void)
{
    uint8_t flags = MCUSR;
    MCUSR = 0;
    wdt_disable();
    uint8_t valid = record.magic == RECORD_MAGIC &&
                    (uint8_t)(record.mark ^ record.mark_complement) == 0xFF;
    if (flags)
        saved_cause = cause_of(flags);
    else if (valid && record.mark == MARK_WATCHDOG)
        saved_cause = PROTO_RESET_CAUSE_WATCHDOG;
    else if (!valid)
        saved_cause = PROTO_RESET_CAUSE_POWER_ON;
    else
        saved_cause = PROTO_RESET_CAUSE_UNKNOWN;
    record_mark(MARK_RUNNING);
}

uint8_t reset_cause(void)
{
    return saved_cause;
}

/* Two 60 ms periods: a hang stops the motors after 60 ms (the interrupt, which clears WDIE) and
 * resets the chip 60 ms later, 120 ms after the last feed as before this mode. */
void reset_watchdog_start(void)
{
    wdt_enable(WDTO_60MS);
    WDTCSR |= _BV(WDIE); /* WDE and WDIE: interrupt first, then reset */
}

/* The firmware hung for a watchdog period: stop the motors now and leave the cause in RAM;
 * the next timeout resets the chip (the interrupt cleared WDIE). */
ISR(WDT_vect)
{
    board_motor_output(0, 0);
    record_mark(MARK_WATCHDOG);
}
