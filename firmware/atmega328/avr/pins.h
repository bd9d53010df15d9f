/* Pin map: every pin the firmware uses, for an Arduino Uno or Nano (ATmega328P) wired to an
 * L298N-style dual H-bridge. See docs/wiring.md. */
#ifndef PINS_H
#define PINS_H

#include <avr/io.h>

/* PWM enables: Timer1 outputs */
#define MOTOR_LEFT_EN_DDR DDRB
#define MOTOR_LEFT_EN_BIT PB1   /* Uno digital pin 9,  OC1A -> L298N ENA */
#define MOTOR_RIGHT_EN_DDR DDRB
#define MOTOR_RIGHT_EN_BIT PB2  /* Uno digital pin 10, OC1B -> L298N ENB */

/* Direction inputs of the bridge, all on port D */
#define MOTOR_DIR_PORT PORTD
#define MOTOR_DIR_DDR DDRD
#define MOTOR_LEFT_IN1_BIT PD4  /* Uno digital pin 4 -> IN1 */
#define MOTOR_LEFT_IN2_BIT PD5  /* Uno digital pin 5 -> IN2 */
#define MOTOR_RIGHT_IN3_BIT PD6 /* Uno digital pin 6 -> IN3 */
#define MOTOR_RIGHT_IN4_BIT PD7 /* Uno digital pin 7 -> IN4 */

/* UART0: PD0 (pin 0) RX, PD1 (pin 1) TX, through the board's USB-serial adapter */

#endif
