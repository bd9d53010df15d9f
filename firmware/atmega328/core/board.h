/* What the register-free core asks of the board. The AVR layer (avr/) implements it on the
 * ATmega328P, the emulator (host/emulator) on a PC. */
#ifndef BOARD_H
#define BOARD_H

#include <stdint.h>

/* Apply motor duties in permille, -1000..1000; positive drives forward, 0 lets the motor coast
 * (bridge disabled). Safe to call from the timer interrupt (robot_guard) as well. */
void board_motor_output(int16_t left, int16_t right);

/* Queue a whole frame for the serial line. Never waits: when the transmit buffer lacks room
 * the frame is dropped and counted (board_tx_dropped). */
void board_tx(const uint8_t *data, uint8_t n);

/* Hold off the timer interrupt (and so robot_guard) until board_unlock(state). */
uint8_t board_lock(void);
void board_unlock(uint8_t state);

/* Counters since reset (wrapping): received bytes lost to an overrun (UART or receive ring),
 * frames dropped because the transmit buffer was full. */
uint16_t board_rx_overruns(void);
uint16_t board_tx_dropped(void);

#endif
