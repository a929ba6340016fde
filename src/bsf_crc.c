/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_stream.h"

/* CRC-32C, reflected, four bits at a time: a 64-byte table instead of the
 * usual 1 KiB keeps flash small on a microcontroller at half the speed of a
 * byte table, which is plenty for frames of a few hundred bytes. */
static const uint32_t crc32c_nibble[16] = {0x00000000u, 0x105EC76Fu, 0x20BD8EDEu, 0x30E349B1u,
                                           0x417B1DBCu, 0x5125DAD3u, 0x61C69362u, 0x7198540Du,
                                           0x82F63B78u, 0x92A8FC17u, 0xA24BB5A6u, 0xB21572C9u,
                                           0xC38D26C4u, 0xD3D3E1ABu, 0xE330A81Au, 0xF36E6F75u};

uint32_t bsf_crc32c(uint32_t crc, const uint8_t *data, size_t len)
{
    size_t i;
    uint32_t reg = ~crc;

    if (data == NULL) {
        return crc;
    }
    for (i = 0; i < len; ++i) {
        reg ^= data[i];
        reg = (reg >> 4) ^ crc32c_nibble[reg & 0x0Fu];
        reg = (reg >> 4) ^ crc32c_nibble[reg & 0x0Fu];
    }
    return ~reg;
}
