/* CRC-16 update for the protocol: avr-libc's _crc_xmodem_update on the AVR; on a PC (tests,
 * emulator) the C equivalent that avr-libc's <util/crc16.h> documents for it. */
#ifndef CRC16_H
#define CRC16_H

#include <stdint.h>

#ifdef __AVR__
#include <util/crc16.h>
#define crc16_update _crc_xmodem_update
#else
static inline uint16_t crc16_update(uint16_t crc, uint8_t data)
{
    crc = crc ^ ((uint16_t)data << 8);
    for (uint8_t i = 0; i < 8; i++)
        crc = (crc & 0x8000) ? (uint16_t)((crc << 1) ^ 0x1021) : (uint16_t)(crc << 1);
    return crc;
}
#endif

#endif
