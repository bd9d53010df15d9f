/* Motor outputs (implements board_motor_output). Duty 0 coasts: enable low (bridge off), the
 * direction inputs left as they were. */
#include "motors.h"

#include <avr/io.h>
#include <util/atomic.h>

#include "../config.h"
#include "../core/board.h"
#include "pins.h"

void motors_init(void)
{
    MOTOR_DIR_PORT &= (uint8_t)~(_BV(MOTOR_LEFT_IN1_BIT) | _BV(MOTOR_LEFT_IN2_BIT) |
                                 _BV(MOTOR_RIGHT_IN3_BIT) | _BV(MOTOR_RIGHT_IN4_BIT));
    MOTOR_DIR_DDR |= _BV(MOTOR_LEFT_IN1_BIT) | _BV(MOTOR_LEFT_IN2_BIT) |
                     _BV(MOTOR_RIGHT_IN3_BIT) | _BV(MOTOR_RIGHT_IN4_BIT);
    OCR1A = 0;
    OCR1B = 0;
    ICR1 = PWM_TOP;
    /* mode 10: phase-correct PWM, TOP = ICR1; clear OC1A/OC1B on up-count match; no prescaler */
    TCCR1A = _BV(COM1A1) | _BV(COM1B1) | _BV(WGM11);
    TCCR1B = _BV(WGM13) | _BV(CS10);
    MOTOR_LEFT_EN_DDR |= _BV(MOTOR_LEFT_EN_BIT);
    MOTOR_RIGHT_EN_DDR |= _BV(MOTOR_RIGHT_EN_BIT);
}

static uint16_t compare(int16_t duty)
{
    /* duty * PWM_TOP / 1000 = duty * 2 / 5 for PWM_TOP 400: 16-bit arithmetic suffices */
    uint16_t magnitude = (uint16_t)(duty < 0 ? -duty : duty);
    return (uint16_t)(magnitude * (PWM_TOP / 200) / 5);
}

/* The direction inputs for a duty: a motor at zero keeps the inputs it had, since its enable
 * (OCR 0) is what switches the bridge off; so the inputs change only together with a non-zero
 * duty, which the core applies only after a coast interval at zero. Writing the inputs first
 * and OCR1x second, the new duty reaches the pin at the timer's next TOP, after them. */
static uint8_t direction(int16_t duty, uint8_t now, uint8_t forward_bit, uint8_t reverse_bit)
{
    if (duty > 0)
        return _BV(forward_bit);
    if (duty < 0)
        return _BV(reverse_bit);
    return now & (_BV(forward_bit) | _BV(reverse_bit));
}

void board_motor_output(int16_t left, int16_t right)
{
    uint8_t mask = _BV(MOTOR_LEFT_IN1_BIT) | _BV(MOTOR_LEFT_IN2_BIT) |
                   _BV(MOTOR_RIGHT_IN3_BIT) | _BV(MOTOR_RIGHT_IN4_BIT);
    uint16_t a = compare(left), b = compare(right);
    /* Called from the main loop and from the timer interrupt (the link-loss cut): the 16-bit
     * OCR writes share the timer's TEMP register, so no interrupt may come between them. */
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE)
    {
        uint8_t now = MOTOR_DIR_PORT;
        uint8_t dir = direction(left, now, MOTOR_LEFT_IN1_BIT, MOTOR_LEFT_IN2_BIT) |
                      direction(right, now, MOTOR_RIGHT_IN3_BIT, MOTOR_RIGHT_IN4_BIT);
        MOTOR_DIR_PORT = (uint8_t)((now & ~mask) | dir);
        OCR1A = a;
        OCR1B = b;
    }
}
