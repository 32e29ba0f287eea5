/* Shared HDF5 helpers (see h5util.h). Every dataset seixo writes is
 * chunked and Fletcher-32 checksummed, so a flipped bit in the data is
 * reported as corruption instead of loading silently; the 1.8 file format
 * adds checksums to the metadata as well. */
#include "h5util.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void sx_h5_begin(sx_h5 *h, const char *path, char *err, size_t errlen)
{
    /* HDF5 1.10 keeps a little state of a file whose superblock failed to
     * load, and its shutdown at exit then reports an "infinite loop closing
     * library"; every file seixo writes is complete on disk before its call
     * returns, so that shutdown is not needed. (Effective only before HDF5's
     * first use; harmless after.) */
    static bool once;
    if (!once) {
        once = true;
        H5dont_atexit();
        /* No free lists: HDF5 would keep the memory it frees for reuse, and a
         * leak checker (valgrind, LSan) would then blame a leaked block on
         * whichever call first allocated it (a save, say) instead of the one
         * that leaked it; the suppressions of HDF5's own leaks on damaged
         * files (tests/io/valgrind.supp, lsan.supp) match the leaking call's frames. Freed
         * memory goes back to the C library, whose allocator is fast. */
        H5set_free_list_limits(0, 0, 0, 0, 0, 0);
    }
    memset(h, 0, sizeof *h);
    h->path = path;
    h->err = err;
    h->errlen = errlen;
    if (err && errlen) err[0] = 0;
    H5Eget_auto2(H5E_DEFAULT, &h->old_func, &h->old_data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

void sx_h5_end(sx_h5 *h)
{
    H5Eclear2(H5E_DEFAULT);
    H5Eset_auto2(H5E_DEFAULT, h->old_func, h->old_data);
}

static bool vfail(sx_h5 *h, const char *detail, const char *fmt, va_list ap)
{
    if (h->failed) return false;
    h->failed = true;
    if (!h->err || !h->errlen) return false;
    char msg[768];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (detail && *detail)
        snprintf(h->err, h->errlen, "'%s': %s (%s)", h->path, msg, detail);
    else
        snprintf(h->err, h->errlen, "'%s': %s", h->path, msg);
    return false;
}

bool sx_h5_fail(sx_h5 *h, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vfail(h, NULL, fmt, ap);
    va_end(ap);
    return false;
}

/* The innermost message of HDF5's error stack: the most specific one, on
 * one line. A failed write's says "file write failed: time = <ctime text
 * with its newline>, filename = ..., errno = 28, error message = 'No space
 * left on device', ...": then the system's message alone is kept. */
static herr_t innermost(unsigned n, const H5E_error2_t *e, void *ud)
{
    char *out = ud;
    if (n != 0 || !e->desc || !*e->desc) return 0;
    const char *sys = strstr(e->desc, "error message = '");
    if (sys) {
        sys += strlen("error message = '");
        const char *end = strchr(sys, '\'');
        snprintf(out, 256, "%.*s", (int)(end ? end - sys : (ptrdiff_t)strlen(sys)), sys);
    } else {
        snprintf(out, 256, "%s", e->desc);
    }
    for (char *c = out; *c; c++)
        if (*c == '\n' || *c == '\r' || *c == '\t') *c = ' ';
    return 0;
}

bool sx_h5_fail_h5(sx_h5 *h, const char *fmt, ...)
{
    char detail[256] = "";
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost, detail);
    H5Eclear2(H5E_DEFAULT);
    va_list ap;
    va_start(ap, fmt);
    vfail(h, detail, fmt, ap);
    va_end(ap);
    return false;
}

void sx_h5_close(hid_t id)
{
    if (id < 0) return;
    switch (H5Iget_type(id)) {
    case H5I_FILE: H5Fclose(id); break;
    case H5I_GROUP: H5Gclose(id); break;
    case H5I_DATASET: H5Dclose(id); break;
    case H5I_DATASPACE: H5Sclose(id); break;
    case H5I_DATATYPE: H5Tclose(id); break;
    case H5I_ATTR: H5Aclose(id); break;
    case H5I_GENPROP_LST: H5Pclose(id); break;
    default: break;
    }
}

/* --------------------------------------------------------------- files */

const char *sx_io_unreplaceable(const char *path)
{
    struct stat st;
    if (!path || lstat(path, &st) != 0 || S_ISREG(st.st_mode)) return NULL; /* (a missing folder: the write says) */
    if (S_ISLNK(st.st_mode))
        return "is a symbolic link: writing renames a new file over it, which would replace the link and leave its "
               "target as it was; give the target's path";
    if (S_ISDIR(st.st_mode)) return "is a folder";
    return "is not a regular file (a device, a pipe or a socket): writing renames a new file over it, which would "
           "replace it";
}

static bool temp_name(const char *path, char *out, size_t len)
{
    static unsigned counter;
    const char *slash = strrchr(path, '/');
    const int dirlen = slash ? (int)(slash - path + 1) : 0;
    const char *base = slash ? slash + 1 : path;
    const int n = snprintf(out, len, "%.*s.%s.tmp-%ld-%u", dirlen, path, base, (long)getpid(), counter++);
    return n > 0 && (size_t)n < len && *base;
}

hid_t sx_h5_fapl(bool latest)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl < 0) return fapl;
    /* latest (snapshots, made complete before they are renamed into
     * place): the 1.10 format, whose chunk indices are checksummed like
     * every other piece of metadata. Otherwise (series, appended in place)
     * the 1.8 format: checksummed object headers, and no "open for
     * writing" flag that would leave a file whose writer was killed
     * unopenable; and each flush made atomic by a journal (journal.c).
     * SEMI: closing a file with objects still open is an error, never a
     * file left half-written behind a successful close. */
    const H5F_libver_t v = latest ? H5F_LIBVER_LATEST : H5F_LIBVER_V18;
    if (H5Pset_libver_bounds(fapl, v, v) < 0 || H5Pset_fclose_degree(fapl, H5F_CLOSE_SEMI) < 0 ||
        (!latest && H5Pset_driver(fapl, sx_h5_journal_driver(), NULL) < 0)) {
        H5Pclose(fapl);
        return -1;
    }
    return fapl;
}

