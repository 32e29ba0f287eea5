/* What every seixo file shares: provenance attributes on the root, the
 * checks made before anything is read, and string datasets. */
#include "io_internal.h"
#include "sha256.h"
#include "sx_git.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

const char *sx_io_git_commit(void) { return SX_GIT_COMMIT; }

bool sx_io_write_provenance(sx_h5 *h, hid_t file, const char *kind, int dim, const sx_io_provenance *p)
{
    char created[32] = "";
    const time_t now = time(NULL);
    struct tm tm;
    if (gmtime_r(&now, &tm)) strftime(created, sizeof created, "%Y-%m-%dT%H:%M:%SZ", &tm);
    unsigned maj = 0, min = 0, rel = 0;
    H5get_libversion(&maj, &min, &rel);
    char h5v[32];
    snprintf(h5v, sizeof h5v, "%u.%u.%u", maj, min, rel);
    const char *script = p && p->script ? p->script : "";
    char sha[65] = "";
    if (*script) sx_sha256_file(script, sha);
    sx_h5_attr_str(h, file, "format", "seixo");
    sx_h5_attr_int(h, file, "format_version", SX_IO_FORMAT_VERSION);
    sx_h5_attr_str(h, file, "kind", kind);
    sx_h5_attr_str(h, file, "seixo_version", SX_VERSION);
    sx_h5_attr_str(h, file, "git_commit", SX_GIT_COMMIT);
    sx_h5_attr_str(h, file, "hdf5_version", h5v);
    sx_h5_attr_str(h, file, "created", created);
    sx_h5_attr_str(h, file, "script", script);
    sx_h5_attr_str(h, file, "script_sha256", sha);
    sx_h5_attr_i64(h, file, "seeds", p ? p->seeds : NULL, p && p->seeds ? (size_t)p->nseeds : 0, false);
    sx_h5_attr_int(h, file, "dim", dim);
    return sx_h5_attr_str(h, file, "units", "SI");
}

hid_t sx_io_open(sx_h5 *h, const char *path, bool rdwr, const char *kind, int want_dim, int *dim, int *version)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        sx_h5_fail(h, "%s", errno == ENOENT ? "no such file" : strerror(errno));
        return -1;
    }
    if (S_ISDIR(st.st_mode)) {
        sx_h5_fail(h, "is a folder, not a file");
        return -1;
    }
    /* a FIFO or a device would block the read (or never end): files only */
    if (!S_ISREG(st.st_mode)) {
        sx_h5_fail(h, "is not a regular file (a pipe, socket or device)");
        return -1;
    }
    const htri_t is = H5Fis_hdf5(path);
    if (is <= 0) {
        H5Eclear2(H5E_DEFAULT);
        if (st.st_size == 0) sx_h5_fail(h, "empty file, not an HDF5 file");
        else sx_h5_fail(h, "not an HDF5 file (no HDF5 signature: another format, or damaged at its start)");
        return -1;
    }
    /* checked read-only, in any format; reopened for appending afterwards */
    hid_t fapl = sx_h5_fapl(false);
    if (fapl >= 0 && H5Pset_libver_bounds(fapl, H5F_LIBVER_EARLIEST, H5F_LIBVER_LATEST) < 0) {
        H5Pclose(fapl);
        fapl = -1;
    }
    hid_t f = fapl >= 0 ? H5Fopen(path, H5F_ACC_RDONLY, fapl) : -1;
    if (f < 0) sx_h5_fail_h5(h, "truncated or damaged HDF5 file, cannot be opened");
    sx_h5_close(fapl);
    if (f < 0) return -1;
    char fmt[32], k[32];
    int64_t ver = 0, d = 0;
    if (sx_h5_attr_is_vlen(f, "format") || sx_h5_attr_is_vlen(f, "kind")) {
        /* rewritten by h5py: said as it is, not as a missing attribute */
        sx_h5_fail(h, "its '%s' attribute is a variable-length string (as h5py writes one by default); seixo reads "
                      "fixed-length strings: write it as one (h5py: numpy.bytes_)",
                   sx_h5_attr_is_vlen(f, "format") ? "format" : "kind");
    } else if (!sx_h5_get_str(f, "format", fmt, sizeof fmt) || strcmp(fmt, "seixo") != 0) {
        sx_h5_fail(h, "an HDF5 file, but not a seixo file (its root has no 'format' attribute \"seixo\")");
    } else if (!sx_h5_get_i64(h, f, "/", "format_version", &ver, 1, true)) {
        /* failed */
    } else if (ver > SX_IO_FORMAT_VERSION) {
        sx_h5_fail(h, "written in seixo file format %lld, newer than this seixo %s reads (formats 1 to %d): "
                      "update seixo to read it", (long long)ver, SX_VERSION, SX_IO_FORMAT_VERSION);
    } else if (ver < 1) {
        sx_h5_fail(h, "damaged: format version %lld", (long long)ver);
    } else if (!sx_h5_get_str(f, "kind", k, sizeof k) || strcmp(k, kind) != 0) {
        sx_h5_fail(h, "a seixo %s file, not a %s%s", k[0] ? k : "(unknown kind)", kind,
                   strcmp(kind, "snapshot") == 0 ? " (seixo.load reads files written by m:save)" : "");
    } else if (!sx_h5_get_i64(h, f, "/", "dim", &d, 1, true)) {
        /* failed */
    } else if (d != 2 && d != 3) {
        sx_h5_fail(h, "damaged: dim is %lld", (long long)d);
    } else if (want_dim > 0 && d != want_dim) {
        sx_h5_fail(h, "holds a %lldD model, but a %dD one was asked for", (long long)d, want_dim);
    }
    if (h->failed) {
        H5Fclose(f);
        return -1;
    }
    if (rdwr) { /* a series grows in the 1.8 format it was made in */
        H5Fclose(f);
        fapl = sx_h5_fapl(false);
        f = fapl >= 0 ? H5Fopen(path, H5F_ACC_RDWR, fapl) : -1;
        if (f < 0) sx_h5_fail_h5(h, "cannot be opened for writing");
        sx_h5_close(fapl);
        if (f < 0) return -1;
    }
    if (dim) *dim = (int)d;
    if (version) *version = (int)ver;
    return f;
}

