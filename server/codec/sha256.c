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

int codec_sha256_hex(const void *data, size_t len, char hex[65])
{
    static const char digits[] = "0123456789abcdef";
    uint32_t h[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                     0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    const unsigned char *p = data;
    unsigned char tail[128];
    uint64_t bits = (uint64_t)len * 8;
    size_t rest = len % 64, n_tail = rest < 56 ? 64 : 128, i;

    for (i = 0; i + 64 <= len; i += 64)
        sha_block(h, p + i);
    memset(tail, 0, sizeof tail);
    if (rest)
        memcpy(tail, p + len - rest, rest);
    tail[rest] = 0x80;
    for (i = 0; i < 8; i++)
        tail[n_tail - 1 - i] = (unsigned char)(bits >> (8 * i));
    for (i = 0; i < n_tail; i += 64)
        sha_block(h, tail + i);
    for (i = 0; i < 32; i++) {
        unsigned char b = (unsigned char)(h[i / 4] >> (24 - 8 * (i % 4)));
        hex[2 * i] = digits[b >> 4];
        hex[2 * i + 1] = digits[b & 15];
    }
    hex[64] = '\0';
    return SM_OK;
}
