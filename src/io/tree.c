/* Trees of plain values (a script's variables: numbers, strings, booleans
 * and nested tables of them) as a group of columns, one row per table
 * entry parent[key] = value:
 *     parent, key_kind, key_integer, key_number, key_offset, key_length,
 *     kind, integer, number, offset, length
 * and `text`, the bytes of every string key and value (offset and length
 * index it), so strings keep any byte. The kinds are HDF5 enums, so h5dump
 * and h5py show their names. A parent always precedes its children: a
 * reader rebuilds the tables in one pass. */
#include "io_internal.h"

#include <stdlib.h>
#include <string.h>

static char *dup_bytes(const char *s, size_t n)
{
    char *p = malloc(n + 1);
    if (!p) return NULL;
    if (n) memcpy(p, s, n);
    p[n] = 0;
    return p;
}

int64_t sx_io_tree_add(sx_io_tree *t, const sx_io_node *node)
{
    if (t->n == t->cap) {
        const int64_t cap = t->cap ? 2 * t->cap : 16;
        sx_io_node *q = realloc(t->node, (size_t)cap * sizeof *q);
        if (!q) return -1;
        t->node = q;
        t->cap = cap;
    }
    sx_io_node c = *node;
    c.key_string = NULL;
    c.string = NULL;
    if (c.key_kind == SX_IO_STRING) c.key_string = dup_bytes(node->key_string ? node->key_string : "", node->key_length);
    else c.key_length = 0;
    if (c.kind == SX_IO_STRING) c.string = dup_bytes(node->string ? node->string : "", node->length);
    else c.length = 0;
    if ((c.key_kind == SX_IO_STRING && !c.key_string) || (c.kind == SX_IO_STRING && !c.string)) {
        free(c.key_string);
        free(c.string);
        return -1;
    }
    t->node[t->n] = c;
    return t->n++;
}

void sx_io_tree_free(sx_io_tree *t)
{
    for (int64_t i = 0; i < t->n; i++) {
        free(t->node[i].key_string);
        free(t->node[i].string);
    }
    free(t->node);
    memset(t, 0, sizeof *t);
}

static const char *const kind_names[] = {"boolean", "integer", "number", "string", "table"};
static const int kind_values[] = {SX_IO_BOOLEAN, SX_IO_INTEGER, SX_IO_NUMBER, SX_IO_STRING, SX_IO_TABLE};

/* The columns of a tree. */
typedef struct cols {
    int64_t *parent, *key_integer, *key_offset, *key_length, *integer, *offset, *length;
    double *key_number, *number;
    int *key_kind, *kind;
} cols;

static bool cols_alloc(cols *c, int64_t n)
{
    const size_t k = (size_t)(n > 0 ? n : 1);
    int64_t **i64[] = {&c->parent, &c->key_integer, &c->key_offset, &c->key_length, &c->integer, &c->offset, &c->length};
    bool ok = true;
    for (size_t q = 0; q < sizeof i64 / sizeof *i64; q++) ok &= (*i64[q] = calloc(k, sizeof(int64_t))) != NULL;
    ok &= (c->key_number = calloc(k, sizeof(double))) != NULL;
    ok &= (c->number = calloc(k, sizeof(double))) != NULL;
    ok &= (c->key_kind = calloc(k, sizeof(int))) != NULL;
    ok &= (c->kind = calloc(k, sizeof(int))) != NULL;
    return ok;
}

static void cols_free(cols *c)
{
    void *p[] = {c->parent, c->key_integer, c->key_offset, c->key_length, c->integer, c->offset, c->length,
                 c->key_number, c->number, c->key_kind, c->kind};
    for (size_t q = 0; q < sizeof p / sizeof *p; q++) free(p[q]);
}

/* Reads (write = false) or writes the columns. */
static void cols_io(sx_h5 *h, hid_t g, const char *where, cols *c, int64_t n, bool write)
{
    hid_t km = sx_h5_enum(H5T_NATIVE_INT, kind_names, kind_values, 5);
    hid_t kf = sx_h5_enum(H5T_STD_U8LE, kind_names, kind_values, 5);
    if (km < 0 || kf < 0) {
        sx_h5_fail_h5(h, "cannot make the kinds' type");
    } else {
        const struct {
            const char *name;
            hid_t mem, file;
            void *data;
        } col[] = {
            {"parent", H5T_NATIVE_INT64, H5T_STD_I64LE, c->parent},
            {"key_kind", km, kf, c->key_kind},
            {"key_integer", H5T_NATIVE_INT64, H5T_STD_I64LE, c->key_integer},
            {"key_number", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c->key_number},
            {"key_offset", H5T_NATIVE_INT64, H5T_STD_I64LE, c->key_offset},
            {"key_length", H5T_NATIVE_INT64, H5T_STD_I64LE, c->key_length},
            {"kind", km, kf, c->kind},
            {"integer", H5T_NATIVE_INT64, H5T_STD_I64LE, c->integer},
            {"number", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c->number},
            {"offset", H5T_NATIVE_INT64, H5T_STD_I64LE, c->offset},
            {"length", H5T_NATIVE_INT64, H5T_STD_I64LE, c->length},
        };
        for (size_t q = 0; q < sizeof col / sizeof *col; q++) {
            if (write) sx_h5_write(h, g, col[q].name, col[q].mem, col[q].file, col[q].data, n, 1, NULL);
            else sx_h5_read(h, g, where, col[q].name, col[q].mem, col[q].data, n, 1, true);
        }
    }
    sx_h5_close(km);
    sx_h5_close(kf);
}

