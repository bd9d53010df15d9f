/* Command dispatch and robot state; see robot.h. Each handler sits next to the message it
 * serves; layouts, ids and checks come from the generated protocol header. */
#include "robot.h"

#include "../config.h"
#include "board.h"
#include "drive.h"
#include "frame.h"
#include "link_loss.h"

/* A resend is recognised by SEQ, ID and the whole payload; commands are at most this long. */
#define LAST_PAYLOAD_MAX 4
_Static_assert(PROTO_SET_DRIVE_LEN <= LAST_PAYLOAD_MAX && PROTO_SET_CONFIG_LEN <= LAST_PAYLOAD_MAX &&
                   PROTO_STOP_LEN <= LAST_PAYLOAD_MAX,
               "a command's payload must fit the resend check");

/* Shared with the timer interrupt (robot_guard): touched in the main loop only under
 * board_lock. */
static struct link_loss link_loss;

static struct {
    struct frame_parser parser;
    struct drive drive;
    uint32_t now_ms;
    uint32_t last_tick_ms;
    uint8_t reset_cause;
    uint8_t tx_seq;
    uint8_t nack_credit; /* NACKs that may still be sent now (NACK_BURST at most) */
    uint8_t nack_ms;     /* ms towards the next credit */
    uint8_t rx_ms;       /* low byte of the time of the last received byte (frame gap) */
    uint16_t link_losses;
    uint8_t have_last;   /* last_* hold the last applied command */
    uint8_t last_seq;
    uint8_t last_id;
    uint8_t last_len;
    uint8_t last_payload[LAST_PAYLOAD_MAX];
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
    if (!robot.nack_credit)
        return; /* rate-limited: a flood of bad frames must not crowd out the answers */
    robot.nack_credit--;
    uint8_t p[PROTO_NACK_LEN];
    struct proto_nack m = {seq, error};
    proto_nack_pack(p, &m);
    send(PROTO_MSG_NACK, p, sizeof p);
}

static void output(void)
{
    /* under the lock the guard cannot cut between the check and the write; once it has cut,
     * only a new accepted SET_DRIVE (link_loss_heard) lets the bridge be driven again */
    uint8_t state = board_lock();
    uint8_t on = link_loss.armed;
    board_motor_output(on ? robot.drive.applied[DRIVE_LEFT] : 0,
                       on ? robot.drive.applied[DRIVE_RIGHT] : 0);
    board_unlock(state);
}

/* One NACK credit back every PROTO_DEFAULT_NACK_INTERVAL_MS, up to NACK_BURST. */
static void refill_nacks(uint16_t elapsed)
{
    uint16_t ms = robot.nack_ms + elapsed;
    while (ms >= PROTO_DEFAULT_NACK_INTERVAL_MS && robot.nack_credit < NACK_BURST) {
        ms -= PROTO_DEFAULT_NACK_INTERVAL_MS;
        robot.nack_credit++;
    }
    robot.nack_ms = robot.nack_credit < NACK_BURST ? (uint8_t)ms : 0;
}

/* The ms since the last call (the NACK budget refilled for them): what the drive may use of
 * them. Called at every tick, and wherever the drive state changes between ticks (STOP, a new
 * SET_DRIVE), so that a coast interval started there is counted from then, not from the last
 * tick before it (the fuzzer's finding: STOP after a long pass coasted 6 ms, not 10). */
static uint16_t advance(void)
{
    uint16_t elapsed = (uint16_t)(robot.now_ms - robot.last_tick_ms);
    robot.last_tick_ms = robot.now_ms;
    refill_nacks(elapsed);
    return elapsed;
}

static void stop(void)
{
    uint8_t state = board_lock();
    link_loss.armed = 0;
    board_unlock(state);
    advance();
    drive_stop(&robot.drive);
    output();
}

static void on_hello(const uint8_t *payload)
{
    struct proto_hello in;
    proto_hello_unpack(payload, &in);
    struct proto_hello_reply m = {in.nonce, PROTO_SCHEMA_HASH, FW_VERSION, robot.reset_cause,
                                  link_loss.timeout_ms};
    uint8_t p[PROTO_HELLO_REPLY_LEN];
    proto_hello_reply_pack(p, &m);
    send(PROTO_MSG_HELLO_REPLY, p, sizeof p);
}

static uint8_t catch_up_guard(void);

static void on_set_drive(const struct frame *f)
{
    struct proto_set_drive m;
    proto_set_drive_unpack(f->payload, &m);
#ifdef FW_TEST_HANG
    if (m.left == 999 && m.right == -999)
        for (;;) /* test build only: a hang the watchdog must catch */
            ;
    if (m.left == 997) /* test build only: a stall of -right ms (330 turns a ms) */
        for (volatile uint32_t i = 0; i < (uint32_t)-m.right * 330UL; i++)
            ;
    if (m.left == 996 && m.right == -996) { /* test build only: a hang with interrupts off */
        board_lock();
        for (;;)
            ;
    }
#endif
    /* a trip since on_frame's catch-up (the deadline of the drive before passed just now) is
     * caught up here, with the timer interrupt held off until the deadline is restarted: none
     * can fall between, to stop this drive after its ACK APPLIED (such a catch-up forgets this
     * command too: a resend of it is applied again, which changes nothing but the ACK) */
    uint8_t state = board_lock();
    catch_up_guard();
    link_loss_heard(&link_loss, robot.now_ms);
    board_unlock(state);
    drive_command(&robot.drive, m.left, m.right);
    drive_tick(&robot.drive, advance());
    output();
    send_ack(f->seq, PROTO_ACK_RESULT_APPLIED);
}

