/* Drive state: commanded and applied duty of both motors, the acceleration limit, and the coast
 * interval that every pass through zero must sit out before the bridge is driven again. */
#ifndef DRIVE_H
#define DRIVE_H

#include <stdint.h>

enum { DRIVE_LEFT, DRIVE_RIGHT };

struct drive {
    int16_t target[2];    /* commanded duty, permille */
    int16_t applied[2];   /* duty applied to the motors now, permille */
    uint16_t coast_ms[2]; /* ms the motor must still stay at zero (bridge off) */
    uint16_t accel_limit; /* largest change per 100 ms, permille; 0 = none */
    uint8_t budget;       /* the fraction of a permille of ramp not yet spent, in 1/100
                             permille: below 100 by construction, so it cannot wrap */
};

void drive_init(struct drive *d);
void drive_command(struct drive *d, int16_t left, int16_t right);
/* Both motors to zero at once (never ramped: it is how safety acts), then coast. */
void drive_stop(struct drive *d);
/* Move the applied duty towards the target for elapsed_ms: ramped by accel_limit, and a change
 * of direction always goes through zero and PROTO_DEFAULT_REVERSE_COAST_MS of coasting.
 * Returns 1 when the applied duty changed. */
uint8_t drive_tick(struct drive *d, uint16_t elapsed_ms);
uint8_t drive_ramping(const struct drive *d);

#endif
