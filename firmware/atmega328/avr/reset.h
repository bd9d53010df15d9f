/* Why the chip last reset, saved before anything else runs. */
#ifndef RESET_H
#define RESET_H

#include <stdint.h>

/* proto_reset_cause of the last reset. */
uint8_t reset_cause(void);

/* Start the watchdog in interrupt-then-reset mode at 30 ms (feed it with wdt_reset()): a pass of
 * the main loop that misses a period stops the motors at the interrupt and leaves WATCHDOG in RAM
 * for the next start, then the chip resets; within two periods either way. */
void reset_watchdog_start(void);

#endif
