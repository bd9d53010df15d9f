/* libFuzzer target for the frame parser (protocol/c/frame.c), built with ASan and UBSan:
 *
 *   clang -fsanitize=fuzzer,address,undefined -Iprotocol/c tests/c/fuzz_parser.c protocol/c/frame.c
 *
 * Invariants, beyond the sanitizers': every frame handed over has LEN <= PROTO_MAX_PAYLOAD and a
 * payload inside the parser's buffer, re-encodes to bytes that came in, in a row (START ... CRC),
 * and the counters only grow, one frame at most counted per START seen. abort() on a violation: libFuzzer reports it. */
#define _GNU_SOURCE /* memmem */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "frame.h"

struct seen {
    const uint8_t *data; /* the input */
    size_t at;           /* index of the byte being fed */
    unsigned frames;
    const struct frame_parser *parser;
};

static void on_frame(void *ctx, const struct frame *f)
{
    struct seen *s = ctx;
    if (f->len > PROTO_MAX_PAYLOAD)
        abort();
    const uint8_t *lo = s->parser->buf, *hi = s->parser->buf + sizeof s->parser->buf;
    if (f->payload < lo || f->payload + f->len > hi)
        abort();
    uint8_t out[PROTO_FRAME_MAX];
    uint8_t n = frame_encode(out, f->seq, f->id, f->payload, f->len);
    /* a good frame's bytes are in the input, in a row, up to the byte being fed (a frame found
     * by searching a rejected frame's bytes again may end before it) */
    if (!memmem(s->data, s->at + 1, out, n))
        abort();
    s->frames++;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct frame_parser p;
    frame_parser_init(&p);
    struct seen s = {data, 0, 0, &p};
    unsigned starts = 0;
    uint32_t before = 0;
    for (s.at = 0; s.at < size; s.at++) {
        starts += data[s.at] == PROTO_START;
        uint8_t rejected = frame_parse_byte(&p, data[s.at], on_frame, &s);
        uint32_t counted = (uint32_t)p.good_frames + p.crc_errors + p.framing_errors;
        if (counted < before || p.crc_errors < rejected || counted > starts)
            abort();
        before = counted;
    }
    if (s.frames != p.good_frames)
        abort();
    return 0;
}
