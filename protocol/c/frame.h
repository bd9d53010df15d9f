/* Framing of the serial protocol (docs/protocol.md): a byte-at-a-time parser with a fixed
 * buffer, and the encoder. Knows no registers: the firmware, the emulator and the native tests
 * compile this same file. */
#ifndef FRAME_H
#define FRAME_H

#include <stdint.h>

#include "protocol_gen.h"

/* A frame as the handler sees it; payload points into the parser and is valid during the call. */
struct frame {
    uint8_t seq;
    uint8_t id;
    uint8_t len;
    const uint8_t *payload;
};

typedef void (*frame_handler)(void *ctx, const struct frame *f);

enum frame_state {
    FRAME_WAIT_START, /* looking for PROTO_START */
    FRAME_READ_LEN,   /* the byte after START: the payload length */
    FRAME_READ_BODY,  /* SEQ ID PAYLOAD CRC, until the length says the frame is complete */
};

struct frame_parser {
    uint8_t state;
    uint8_t count;                            /* bytes in buf */
    uint8_t buf[PROTO_FRAME_MAX - 1];         /* LEN SEQ ID PAYLOAD CRC (START not kept) */
    uint16_t good_frames;
    uint16_t crc_errors;
    uint16_t framing_errors;
    uint8_t last_seq;     /* SEQ and ID of the last frame rejected for its CRC, for a NACK */
    uint8_t last_id;
};

void frame_parser_init(struct frame_parser *p);

/* Feed one received byte; calls handler once for every frame it completes with a good CRC
 * (a rejected frame's bytes are searched again, so one byte may complete more than one).
 * Returns the number of frames rejected for a bad CRC while handling this byte. */
uint8_t frame_parse_byte(struct frame_parser *p, uint8_t byte, frame_handler handler,
                         void *ctx);

/* Write a whole frame into out (at least PROTO_FRAME_MAX bytes); returns its length. */
uint8_t frame_encode(uint8_t *out, uint8_t seq, uint8_t id, const uint8_t *payload,
                     uint8_t len);

#endif
