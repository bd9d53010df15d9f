/* Link-loss guard: while armed, the motors are cut timeout_ms after the last accepted motion
 * command. link_loss_expired runs in the 1 kHz timer interrupt (robot_guard), the rest in the main
 * loop with interrupts held off (board_lock), so the two never see half-written fields. */
#ifndef LINK_LOSS_H
#define LINK_LOSS_H

#include <stdint.h>

struct link_loss {
    uint32_t heard_ms;   /* time of the last accepted motion command (SET_DRIVE) */
    uint16_t timeout_ms;
    uint8_t armed;       /* a SET_DRIVE is in force: the guard watches the deadline */
    uint8_t tripped;     /* the guard cut the motors; the main loop has not caught up yet */
    uint8_t lost;        /* the motors were stopped for link loss (STATUS LINK_LOST) */
};

void link_loss_init(struct link_loss *l, uint32_t now_ms, uint16_t timeout_ms);
/* An accepted motion command: arm the guard and restart its deadline. */
void link_loss_heard(struct link_loss *l, uint32_t now_ms);
/* Armed and the deadline has passed. */
uint8_t link_loss_expired(const struct link_loss *l, uint32_t now_ms);

#endif
