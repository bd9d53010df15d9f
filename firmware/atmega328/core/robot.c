/* Command dispatch and robot state; see robot.h. Each handler sits next to the message it
 * serves; layouts, ids and checks come from the generated protocol header. */
#include "robot.h"

#include "../config.h"
#include "board.h"
#include "drive.h"
#include "frame.h"
#include "link.h"

static struct {
    struct frame_parser parser;
    struct drive drive;
    struct link link;
    uint32_t now_ms;
    uint32_t last_tick_ms;
    uint8_t reset_cause;
    uint8_t tx_seq;
    uint8_t driving;    /* a SET_DRIVE is in force */
    uint8_t have_last;  /* last_seq/last_id hold the last applied command */
    uint8_t last_seq;
    uint8_t last_id;
} robot;

static void send(uint8_t id, const uint8_t *payload, uint8_t len)
{
    uint8_t out[PROTO_FRAME_MAX];
    board_tx(out, frame_encode(out, robot.tx_seq++, id, payload, len));
}

static void send_ack(uint8_t seq, uint8_t result)
{
    uint8_t p[PROTO_ACK_LEN];
    struct proto_ack m = {seq, result};
    proto_ack_pack(p, &m);
    send(PROTO_MSG_ACK, p, sizeof p);
}

static void send_nack(uint8_t seq, uint8_t error)
{
    uint8_t p[PROTO_NACK_LEN];
    struct proto_nack m = {seq, error};
    proto_nack_pack(p, &m);
    send(PROTO_MSG_NACK, p, sizeof p);
}

static void output(void)
{
    board_motor_output(robot.drive.applied[DRIVE_LEFT], robot.drive.applied[DRIVE_RIGHT]);
}

static void stop(void)
{
    drive_stop(&robot.drive);
    robot.driving = 0;
    output();
}

static void on_hello(const uint8_t *payload)
{
    struct proto_hello in;
    proto_hello_unpack(payload, &in);
    struct proto_hello_reply m = {in.nonce, PROTO_SCHEMA_HASH, FW_VERSION, robot.reset_cause,
                                  robot.link.timeout_ms};
    uint8_t p[PROTO_HELLO_REPLY_LEN];
    proto_hello_reply_pack(p, &m);
    send(PROTO_MSG_HELLO_REPLY, p, sizeof p);
}

static void on_set_drive(const struct frame *f)
{
    struct proto_set_drive m;
    proto_set_drive_unpack(f->payload, &m);
#ifdef FW_TEST_HANG
    if (m.left == 999 && m.right == -999)
        for (;;) /* test build only: a hang the watchdog must catch */
            ;
#endif
    drive_command(&robot.drive, m.left, m.right);
    robot.driving = 1;
    robot.link.lost = 0;
    if (drive_tick(&robot.drive, 0))
        output();
    send_ack(f->seq, PROTO_ACK_RESULT_APPLIED);
}

static void on_set_config(const struct frame *f)
{
    struct proto_set_config m;
    proto_set_config_unpack(f->payload, &m);
    robot.link.timeout_ms = m.link_timeout_ms;
    robot.drive.accel_limit = m.accel_limit;
    send_ack(f->seq, PROTO_ACK_RESULT_APPLIED);
}

static uint8_t status_flags(void)
{
    return (robot.link.lost ? PROTO_STATUS_LINK_LOST : 0) |
           (robot.reset_cause == PROTO_RESET_CAUSE_WATCHDOG ? PROTO_STATUS_WATCHDOG_RESET : 0) |
           (robot.driving ? PROTO_STATUS_DRIVING : 0) |
           (drive_ramping(&robot.drive) ? PROTO_STATUS_ACCEL_LIMITED : 0);
}

static void on_get_status(void)
{
    struct proto_status m = {
        robot.now_ms, robot.drive.applied[DRIVE_LEFT], robot.drive.applied[DRIVE_RIGHT],
        status_flags(), robot.reset_cause, robot.parser.good_frames, robot.parser.crc_errors,
        robot.parser.framing_errors, robot.link.timeout_ms, robot.drive.accel_limit};
    uint8_t p[PROTO_STATUS_LEN];
    proto_status_pack(p, &m);
    send(PROTO_MSG_STATUS, p, sizeof p);
}

static void dispatch(const struct frame *f)
{
    switch (f->id) {
    case PROTO_MSG_HELLO:
        on_hello(f->payload);
        break;
    case PROTO_MSG_SET_DRIVE:
        on_set_drive(f);
        break;
    case PROTO_MSG_STOP:
        stop();
        send_ack(f->seq, PROTO_ACK_RESULT_APPLIED);
        break;
    case PROTO_MSG_SET_CONFIG:
        on_set_config(f);
        break;
    default: /* PROTO_MSG_GET_STATUS: proto_check admits no other host-to-robot id */
        on_get_status();
        break;
    }
}

static void on_frame(void *ctx, const struct frame *f)
{
    (void)ctx;
    link_heard(&robot.link, robot.now_ms);
    uint8_t error = proto_check(f->id, f->payload, f->len);
    if (!error && !proto_is_host_to_robot(f->id))
        error = PROTO_ERROR_WRONG_DIRECTION;
    if (error) {
        send_nack(f->seq, error);
        return;
    }
    if (f->id == PROTO_MSG_HELLO) {
        robot.have_last = 0; /* a new session numbers its commands afresh */
    } else if (f->id != PROTO_MSG_GET_STATUS) {
        if (robot.have_last && f->seq == robot.last_seq && f->id == robot.last_id) {
            send_ack(f->seq, PROTO_ACK_RESULT_DUPLICATE); /* a resend: do not apply twice */
            return;
        }
        robot.have_last = 1;
        robot.last_seq = f->seq;
        robot.last_id = f->id;
    }
    dispatch(f);
}

void robot_init(uint8_t reset_cause, uint32_t now_ms)
{
    frame_parser_init(&robot.parser);
    drive_init(&robot.drive);
    link_init(&robot.link, now_ms, PROTO_DEFAULT_LINK_TIMEOUT_MS);
    robot.drive.accel_limit = PROTO_DEFAULT_ACCEL_LIMIT;
    robot.now_ms = robot.last_tick_ms = now_ms;
    robot.reset_cause = reset_cause;
    robot.tx_seq = 0;
    robot.have_last = 0;
    stop();
    struct proto_boot m = {reset_cause, FW_VERSION, PROTO_SCHEMA_HASH};
    uint8_t p[PROTO_BOOT_LEN];
    proto_boot_pack(p, &m);
    send(PROTO_MSG_BOOT, p, sizeof p);
}

void robot_rx_byte(uint8_t byte, uint32_t now_ms)
{
    robot.now_ms = now_ms;
    if (frame_parse_byte(&robot.parser, byte, on_frame, 0) &&
        proto_is_host_to_robot(robot.parser.last_id))
        send_nack(robot.parser.last_seq, PROTO_ERROR_BAD_CRC);
}

void robot_tick(uint32_t now_ms)
{
    robot.now_ms = now_ms;
    uint16_t elapsed = (uint16_t)(now_ms - robot.last_tick_ms);
    robot.last_tick_ms = now_ms;
    if (robot.driving && link_expired(&robot.link, now_ms)) {
        robot.link.lost = 1;
        robot.have_last = 0; /* a resend after this stop is applied again, not a duplicate */
        stop();
        return;
    }
    if (drive_tick(&robot.drive, elapsed))
        output();
}
