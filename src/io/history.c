/* Histories on disk: one group per history under /histories, named by the
 * history, holding three extendable 1-D datasets (step, time, value) and
 * the history's definition as attributes. The datasets have no maximum
 * size (H5S_UNLIMITED) and are chunked, so a series grows them in place as
 * the run goes; the group's attribute `count` says how many rows are
 * complete (rows beyond it were being written when a writer stopped).
 * A snapshot writes them the same way, complete, so a reader needs one
 * code path for both.
 *
 * And the CSV writer of m:history_csv, which writes like every other
 * seixo file: a unique temporary name, fsync, rename. */
#include "io_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *const source_names[] = {NULL, "function", "builtin", "ball", "wall"};
enum { NSOURCES = 5 };

/* What is wrong with a history (NULL: nothing), into buf. */
static const char *problem(const sx_io_history *x, char *buf, size_t len)
{
    if (!x->name || !*x->name || strcmp(x->name, ".") == 0 || strchr(x->name, '/'))
        snprintf(buf, len, "the history name '%s' cannot name a group: it must not be empty, \".\" or hold a '/'",
                 x->name ? x->name : "");
    else if (x->every < 1)
        snprintf(buf, len, "history '%s': every must be >= 1", x->name);
    else if (x->source < SX_IO_SOURCE_FUNCTION || x->source > SX_IO_SOURCE_WALL)
        snprintf(buf, len, "history '%s': unknown source %d", x->name, (int)x->source);
    else if (x->source == SX_IO_SOURCE_BUILTIN && (!x->builtin || !*x->builtin))
        snprintf(buf, len, "history '%s': a builtin source without its name", x->name);
    else if ((x->source == SX_IO_SOURCE_BALL || x->source == SX_IO_SOURCE_WALL) &&
             (!x->field || !*x->field || x->component < 0 || x->component > 2))
        snprintf(buf, len, "history '%s': an entity source without a field or with a component outside 0..2",
                 x->name);
    else if (x->n < 0 || (x->n > 0 && (!x->steps || !x->times || !x->values)))
        snprintf(buf, len, "history '%s': %lld samples without their arrays", x->name, (long long)x->n);
    else
        for (int64_t i = 1; i < x->n; i++)
            if (x->steps[i] <= x->steps[i - 1]) {
                snprintf(buf, len, "history '%s': its steps do not increase (sample %lld)", x->name, (long long)i);
                return buf;
            }
    return buf[0] ? buf : NULL;
}

bool sx_io_history_valid(sx_h5 *h, const sx_io_history *x)
{
    char buf[512] = "";
    const char *why = problem(x, buf, sizeof buf);
    return why ? sx_h5_fail(h, "%s", why) : true;
}

/* An empty 1-D dataset without a maximum size, in chunks of `chunk` rows. */
static bool create_column(sx_h5 *h, hid_t g, const char *name, hid_t file, int64_t chunk, const char *units)
{
    if (h->failed) return false;
    hsize_t dim = 0, max = H5S_UNLIMITED, ch = (hsize_t)chunk;
    hid_t s = H5Screate_simple(1, &dim, &max), p = H5Pcreate(H5P_DATASET_CREATE), d = -1;
    bool ok = s >= 0 && p >= 0 && H5Pset_chunk(p, 1, &ch) >= 0;
    if (ok && h->compression > 0 && H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0)
        ok = H5Pset_shuffle(p) >= 0 && H5Pset_deflate(p, (unsigned)h->compression) >= 0;
    ok = ok && H5Pset_fletcher32(p) >= 0;
    ok = ok && (d = H5Dcreate2(g, name, file, s, H5P_DEFAULT, p, H5P_DEFAULT)) >= 0;
    if (!ok) sx_h5_fail_h5(h, "cannot create the dataset '%s'", name);
    if (ok && units) ok = sx_h5_attr_str(h, d, "units", units);
    sx_h5_close(d);
    sx_h5_close(p);
    sx_h5_close(s);
    return ok;
}