static void on_set_config(const struct frame *f)
{
    struct proto_set_config m;
    proto_set_config_unpack(f->payload, &m);
    uint8_t state = board_lock();
    link_loss.timeout_ms = m.link_timeout_ms;
    board_unlock(state);
    robot.drive.accel_limit = m.accel_limit;
    send_ack(f->seq, PROTO_ACK_RESULT_APPLIED);
}

static uint8_t status_flags(void)
{
    return (link_loss.lost ? PROTO_STATUS_LINK_LOST : 0) |
           (robot.reset_cause == PROTO_RESET_CAUSE_WATCHDOG ? PROTO_STATUS_WATCHDOG_RESET : 0) |
           (link_loss.armed ? PROTO_STATUS_DRIVING : 0) |
           (drive_ramping(&robot.drive) ? PROTO_STATUS_ACCEL_LIMITED : 0);
}

static void on_get_status(void)
{
    struct proto_status m = {
        robot.now_ms, robot.drive.applied[DRIVE_LEFT], robot.drive.applied[DRIVE_RIGHT],
        status_flags(), robot.reset_cause, robot.parser.good_frames, robot.parser.crc_errors,
        robot.parser.framing_errors, link_loss.timeout_ms, robot.drive.accel_limit,
        board_rx_overruns(), board_tx_dropped(), robot.link_losses};
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

/* A command with the SEQ, ID and payload of the last applied one: a resend. */
static uint8_t is_resend(const struct frame *f)
{
    if (!robot.have_last || f->seq != robot.last_seq || f->id != robot.last_id ||
        f->len != robot.last_len)
        return 0;
    for (uint8_t i = 0; i < f->len; i++)
        if (f->payload[i] != robot.last_payload[i])
            return 0;
    return 1;
}

static void remember(const struct frame *f)
{
    robot.have_last = 1;
    robot.last_seq = f->seq;
    robot.last_id = f->id;
    robot.last_len = f->len;
    for (uint8_t i = 0; i < f->len; i++)
        robot.last_payload[i] = f->payload[i];
}

/* A resend of the SET_DRIVE in force is still that motion command: it refreshes the deadline.
 * Returns 0 when it is no longer in force (the guard cut it since on_frame's catch-up): it is
 * then applied again, not acknowledged as in force. */
static uint8_t on_resend(const struct frame *f)
{
    if (f->id == PROTO_MSG_SET_DRIVE) {
        uint8_t state = board_lock();
        uint8_t armed = link_loss.armed;
        if (armed)
            link_loss_heard(&link_loss, robot.now_ms);
        board_unlock(state);
        if (!armed)
            return 0;
    }
    send_ack(f->seq, PROTO_ACK_RESULT_DUPLICATE); /* do not apply twice */
    return 1;
}

/* When the guard has cut the motors, bring the drive state in line (before anything else may
 * drive them again); returns 1 if it had. */
static uint8_t catch_up_guard(void)
{
    uint8_t state = board_lock();
    uint8_t tripped = link_loss.tripped;
    link_loss.tripped = 0;
    board_unlock(state);
    if (!tripped)
        return 0;
    link_loss.lost = 1;
    robot.link_losses++;
    robot.have_last = 0; /* a resend after this stop is applied again, not a duplicate */
    stop();
    return 1;
}

static void on_frame(void *ctx, const struct frame *f)
{
    (void)ctx; /* only an accepted SET_DRIVE refreshes the link-loss deadline, not any frame */
    catch_up_guard();
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
        if (is_resend(f) && on_resend(f))
            return;
        remember(f);
    }
    dispatch(f);
}

void robot_init(uint8_t reset_cause, uint32_t now_ms)
{
    frame_parser_init(&robot.parser);
    drive_init(&robot.drive);
    uint8_t state = board_lock();
    link_loss_init(&link_loss, now_ms, PROTO_DEFAULT_LINK_TIMEOUT_MS);
    board_unlock(state);
    robot.drive.accel_limit = PROTO_DEFAULT_ACCEL_LIMIT;
    robot.now_ms = robot.last_tick_ms = now_ms;
    robot.reset_cause = reset_cause;
    robot.tx_seq = 0;
    robot.have_last = 0;
    robot.nack_credit = NACK_BURST;
    robot.nack_ms = 0;
    robot.link_losses = 0;
    stop();
    struct proto_boot m = {reset_cause, FW_VERSION, PROTO_SCHEMA_HASH};
    uint8_t p[PROTO_BOOT_LEN];
    proto_boot_pack(p, &m);
    send(PROTO_MSG_BOOT, p, sizeof p);
}

void robot_rx_byte(uint8_t byte, uint32_t now_ms)
{
    robot.now_ms = now_ms;
    robot.rx_ms = (uint8_t)now_ms;
    if (frame_parse_byte(&robot.parser, byte, on_frame, 0) &&
        proto_is_host_to_robot(robot.parser.last_id))
        send_nack(robot.parser.last_seq, PROTO_ERROR_BAD_CRC);
}

void robot_tick(uint32_t now_ms)
{
    robot.now_ms = now_ms;
    uint16_t elapsed = advance();
    /* a partial frame whose next byte is overdue is dropped: checked every tick, so the 8-bit
     * difference is read long before it could wrap */
    if (robot.parser.state != FRAME_WAIT_START &&
        (uint8_t)((uint8_t)now_ms - robot.rx_ms) > PROTO_DEFAULT_FRAME_GAP_MS) {
        robot.parser.state = FRAME_WAIT_START;
        robot.parser.framing_errors++;
    }
    if (!catch_up_guard() && drive_tick(&robot.drive, elapsed))
        output();
}

void robot_guard(uint32_t now_ms)
{
    /* the timer interrupt: the main loop only touches link_loss under board_lock */
    if (!link_loss_expired(&link_loss, now_ms))
        return;
    link_loss.armed = 0;
    link_loss.tripped = 1;
    board_motor_output(0, 0);
}
