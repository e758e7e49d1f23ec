/*
 * sha256.c — SHA-256 (FIPS 180-4) of a byte string, as lowercase hex.
 *
 * How it fits: the request's identity (request.c), the daemon's job ids (jobdoc.c), its
 * body hashes and its token hash all come through codec_sha256_hex.  It used OpenSSL's
 * EVP_Digest; that cost a small solve more than the hash itself (issue 27: libcrypto's
 * 21 000 relocations at start-up and its provider set-up at the first EVP call, together
 * about 9 % of the instructions of `spinmodal solve` on the 12-element blade), so the
 * hash is written out here and no binary links libcrypto.  Checked against the FIPS
 * 180-2 vectors in tests/codec (unit "sha").
 */
#include "codec_internal.h"

#include <stdint.h>
#include <string.h>

/* The round constants: the first 32 bits of the fractional parts of the cube roots of the
 * first 64 primes (FIPS 180-4 §4.2.2). */
static const uint32_t sha_k[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

/* x rotated right by n bits (0 < n < 32). */
static uint32_t sha_ror(uint32_t x, int n)
{
    return (x >> n) | (x << (32 - n));
}

/* Fold one 64-byte block p into the state h (FIPS 180-4 §6.2.2). */
static void sha_block(uint32_t h[8], const unsigned char *p)
{
    uint32_t w[64], a[8], s0, s1, t1, t2;
    int i;

    for (i = 0; i < 16; i++)
        w[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 |
               (uint32_t)p[4 * i + 2] << 8 | (uint32_t)p[4 * i + 3];
    for (i = 16; i < 64; i++) {
        s0 = sha_ror(w[i - 15], 7) ^ sha_ror(w[i - 15], 18) ^ (w[i - 15] >> 3);
        s1 = sha_ror(w[i - 2], 17) ^ sha_ror(w[i - 2], 19) ^ (w[i - 2] >> 10);
        w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    memcpy(a, h, sizeof a);
    for (i = 0; i < 64; i++) {
        t1 = a[7] + (sha_ror(a[4], 6) ^ sha_ror(a[4], 11) ^ sha_ror(a[4], 25)) +
             ((a[4] & a[5]) ^ (~a[4] & a[6])) + sha_k[i] + w[i];
        t2 = (sha_ror(a[0], 2) ^ sha_ror(a[0], 13) ^ sha_ror(a[0], 22)) +
             ((a[0] & a[1]) ^ (a[0] & a[2]) ^ (a[1] & a[2]));
        memmove(a + 1, a, 7 * sizeof a[0]);
        a[4] += t1;
        a[0] = t1 + t2;
    }
    for (i = 0; i < 8; i++)
        h[i] += a[i];
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#if __has_include(<sys/platform/x86.h>)
#include <sys/platform/x86.h> /* glibc 2.33 and later */
#else
#include <cpuid.h>
#endif
#define SHA_NI 1

/* 1 when the CPU has the SHA extensions and SSSE3 / SSE4.1 (their shuffles and blends).  glibc
 * (2.33 on) answers from the CPU features it read at start-up; asking CPUID again cost four
 * CPUID instructions, each a trap to the hypervisor in a virtual machine (8 us each on the
 * development VM: 1 % of the 12-element blade's whole solve).  Elsewhere CPUID itself, once
 * (leaf 7 EBX bit 29, leaf 1 ECX bits 9 and 19).  Valgrind's CPU leaves SHA out, so under it
 * the portable rounds run. */
static int sha_ni_have(void)
{
#if __has_include(<sys/platform/x86.h>)
    return CPU_FEATURE_ACTIVE(SHA) && CPU_FEATURE_ACTIVE(SSSE3) && CPU_FEATURE_ACTIVE(SSE4_1);
#else
    static int have = -1; /* -1 unknown; every thread finds the same answer */
    int h = __atomic_load_n(&have, __ATOMIC_RELAXED);
    if (h < 0) {
        unsigned a, b, c, d;
        h = __get_cpuid_count(7, 0, &a, &b, &c, &d) && (b & (1u << 29)) &&
            __get_cpuid(1, &a, &b, &c, &d) && (c & (1u << 9)) && (c & (1u << 19));
        __atomic_store_n(&have, h, __ATOMIC_RELAXED);
    }
    return h;
#endif
}

/* Four rounds from the message words x (W[4g..4g+3]) and the constants K[4g..]: SHA256RNDS2
 * does two rounds on the state halves abef, cdgh (Intel's SHA extensions reference). */
#define SHA_NI_ROUNDS4(x, g)                                                                  \
    do {                                                                                      \
        __m128i m_ = _mm_add_epi32((x), _mm_loadu_si128((const __m128i *)(sha_k + 4 * (g)))); \
        cdgh = _mm_sha256rnds2_epu32(cdgh, abef, m_);                                         \
        abef = _mm_sha256rnds2_epu32(abef, cdgh, _mm_shuffle_epi32(m_, 0x0E));                \
    } while (0)

/* sha_block's fold for n blocks at p with the SHA extensions: the same state, ~4 instructions a
 * byte instead of ~80 (issue 27: the request's hash was 4 % of a small solve). */
__attribute__((target("sha,sse4.1,ssse3"))) static void
sha_blocks_ni(uint32_t h[8], const unsigned char *p, size_t n)
{
    const __m128i bswap = _mm_set_epi64x(0x0c0d0e0f08090a0bLL, 0x0405060700010203LL);
    __m128i t = _mm_shuffle_epi32(_mm_loadu_si128((const __m128i *)h), 0xB1);          /* cdab */
    __m128i cdgh = _mm_shuffle_epi32(_mm_loadu_si128((const __m128i *)(h + 4)), 0x1B); /* efgh */
    __m128i abef = _mm_alignr_epi8(t, cdgh, 8);
    cdgh = _mm_blend_epi16(cdgh, t, 0xF0);
    for (; n > 0; n--, p += 64) {
        __m128i abef0 = abef, cdgh0 = cdgh, w[4];
        for (int i = 0; i < 4; i++)
            w[i] = _mm_shuffle_epi8(_mm_loadu_si128((const __m128i *)(p + 16 * i)), bswap);
        /* group g uses w[g % 4]; the schedule makes w[(g + 1) % 4] for group g + 1 (from group
         * 3 on) and starts w[(g - 1) % 4] for group g + 3 (groups 1 to 12) */
        for (int g = 0; g < 16; g++) {
            __m128i x = w[g & 3];
            if (g >= 3 && g <= 14) {
                __m128i nx = _mm_add_epi32(w[(g + 1) & 3], _mm_alignr_epi8(x, w[(g + 3) & 3], 4));
                w[(g + 1) & 3] = _mm_sha256msg2_epu32(nx, x);
            }
            SHA_NI_ROUNDS4(x, g);
            if (g >= 1 && g <= 12)
                w[(g + 3) & 3] = _mm_sha256msg1_epu32(w[(g + 3) & 3], x);
        }
        abef = _mm_add_epi32(abef, abef0);
        cdgh = _mm_add_epi32(cdgh, cdgh0);
    }
    t = _mm_shuffle_epi32(abef, 0x1B);    /* feba */
    cdgh = _mm_shuffle_epi32(cdgh, 0xB1); /* dchg */
    _mm_storeu_si128((__m128i *)h, _mm_blend_epi16(t, cdgh, 0xF0));
    _mm_storeu_si128((__m128i *)(h + 4), _mm_alignr_epi8(cdgh, t, 8));
}
#else
#define SHA_NI 0
#endif

int codec_sha256_accelerated(void)
{
#if SHA_NI
    return sha_ni_have();
#else
    return 0;
#endif
}

/* n blocks at p into h: the SHA extensions where the CPU has them and accel, else sha_block. */
static void sha_blocks(uint32_t h[8], const unsigned char *p, size_t n, int accel)
{
#if SHA_NI
    if (accel && n > 0 && sha_ni_have()) {
        sha_blocks_ni(h, p, n);
        return;
    }
#else
    (void)accel;
#endif
    for (size_t i = 0; i < n; i++)
        sha_block(h, p + 64 * i);
}

int codec_sha256_hex(const void *data, size_t len, char hex[65])
{
    return codec_sha256_hex_with(data, len, hex, 1);
}

int codec_sha256_hex_with(const void *data, size_t len, char hex[65], int accel)
{
    static const char digits[] = "0123456789abcdef";
    uint32_t h[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                     0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    const unsigned char *p = data;
    unsigned char tail[128];
    uint64_t bits = (uint64_t)len * 8;
    size_t rest = len % 64, n_tail = rest < 56 ? 64 : 128, i;

    sha_blocks(h, p, len / 64, accel);
    memset(tail, 0, sizeof tail);
    if (rest)
        memcpy(tail, p + len - rest, rest);
    tail[rest] = 0x80;
    for (i = 0; i < 8; i++)
        tail[n_tail - 1 - i] = (unsigned char)(bits >> (8 * i));
    sha_blocks(h, tail, n_tail / 64, accel);
    for (i = 0; i < 32; i++) {
        unsigned char b = (unsigned char)(h[i / 4] >> (24 - 8 * (i % 4)));
        hex[2 * i] = digits[b >> 4];
        hex[2 * i + 1] = digits[b & 15];
    }
    hex[64] = '\0';
    return SM_OK;
}
