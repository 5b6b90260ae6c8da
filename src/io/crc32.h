/* CRC-32 as in IEEE 802.3, zlib, PNG and gzip: reflected polynomial
 * 0xEDB88320, initial value and final xor 0xFFFFFFFF. Internal to the library
 * (checkpoints); not installed. */
#ifndef PX_IO_CRC32_H
#define PX_IO_CRC32_H

#include <stddef.h>
#include <stdint.h>

/* Continue a CRC over n more bytes. Start with crc = 0; the result of one call
 * is the `crc` of the next, so update(update(0, a), b) == update(0, a||b).
 * The check value update(0, "123456789", 9) is 0xCBF43926. Slicing-by-16;
 * data may be NULL when n == 0. Thread-safe. */
uint32_t px_crc32_update(uint32_t crc, const void *data, size_t n);

/* The CRC of a||b from crc_a = CRC(a), crc_b = CRC(b) and len_b = |b| bytes,
 * without touching the data: O(log len_b) (zlib's crc32_combine). */
uint32_t px_crc32_combine(uint32_t crc_a, uint32_t crc_b, uint64_t len_b);

/* Bit-at-a-time reference implementation (for tests). */
uint32_t px_crc32_reference(uint32_t crc, const void *data, size_t n);

#endif