hid_t sx_io_history_create(sx_h5 *h, hid_t parent, const sx_io_history *x, int64_t order, int64_t chunk)
{
    if (h->failed || !sx_io_history_valid(h, x)) return -1;
    hid_t g = H5Gcreate2(parent, x->name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) {
        sx_h5_fail_h5(h, "cannot create the group of history '%s'", x->name);
        return -1;
    }
    sx_h5_attr_int(h, g, "order", order);
    sx_h5_attr_int(h, g, "every", x->every);
    sx_h5_attr_str(h, g, "source", source_names[x->source]);
    if (x->source == SX_IO_SOURCE_BUILTIN) sx_h5_attr_str(h, g, "builtin", x->builtin);
    if (x->source == SX_IO_SOURCE_BALL || x->source == SX_IO_SOURCE_WALL) {
        sx_h5_attr_int(h, g, "id", x->id);
        sx_h5_attr_str(h, g, "field", x->field);
        sx_h5_attr_int(h, g, "component", x->component);
    }
    sx_h5_attr_int(h, g, "count", 0);
    if (chunk < 1) chunk = 1;
    create_column(h, g, "step", H5T_STD_I64LE, chunk, NULL);
    create_column(h, g, "time", H5T_IEEE_F64LE, chunk, "s");
    create_column(h, g, "value", H5T_IEEE_F64LE, chunk, NULL);
    if (h->failed) {
        sx_h5_close(g);
        return -1;
    }
    return g;
}

/* Rows [at, at + k) of the column `name` of g, the dataset extended to at + k. */
static bool put_column(sx_h5 *h, hid_t g, const char *name, hid_t mem, const void *data, int64_t at, int64_t k)
{
    if (h->failed) return false;
    hid_t d = H5Dopen2(g, name, H5P_DEFAULT), fs = -1, ms = -1;
    hsize_t size = (hsize_t)(at + k), start = (hsize_t)at, count = (hsize_t)k;
    bool ok = d >= 0 && H5Dset_extent(d, &size) >= 0 && (fs = H5Dget_space(d)) >= 0 &&
              (ms = H5Screate_simple(1, &count, NULL)) >= 0 &&
              H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &count, NULL) >= 0 &&
              H5Dwrite(d, mem, ms, fs, H5P_DEFAULT, data) >= 0;
    if (!ok) sx_h5_fail_h5(h, "cannot extend the dataset '%s' of a history", name);
    sx_h5_close(ms);
    sx_h5_close(fs);
    sx_h5_close(d);
    return ok;
}

bool sx_io_history_put(sx_h5 *h, hid_t g, const sx_io_history *x, int64_t from, int64_t at)
{
    const int64_t k = x->n - from;
    if (h->failed || k <= 0) return !h->failed;
    put_column(h, g, "step", H5T_NATIVE_INT64, x->steps + from, at, k);
    put_column(h, g, "time", H5T_NATIVE_DOUBLE, x->times + from, at, k);
    put_column(h, g, "value", H5T_NATIVE_DOUBLE, x->values + from, at, k);
    return !h->failed;
}

/* Rows of a 1-D column (-1 failing when it is not one). */
static int64_t column_rows(sx_h5 *h, hid_t g, const char *where, const char *name)
{
    return sx_h5_rows(h, g, where, name, 1, true);
}

/* The first k rows of a column. */
static bool get_column(sx_h5 *h, hid_t g, const char *where, const char *name, hid_t mem, void *data, int64_t k)
{
    if (h->failed || k == 0) return !h->failed;
    hid_t d = H5Dopen2(g, name, H5P_DEFAULT), fs = -1, ms = -1;
    hsize_t start = 0, count = (hsize_t)k;
    bool ok = d >= 0 && (fs = H5Dget_space(d)) >= 0 && (ms = H5Screate_simple(1, &count, NULL)) >= 0 &&
                    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &count, NULL) >= 0 &&
                    H5Dread(d, mem, ms, fs, H5P_DEFAULT, data) >= 0;
    if (!ok) sx_h5_fail_h5(h, "corrupted: the dataset %s/%s cannot be read", where, name);
    ok = ok && sx_h5_check_seal(h, d, where, name, mem, data, k);
    sx_h5_close(ms);
    sx_h5_close(fs);
    sx_h5_close(d);
    return ok;
}

