/* SHA-256 (FIPS 180-4), for the provenance of files: the hash of the
 * script's text, comparable with `sha256sum script.lua`. */
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct sx_sha256 {
    uint32_t h[8];
    uint64_t len;        ///< bytes hashed so far
    uint8_t block[64];
    size_t fill;
} sx_sha256;

void sx_sha256_init(sx_sha256 *s);
void sx_sha256_update(sx_sha256 *s, const void *data, size_t n);
/// Finishes and writes 64 lowercase hex digits and a NUL to hex.
void sx_sha256_hex(sx_sha256 *s, char hex[65]);
/// The hash of a file's contents; false (hex = "") if it cannot be read.
bool sx_sha256_file(const char *path, char hex[65]);
