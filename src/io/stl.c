/* STL files (ASCII and binary) read into a triangle soup for a mesh wall.
 *
 * A binary file is an 80-byte header, a little-endian uint32 triangle
 * count and 50 bytes per triangle (a normal, three corners as float32,
 * two attribute bytes); an ASCII file is `solid ... facet normal ...
 * outer loop vertex x y z (x3) endloop endfacet ... endsolid`. Some
 * binary files begin with "solid" too, so the binary form is recognised by
 * its size (84 + 50 n bytes). The facet normals written in the file are
 * not read: the corners' order (right-handed) says which way a facet
 * faces, and the core welds the corners and checks the triangles. */
#include "seixo_io.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static sx_status fail(char *err, size_t len, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static sx_status fail(char *err, size_t len, const char *path, const char *fmt, ...)
{
    char why[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    snprintf(err, len, "'%s': %s", path, why);
    return SX_EINVAL;
}

static double le_float(const unsigned char *b)
{
    const uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    float f;
    memcpy(&f, &u, sizeof f);
    return (double)f;
}

static sx_status read_binary(const unsigned char *data, int64_t nt, double *xyz)
{
    for (int64_t t = 0; t < nt; t++) {
        const unsigned char *rec = data + 84 + 50 * t + 12; /* past the normal */
        for (int k = 0; k < 9; k++) xyz[9 * t + k] = le_float(rec + 4 * k);
    }
    return SX_OK;
}

/* The next whitespace-separated word of the text at *p (NUL-terminated), or NULL. */
static const char *word(const char **p, size_t *len)
{
    const char *s = *p;
    while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n') s++;
    if (!*s) return NULL;
    const char *e = s;
    while (*e && *e != ' ' && *e != '\t' && *e != '\r' && *e != '\n') e++;
    *len = (size_t)(e - s);
    *p = e;
    return s;
}

static bool is(const char *w, size_t len, const char *lit) { return w && len == strlen(lit) && !memcmp(w, lit, len); }

/* The next word at *p is lit. */
static bool expect(const char **p, const char *lit)
{
    size_t len = 0;
    const char *w = word(p, &len);
    return is(w, len, lit);
}

/* Line number of position s in text (for messages). */
static int64_t line_of(const char *text, const char *s)
{
    int64_t n = 1;
    for (const char *c = text; c < s; c++) n += *c == '\n';
    return n;
}

static sx_status read_ascii(const char *path, const char *text, double **out, int64_t *nt, char *err, size_t len)
{
    int64_t cap = 64, n = 0;
    double *xyz = malloc((size_t)cap * 9 * sizeof *xyz);
    if (!xyz) return fail(err, len, path, "out of memory");
    const char *p = text, *w;
    size_t wl;
    /* "solid" and the rest of its line, a name */
    while (*p && *p != '\n') p++;
    for (;;) {
        w = word(&p, &wl);
        if (!w) {
            free(xyz);
            return fail(err, len, path, "the file ends before 'endsolid'");
        }
        if (is(w, wl, "endsolid")) break;
        if (!is(w, wl, "facet")) {
            free(xyz);
            return fail(err, len, path, "line %lld: expected 'facet' or 'endsolid', found '%.*s'",
                        (long long)line_of(text, w), (int)(wl > 40 ? 40 : wl), w);
        }
        while (*p && *p != '\n') p++; /* "normal nx ny nz": not read */
        if (n == cap) {
            double *q = realloc(xyz, (size_t)(2 * cap) * 9 * sizeof *q);
            if (!q) {
                free(xyz);
                return fail(err, len, path, "out of memory");
            }
            xyz = q, cap *= 2;
        }
        bool ok = expect(&p, "outer") && expect(&p, "loop");
        for (int v = 0; v < 3 && ok; v++) {
            ok = expect(&p, "vertex");
            for (int k = 0; k < 3 && ok; k++) {
                char *end;
                errno = 0;
                xyz[9 * n + 3 * v + k] = strtod(p, &end);
                ok = end != p && errno != ERANGE;
                p = end;
            }
        }
        ok = ok && expect(&p, "endloop") && expect(&p, "endfacet");
        if (!ok) {
            free(xyz);
            return fail(err, len, path,
                        "line %lld: facet %lld is not 'outer loop', three 'vertex x y z' and 'endloop endfacet'",
                        (long long)line_of(text, p), (long long)n + 1);
        }
        n++;
    }
    *out = xyz;
    *nt = n;
    return SX_OK;
}

sx_status sx_io_read_stl(const char *path, double **xyz, int64_t *nt, char *err, size_t errlen)
{
    *xyz = NULL;
    *nt = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return fail(err, errlen, path, "cannot open it: %s", strerror(errno));
    unsigned char *data = NULL;
    size_t size = 0, cap = 0;
    for (;;) {
        if (size == cap) {
            cap = cap ? 2 * cap : 1 << 16;
            unsigned char *q = realloc(data, cap + 1);
            if (!q) {
                free(data);
                fclose(f);
                return fail(err, errlen, path, "out of memory");
            }
            data = q;
        }
        const size_t got = fread(data + size, 1, cap - size, f);
        size += got;
        if (got == 0) break;
    }
    const bool bad = ferror(f);
    fclose(f);
    if (bad) {
        free(data);
        return fail(err, errlen, path, "read error");
    }
    data[size] = 0;
    sx_status st;
    uint32_t count = 0;
    if (size >= 84) count = (uint32_t)data[80] | (uint32_t)data[81] << 8 | (uint32_t)data[82] << 16 | (uint32_t)data[83] << 24;
    if (size >= 84 && (uint64_t)size == 84 + 50 * (uint64_t)count) {
        if (count == 0) {
            free(data);
            return fail(err, errlen, path, "a binary STL file with no triangle");
        }
        *xyz = malloc((size_t)count * 9 * sizeof **xyz);
        st = *xyz ? read_binary(data, count, *xyz) : fail(err, errlen, path, "out of memory");
        if (!st) *nt = count;
    } else if (size >= 5 && !memcmp(data, "solid", 5) && !memchr(data, 0, size)) {
        st = read_ascii(path, (const char *)data, xyz, nt, err, errlen);
        if (!st && *nt == 0) {
            free(*xyz);
            *xyz = NULL;
            st = fail(err, errlen, path, "an ASCII STL file with no facet");
        }
    } else {
        st = fail(err, errlen, path,
                  "not an STL file: neither ASCII (begins with 'solid') nor binary (84 + 50 n bytes for the n "
                  "triangles its header gives; it has %zu bytes and says %u triangles)",
                  size, count);
    }
    free(data);
    return st;
}
