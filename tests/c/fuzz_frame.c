/* Randomised and mutation testing of the frame parser, built with ASan and UBSan.
 *
 *   fuzz_frame ITERATIONS SEED
 *
 * Each iteration runs three checks: a random byte stream (the parser must not fault, and every
 * frame it hands over must have a valid length); a valid frame hit by a burst error of 1..16
 * bits (CRC-32C, like every CRC of 32 bits, detects every burst of up to 32 bits: an accepted
 * different frame is a failure); and random garbage, a valid frame, then padding (the frame must
 * come out, unless garbage formed a frame with a good CRC by chance, which is counted). It also
 * corrupts 2..4 bytes at random places, outside the burst guarantee, and reports how many of
 * those were accepted.
 * Exit status 1 when a check fails. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "frame.h"

static uint64_t rng_state;

static uint32_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 11);
}

struct capture {
    uint8_t count;
    uint8_t valid_messages; /* frames that also pass the message check (id, length, range) */
    struct frame last;
    uint8_t payload[PROTO_MAX_PAYLOAD];
};

static void on_frame(void *ctx, const struct frame *f)
{
    struct capture *c = ctx;
    if (f->len > PROTO_MAX_PAYLOAD)
        abort();
    c->count++;
    c->valid_messages += proto_check(f->id, f->payload, f->len) == 0;
    c->last = *f;
    memcpy(c->payload, f->payload, f->len);
}

static uint8_t random_frame(uint8_t *out, uint8_t *payload, uint8_t *len)
{
    *len = (uint8_t)(rnd() % (PROTO_MAX_PAYLOAD + 1));
    for (uint8_t i = 0; i < *len; i++)
        payload[i] = (uint8_t)rnd();
    return frame_encode(out, (uint8_t)rnd(), (uint8_t)rnd(), payload, *len);
}

static int same(const struct capture *c, const uint8_t *frame, const uint8_t *payload, uint8_t len)
{
    return c->last.seq == frame[2] && c->last.id == frame[3] && c->last.len == len &&
           memcmp(c->payload, payload, len) == 0;
}

static uint64_t feed(struct frame_parser *p, const uint8_t *data, size_t n, struct capture *c)
{
    for (size_t i = 0; i < n; i++)
        frame_parse_byte(p, data[i], on_frame, c);
    return n;
}

int main(int argc, char **argv)
{
    long iterations = argc > 1 ? atol(argv[1]) : 100000;
    rng_state = argc > 2 ? strtoull(argv[2], NULL, 0) : 88172645463325252ULL;
    if (!rng_state)
        rng_state = 1;
    uint8_t frame[PROTO_FRAME_MAX], payload[PROTO_MAX_PAYLOAD], buf[256];
    uint64_t bytes = 0, burst_accepted = 0, multi_accepted = 0, lost = 0;
    uint64_t junk_frames = 0, junk_messages = 0;
    clock_t t0 = clock();
    for (long it = 0; it < iterations; it++) {
        struct frame_parser p;
        struct capture c = {0};
        uint8_t len, n;

        /* 1: random stream */
        frame_parser_init(&p);
        n = (uint8_t)(rnd() % 200);
        for (uint8_t i = 0; i < n; i++)
            buf[i] = (rnd() % 8) ? (uint8_t)rnd() : PROTO_START;
        bytes += feed(&p, buf, n, &c);

        /* 2: burst error of 1..16 bits inside one valid frame */
        frame_parser_init(&p);
        memset(&c, 0, sizeof c);
        n = random_frame(frame, payload, &len);
        uint32_t bits = 1 + rnd() % 16, at = rnd() % (8u * n - bits + 1);
        uint32_t pattern = (1u << (bits - 1)) | (rnd() & ((1u << (bits - 1)) - 1)) | 1u;
        for (uint32_t b = 0; b < bits; b++)
            if (pattern >> b & 1)
                frame[(at + b) / 8] ^= (uint8_t)(1u << ((at + b) % 8));
        bytes += feed(&p, frame, n, &c);
        if (c.count && !same(&c, frame, payload, len))
            burst_accepted++;

        /* 3: 2..4 bytes replaced at random places (no guarantee: counted, not failed) */
        frame_parser_init(&p);
        memset(&c, 0, sizeof c);
        n = random_frame(frame, payload, &len);
        uint8_t copy[PROTO_FRAME_MAX];
        memcpy(copy, frame, n);
        uint8_t hits = (uint8_t)(2 + rnd() % 3);
        for (uint8_t h = 0; h < hits; h++)
            copy[rnd() % n] ^= (uint8_t)(1 + rnd() % 255);
        if (memcmp(copy, frame, n)) {
            bytes += feed(&p, copy, n, &c);
            if (c.count && !same(&c, frame, payload, len))
                multi_accepted++;
        }

        /* 4: garbage, a valid frame, then padding that completes any false frame */
        frame_parser_init(&p);
        memset(&c, 0, sizeof c);
        uint8_t g = (uint8_t)(rnd() % 64);
        for (uint8_t i = 0; i < g; i++)
            buf[i] = (rnd() % 4) ? (uint8_t)rnd() : PROTO_START;
        n = random_frame(frame, payload, &len);
        memcpy(&buf[g], frame, n);
        memset(&buf[g + n], 0, PROTO_FRAME_MAX);
        bytes += feed(&p, buf, g + n + PROTO_FRAME_MAX, &c);
        if (c.count && same(&c, frame, payload, len)) {
            junk_frames += c.count - 1u;
        } else if (c.count) {
            /* garbage formed a frame with a good CRC by chance (about 2^-32 per false START)
             * and it took the real frame's first bytes: the CRC's limit, not a parser fault */
            junk_frames += c.count;
            junk_messages += c.valid_messages;
        } else {
            lost++;
        }
    }
    double s = (double)(clock() - t0) / CLOCKS_PER_SEC;
    printf("iterations %ld bytes %llu seconds %.2f bytes_per_second %.0f\n", iterations,
           (unsigned long long)bytes, s, s > 0 ? bytes / s : 0.0);
    printf("burst_corruptions %ld accepted %llu\n", iterations, (unsigned long long)burst_accepted);
    printf("multibyte_corruptions %ld accepted %llu\n", iterations,
           (unsigned long long)multi_accepted);
    printf("frames_after_garbage %ld lost %llu\n", iterations, (unsigned long long)lost);
    printf("garbage_frames_with_good_crc %llu of_them_valid_messages %llu\n",
           (unsigned long long)junk_frames, (unsigned long long)junk_messages);
    return burst_accepted || lost ? 1 : 0;
}
