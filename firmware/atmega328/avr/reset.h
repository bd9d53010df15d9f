/* Why the chip last reset, saved before anything else runs. */
#ifndef RESET_H
#define RESET_H

#include <stdint.h>

/* proto_reset_cause of the last reset. */
uint8_t reset_cause(void);

#endif
