/* Firmware options. Each is explained here; the protocol's own constants come from
 * protocol/c/protocol_gen.h. */
#ifndef CONFIG_H
#define CONFIG_H

/* Firmware version sent in BOOT and HELLO_REPLY: major * 256 + minor. */
#define FW_VERSION 0x0100

/* UART receive and transmit ring sizes (bytes, powers of two). 64 bytes of RX hold more than two
 * whole frames, so a burst that arrives while the main loop handles a frame is not lost; TX holds
 * a STATUS frame (30 bytes) and an ACK together. A reply that does not fit is dropped, never
 * waited for: the main loop must not stall behind the line. */
#define UART_RX_SIZE 64
#define UART_TX_SIZE 64

/* Received bytes the main loop hands the core per pass, so a pass (and with it the ramp and the
 * one watchdog feed) takes bounded time whatever arrives. At line rate a byte comes every 87 us;
 * a pass with 8 bytes of the costliest input stays well inside a millisecond. */
#define RX_BYTES_PER_PASS 8

/* NACKs are rate-limited: at most NACK_BURST at once, then one per
 * PROTO_DEFAULT_NACK_INTERVAL_MS, so a flood of bad frames cannot fill the transmit line. */
#define NACK_BURST 4

/* The link-loss timeout that SET_CONFIG may set is bounded by the spec (50..5000 ms); the default
 * (250 ms) comes from the spec as PROTO_DEFAULT_LINK_TIMEOUT_MS. */

/* PWM: Timer1 in phase-correct mode with TOP = ICR1 = PWM_TOP at prescaler 1 gives
 * F_CPU / (2 * PWM_TOP) = 20 kHz: above hearing, and slow enough for the L298's switching times
 * (docs/wiring.md). Duty in permille maps to OCR1x = duty * PWM_TOP / 1000 (avr/motors.c
 * assumes PWM_TOP is a multiple of 200). */
#define PWM_TOP 400

#endif
