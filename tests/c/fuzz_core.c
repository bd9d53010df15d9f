/* libFuzzer target for the firmware core (firmware/atmega328/core with protocol/c/frame.c) on a
 * mock board that checks the safety rules at every motor output, built with ASan and UBSan:
 *
 *   clang -fsanitize=fuzzer,address,undefined -Iprotocol/c tests/c/fuzz_core.c \
 *         firmware/atmega328/core/{robot,drive,link_loss}.c \
 *         firmware/atmega328/emu/single_thread.c protocol/c/frame.c
 *
 * (tools/fuzz.py builds it; the board's lock and receive counter are the emulator's,
 * emu/single_thread.c: the fuzzer calls the core from one thread and hands it bytes straight.)
 *
 * The input is a program of operations, one byte each (and its arguments):
 *   00xxxxxx  a well-formed frame: SEQ, then 4 bytes of payload; the message is xxxxxx % 8
 *             (HELLO, SET_DRIVE x3, STOP, SET_CONFIG, GET_STATUS, and a robot-to-host ACK),
 *             with fields mostly but not always in range; its bytes all arrive at once
 *   01xxxxxx  one raw byte (the next input byte)
 *   10xxxxxx  xxxxxx ms pass, the guard runs every ms (the 1 kHz interrupt), then a pass of the
 *             main loop (robot_tick)
 *   11xxxxxx  xxxxxx ms pass with the guard only: the main loop is stalled
 * Invariants (abort() on a violation, which libFuzzer reports):
 *   - range: every output duty is within -1000..1000;
 *   - reversal: a motor never goes from one direction to the other without zero in between,
 *     and once it has been driven, it stays at zero for reverse_coast_ms before it is driven
 *     again (after a ramp to zero, STOP, or the guard's cut alike);
 *   - link loss: the motors are driven only while an accepted SET_DRIVE is at most
 *     link_timeout_ms old. A shadow parser reads the same bytes (with the same frame gap) and
 *     takes every valid SET_DRIVE as accepted: the robot's own deadline can only be older, so
 *     any other frame restarting it would show here. The timeout is the one the guard last ran
 *     with: a SET_CONFIG that shortens it below the age of the drive in force is cut at the
 *     guard's next tick, within 1 ms, and a main-loop tick in the same ms may still write one
 *     ramp step (the fuzzer's finding set-config-shortens-the-timeout-behind-the-drive; the
 *     guard's resolution is 1 ms anyway, and the guard run from on_set_config as well made the
 *     image 68 B larger, 4160 B of a 4096 B budget: docs/wiring.md, Fuzzing);
 *   - NACK rate: at most NACK_BURST plus one per nack_interval_ms since the start;
 *   - ramp: a change of duty other than a cut to zero is at most accel_limit / 100 permille per
 *     ms since that motor's last change, plus the one permille the budget may carry (each change
 *     is one tick's, and a tick's step is the limit in force times the ms since the last tick). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "../../firmware/atmega328/config.h"
#include "../../firmware/atmega328/core/board.h"
#include "../../firmware/atmega328/core/robot.h"
#include "frame.h"

static struct {
    uint32_t now, start;
    int16_t out[2];
    uint32_t changed_at[2]; /* time of the motor's last output change */
    uint32_t zero_since[2]; /* when it last went to zero from a duty */
    uint8_t was_driven[2];
    /* the shadow reading of the line */
    struct frame_parser shadow;
    uint8_t shadow_rx_ms;
    uint8_t have_drive;
    uint32_t last_drive;
    uint16_t timeout, accel;
    uint16_t guard_timeout; /* the link timeout the guard last ran with */
    uint32_t nacks;
} m;

static void check_deadline(void)
{
    if (!m.out[0] && !m.out[1])
        return;
    if (!m.have_drive || m.now - m.last_drive > m.guard_timeout)
        abort(); /* driven with no SET_DRIVE within the link timeout */
}

static int trace; /* FUZZ_TRACE set: print what happens (to read a finding) */

void board_motor_output(int16_t left, int16_t right)
{
    if (trace)
        fprintf(stderr, "%u ms: motors %d %d\n", (unsigned)(m.now - m.start), left, right);
    int16_t next[2] = {left, right};
    for (int i = 0; i < 2; i++) {
        int16_t from = m.out[i], to = next[i];
        if (to < -1000 || to > 1000)
            abort();
        if (to == from)
            continue;
        if ((from > 0 && to < 0) || (from < 0 && to > 0))
            abort(); /* reversed without passing zero */
        if (from == 0 && m.was_driven[i] && m.now - m.zero_since[i] < PROTO_DEFAULT_REVERSE_COAST_MS)
            abort(); /* driven again before the coast interval ended */
        if (to != 0 && m.accel) {
            uint32_t change = (uint32_t)abs(to - from);
            if (change > (uint32_t)m.accel * (m.now - m.changed_at[i]) / 100 + 1)
                abort(); /* faster than the acceleration limit */
        }
        if (to == 0) {
            m.zero_since[i] = m.now;
        } else {
            m.was_driven[i] = 1;
        }
        m.out[i] = to;
        m.changed_at[i] = m.now;
    }
    check_deadline();
}

