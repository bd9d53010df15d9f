/* Byte-at-a-time frame parser and encoder; see frame.h. No allocation, no registers. */
#include "frame.h"

#include "crc.h"

void frame_parser_init(struct frame_parser *p)
{
    p->state = FRAME_WAIT_START;
    p->count = 0;
    p->good_frames = 0;
    p->crc_errors = 0;
    p->framing_errors = 0;
    p->last_seq = 0;
    p->last_id = 0;
}

static uint32_t crc_of(const uint8_t *data, uint8_t n)
{
    uint32_t crc = PROTO_CRC_INIT;
    for (uint8_t i = 0; i < n; i++)
        crc = crc_update(crc, data[i]);
    return crc ^ PROTO_CRC_XOROUT;
}

/* The CRC field, little-endian. */
static uint32_t crc_field(const uint8_t *p)
{
    uint32_t crc = 0;
    for (uint8_t i = PROTO_CRC_LEN; i--;)
        crc = crc << 8 | p[i];
    return crc;
}

/* Returns 1 when the byte completed a frame whose CRC failed: the caller searches its bytes
 * again. A completed good frame goes to the handler. */
static uint8_t step(struct frame_parser *p, uint8_t byte, frame_handler handler, void *ctx)
{
    switch (p->state) {
    case FRAME_WAIT_START:
        if (byte == PROTO_START)
            p->state = FRAME_READ_LEN;
        return 0;
    case FRAME_READ_LEN:
        if (byte > PROTO_MAX_PAYLOAD) {
            p->framing_errors++;
            /* the rejected length byte may itself be the START of the next frame */
            p->state = byte == PROTO_START ? FRAME_READ_LEN : FRAME_WAIT_START;
            return 0;
        }
        p->buf[0] = byte;
        p->count = 1;
        p->state = FRAME_READ_BODY;
        return 0;
    default: /* FRAME_READ_BODY */
        p->buf[p->count++] = byte;
        if (p->count < (PROTO_HEADER_LEN - 1u) + p->buf[0] + PROTO_CRC_LEN) /* after START */
            return 0;
        p->state = FRAME_WAIT_START;
        uint8_t n = p->count - PROTO_CRC_LEN;
        uint32_t crc = crc_field(&p->buf[n]);
        if (crc_of(p->buf, n) != crc) {
            p->crc_errors++;
            p->last_seq = p->buf[1];
            p->last_id = p->buf[2];
            return 1;
        }
        p->good_frames++;
        struct frame f = {p->buf[1], p->buf[2], p->buf[0], &p->buf[3]};
        handler(ctx, &f);
        return 0;
    }
}

uint8_t frame_parse_byte(struct frame_parser *p, uint8_t byte, frame_handler handler,
                         void *ctx)
{
    /* Bytes still to examine, in stream order. After a CRC failure the failed frame's bytes
     * (all after its START) go back in front of the queue. Bytes in the parser's buffer plus
     * bytes in the queue never grow (a failure moves the one into the other), and start at
     * most PROTO_FRAME_MAX - 2 plus the new byte, so the queue never overflows. */
    uint8_t queue[PROTO_FRAME_MAX];
    uint8_t head = 0, tail = 0, rejected = 0;
    queue[tail++] = byte;
    while (head < tail) {
        uint8_t b = queue[head++];
        if (!step(p, b, handler, ctx))
            continue;
        rejected++;
        uint8_t rest = tail - head;
        uint8_t again = p->count;
        for (uint8_t i = 0; i < rest; i++) /* keep the unexamined bytes after the replay */
            queue[again + i] = queue[head + i];
        for (uint8_t i = 0; i < again; i++)
            queue[i] = p->buf[i];
        head = 0;
        tail = again + rest;
    }
    return rejected;
}

uint8_t frame_encode(uint8_t *out, uint8_t seq, uint8_t id, const uint8_t *payload,
                     uint8_t len)
{
    out[0] = PROTO_START;
    out[1] = len;
    out[2] = seq;
    out[3] = id;
    for (uint8_t i = 0; i < len; i++)
        out[4 + i] = payload[i];
    uint32_t crc = crc_of(&out[1], (uint8_t)(3 + len));
    for (uint8_t i = 0; i < PROTO_CRC_LEN; i++, crc >>= 8)
        out[4 + len + i] = (uint8_t)crc;
    return (uint8_t)(len + PROTO_HEADER_LEN + PROTO_CRC_LEN);
}
