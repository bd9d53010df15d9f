/* The protocol's CRC-32C (Castagnoli: reflected polynomial 0x82F63B78, init and final XOR
 * 0xFFFFFFFF), bit by bit: no table, so it fits the ATmega328P's flash; the same code on the AVR,
 * in the emulator and in the native tests. Why CRC-32C: docs/protocol.md, "Choice of CRC". */
#ifndef CRC_H
#define CRC_H

#include <stdint.h>

static inline uint32_t crc_update(uint32_t crc, uint8_t data)
{
    crc ^= data;
    for (uint8_t i = 0; i < 8; i++)
        crc = (crc & 1) ? (crc >> 1) ^ 0x82F63B78UL : crc >> 1;
    return crc;
}

#endif
