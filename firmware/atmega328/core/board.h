/* What the register-free core asks of the board. The AVR layer (avr/) implements it on the
 * ATmega328P, the emulator (host/emulator) on a PC. */
#ifndef BOARD_H
#define BOARD_H

#include <stdint.h>

/* Apply motor duties in permille, -1000..1000; positive drives forward, 0 lets the motor coast. */
void board_motor_output(int16_t left, int16_t right);

/* Queue bytes for the serial line; waits while the transmit buffer is full. */
void board_tx(const uint8_t *data, uint8_t n);

#endif