hid_t sx_h5_fcpl(void)
{
    hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    /* Small B-tree nodes for the chunk index: a snapshot's datasets have
     * one chunk or a few, and HDF5's default nodes (room for 64 chunks)
     * would make most of a small file empty index space. */
    if (fcpl >= 0 && H5Pset_istore_k(fcpl, 2) < 0) {
        H5Pclose(fcpl);
        return -1;
    }
    return fcpl;
}

static bool sync_path(const char *path)
{
    const int fd = open(path, O_RDONLY);
    if (fd < 0) return false;
    const bool ok = fsync(fd) == 0;
    close(fd);
    return ok;
}

bool sx_h5_commit(sx_h5 *h, const char *tmp, const char *path)
{
    if (h->failed) return false;
    if (!sync_path(tmp)) {
        sx_h5_fail(h, "cannot flush the temporary file '%s' to disk: %s", tmp, strerror(errno));
        return false;
    }
    /* the file replaced may have left a journal (its writer killed in a
     * flush): applied to the new file it would damage it */
    if (!sx_h5_journal_drop(path)) {
        sx_h5_fail(h, "cannot remove the journal of the file '%s' replaces: %s", path, strerror(errno));
        return false;
    }
    return sx_h5_rename(h, tmp, path);
}

bool sx_h5_temp_for(sx_h5 *h, const char *path, char *tmp, size_t len)
{
    if (h->failed) return false;
    /* the context names its own file; another one (a series' .xmf) is named here */
    const bool other = strcmp(path, h->path) != 0;
    const char *why = sx_io_unreplaceable(path);
    if (why) return other ? sx_h5_fail(h, "'%s' %s", path, why) : sx_h5_fail(h, "%s", why);
    if (!temp_name(path, tmp, len))
        return other ? sx_h5_fail(h, "the path of '%s' is too long", path) : sx_h5_fail(h, "the path is too long");
    return true;
}