bool sx_io_write_strings(sx_h5 *h, hid_t loc, const char *name, const char *s, size_t width, int64_t n)
{
    if (h->failed) return false;
    hid_t t = sx_h5_string_type(width);
    if (t < 0) return sx_h5_fail_h5(h, "cannot write the dataset '%s'", name);
    const bool ok = sx_h5_write(h, loc, name, t, t, s, n, 1, NULL);
    sx_h5_close(t);
    return ok;
}

bool sx_io_read_strings(sx_h5 *h, hid_t loc, const char *where, const char *name, char *out, size_t width, int64_t n)
{
    if (h->failed) return false;
    /* read at the stored width (any), then checked against ours */
    hid_t d = H5Lexists(loc, name, H5P_DEFAULT) > 0 ? H5Dopen2(loc, name, H5P_DEFAULT) : -1;
    hid_t ft = d >= 0 ? H5Dget_type(d) : -1;
    const size_t sw = ft >= 0 && H5Tget_class(ft) == H5T_STRING && H5Tis_variable_str(ft) == 0 ? H5Tget_size(ft) : 0;
    sx_h5_close(ft);
    sx_h5_close(d);
    if (sw == 0 || sw > 4096) {
        if (!h->failed) sx_h5_fail(h, "damaged: %s/%s is missing or not a dataset of strings", where, name);
        return false;
    }
    char *buf = calloc((size_t)(n > 0 ? n : 1), sw + 1);
    hid_t t = sx_h5_string_type(sw);
    bool ok = buf && t >= 0;
    if (!ok) sx_h5_fail(h, "out of memory");
    ok = ok && sx_h5_read(h, loc, where, name, t, buf, n, 1, true);
    for (int64_t i = 0; ok && i < n; i++) {
        const char *p = buf + (size_t)i * sw;
        const size_t len = strnlen(p, sw);
        if (len >= width) {
            ok = sx_h5_fail(h, "damaged: string %lld of %s/%s is longer than %zu bytes", (long long)i, where, name,
                            width - 1);
            break;
        }
        memcpy(out + (size_t)i * width, p, len);
        out[(size_t)i * width + len] = 0;
    }
    free(buf);
    sx_h5_close(t);
    return ok;
}
