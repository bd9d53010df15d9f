/* The board API on a PC, for the emulator (host/emulator/core.py): motor outputs are kept in
 * variables and transmitted bytes in a buffer, both read back through the emu_ functions; the lock
 * and the receive counter are single_thread.c's. The firmware core (the core folder) and the
 * frame parser are linked in unchanged. */
#include <stdint.h>
#include <string.h>

#include "../core/board.h"

#define TX_SIZE 4096

static int16_t motor[2];
static uint32_t motor_writes;
static uint8_t tx[TX_SIZE];
static uint16_t tx_len;
static uint32_t tx_dropped;

void board_motor_output(int16_t left, int16_t right)
{
    motor[0] = left;
    motor[1] = right;
    motor_writes++;
}

void board_tx(const uint8_t *data, uint8_t n)
{
    if (tx_len + n > TX_SIZE) { /* as on the AVR: a frame that does not fit is dropped whole */
        tx_dropped++;
        return;
    }
    memcpy(tx + tx_len, data, n);
    tx_len += n;
}

uint16_t board_tx_dropped(void)
{
    return (uint16_t)tx_dropped;
}

/* Move up to max transmitted bytes into out; returns how many. */
uint16_t emu_take_tx(uint8_t *out, uint16_t max)
{
    uint16_t n = tx_len < max ? tx_len : max;
    memcpy(out, tx, n);
    memmove(tx, tx + n, tx_len - n);
    tx_len -= n;
    return n;
}

/* Applied motor duties (permille) and how many times the core has set them. */
uint32_t emu_motors(int16_t *left, int16_t *right)
{
    *left = motor[0];
    *right = motor[1];
    return motor_writes;
}
