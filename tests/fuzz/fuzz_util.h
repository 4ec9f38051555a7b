/* fuzz_util.h - what every harness in tests/fuzz/ may use: stopping on a failed
 * property, little-endian words, exact-size copies, a small generator and a
 * CRC-32 written apart from firmware/crc32.c so that it can check that code. */
#ifndef FUZZ_UTIL_H
#define FUZZ_UTIL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A property of the code under test failed: report it and stop, so libFuzzer keeps
 * the input as a crash. */
#define FUZZ_REQUIRE(cond, ...)                                                                                        \
    do {                                                                                                               \
        if (!(cond)) {                                                                                                 \
            fprintf(stderr, "fuzz: %s:%d: %s: ", __FILE__, __LINE__, #cond);                                           \
            fprintf(stderr, __VA_ARGS__);                                                                              \
            fputc('\n', stderr);                                                                                       \
            abort();                                                                                                   \
        }                                                                                                              \
    } while (0)
#define REQUIRE(cond) FUZZ_REQUIRE(cond, "property failed")

/* The harnesses' own checks are not traced: they would cost more than the code
 * under test and tell libFuzzer nothing about it. */
#define UNTRACED __attribute__((no_sanitize("coverage")))

static inline uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline void wr32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}

/* malloc that cannot fail quietly (the harnesses' buffers are small). */
static inline void *fuzz_alloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) abort();
    return p;
}

/* A copy in a block of exactly n bytes: a read one past the end is an ASan report. */
static inline uint8_t *fuzz_copy_exact(const uint8_t *p, size_t n)
{
    uint8_t *b = fuzz_alloc(n);
    if (n) memcpy(b, p, n);
    return b;
}

static inline uint32_t xorshift(uint32_t *s)
{
    uint32_t x = *s ? *s : 0x9E3779B9u;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return *s = x;
}

/* CRC-32 as zlib's crc32(). */
UNTRACED static inline uint32_t ref_crc(const uint8_t *p, size_t n)
{
    static uint32_t table[256];
    if (!table[1])
        for (uint32_t i = 0; i < 256; i++) {
            uint32_t c = i;
            for (int k = 0; k < 8; k++) c = c & 1u ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            table[i] = c;
        }
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) c = table[(c ^ p[i]) & 0xFFu] ^ (c >> 8);
    return ~c;
}

#endif