hid_t sx_h5_create_temp(sx_h5 *h, const char *tmp, bool latest)
{
    if (h->failed) return -1;
    hid_t fapl = sx_h5_fapl(latest);
    hid_t fcpl = sx_h5_fcpl();
    const bool taken = access(tmp, F_OK) == 0; /* another writer's: never removed */
    /* EXCL: a name left by another writer is never written into */
    hid_t f = fapl >= 0 && fcpl >= 0 ? H5Fcreate(tmp, H5F_ACC_EXCL, fcpl, fapl) : -1;
    /* (before any other HDF5 call, which would clear the reason from its stack) */
    if (f < 0) sx_h5_fail_h5(h, "cannot create a file in its folder");
    sx_h5_close(fapl);
    sx_h5_close(fcpl);
    if (f < 0 && !taken) remove(tmp); /* an empty file a full disk left */
    return f;
}

bool sx_h5_write_temp(sx_h5 *h, const char *path, const void *data, size_t n, char *tmp, size_t len)
{
    if (!sx_h5_temp_for(h, path, tmp, len)) return false;
    /* O_EXCL: a name left by another writer is never written into */
    const int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL, 0666);
    if (fd < 0) return sx_h5_fail(h, "cannot create '%s': %s", tmp, strerror(errno));
    const char *p = data;
    size_t done = 0;
    int e = 0;
    while (done < n && !e) {
        const ssize_t w = write(fd, p + done, n - done);
        if (w > 0) done += (size_t)w;
        else if (w == 0) e = EIO;
        else if (errno != EINTR) e = errno;
    }
    if (!e && fsync(fd) != 0) e = errno;
    if (close(fd) != 0 && !e) e = errno;
    if (e) {
        remove(tmp);
        return sx_h5_fail(h, "cannot write '%s': %s", tmp, strerror(e));
    }
    return true;
}

bool sx_h5_rename(sx_h5 *h, const char *tmp, const char *path)
{
    if (h->failed) return false;
    if (rename(tmp, path) != 0) return sx_h5_fail(h, "cannot rename '%s' to '%s': %s", tmp, path, strerror(errno));
    /* the rename itself is durable once the folder is synced */
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (slash == path) snprintf(dir, sizeof dir, "/");
    else if (slash) snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    else snprintf(dir, sizeof dir, ".");
    const int fd = open(dir, O_RDONLY);
    if (fd >= 0) {
        fsync(fd);
        close(fd);
    }
    return true;
}

/* ---------------------------------------------------------- attributes */

/* A fixed-length UTF-8 string type of n bytes. Fixed, never variable-
 * length: variable-length strings live in HDF5's global heap, which has no
 * checksum, and HDF5 1.10 crashes on some damaged heaps; fixed strings
 * live in the (checksummed) object headers and datasets. */
static hid_t fixed_string(size_t n)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t >= 0 && (H5Tset_size(t, n > 0 ? n : 1) < 0 || H5Tset_strpad(t, H5T_STR_NULLPAD) < 0 ||
                   H5Tset_cset(t, H5T_CSET_UTF8) < 0)) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

hid_t sx_h5_string_type(size_t n) { return fixed_string(n); }

/* Replaces an existing attribute (a series rewrites its counters). */
static hid_t new_attr(hid_t obj, const char *name, hid_t type, hid_t space)
{
    if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
    return H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
}

bool sx_h5_attr_str(sx_h5 *h, hid_t obj, const char *name, const char *value)
{
    if (h->failed) return false;
    const size_t len = strlen(value);
    hid_t t = fixed_string(len), s = H5Screate(H5S_SCALAR), a = -1;
    bool ok = t >= 0 && s >= 0 && (a = new_attr(obj, name, t, s)) >= 0 && H5Awrite(a, t, len ? value : "") >= 0;
    if (!ok) sx_h5_fail_h5(h, "cannot write the attribute '%s'", name); /* before any close clears HDF5's errors */
    sx_h5_close(a);
    sx_h5_close(s);
    sx_h5_close(t);
    return ok;
}

/* An existing attribute of the same class and size is written in place
 * (a series updates its counters so, never deleting them in between). */
