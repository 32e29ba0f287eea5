/* Shared HDF5 helpers of the I/O layer: one error context per operation,
 * attributes and datasets of plain arrays, and files written to a
 * temporary name and renamed when complete.
 *
 * Errors: HDF5's own printing is switched off while a context is open;
 * the first failure is kept as one line "'<file>': <problem>" (with the
 * innermost HDF5 message when it says more), later ones are dropped, and
 * every helper returns false (or a negative id) once the context failed, so
 * a sequence of calls can be checked once at the end. */
#pragma once

#include <hdf5.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct sx_h5 {
    const char *path;      ///< the file, named in messages
    char *err;             ///< where the first failure goes (may be NULL)
    size_t errlen;
    bool failed;
    int compression;       ///< deflate level of datasets written (0: none)
    H5E_auto2_t old_func;  ///< HDF5's error printer, restored by sx_h5_end
    void *old_data;
} sx_h5;

/// Opens an error context for an operation on `path`.
void sx_h5_begin(sx_h5 *h, const char *path, char *err, size_t errlen);
/// Closes it (restores HDF5's error printing).
void sx_h5_end(sx_h5 *h);
/// Records a failure "'<path>': <message>" unless one is recorded; returns false.
bool sx_h5_fail(sx_h5 *h, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/// Like sx_h5_fail, with HDF5's innermost message appended in parentheses.
bool sx_h5_fail_h5(sx_h5 *h, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* --------------------------------------------------------------- files */

/// The file access list of seixo files: with `latest` the 1.10 format
/// (every piece of metadata checksummed; snapshots), else the 1.8 format
/// (which a writer killed mid-write leaves openable; series).
hid_t sx_h5_fapl(bool latest);
/// The file creation list of every seixo file (small chunk-index nodes).
hid_t sx_h5_fcpl(void);
/// The file driver that makes each flush of a file appended in place atomic
/// (journal.c); opening a file through it first completes a killed flush.
hid_t sx_h5_journal_driver(void);
/// Removes the journal beside `path` (a file about to take that name is a
/// new file: an older one's journal must never be applied to it).
bool sx_h5_journal_drop(const char *path);
/// Flushes a file; with `sync` on disk too (a power failure keeps it),
/// else only as far as a killed process keeps it (the journal's steps are
/// not synced one by one: the flush returns in microseconds).
bool sx_h5_flush(hid_t file, bool sync);
/// Flushes `tmp` to disk and renames it over `path`, then syncs the folder.
bool sx_h5_commit(sx_h5 *h, const char *tmp, const char *path);
/// The second half of sx_h5_commit, for a `tmp` already on disk: the
/// rename and the folder's sync.
bool sx_h5_rename(sx_h5 *h, const char *tmp, const char *path);
/// Checks that `path` may be replaced by a rename (sx_io_unreplaceable)
/// and puts a temporary name beside it in tmp (len bytes): same folder, so
/// the rename is atomic, "<dir>/.<name>.tmp-<pid>-<n>". False (failed,
/// the reason named) if not.
bool sx_h5_temp_for(sx_h5 *h, const char *path, char *tmp, size_t len);
/// A new HDF5 file named tmp (from sx_h5_temp_for; `latest` as for
/// sx_h5_fapl), never one another writer made. Negative (failed) on any
/// error, with no file of its own left behind.
hid_t sx_h5_create_temp(sx_h5 *h, const char *tmp, bool latest);
/// Writes n bytes to a new temporary file beside `path` and flushes it to
/// disk; its name goes to tmp (len bytes). False (failed) on any error, with
/// nothing left behind.
bool sx_h5_write_temp(sx_h5 *h, const char *path, const void *data, size_t n, char *tmp, size_t len);

/// Gives dataset d its attribute "checksum": of the n values of `mem` at
/// data (the dataset's whole contents), as the file stores them.
bool sx_h5_seal(sx_h5 *h, hid_t d, hid_t mem, const void *data, int64_t n);
/// Compares the n values of `mem` just read from dataset d (where/name, for
/// the message) with its "checksum", if it has one: false (failed) if they
/// differ.
bool sx_h5_check_seal(sx_h5 *h, hid_t d, const char *where, const char *name, hid_t mem, const void *data, int64_t n);

/* ---------------------------------------------------------- attributes */

bool sx_h5_attr_str(sx_h5 *h, hid_t obj, const char *name, const char *value);
/// n values; n == 0 writes an empty attribute; scalar when `scalar`.
bool sx_h5_attr_f64(sx_h5 *h, hid_t obj, const char *name, const double *v, size_t n, bool scalar);
bool sx_h5_attr_i64(sx_h5 *h, hid_t obj, const char *name, const int64_t *v, size_t n, bool scalar);
static inline bool sx_h5_attr_double(sx_h5 *h, hid_t obj, const char *name, double v)
{
    return sx_h5_attr_f64(h, obj, name, &v, 1, true);
}
static inline bool sx_h5_attr_int(sx_h5 *h, hid_t obj, const char *name, int64_t v)
{
    return sx_h5_attr_i64(h, obj, name, &v, 1, true);
}

/// Reads n numbers (a scalar when n == 1) converted to double / int64.
/// A missing attribute fails when `required`, else leaves v untouched and
/// returns true. `where` names the object in messages ("/model").
bool sx_h5_get_f64(sx_h5 *h, hid_t obj, const char *where, const char *name, double *v, size_t n, bool required);
bool sx_h5_get_i64(sx_h5 *h, hid_t obj, const char *where, const char *name, int64_t *v, size_t n, bool required);
/// Number of elements of an attribute (0 if absent or empty).
size_t sx_h5_attr_len(hid_t obj, const char *name);
/// Reads a string attribute into out (truncated to len - 1); false without
/// failing when absent or not a string.
bool sx_h5_get_str(hid_t obj, const char *name, char *out, size_t len);
/// The attribute `name` of obj exists as a variable-length string (as
/// h5py writes strings by default), which sx_h5_get_str does not read.
bool sx_h5_attr_is_vlen(hid_t obj, const char *name);

/* ------------------------------------------------------------ datasets */

/// A fixed-length, NUL-padded UTF-8 string type of n bytes (caller closes).
hid_t sx_h5_string_type(size_t n);

/// An HDF5 enum of the given names and values on `base` (caller closes).
hid_t sx_h5_enum(hid_t base, const char *const names[], const int values[], int n);

/// Writes an n x per array (1-D when per == 1) of memory type `mem`
/// stored as `file`: chunked, Fletcher-32 checksummed, deflated at the
/// context's level; `units` (may be NULL) as an attribute.
bool sx_h5_write(sx_h5 *h, hid_t loc, const char *name, hid_t mem, hid_t file, const void *data, int64_t n, int per,
                 const char *units);
/// Rows of a dataset whose rows have `per` components; -1 (failing when
/// `required`, else silently) when absent or shaped otherwise.
int64_t sx_h5_rows(sx_h5 *h, hid_t loc, const char *where, const char *name, int per, bool required);
/// Reads an n x per dataset into data (converted to `mem`). A missing
/// dataset fails when `required`, else data is untouched and true returned.
bool sx_h5_read(sx_h5 *h, hid_t loc, const char *where, const char *name, hid_t mem, void *data, int64_t n, int per,
                bool required);

/// Creates (or opens when it exists) a group.
hid_t sx_h5_group(sx_h5 *h, hid_t loc, const char *name);
/// Opens a group; fails (when `required`) if absent.
hid_t sx_h5_open_group(sx_h5 *h, hid_t loc, const char *name, bool required);

/// Closes any HDF5 id (ignores negative ids).
void sx_h5_close(hid_t id);
