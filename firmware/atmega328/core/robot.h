/* The robot's protocol side: frames in, motor outputs and replies out. Knows no registers;
 * the board calls these functions with the time in ms. */
#ifndef ROBOT_H
#define ROBOT_H

#include <stdint.h>

/* Start with the motors off and announce the boot (BOOT frame). reset_cause: proto_reset_cause. */
void robot_init(uint8_t reset_cause, uint32_t now_ms);

/* One byte received from the serial line. */
void robot_rx_byte(uint8_t byte, uint32_t now_ms);

/* Periodic work in the main loop (ramps, NACK budget, bookkeeping of a link-loss stop); call
 * at least every millisecond or two. */
void robot_tick(uint32_t now_ms);

/* The link-loss guard: call from the 1 kHz timer interrupt with the new time. Cuts the motors
 * itself when the deadline has passed, whatever the main loop is busy with. */
void robot_guard(uint32_t now_ms);

#endif