bool sx_io_history_tail(sx_h5 *h, hid_t g, const char *where, int64_t *count, int64_t *last)
{
    *count = 0;
    *last = INT64_MIN;
    if (!sx_h5_get_i64(h, g, where, "count", count, 1, true)) return false;
    const int64_t rows = column_rows(h, g, where, "step");
    if (rows < 0) return false;
    if (*count < 0 || *count > rows)
        return sx_h5_fail(h, "damaged: %s counts %lld rows of %lld", where, (long long)*count, (long long)rows);
    if (*count == 0) return true;
    hid_t d = H5Dopen2(g, "step", H5P_DEFAULT), fs = -1, ms = -1;
    hsize_t start = (hsize_t)(*count - 1), one = 1;
    const bool ok = d >= 0 && (fs = H5Dget_space(d)) >= 0 && (ms = H5Screate_simple(1, &one, NULL)) >= 0 &&
                    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, NULL, &one, NULL) >= 0 &&
                    H5Dread(d, H5T_NATIVE_INT64, ms, fs, H5P_DEFAULT, last) >= 0;
    if (!ok) sx_h5_fail_h5(h, "corrupted: the dataset %s/step cannot be read", where);
    sx_h5_close(ms);
    sx_h5_close(fs);
    sx_h5_close(d);
    return ok;
}

/* A snapshot's column, written whole, gets its checksum (a series' grows
 * in place: none). */
static void seal_column(sx_h5 *h, hid_t g, const char *name, hid_t mem, const void *data, int64_t n)
{
    if (h->failed) return;
    hid_t d = H5Dopen2(g, name, H5P_DEFAULT);
    if (d < 0) sx_h5_fail_h5(h, "cannot open the dataset '%s' of a history", name);
    else sx_h5_seal(h, d, mem, data, n);
    sx_h5_close(d);
}

bool sx_io_histories_write(sx_h5 *h, hid_t file, const sx_io_history *x, int n)
{
    if (h->failed || n <= 0) return !h->failed;
    hid_t g = sx_h5_group(h, file, "histories");
    for (int i = 0; i < n && !h->failed; i++) {
        /* chunks of the whole history when it is short, of 64 Ki rows (512 KiB) when long */
        const int64_t chunk = x[i].n < 64 ? 64 : x[i].n > 65536 ? 65536 : x[i].n;
        hid_t q = sx_io_history_create(h, g, &x[i], i, chunk);
        sx_io_history_put(h, q, &x[i], 0, 0);
        sx_h5_attr_int(h, q, "count", x[i].n);
        seal_column(h, q, "step", H5T_NATIVE_INT64, x[i].steps, x[i].n);
        seal_column(h, q, "time", H5T_NATIVE_DOUBLE, x[i].times, x[i].n);
        seal_column(h, q, "value", H5T_NATIVE_DOUBLE, x[i].values, x[i].n);
        sx_h5_close(q);
    }
    sx_h5_close(g);
    return !h->failed;
}

void sx_io_histories_free(sx_io_history *x, int n)
{
    if (!x) return;
    for (int i = 0; i < n; i++) {
        free(x[i].name);
        free(x[i].builtin);
        free(x[i].field);
        free(x[i].steps);
        free(x[i].times);
        free(x[i].values);
    }
    free(x);
}

static char *dup_str(const char *s)
{
    const size_t n = strlen(s) + 1;
    char *p = malloc(n);
    if (p) memcpy(p, s, n);
    return p;
}

