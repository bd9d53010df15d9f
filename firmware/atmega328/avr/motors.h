/* Motor outputs: Timer1 PWM on the bridge's enable pins, direction on its inputs. */
#ifndef MOTORS_H
#define MOTORS_H

void motors_init(void);

#endif