static bool attr_rewrite(hid_t obj, const char *name, hid_t mem, const void *v, size_t n, bool *done)
{
    *done = false;
    if (n == 0 || H5Aexists(obj, name) <= 0) return true;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), s = a >= 0 ? H5Aget_space(a) : -1, t = a >= 0 ? H5Aget_type(a) : -1;
    bool ok = true;
    if (s >= 0 && t >= 0 && H5Sget_simple_extent_npoints(s) == (hssize_t)n && H5Tget_class(t) == H5Tget_class(mem)) {
        ok = H5Awrite(a, mem, v) >= 0;
        *done = true;
    }
    sx_h5_close(t);
    sx_h5_close(s);
    sx_h5_close(a);
    return ok;
}

static bool attr_num(sx_h5 *h, hid_t obj, const char *name, hid_t mem, hid_t file, const void *v, size_t n,
                     bool scalar)
{
    if (h->failed) return false;
    bool done;
    if (!attr_rewrite(obj, name, mem, v, n, &done)) return sx_h5_fail_h5(h, "cannot write the attribute '%s'", name);
    if (done) return true;
    hsize_t dim = n;
    hid_t s = n == 0 ? H5Screate(H5S_NULL) : scalar && n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &dim, NULL);
    hid_t a = -1;
    bool ok = s >= 0 && (a = new_attr(obj, name, file, s)) >= 0 && (n == 0 || H5Awrite(a, mem, v) >= 0);
    if (!ok) sx_h5_fail_h5(h, "cannot write the attribute '%s'", name);
    sx_h5_close(a);
    sx_h5_close(s);
    return ok;
}

bool sx_h5_attr_f64(sx_h5 *h, hid_t obj, const char *name, const double *v, size_t n, bool scalar)
{
    return attr_num(h, obj, name, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, v, n, scalar);
}

bool sx_h5_attr_i64(sx_h5 *h, hid_t obj, const char *name, const int64_t *v, size_t n, bool scalar)
{
    return attr_num(h, obj, name, H5T_NATIVE_INT64, H5T_STD_I64LE, v, n, scalar);
}


size_t sx_h5_attr_len(hid_t obj, const char *name)
{
    if (H5Aexists(obj, name) <= 0) return 0;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), s = a >= 0 ? H5Aget_space(a) : -1;
    const hssize_t n = s >= 0 ? H5Sget_simple_extent_npoints(s) : 0;
    sx_h5_close(s);
    sx_h5_close(a);
    return n > 0 ? (size_t)n : 0;
}

static bool get_num(sx_h5 *h, hid_t obj, const char *where, const char *name, hid_t mem, void *v, size_t n,
                    bool required)
{
    if (h->failed) return false;
    const htri_t exists = H5Aexists(obj, name);
    if (exists <= 0) {
        if (!required) return true;
        return sx_h5_fail(h, "not a complete seixo file: the attribute '%s' of %s is missing", name, where);
    }
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), s = a >= 0 ? H5Aget_space(a) : -1, t = a >= 0 ? H5Aget_type(a) : -1;
    const H5T_class_t cls = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
    const hssize_t np = s >= 0 ? H5Sget_simple_extent_npoints(s) : -1;
    bool ok = false;
    if (a < 0 || s < 0 || t < 0) {
        sx_h5_fail_h5(h, "damaged: cannot read the attribute '%s' of %s", name, where);
    } else if ((cls != H5T_INTEGER && cls != H5T_FLOAT) || np != (hssize_t)n) {
        sx_h5_fail(h, "damaged: the attribute '%s' of %s should hold %zu number%s", name, where, n, n == 1 ? "" : "s");
    } else if (n > 0 && H5Aread(a, mem, v) < 0) {
        sx_h5_fail_h5(h, "damaged: cannot read the attribute '%s' of %s", name, where);
    } else {
        ok = true;
    }
    sx_h5_close(t);
    sx_h5_close(s);
    sx_h5_close(a);
    return ok;
}

bool sx_h5_get_f64(sx_h5 *h, hid_t obj, const char *where, const char *name, double *v, size_t n, bool required)
{
    return get_num(h, obj, where, name, H5T_NATIVE_DOUBLE, v, n, required);
}

