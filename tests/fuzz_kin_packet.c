/* fuzz_kin_packet.c - libFuzzer target of kin_track_packet_read, the live
 * UDP pose packet (docs/tracking.md). When the input's last byte is odd
 * and it has the packet's size, the harness writes the right CRC-32 first,
 * so the fuzzer gets past the checksum to the fields. A packet that reads
 * writes back to the same bytes' fields. `make fuzz`, seeds in
 * tests/fuzz/corpus/kin_packet/; docs/fuzzing.md. */
#include <string.h>

#include "../src/kin/kin.h"
#include "fuzz/fuzz_util.h"

static uint32_t crc32_ieee(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return ~c;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t *b = malloc(size ? size : 1);
    if (!b) return 0;
    if (size) memcpy(b, data, size);
    if (size == KIN_TRACK_PACKET_SIZE + 1 && (data[size - 1] & 1)) {
        size--;
        uint32_t c = crc32_ieee(b, 168);
        for (int i = 0; i < 4; i++) b[168 + i] = (uint8_t)(c >> (8 * i));
    }
    kin_track_sample s;
    uint32_t seq = 0;
    char why[256] = "";
    if (kin_track_packet_read(b, size, &s, &seq, why, sizeof why) == 0) {
        uint8_t out[KIN_TRACK_PACKET_SIZE];
        kin_track_packet_write(&s, seq, out);
        kin_track_sample s2;
        uint32_t seq2 = 0;
        if (kin_track_packet_read(out, sizeof out, &s2, &seq2, why, sizeof why) != 0 ||
            seq2 != seq)
            abort();
    } else if (!why[0]) {
        abort();
    }
    free(b);
    return 0;
}