void board_tx(const uint8_t *data, uint8_t n)
{
    if (n < PROTO_HEADER_LEN + PROTO_CRC_LEN || data[0] != PROTO_START ||
        data[1] + PROTO_HEADER_LEN + PROTO_CRC_LEN != n)
        abort(); /* the core sends whole frames only */
    if (data[3] == PROTO_MSG_NACK &&
        ++m.nacks > NACK_BURST + (m.now - m.start) / PROTO_DEFAULT_NACK_INTERVAL_MS)
        abort();
}

uint16_t board_tx_dropped(void)
{
    return 0;
}

static void on_shadow(void *ctx, const struct frame *f)
{
    (void)ctx;
    if (proto_check(f->id, f->payload, f->len) || !proto_is_host_to_robot(f->id))
        return;
    if (f->id == PROTO_MSG_SET_DRIVE) {
        m.have_drive = 1;
        m.last_drive = m.now;
    } else if (f->id == PROTO_MSG_SET_CONFIG) {
        struct proto_set_config c;
        proto_set_config_unpack(f->payload, &c);
        m.timeout = c.link_timeout_ms;
        m.accel = c.accel_limit;
    }
}

static void rx(uint8_t byte)
{
    m.shadow_rx_ms = (uint8_t)m.now;
    frame_parse_byte(&m.shadow, byte, on_shadow, 0);
    robot_rx_byte(byte, m.now);
}

static void pass_ms(unsigned ms, int tick)
{
    if (trace && ms)
        fprintf(stderr, "%u ms: %u ms pass%s\n", (unsigned)(m.now - m.start), ms,
                tick ? ", then a tick" : " (main loop stalled)");
    for (unsigned i = 0; i < ms; i++) {
        m.now++;
        m.guard_timeout = m.timeout;
        robot_guard(m.now);
        check_deadline();
    }
    if (!tick)
        return;
    /* the frame gap, as robot_tick applies it (spec rule "Frame gap") */
    if (m.shadow.state != FRAME_WAIT_START &&
        (uint8_t)((uint8_t)m.now - m.shadow_rx_ms) > PROTO_DEFAULT_FRAME_GAP_MS)
        m.shadow.state = FRAME_WAIT_START;
    robot_tick(m.now);
}

static int16_t duty(uint8_t lo, uint8_t hi)
{
    return (int16_t)((int16_t)(uint16_t)(lo | hi << 8) % 1101); /* -1100..1100: some refused */
}

static void frame(uint8_t kind, const uint8_t *arg)
{
    static const uint8_t ids[8] = {PROTO_MSG_HELLO, PROTO_MSG_SET_DRIVE, PROTO_MSG_SET_DRIVE,
                                   PROTO_MSG_SET_DRIVE, PROTO_MSG_STOP, PROTO_MSG_SET_CONFIG,
                                   PROTO_MSG_GET_STATUS, PROTO_MSG_ACK};
    uint8_t id = ids[kind % 8], payload[PROTO_MAX_PAYLOAD] = {0}, len = 0;
    if (id == PROTO_MSG_HELLO) {
        struct proto_hello h = {arg[1] | (uint32_t)arg[2] << 8};
        proto_hello_pack(payload, &h);
        len = PROTO_HELLO_LEN;
    } else if (id == PROTO_MSG_SET_DRIVE) {
        struct proto_set_drive d = {duty(arg[1], arg[2]), duty(arg[3], arg[4])};
        proto_set_drive_pack(payload, &d);
        len = PROTO_SET_DRIVE_LEN;
    } else if (id == PROTO_MSG_SET_CONFIG) {
        uint16_t t = (uint16_t)(arg[1] | arg[2] << 8), a = (uint16_t)(arg[3] | arg[4] << 8);
        struct proto_set_config c = {(uint16_t)(40 + t % 5000), (uint16_t)(a % 10100)};
        proto_set_config_pack(payload, &c);
        len = PROTO_SET_CONFIG_LEN;
    } else if (id == PROTO_MSG_ACK) {
        len = PROTO_ACK_LEN;
    }
    uint8_t out[PROTO_FRAME_MAX];
    uint8_t n = frame_encode(out, arg[0], id, payload, len);
    if (trace) {
        fprintf(stderr, "%u ms: frame seq %u id %02x", (unsigned)(m.now - m.start), arg[0], id);
        for (uint8_t i = 0; i < len; i++)
            fprintf(stderr, " %02x", payload[i]);
        fputc('\n', stderr);
    }
    for (uint8_t i = 0; i < n; i++)
        rx(out[i]);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    m = (__typeof__(m)){0};
    trace = getenv("FUZZ_TRACE") != NULL;
    m.now = m.start = 1000;
    m.timeout = m.guard_timeout = PROTO_DEFAULT_LINK_TIMEOUT_MS;
    m.accel = PROTO_DEFAULT_ACCEL_LIMIT;
    frame_parser_init(&m.shadow);
    robot_init(PROTO_RESET_CAUSE_POWER_ON, m.now);
    for (size_t i = 0; i < size;) {
        uint8_t op = data[i++];
        switch (op >> 6) {
        case 0:
            if (size - i < 5)
                return 0;
            frame(op & 0x3F, data + i);
            i += 5;
            break;
        case 1:
            if (i < size)
                rx(data[i++]);
            break;
        case 2:
            pass_ms(op & 0x3F, 1);
            break;
        default:
            pass_ms(op & 0x3F, 0);
            break;
        }
    }
    pass_ms(PROTO_SET_CONFIG_LINK_TIMEOUT_MS_MAX + 2, 1); /* silence: the link-loss stop comes */
    if (m.out[0] || m.out[1])
        abort();
    return 0;
}
