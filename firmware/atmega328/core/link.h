/* Link-loss timer: the motors stop when no valid frame arrives for timeout_ms. */
#ifndef LINK_H
#define LINK_H

#include <stdint.h>

struct link {
    uint32_t last_heard_ms; /* time of the last frame with a good CRC */
    uint16_t timeout_ms;
    uint8_t lost;           /* the motors were stopped for link loss (STATUS LINK_LOST) */
};

void link_init(struct link *l, uint32_t now_ms, uint16_t timeout_ms);
void link_heard(struct link *l, uint32_t now_ms);
uint8_t link_expired(const struct link *l, uint32_t now_ms);

#endif
