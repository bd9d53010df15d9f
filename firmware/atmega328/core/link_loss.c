/* Link-loss guard; see link_loss.h. Times are unsigned ms, compared by difference (wrap-safe). */
#include "link_loss.h"

void link_loss_init(struct link_loss *l, uint32_t now_ms, uint16_t timeout_ms)
{
    l->heard_ms = now_ms;
    l->timeout_ms = timeout_ms;
    l->armed = 0;
    l->tripped = 0;
    l->lost = 0;
}

void link_loss_heard(struct link_loss *l, uint32_t now_ms)
{
    l->heard_ms = now_ms;
    l->armed = 1;
    l->lost = 0;
}

uint8_t link_loss_expired(const struct link_loss *l, uint32_t now_ms)
{
    /* strictly more: the ms clock may tick just after the frame arrived, so "more than
     * timeout ticks" is the first moment at which at least timeout_ms have surely passed */
    return l->armed && now_ms - l->heard_ms > l->timeout_ms;
}
