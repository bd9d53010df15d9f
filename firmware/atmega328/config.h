/* Firmware options. Each is explained here; the protocol's own constants come from
 * protocol/c/protocol_gen.h. */
#ifndef CONFIG_H
#define CONFIG_H

/* Firmware version sent in BOOT and HELLO_REPLY: major * 256 + minor. */
#define FW_VERSION 0x0100

/* UART receive and transmit ring sizes (bytes, powers of two). 64 bytes of RX (63 usable, 5.5 ms
 * of line) hold four SET_DRIVE frames, so a burst that arrives while the main loop is busy is not
 * lost (tests/firmware/test_rules.py); TX holds a STATUS frame (34 bytes) and an ACK (10)
 * together. A reply that does not fit is dropped, never waited for: the main loop must not stall
 * behind the line. */
#define UART_RX_SIZE 64
#define UART_TX_SIZE 64

/* Received bytes the main loop hands the core per pass, so a pass (and with it the ramp and the
 * one watchdog feed) takes bounded time whatever arrives. At line rate a byte comes every 87 us.
 * A pass is not within a millisecond: issue 29 measured 1.0-1.8 ms for mixed traffic and up to
 * 3.55 ms for nested false frames (START and the largest LEN over and over, which make the parser
 * search each rejected frame again), so under such a flood the core falls behind the line and the
 * receive ring overflows (counted, STATUS rx_overruns); what the bound keeps is the watchdog fed
 * (30 ms period) and the ramp ticked every few ms. */
#define RX_BYTES_PER_PASS 8

/* NACKs are rate-limited: at most NACK_BURST at once, then one per
 * PROTO_DEFAULT_NACK_INTERVAL_MS, so a flood of bad frames cannot fill the transmit line. */
#define NACK_BURST 4

/* The link-loss timeout that SET_CONFIG may set is bounded by the spec (50..5000 ms); the default
 * (250 ms) comes from the spec as PROTO_DEFAULT_LINK_TIMEOUT_MS, and so does the frame gap
 * (PROTO_DEFAULT_FRAME_GAP_MS) after which a partial frame is dropped. */

/* PWM: Timer1 in phase-correct mode with TOP = ICR1 = PWM_TOP at prescaler 1 gives
 * F_CPU / (2 * PWM_TOP) = 20 kHz: above hearing, and slow enough for the L298's switching times
 * (docs/wiring.md). Duty in permille maps to OCR1x = duty * PWM_TOP / 1000 (avr/motors.c
 * assumes PWM_TOP is a multiple of 200). */
#define PWM_TOP 400

#endif