/* One history group: its definition and its first `count` rows. */
static void read_one(sx_h5 *h, hid_t g, const char *where, sx_io_history *x, int64_t *order)
{
    char text[64];
    int64_t src = 0, comp = 0, count = 0, last = 0;
    sx_h5_get_i64(h, g, where, "order", order, 1, true);
    sx_h5_get_i64(h, g, where, "every", &x->every, 1, true);
    if (h->failed) return;
    if (!sx_h5_get_str(g, "source", text, sizeof text)) {
        sx_h5_fail(h, "damaged: %s has no source", where);
        return;
    }
    for (int k = 1; k < NSOURCES; k++)
        if (strcmp(text, source_names[k]) == 0) src = k;
    if (!src) {
        sx_h5_fail(h, "damaged: %s has an unknown source '%s'", where, text);
        return;
    }
    x->source = (sx_io_source)src;
    if (src == SX_IO_SOURCE_BUILTIN) {
        if (!sx_h5_get_str(g, "builtin", text, sizeof text) || !(x->builtin = dup_str(text))) {
            sx_h5_fail(h, "damaged: %s has no builtin name", where);
            return;
        }
    } else if (src == SX_IO_SOURCE_BALL || src == SX_IO_SOURCE_WALL) {
        sx_h5_get_i64(h, g, where, "id", &x->id, 1, true);
        sx_h5_get_i64(h, g, where, "component", &comp, 1, true);
        if (h->failed) return;
        if (!sx_h5_get_str(g, "field", text, sizeof text) || !(x->field = dup_str(text))) {
            sx_h5_fail(h, "damaged: %s has no field name", where);
            return;
        }
        x->component = comp >= 0 && comp <= 2 ? (int)comp : -1;
    }
    if (!sx_io_history_tail(h, g, where, &count, &last)) return;
    if (column_rows(h, g, where, "time") < count || column_rows(h, g, where, "value") < count) {
        sx_h5_fail(h, "damaged: the columns of %s have fewer rows than its count %lld", where, (long long)count);
        return;
    }
    const size_t k = (size_t)(count > 0 ? count : 1);
    x->steps = malloc(k * sizeof *x->steps);
    x->times = malloc(k * sizeof *x->times);
    x->values = malloc(k * sizeof *x->values);
    if (!x->steps || !x->times || !x->values) {
        sx_h5_fail(h, "out of memory for %lld samples of %s", (long long)count, where);
        return;
    }
    get_column(h, g, where, "step", H5T_NATIVE_INT64, x->steps, count);
    get_column(h, g, where, "time", H5T_NATIVE_DOUBLE, x->times, count);
    get_column(h, g, where, "value", H5T_NATIVE_DOUBLE, x->values, count);
    x->n = count;
    char buf[512] = "";
    const char *why = h->failed ? NULL : problem(x, buf, sizeof buf);
    if (why) sx_h5_fail(h, "damaged: %s", why);
}

static int by_order(const void *a, const void *b)
{
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : x > y;
}

bool sx_io_histories_read(sx_h5 *h, hid_t file, sx_io_history **out, int *nout)
{
    *out = NULL;
    *nout = 0;
    if (h->failed || H5Lexists(file, "/histories", H5P_DEFAULT) <= 0) return !h->failed;
    hid_t g = sx_h5_open_group(h, file, "/histories", true);
    H5G_info_t gi;
    if (g < 0 || H5Gget_info(g, &gi) < 0) {
        sx_h5_close(g);
        return sx_h5_fail_h5(h, "damaged: cannot list /histories");
    }
    if (gi.nlinks > 100000) {
        sx_h5_close(g);
        return sx_h5_fail(h, "damaged: /histories lists %llu entries", (unsigned long long)gi.nlinks);
    }
    const int n = (int)gi.nlinks;
    sx_io_history *x = calloc((size_t)n + 1, sizeof *x);
    /* (order, index) pairs, sorted to give the creation order */
    int64_t *ord = calloc(2 * (size_t)n + 2, sizeof *ord);
    if (!x || !ord) sx_h5_fail(h, "out of memory");
    for (int k = 0; k < n && !h->failed; k++) {
        const ssize_t len = H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, (hsize_t)k, NULL, 0, H5P_DEFAULT);
        if (len <= 0 || len > SX_IO_HISTORY_NAME_MAX || !(x[k].name = malloc((size_t)len + 1)) ||
            H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, (hsize_t)k, x[k].name, (size_t)len + 1,
                               H5P_DEFAULT) != len) {
            sx_h5_fail(h, "damaged: a name in /histories is unreadable");
            break;
        }
        char *where = malloc((size_t)len + 16);
        if (!where) {
            sx_h5_fail(h, "out of memory");
            break;
        }
        snprintf(where, (size_t)len + 16, "/histories/%s", x[k].name);
        hid_t q = sx_h5_open_group(h, g, x[k].name, true);
        if (q >= 0) read_one(h, q, where, &x[k], &ord[2 * k]);
        ord[2 * k + 1] = k;
        sx_h5_close(q);
        free(where);
    }
    sx_h5_close(g);
    if (!h->failed) {
        qsort(ord, (size_t)n, 2 * sizeof *ord, by_order);
        sx_io_history *y = calloc((size_t)n + 1, sizeof *y);
        if (!y) {
            sx_h5_fail(h, "out of memory");
        } else {
            for (int k = 0; k < n; k++) y[k] = x[ord[2 * k + 1]];
            free(x);
            x = y;
        }
    }
    free(ord);
    if (h->failed) {
        sx_io_histories_free(x, n);
        return false;
    }
    *out = x;
    *nout = n;
    return true;
}

