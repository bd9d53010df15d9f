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

/* Interrupt, then reset, at 30 ms periods (32 ms in simavr; the watchdog oscillator's tolerance
 * stretches them on a chip): a hang with interrupts on stops the motors one period after the
 * last feed (the interrupt) and resets the chip one period later; a hang with interrupts held
 * off cannot take the interrupt, and the chip resets at the second time-out. Either way the
 * motors are stopped within two periods of the last feed. A main-loop pass takes at most a few
 * ms (config.h), far inside one period. */
void reset_watchdog_start(void)
{
    wdt_enable(WDTO_30MS);
    WDTCSR |= _BV(WDIE); /* WDE and WDIE: interrupt first, then reset */
}

/* The main loop missed a whole watchdog period: stop the motors now, leave the cause in RAM,
 * and wait here, interrupts off, for the reset at the next time-out (taking this vector cleared
 * WDIE). Never return: a main loop that merely stalled would otherwise go on with the motors
 * cut behind the core's back, the interrupt disarmed and the host told nothing; after the reset
 * it learns of it by BOOT (WATCHDOG), and the drive state starts again from zero. */
ISR(WDT_vect, ISR_NAKED) /* no prologue: it never returns, so nothing needs saving */
{
    __asm__ volatile("clr __zero_reg__"); /* the interrupted code may have left r1 non-zero */
    board_motor_output(0, 0);
    record_mark(MARK_WATCHDOG);
    for (;;)
        ;
}
