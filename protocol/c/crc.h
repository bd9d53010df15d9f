/* The protocol's CRC (PROTO_CRC_POLY, reflected; init PROTO_CRC_INIT and final XOR
 * PROTO_CRC_XOROUT are applied by the caller, frame.c), bit by bit: no table, so it fits the
 * ATmega328P's flash; the same code on the AVR, in the emulator and in the native tests. Its
 * parameters come from protocol/spec.toml through protocol_gen.h. Why CRC-32C: docs/protocol.md,
 * "Choice of CRC". */
#ifndef CRC_H
#define CRC_H

#include <stdint.h>

#include "protocol_gen.h"

static inline uint32_t crc_update(uint32_t crc, uint8_t data)
{
    crc ^= data;
    for (uint8_t i = 0; i < 8; i++)
        crc = (crc & 1) ? (crc >> 1) ^ PROTO_CRC_POLY : crc >> 1;
    return crc;
}

#endif