/* ------------------------------------------------------------------ CSV */

/* A CSV field: quoted, with its quotes doubled, when it holds a separator,
 * a quote or a line break (RFC 4180, 2.6-2.7). */
static void csv_field(FILE *f, const char *s)
{
    if (!strpbrk(s, ",\"\r\n")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

static void csv_rows(FILE *f, const sx_io_history *x, int nh, int64_t *at)
{
    fputs("step,time", f);
    for (int i = 0; i < nh; i++) {
        fputc(',', f);
        csv_field(f, x[i].name);
    }
    fputc('\n', f);
    for (;;) {
        /* the smallest next step; its time from the first history that has it */
        int64_t row = INT64_MAX;
        double t = 0;
        for (int i = 0; i < nh; i++)
            if (at[i] < x[i].n && x[i].steps[at[i]] < row) row = x[i].steps[at[i]], t = x[i].times[at[i]];
        if (row == INT64_MAX) break;
        fprintf(f, "%lld,%.17g", (long long)row, t);
        for (int i = 0; i < nh; i++) {
            fputc(',', f);
            if (at[i] < x[i].n && x[i].steps[at[i]] == row) fprintf(f, "%.17g", x[i].values[at[i]++]);
        }
        fputc('\n', f);
    }
}

sx_status sx_history_csv_write(const char *path, const sx_io_history *x, int nh, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, path ? path : "", err, errlen);
    char tmp[4096];
    int64_t *at = calloc((size_t)(nh > 0 ? nh : 1), sizeof *at);
    FILE *f = NULL;
    if (!path || !*path) {
        sx_h5_fail(&h, "an empty path");
    } else if (nh < 1) {
        sx_h5_fail(&h, "no history to write");
    } else if (!at) {
        sx_h5_fail(&h, "out of memory");
    } else if (!sx_h5_temp_for(&h, path, tmp, sizeof tmp)) {
        /* (failed, the reason named) */
    } else if (sx_io_series_open_at(path)) {
        sx_h5_fail(&h, "an output series open in this session writes this file: close it first, or write elsewhere");
    } else if (!(f = fopen(tmp, "wx"))) { /* "x": never into a file another writer made */
        sx_h5_fail(&h, "cannot create a file in its folder: %s", strerror(errno));
    } else {
        for (int i = 0; i < nh && !h.failed; i++) sx_io_history_valid(&h, &x[i]);
        if (!h.failed) csv_rows(f, x, nh, at);
        int e = ferror(f) ? EIO : 0;
        if (!e && fflush(f) != 0) e = errno;
        if (!e && fsync(fileno(f)) != 0) e = errno;
        if (fclose(f) != 0 && !e) e = errno;
        if (e) sx_h5_fail(&h, "cannot write '%s': %s", tmp, strerror(e));
        if (!h.failed) sx_h5_rename(&h, tmp, path);
        if (h.failed) remove(tmp);
    }
    free(at);
    const bool failed = h.failed;
    sx_h5_end(&h);
    return failed ? SX_EINVAL : SX_OK;
}
