/* Native test driver: one hex-encoded input a line on stdin; for each, prints the frames the
 * firmware's parser decodes and its counters, in the form tests/protocol/test_vectors.py
 * compares with protocol/vectors.json. */
#include <stdio.h>
#include <string.h>

#include "frame.h"
#include "protocol_format_gen.h"

static void on_frame(void *ctx, const struct frame *f)
{
    (void)ctx;
    char text[256];
    uint8_t err = proto_check(f->id, f->payload, f->len);
    if (err)
        snprintf(text, sizeof text, "error %s", proto_error_name(err));
    else
        proto_format(f->id, f->payload, text, sizeof text);
    printf("frame %u %u ", f->seq, f->id);
    for (uint8_t i = 0; i < f->len; i++)
        printf("%02x", f->payload[i]);
    printf(" %s\n", text);
}

int main(void)
{
    static char line[8192];
    while (fgets(line, sizeof line, stdin)) {
        struct frame_parser p;
        frame_parser_init(&p);
        size_t n = strcspn(line, "\r\n");
        for (size_t i = 0; i + 1 < n; i += 2) {
            unsigned byte;
            if (sscanf(&line[i], "%2x", &byte) != 1)
                return 2;
            frame_parse_byte(&p, (uint8_t)byte, on_frame, NULL);
        }
        printf("counters %u %u %u\n", p.good_frames, p.crc_errors, p.framing_errors);
        fflush(stdout);
    }
    return 0;
}