bool sx_h5_get_i64(sx_h5 *h, hid_t obj, const char *where, const char *name, int64_t *v, size_t n, bool required)
{
    return get_num(h, obj, where, name, H5T_NATIVE_INT64, v, n, required);
}

bool sx_h5_get_str(hid_t obj, const char *name, char *out, size_t len)
{
    if (!len) return false;
    out[0] = 0;
    if (H5Aexists(obj, name) <= 0) return false;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), t = a >= 0 ? H5Aget_type(a) : -1, s = a >= 0 ? H5Aget_space(a) : -1;
    bool ok = false;
    /* variable-length strings are not read (see fixed_string) */
    if (t >= 0 && s >= 0 && H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) == 0 &&
        H5Sget_simple_extent_npoints(s) == 1) {
        const size_t sz = H5Tget_size(t);
        char *buf = sz > 0 && sz < (1u << 20) ? calloc(1, sz + 1) : NULL;
        hid_t mt = buf ? fixed_string(sz) : -1;
        if (mt >= 0 && H5Aread(a, mt, buf) >= 0) {
            snprintf(out, len, "%s", buf);
            ok = true;
        }
        sx_h5_close(mt);
        free(buf);
    }
    sx_h5_close(s);
    sx_h5_close(t);
    sx_h5_close(a);
    return ok;
}

bool sx_h5_attr_is_vlen(hid_t obj, const char *name)
{
    if (H5Aexists(obj, name) <= 0) return false;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), t = a >= 0 ? H5Aget_type(a) : -1;
    const bool vlen = t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) > 0;
    sx_h5_close(t);
    sx_h5_close(a);
    return vlen;
}

/* ------------------------------------------------------------ datasets */

hid_t sx_h5_enum(hid_t base, const char *const names[], const int values[], int n)
{
    hid_t t = H5Tenum_create(base);
    if (t < 0) return t;
    const size_t size = H5Tget_size(base);
    for (int i = 0; i < n; i++) {
        int32_t v4 = values[i];
        int8_t v1 = (int8_t)values[i];
        int16_t v2 = (int16_t)values[i];
        int64_t v8 = values[i];
        const void *v = size == 1 ? (const void *)&v1 : size == 2 ? (const void *)&v2 : size == 4 ? (const void *)&v4 : (const void *)&v8;
        if (H5Tenum_insert(t, names[i], v) < 0) {
            H5Tclose(t);
            return -1;
        }
    }
    return t;
}

/* seixo's own checksum of a dataset's values, kept in its attribute
 * "checksum": HDF5's Fletcher-32 of a chunk zeroed with its checksum (a
 * block a crash left unwritten) reads as valid. Taken over the values as
 * the file stores them (its type, little-endian), read a word at a time in
 * that order, so any host computes the same (a multiply and a shift per 8
 * bytes: a few GB/s), the length folded in. */
static uint64_t bytes_checksum(const unsigned char *p, size_t n)
{
    uint64_t h = 0x9e3779b97f4a7c15ULL ^ n;
    for (size_t i = 0; i < n; i += 8) {
        uint64_t w = 0;
        for (size_t b = 0; b < 8 && i + b < n; b++) w |= (uint64_t)p[i + b] << (8 * b);
        h = (h ^ w) * 0xff51afd7ed558ccdULL;
        h ^= h >> 32;
    }
    h *= 0xc4ceb9fe1a85ec53ULL;
    return h ^ (h >> 29);
}

/* The checksum of n values of `mem` (data) as stored in the type `file`:
 * converted to it first when the two differ (an enum written from native
 * ints, a host of the other byte order). False when they cannot be. */
static bool file_checksum(hid_t mem, hid_t file, size_t n, const void *data, uint64_t *sum)
{
    const size_t ms = H5Tget_size(mem), fs = H5Tget_size(file);
    if (!ms || !fs) return false;
    if (H5Tequal(mem, file) > 0) {
        *sum = bytes_checksum(data, n * fs);
        return true;
    }
    unsigned char *buf = malloc(n * (ms > fs ? ms : fs) + 1);
    bool ok = buf != NULL;
    if (ok) memcpy(buf, data, n * ms);
    ok = ok && H5Tconvert(mem, file, n, buf, NULL, H5P_DEFAULT) >= 0;
    if (ok) *sum = bytes_checksum(buf, n * fs);
    free(buf);
    return ok;
}

