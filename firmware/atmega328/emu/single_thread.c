/* The board API's lock and receive counter for a build on a PC, the same for the emulator
 * (emu/board.c) and the libFuzzer target (tests/c/fuzz_core.c): one thread calls robot_guard
 * and the main-loop functions, so there is nothing to hold, and bytes reach the core straight
 * from the caller, so none is lost to an overrun. */
#include <stdint.h>

#include "../core/board.h"

uint8_t board_lock(void)
{
    return 0;
}

void board_unlock(uint8_t state)
{
    (void)state;
}

uint16_t board_rx_overruns(void)
{
    return 0;
}
