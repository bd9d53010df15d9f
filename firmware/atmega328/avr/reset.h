/* Why the chip last reset, saved before anything else runs. */
#ifndef RESET_H
#define RESET_H

#include <stdint.h>

/* proto_reset_cause of the last reset. */
uint8_t reset_cause(void);

/* Start the watchdog in interrupt-then-reset mode (feed it with wdt_reset()): a hang stops the
 * motors at the interrupt and leaves WATCHDOG in RAM for the next start, then the chip resets. */
void reset_watchdog_start(void);

#endif