bool sx_io_write_tree(sx_h5 *h, hid_t loc, const char *name, const sx_io_tree *t)
{
    if (h->failed) return false;
    cols c;
    memset(&c, 0, sizeof c);
    size_t bytes = 0;
    for (int64_t i = 0; i < t->n; i++) bytes += t->node[i].key_length + t->node[i].length;
    char *text = malloc(bytes + 1);
    if (!text || !cols_alloc(&c, t->n)) {
        free(text);
        cols_free(&c);
        return sx_h5_fail(h, "out of memory writing '%s'", name);
    }
    size_t at = 0;
    for (int64_t i = 0; i < t->n; i++) {
        const sx_io_node *n = &t->node[i];
        c.parent[i] = n->parent;
        c.key_kind[i] = (int)n->key_kind;
        c.key_integer[i] = n->key_integer;
        c.key_number[i] = n->key_number;
        c.key_offset[i] = (int64_t)at;
        c.key_length[i] = (int64_t)n->key_length;
        if (n->key_length) memcpy(text + at, n->key_string, n->key_length);
        at += n->key_length;
        c.kind[i] = (int)n->kind;
        c.integer[i] = n->integer;
        c.number[i] = n->number;
        c.offset[i] = (int64_t)at;
        c.length[i] = (int64_t)n->length;
        if (n->length) memcpy(text + at, n->string, n->length);
        at += n->length;
    }
    hid_t g = sx_h5_group(h, loc, name);
    if (g >= 0) {
        sx_h5_attr_int(h, g, "count", t->n);
        cols_io(h, g, name, &c, t->n, true);
        sx_h5_write(h, g, "text", H5T_NATIVE_UINT8, H5T_STD_U8LE, text, (int64_t)bytes, 1, NULL);
    }
    sx_h5_close(g);
    free(text);
    cols_free(&c);
    return !h->failed;
}

static bool valid_kind(int k, bool key) { return k >= SX_IO_BOOLEAN && k <= (key ? SX_IO_STRING : SX_IO_TABLE); }

bool sx_io_read_tree(sx_h5 *h, hid_t loc, const char *where, const char *name, sx_io_tree *t)
{
    memset(t, 0, sizeof *t);
    char path[256];
    snprintf(path, sizeof path, "%s/%s", where, name);
    hid_t g = sx_h5_open_group(h, loc, name, true);
    if (g < 0) return false;
    const int64_t n = sx_h5_rows(h, g, path, "parent", 1, true);
    const int64_t bytes = sx_h5_rows(h, g, path, "text", 1, true);
    cols c;
    memset(&c, 0, sizeof c);
    char *text = n >= 0 && bytes >= 0 ? malloc((size_t)bytes + 1) : NULL;
    bool ok = n >= 0 && bytes >= 0;
    if (ok && (!text || !cols_alloc(&c, n))) ok = sx_h5_fail(h, "out of memory reading %s", path);
    if (ok) {
        cols_io(h, g, path, &c, n, false);
        sx_h5_read(h, g, path, "text", H5T_NATIVE_UINT8, text, bytes, 1, true);
        ok = !h->failed;
    }
    for (int64_t i = 0; ok && i < n; i++) {
        const int64_t p = c.parent[i];
        const bool strings_ok = c.key_offset[i] >= 0 && c.key_length[i] >= 0 && c.offset[i] >= 0 && c.length[i] >= 0 &&
                                c.key_offset[i] <= bytes - c.key_length[i] && c.offset[i] <= bytes - c.length[i];
        if (p < -1 || p >= i || (p >= 0 && c.kind[p] != SX_IO_TABLE) || !valid_kind(c.key_kind[i], true) ||
            !valid_kind(c.kind[i], false) || !strings_ok) {
            ok = sx_h5_fail(h, "damaged: entry %lld of %s is inconsistent", (long long)i, path);
            break;
        }
        const sx_io_node node = {.parent = p,
                                 .key_kind = (sx_io_kind)c.key_kind[i],
                                 .key_string = text + c.key_offset[i],
                                 .key_length = (size_t)c.key_length[i],
                                 .key_integer = c.key_integer[i],
                                 .key_number = c.key_number[i],
                                 .kind = (sx_io_kind)c.kind[i],
                                 .string = text + c.offset[i],
                                 .length = (size_t)c.length[i],
                                 .integer = c.integer[i],
                                 .number = c.number[i]};
        if (sx_io_tree_add(t, &node) < 0) ok = sx_h5_fail(h, "out of memory reading %s", path);
    }
    sx_h5_close(g);
    free(text);
    cols_free(&c);
    if (!ok) sx_io_tree_free(t);
    return ok;
}
