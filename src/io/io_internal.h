/* Private declarations shared by the files of the I/O layer. */
#pragma once

#include "h5util.h"
#include "seixo_io.h"

/// Root attributes every seixo file carries: format, format_version, kind
/// ("snapshot" or "series"), seixo_version, git_commit, hdf5_version,
/// created, script, script_sha256, seeds, dim, units.
bool sx_io_write_provenance(sx_h5 *h, hid_t file, const char *kind, int dim, const sx_io_provenance *p);

/// Opens path read-only (rdwr: read-write) as a seixo file of `kind` after
/// checking, in this order, that it exists, is HDF5, opens, is a seixo
/// file, is of a format this build reads, is of that kind and, when
/// want_dim > 0, of that dimension. Returns the file (or -1 with h failed)
/// and its dimension and format version.
hid_t sx_io_open(sx_h5 *h, const char *path, bool rdwr, const char *kind, int want_dim, int *dim, int *version);

/// Writes a tree as the compound dataset `name` of loc.
bool sx_io_write_tree(sx_h5 *h, hid_t loc, const char *name, const sx_io_tree *t);
/// Reads the tree dataset `name` of loc (path `where` for messages).
bool sx_io_read_tree(sx_h5 *h, hid_t loc, const char *where, const char *name, sx_io_tree *t);

/// Writes n strings held in fixed buffers of `width` bytes each as a 1-D
/// dataset of fixed-length UTF-8 strings of that width.
bool sx_io_write_strings(sx_h5 *h, hid_t loc, const char *name, const char *s, size_t width, int64_t n);
/// Reads a string dataset of n rows (of any fixed width) into buffers of
/// `width` bytes each (a longer string is damage).
bool sx_io_read_strings(sx_h5 *h, hid_t loc, const char *where, const char *name, char *out, size_t width, int64_t n);

/* ------------------------------------------------------- histories */

/// Checks a history's name and definition (fails naming the history).
bool sx_io_history_valid(sx_h5 *h, const sx_io_history *x);
/* Whether path names the file of an output series open in this process
 * (series.c): a second writer there would replace or interleave it while
 * the first kept writing into the file the name no longer reaches. */
bool sx_io_series_open_at(const char *path);
/// Creates the group of history x under parent: its definition and
/// `order` as attributes, empty datasets step, time, value without a
/// maximum size in chunks of `chunk` rows, and count 0.
hid_t sx_io_history_create(sx_h5 *h, hid_t parent, const sx_io_history *x, int64_t order, int64_t chunk);
/// Writes samples [from, x->n) of x at rows [at, ...) of the history group
/// g, extending its datasets (its count is left to the caller).
bool sx_io_history_put(sx_h5 *h, hid_t g, const sx_io_history *x, int64_t from, int64_t at);
/// The complete rows of the history group g and the step of its last one
/// (INT64_MIN when none); `where` names it in messages.
bool sx_io_history_tail(sx_h5 *h, hid_t g, const char *where, int64_t *count, int64_t *last);
/// Writes the histories into a new group /histories of file (complete).
bool sx_io_histories_write(sx_h5 *h, hid_t file, const sx_io_history *x, int n);
/// Reads the histories of /histories (none when absent), in creation order.
bool sx_io_histories_read(sx_h5 *h, hid_t file, sx_io_history **out, int *n);
void sx_io_histories_free(sx_io_history *x, int n);
