/* Drive state and acceleration limit; see drive.h. */
#include "drive.h"

void drive_init(struct drive *d)
{
    d->target[DRIVE_LEFT] = d->target[DRIVE_RIGHT] = 0;
    d->applied[DRIVE_LEFT] = d->applied[DRIVE_RIGHT] = 0;
    d->accel_limit = 0;
    d->budget = 0;
}

void drive_command(struct drive *d, int16_t left, int16_t right)
{
    d->target[DRIVE_LEFT] = left;
    d->target[DRIVE_RIGHT] = right;
}

void drive_stop(struct drive *d)
{
    /* a stop is never ramped: it is how safety acts */
    drive_command(d, 0, 0);
    d->applied[DRIVE_LEFT] = d->applied[DRIVE_RIGHT] = 0;
    d->budget = 0;
}

static int16_t approach(int16_t from, int16_t to, uint16_t step)
{
    if (to > from)
        return (uint16_t)(to - from) > step ? (int16_t)(from + step) : to;
    return (uint16_t)(from - to) > step ? (int16_t)(from - step) : to;
}

uint8_t drive_tick(struct drive *d, uint16_t elapsed_ms)
{
    uint16_t step = 2000; /* more than any change: no limit */
    if (d->accel_limit) {
        /* accel_limit permille per 100 ms = accel_limit / 100 permille per ms */
        uint32_t budget = d->budget + (uint32_t)d->accel_limit * elapsed_ms;
        step = budget / 100 > 2000 ? 2000 : (uint16_t)(budget / 100);
        d->budget = drive_ramping(d) ? (uint16_t)(budget - (uint32_t)step * 100) : 0;
    }
    uint8_t changed = 0;
    for (uint8_t m = DRIVE_LEFT; m <= DRIVE_RIGHT; m++) {
        int16_t next = approach(d->applied[m], d->target[m], step);
        changed |= next != d->applied[m];
        d->applied[m] = next;
    }
    return changed;
}

uint8_t drive_ramping(const struct drive *d)
{
    return d->applied[DRIVE_LEFT] != d->target[DRIVE_LEFT] ||
           d->applied[DRIVE_RIGHT] != d->target[DRIVE_RIGHT];
}