/* The checksum of dataset d's n values, given as `mem` at data (its whole
 * contents), as the file stores them; false when it cannot be taken (a
 * type HDF5 cannot convert: its values' own checks remain). */
static bool dataset_checksum(hid_t d, hid_t mem, const void *data, int64_t n, uint64_t *sum)
{
    hid_t t = H5Dget_type(d);
    const bool known = t >= 0 && n > 0 && file_checksum(mem, t, (size_t)n, data, sum);
    sx_h5_close(t);
    H5Eclear2(H5E_DEFAULT);
    return known;
}

bool sx_h5_seal(sx_h5 *h, hid_t d, hid_t mem, const void *data, int64_t n)
{
    if (h->failed) return false;
    uint64_t sum = 0;
    return !dataset_checksum(d, mem, data, n, &sum) || sx_h5_attr_int(h, d, "checksum", (int64_t)sum);
}

bool sx_h5_check_seal(sx_h5 *h, hid_t d, const char *where, const char *name, hid_t mem, const void *data, int64_t n)
{
    if (h->failed) return false;
    /* (files before the checksum have none) */
    if (n <= 0 || H5Aexists(d, "checksum") <= 0) return true;
    int64_t want = 0;
    if (!sx_h5_get_i64(h, d, where, "checksum", &want, 1, true)) return false;
    uint64_t sum = 0;
    if (dataset_checksum(d, mem, data, n, &sum) && sum != (uint64_t)want)
        return sx_h5_fail(h, "damaged: the dataset %s/%s does not match its checksum (bytes lost or changed on the "
                          "disk; a dataset changed on purpose with another tool loads once its attribute "
                          "'checksum' is deleted)", where, name);
    return true;
}

/* About 512 KiB of doubles per chunk: large enough for fast I/O and good
 * compression, small enough for HDF5's default chunk cache. */
enum { CHUNK_ELEMS = 65536 };

