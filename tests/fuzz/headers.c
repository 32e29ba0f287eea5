/* headers: damages the object headers of a seixo file one byte at a time,
 * with each header's checksum recomputed so that HDF5 decodes the damaged
 * message instead of refusing the header, and loads every damaged copy
 * (a snapshot: sx_snapshot_load and a few steps; a series: append mode,
 * seixo.xdmf's rebuild, and a load as a snapshot). Built with the
 * sanitizers, it turns up what HDF5 does with messages no checksum
 * catches: it found a heap-buffer-overflow in H5Dread (a damaged type
 * size, now refused by sx_h5_rows), HDF5's leaks that tests/io/lsan.supp
 * names, and a crash in H5Lexists on a series' damaged link index (not
 * fixed: HDF5's own). Not a test: a sweep takes hours under ASan.
 *   build-san/tests/fuzz/headers FILE KIND [FIRST [LAST [BATCH [STRIDE]]]]
 * KIND 0: a snapshot, 1: a series. Case k damages byte k / 4 of the file's
 * header chunks (in file order, past each signature, version and flags)
 * with mutation k % 4 (xor 0xff, 0, +1, 0x80); every BATCH cases (and at
 * the end) LeakSanitizer checks for leaks (run it with LSAN_OPTIONS=
 * suppressions=tests/io/lsan.supp:fast_unwind_on_malloc=0 and the same
 * ASAN_OPTIONS, or every HDF5 frame goes unnamed). Each case is printed
 * to stderr before it runs, so a crash names its case; STRIDE runs every
 * STRIDE-th case only. */
#include "seixo_io.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* HDF5's checksum of metadata, exported by libhdf5 but not declared in
 * its public headers (as in test_badfiles.c). */
uint32_t H5_checksum_metadata(const void *data, size_t len, uint32_t initval);
/* LeakSanitizer's check; absent (NULL) in a build without it. */
int __lsan_do_recoverable_leak_check(void) __attribute__((weak));

/* A header's first chunk: [at, at + len) is checksummed, the checksum follows. */
typedef struct chunk {
    long at, len;
} chunk;

enum { MAX_CHUNKS = 8192, MODES = 4 };
static chunk chunks[MAX_CHUNKS];
static int nchunks;

static unsigned char *slurp(const char *path, long *n)
{
    FILE *f = fopen(path, "rb");
    if (!f || fseek(f, 0, SEEK_END) != 0 || (*n = ftell(f)) <= 0 || fseek(f, 0, SEEK_SET) != 0) return NULL;
    unsigned char *b = malloc((size_t)*n);
    if (b && fread(b, 1, (size_t)*n, f) != (size_t)*n) {
        free(b);
        b = NULL;
    }
    fclose(f);
    return b;
}

/* Every version-2 object header whose checksum holds (so not a chance "OHDR" in data). */
static void find_headers(const unsigned char *b, long n)
{
    for (long i = 0; i + 16 < n && nchunks < MAX_CHUNKS; i++) {
        if (memcmp(b + i, "OHDR", 4) != 0 || b[i + 4] != 2) continue;
        const unsigned flags = b[i + 5];
        long p = i + 6 + (flags & 0x20 ? 16 : 0) + (flags & 0x10 ? 4 : 0);
        const int w = 1 << (flags & 3);
        uint64_t size = 0;
        for (int k = 0; k < w && p + k < n; k++) size |= (uint64_t)b[p + k] << (8 * k);
        p += w;
        if (size > (uint64_t)n || p + (long)size + 4 > n) continue;
        uint32_t stored;
        memcpy(&stored, b + p + (long)size, 4);
        if (H5_checksum_metadata(b + i, (size_t)(p + (long)size - i), 0) != stored) continue;
        chunks[nchunks++] = (chunk){i, p + (long)size - i};
    }
}

static bool damage(const unsigned char *b, long n, const char *out, const chunk *c, long off, int mode)
{
    unsigned char *d = malloc((size_t)n);
    if (!d) return false;
    memcpy(d, b, (size_t)n);
    unsigned char *x = d + c->at + off;
    *x = mode == 0 ? (unsigned char)(*x ^ 0xff) : mode == 1 ? 0 : mode == 2 ? (unsigned char)(*x + 1) : 0x80;
    const uint32_t sum = H5_checksum_metadata(d + c->at, (size_t)c->len, 0);
    memcpy(d + c->at + c->len, &sum, 4);
    FILE *f = fopen(out, "wb");
    const bool ok = f && fwrite(d, 1, (size_t)n, f) == (size_t)n;
    if (f) fclose(f);
    free(d);
    return ok;
}

static void load(const char *path, int kind)
{
    char err[1024];
    if (kind == 0) {
        sx_model *m = sx_snapshot_load(path, 0, NULL, err, sizeof err);
        if (m) sx_model_cycle(m, 2);
        sx_model_destroy(m);
        return;
    }
    sx_series_opts o;
    memset(&o, 0, sizeof o);
    o.append = true;
    sx_series_close(sx_series_open(path, 0, &o, err, sizeof err), NULL, 0);
    sx_series_write_xdmf(path, err, sizeof err);
    sx_model_destroy(sx_snapshot_load(path, 0, NULL, err, sizeof err));
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s FILE KIND(0 snapshot, 1 series) [FIRST [LAST [BATCH [STRIDE]]]]\n", argv[0]);
        return 2;
    }
    long n;
    unsigned char *b = slurp(argv[1], &n);
    if (!b) {
        fprintf(stderr, "%s: cannot read it\n", argv[1]);
        return 1;
    }
    const int kind = atoi(argv[2]);
    find_headers(b, n);
    long total = 0;
    for (int i = 0; i < nchunks; i++) total += chunks[i].len * MODES;
    const long first = argc > 3 ? atol(argv[3]) : 0;
    const long last = argc > 4 && atol(argv[4]) >= 0 ? atol(argv[4]) : total - 1;
    const long batch = argc > 5 && atol(argv[5]) > 0 ? atol(argv[5]) : 100;
    const long stride = argc > 6 && atol(argv[6]) > 0 ? atol(argv[6]) : 1;
    fprintf(stderr, "%s: %d object headers, cases 0 .. %ld\n", argv[1], nchunks, total - 1);
    char out[4096];
    snprintf(out, sizeof out, "%s.damaged", argv[1]);
    long k = 0, ran = 0, leaks = 0;
    for (int ci = 0; ci < nchunks; ci++)
        for (long off = 0; off < chunks[ci].len; off++)
            for (int mode = 0; mode < MODES; mode++, k++) {
                if (k < first || k > last || off < 6 || k % stride != 0) continue; /* 6: signature, version, flags */
                fprintf(stderr, "case %ld: header at %ld, byte %ld, mutation %d\n", k, chunks[ci].at, off, mode);
                if (!damage(b, n, out, &chunks[ci], off, mode)) {
                    fprintf(stderr, "%s: cannot write it\n", out);
                    return 1;
                }
                load(out, kind);
                if (__lsan_do_recoverable_leak_check && ++ran % batch == 0 && __lsan_do_recoverable_leak_check()) {
                    printf("leak by case %ld (the first report names the first leaking batch)\n", k);
                    leaks++;
                }
            }
    if (__lsan_do_recoverable_leak_check && __lsan_do_recoverable_leak_check()) leaks++;
    printf("cases %ld .. %ld: %s\n", first, last, leaks ? "leaks (see above)" : "no leak");
    remove(out);
    free(b);
    return leaks ? 1 : 0;
}
