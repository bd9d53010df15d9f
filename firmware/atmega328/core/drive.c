/* Drive state, acceleration limit and reversal through a coast interval; see drive.h. */
#include "drive.h"

#include "protocol_gen.h"

void drive_init(struct drive *d)
{
    for (uint8_t m = DRIVE_LEFT; m <= DRIVE_RIGHT; m++)
        d->target[m] = d->applied[m] = 0, d->coast_ms[m] = 0;
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
    drive_command(d, 0, 0);
    for (uint8_t m = DRIVE_LEFT; m <= DRIVE_RIGHT; m++) {
        if (d->applied[m])
            d->coast_ms[m] = PROTO_DEFAULT_REVERSE_COAST_MS;
        d->applied[m] = 0;
    }
    d->budget = 0;
}

static int16_t approach(int16_t from, int16_t to, uint16_t step)
{
    if (to > from)
        return (uint16_t)(to - from) > step ? (int16_t)(from + step) : to;
    return (uint16_t)(from - to) > step ? (int16_t)(from - step) : to;
}

/* Where motor m may head now: towards zero first when the target has the other sign, and
 * nowhere while it is still coasting at zero. */
static int16_t goal(const struct drive *d, uint8_t m)
{
    int16_t from = d->applied[m], to = d->target[m];
    if ((from > 0 && to < 0) || (from < 0 && to > 0))
        return 0;
    if (from == 0 && d->coast_ms[m])
        return 0;
    return to;
}

uint8_t drive_tick(struct drive *d, uint16_t elapsed_ms)
{
    uint16_t step = 2000; /* more than any change: no limit */
    if (d->accel_limit) {
        /* accel_limit permille per 100 ms = accel_limit / 100 permille per ms */
        uint32_t budget = d->budget + (uint32_t)d->accel_limit * elapsed_ms;
        step = budget / 100 > 2000 ? 2000 : (uint16_t)(budget / 100);
        /* only the fraction of a permille is carried: a capped step (a long tick) moves as
         * far as any change can, and what it did not spend is not owed to the next tick */
        d->budget = drive_ramping(d) ? (uint8_t)(budget % 100) : 0;
    }
    uint8_t changed = 0;
    for (uint8_t m = DRIVE_LEFT; m <= DRIVE_RIGHT; m++) {
        int16_t next = approach(d->applied[m], goal(d, m), step);
        /* counted down after the move: zero was reached somewhere within the last tick, so the
         * motor leaves it only once more than the coast interval has surely passed */
        if (d->applied[m] && !next)
            d->coast_ms[m] = PROTO_DEFAULT_REVERSE_COAST_MS;
        else if (!next)
            d->coast_ms[m] = d->coast_ms[m] > elapsed_ms ? d->coast_ms[m] - elapsed_ms : 0;
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
