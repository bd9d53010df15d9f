/* The robot's protocol side: frames in, motor outputs and replies out. Knows no registers;
 * the board calls these three functions with the time in ms. */
#ifndef ROBOT_H
#define ROBOT_H

#include <stdint.h>

/* Start with the motors off and announce the boot (BOOT frame). reset_cause: proto_reset_cause. */
void robot_init(uint8_t reset_cause, uint32_t now_ms);

/* One byte received from the serial line. */
void robot_rx_byte(uint8_t byte, uint32_t now_ms);

/* Periodic work (ramps, link-loss stop); call at least every millisecond or two. */
void robot_tick(uint32_t now_ms);

#endif