bool sx_h5_write(sx_h5 *h, hid_t loc, const char *name, hid_t mem, hid_t file, const void *data, int64_t n, int per,
                 const char *units)
{
    if (h->failed) return false;
    const int rank = per == 1 ? 1 : 2;
    hsize_t dims[2] = {(hsize_t)n, (hsize_t)per};
    hsize_t rows = (hsize_t)(CHUNK_ELEMS / per);
    if (rows > (hsize_t)n) rows = (hsize_t)n;
    if (rows < 1) rows = 1;
    hsize_t chunk[2] = {rows, (hsize_t)per};
    hid_t s = H5Screate_simple(rank, dims, NULL), p = H5Pcreate(H5P_DATASET_CREATE), d = -1;
    /* an empty dataset has nothing to checksum (and cannot be chunked at a
     * fixed size of 0); seixo writes no variable-length data, to which
     * HDF5 filters cannot apply */
    const bool filters = n > 0 && H5Tdetect_class(file, H5T_VLEN) <= 0 && H5Tis_variable_str(file) <= 0;
    bool ok = s >= 0 && p >= 0 && (n == 0 || H5Pset_chunk(p, rank, chunk) >= 0);
    if (ok && filters && h->compression > 0 && H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0)
        ok = H5Pset_shuffle(p) >= 0 && H5Pset_deflate(p, (unsigned)h->compression) >= 0;
    ok = ok && (!filters || H5Pset_fletcher32(p) >= 0);
    ok = ok && (d = H5Dcreate2(loc, name, file, s, H5P_DEFAULT, p, H5P_DEFAULT)) >= 0;
    ok = ok && (n == 0 || H5Dwrite(d, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0);
    if (!ok) sx_h5_fail_h5(h, "cannot write the dataset '%s'", name);
    if (ok && units) ok = sx_h5_attr_str(h, d, "units", units);
    if (ok && filters) ok = sx_h5_seal(h, d, mem, data, n * per);
    sx_h5_close(d);
    sx_h5_close(p);
    sx_h5_close(s);
    return ok;
}

int64_t sx_h5_rows(sx_h5 *h, hid_t loc, const char *where, const char *name, int per, bool required)
{
    if (h->failed) return -1;
    if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) {
        if (required) sx_h5_fail(h, "not a complete seixo file: the dataset %s/%s is missing", where, name);
        return -1;
    }
    hid_t d = H5Dopen2(loc, name, H5P_DEFAULT), s = d >= 0 ? H5Dget_space(d) : -1;
    if (s < 0) {
        sx_h5_fail_h5(h, "damaged: cannot open the dataset %s/%s", where, name);
        sx_h5_close(d);
        return -1;
    }
    /* a number of a size seixo never writes: HDF5 1.10 takes a chunk to
     * hold rows times that size and reads past the end of a smaller one */
    hid_t t = H5Dget_type(d);
    const H5T_class_t c = t >= 0 ? H5Tget_class(t) : H5T_NO_CLASS;
    const size_t size = t >= 0 ? H5Tget_size(t) : 0;
    const bool number = c == H5T_INTEGER || c == H5T_FLOAT || c == H5T_ENUM;
    const bool sized = size == 1 || size == 2 || size == 4 || size == 8;
    const bool typed = t >= 0 && (!number || (sized && (c == H5T_ENUM || H5Tget_precision(t) == 8 * size)));
    sx_h5_close(t);
    if (!typed) {
        sx_h5_close(s);
        sx_h5_close(d);
        sx_h5_fail(h, "damaged: the dataset %s/%s has numbers of %zu bytes", where, name, size);
        return -1;
    }
    hsize_t dims[H5S_MAX_RANK];
    const int rank = H5Sget_simple_extent_ndims(s);
    const bool shaped = rank >= 1 && rank <= 2 && H5Sget_simple_extent_dims(s, dims, NULL) == rank &&
                        (per == 1 ? rank == 1 : rank == 2 && dims[1] == (hsize_t)per) && dims[0] < ((hsize_t)1 << 40);
    sx_h5_close(s);
    sx_h5_close(d);
    if (!shaped) {
        sx_h5_fail(h, "damaged: the dataset %s/%s should have %d column%s", where, name, per, per == 1 ? "" : "s");
        return -1;
    }
    return (int64_t)dims[0];
}

bool sx_h5_read(sx_h5 *h, hid_t loc, const char *where, const char *name, hid_t mem, void *data, int64_t n, int per,
                bool required)
{
    if (h->failed) return false;
    if (!required && H5Lexists(loc, name, H5P_DEFAULT) <= 0) return true;
    const int64_t rows = sx_h5_rows(h, loc, where, name, per, true);
    if (rows < 0) return false;
    if (rows != n)
        return sx_h5_fail(h, "damaged: the dataset %s/%s has %lld rows, %lld expected", where, name, (long long)rows,
                          (long long)n);
    if (n == 0) return true;
    hid_t d = H5Dopen2(loc, name, H5P_DEFAULT);
    bool ok = d >= 0 && H5Dread(d, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0;
    if (!ok) sx_h5_fail_h5(h, "corrupted: the dataset %s/%s cannot be read", where, name);
    ok = ok && sx_h5_check_seal(h, d, where, name, mem, data, n * per);
    sx_h5_close(d);
    return ok;
}

hid_t sx_h5_group(sx_h5 *h, hid_t loc, const char *name)
{
    if (h->failed) return -1;
    hid_t g = H5Lexists(loc, name, H5P_DEFAULT) > 0 ? H5Gopen2(loc, name, H5P_DEFAULT)
                                                     : H5Gcreate2(loc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) sx_h5_fail_h5(h, "cannot create the group '%s'", name);
    return g;
}

hid_t sx_h5_open_group(sx_h5 *h, hid_t loc, const char *name, bool required)
{
    if (h->failed) return -1;
    if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) {
        if (required) sx_h5_fail(h, "not a complete seixo file: the group %s is missing", name);
        return -1;
    }
    hid_t g = H5Gopen2(loc, name, H5P_DEFAULT);
    if (g < 0) sx_h5_fail_h5(h, "damaged: cannot open the group %s", name);
    return g;
}
