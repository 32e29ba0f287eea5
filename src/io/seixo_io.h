/* seixo — the I/O layer: HDF5 snapshots that restart bit-for-bit, output
 * series with an XDMF file beside them for ParaView, and the plain-value
 * trees (a script's variables) stored with them. The layout is documented
 * in docs/file-format.md.
 *
 * Errors are returned as an sx_status with a one-line message written to
 * err: "'<file>': <problem>". Nothing here aborts on a bad file.
 */
#pragma once

#include "seixo.h"

/// The newest file format this build writes; it reads every format up to it.
#define SX_IO_FORMAT_VERSION 4

/* ---------------------------------------------------------- STL files */

/// Reads an STL file, ASCII or binary (told apart by the binary form's
/// size), into *xyz: nine doubles per triangle, its three corners (x, y, z)
/// as written, m; *nt triangles. *xyz is malloc'd (free it). The facet
/// normals the file writes are not read: the corners' order is the facet's.
sx_status sx_io_read_stl(const char *path, double **xyz, int64_t *nt, char *err, size_t errlen);

/* -------------------------------------------------------- value trees */

/// Kinds of keys and values of a tree node (as stored in the file).
typedef enum sx_io_kind {
    SX_IO_BOOLEAN = 1,
    SX_IO_INTEGER = 2,
    SX_IO_NUMBER = 3,   ///< a double
    SX_IO_STRING = 4,
    SX_IO_TABLE = 5,    ///< values only: a table whose entries are the nodes naming it as parent
} sx_io_kind;

/// One entry of a table: parent[key] = value. A tree is a flat list of
/// nodes in which a parent always comes before its children; parent -1 is
/// the root table.
typedef struct sx_io_node {
    int64_t parent;
    sx_io_kind key_kind;     ///< boolean, integer, number or string
    char *key_string;        ///< string keys: key_length bytes (any, NUL included) and a NUL (owned by the tree)
    size_t key_length;
    int64_t key_integer;     ///< integer and boolean keys
    double key_number;       ///< number keys
    sx_io_kind kind;
    char *string;            ///< string values: length bytes and a NUL (owned by the tree)
    size_t length;
    int64_t integer;         ///< integer and boolean values
    double number;           ///< number values
} sx_io_node;

typedef struct sx_io_tree {
    int64_t n, cap;
    sx_io_node *node;
} sx_io_tree;

/// Appends a copy of *node (its strings copied: key_length / length bytes);
/// returns its index, or -1 when out of memory.
int64_t sx_io_tree_add(sx_io_tree *t, const sx_io_node *node);
/// Frees the nodes and their strings; the tree is empty afterwards.
void sx_io_tree_free(sx_io_tree *t);

/// A named tree stored with a snapshot under /lua/<name>.
typedef struct sx_io_named_tree {
    char name[64];
    sx_io_tree tree;
} sx_io_named_tree;

/* --------------------------------------------------------- provenance */

/// Where a file comes from, stored as attributes of its root.
typedef struct sx_io_provenance {
    const char *script;        ///< path of the script that made it (NULL: none, e.g. the REPL)
    const int64_t *seeds;      ///< random seeds the script used (may be NULL)
    int nseeds;
} sx_io_provenance;

/// The commit seixo was built from ("unknown" outside a git checkout).
const char *sx_io_git_commit(void);

/* ----------------------------------------------------------- histories */

/// What a history samples (the sources of the Lua layer's m:history).
typedef enum sx_io_source {
    SX_IO_SOURCE_FUNCTION = 1, ///< a Lua function: its samples are saved, the function is not
    SX_IO_SOURCE_BUILTIN = 2,  ///< a builtin quantity named by `builtin` ("time", "kinetic", ...)
    SX_IO_SOURCE_BALL = 3,     ///< a field of the ball `id`
    SX_IO_SOURCE_WALL = 4,     ///< a field of the wall `id`
} sx_io_source;

/// The longest history name a file keeps, in bytes (its group's name).
enum { SX_IO_HISTORY_NAME_MAX = 65536 };

/// A history: its definition and n samples, steps strictly increasing.
/// Given to a writer its strings and arrays are borrowed; returned by a
/// load they are owned (freed by sx_snapshot_info_free).
typedef struct sx_io_history {
    char *name;              ///< not empty, not ".", no '/' (it names an HDF5 group)
    int64_t every;           ///< sampled after every step that is a multiple of it (>= 1)
    sx_io_source source;
    char *builtin;           ///< SX_IO_SOURCE_BUILTIN: its name (else NULL)
    int64_t id;              ///< SX_IO_SOURCE_BALL / _WALL: the entity's id
    char *field;             ///< SX_IO_SOURCE_BALL / _WALL: the field ("pos", "force", ...)
    int component;           ///< of a vector field, 0-based (0 for a scalar field)
    int64_t n;
    int64_t *steps;
    double *times;           ///< s
    double *values;
} sx_io_history;

/// Writes histories as CSV: a header "step,time,<name>,..." (names quoted
/// as RFC 4180 asks when they hold a comma, quote, CR or LF), then one row
/// per step sampled by any of them, ascending, empty where a history has no
/// sample. Written like every seixo file: a temporary name, fsync, rename.
sx_status sx_history_csv_write(const char *path, const sx_io_history *h, int nh, char *err, size_t errlen);

/* ----------------------------------------------------------- snapshots */

typedef struct sx_snapshot_opts {
    sx_io_provenance provenance;
    int compression;                    ///< deflate level 0 (none, default) .. 9
    const sx_io_named_tree *trees;      ///< stored under /lua (may be NULL)
    int ntrees;
    const sx_io_history *histories;     ///< stored under /histories (may be NULL)
    int nhistories;
} sx_snapshot_opts;

/// Writes the complete state of m to path: to a temporary file in the same
/// folder, flushed to disk, then renamed over path, so a save that fails or
/// is killed never damages an existing file. A decomposed model left
/// scattered by a lazy cycle (sx_model_scattered) is refused: gather it
/// first (sx_model_gather, on every rank).
sx_status sx_snapshot_save(const sx_model *m, const char *path, const sx_snapshot_opts *opts, char *err,
                           size_t errlen);

/// What a load returns besides the model.
typedef struct sx_snapshot_info {
    int format_version;
    char seixo_version[32];
    char git_commit[64];
    char script[1024];
    char script_sha256[65];
    sx_io_named_tree *trees;  ///< the trees of /lua (owned; free with sx_snapshot_info_free)
    int ntrees;
    sx_io_history *histories; ///< the histories of /histories, in their creation order (owned)
    int nhistories;
    int64_t *seeds;           ///< the provenance's seeds (owned)
    int nseeds;
} sx_snapshot_info;

/// Reads a snapshot into a new model that continues exactly like the saved
/// one. dim: the dimension the caller expects (0: any). info may be NULL.
/// On failure returns NULL with the message in err.
sx_model *sx_snapshot_load(const char *path, int dim, sx_snapshot_info *info, char *err, size_t errlen);
void sx_snapshot_info_free(sx_snapshot_info *info);

/* -------------------------------------------------------------- series */

/// What each snapshot of a series holds (bits). Ball positions are always written.
enum {
    SX_OUT_ID = 1 << 0,        ///< ball ids
    SX_OUT_RADIUS = 1 << 1,    ///< m
    SX_OUT_VELOCITY = 1 << 2,  ///< m/s
    SX_OUT_SPIN = 1 << 3,      ///< rad/s (2D: about z)
    SX_OUT_FORCE = 1 << 4,     ///< N, the last step's
    SX_OUT_MOMENT = 1 << 5,    ///< N m
    SX_OUT_GROUP = 1 << 6,     ///< group numbers
    SX_OUT_MATERIAL = 1 << 7,  ///< material indices
    SX_OUT_MASS = 1 << 8,      ///< kg
    SX_OUT_CONTACTS = 1 << 9,  ///< contacts as line cells with their forces
    SX_OUT_BONDS = 1 << 10,    ///< intact bonds as line cells with their forces and moments
    SX_OUT_WALLS = 1 << 11,    ///< walls as geometry with their forces
    SX_OUT_DEFAULT = SX_OUT_ID | SX_OUT_RADIUS | SX_OUT_VELOCITY | SX_OUT_SPIN | SX_OUT_FORCE | SX_OUT_GROUP |
                     SX_OUT_CONTACTS | SX_OUT_BONDS | SX_OUT_WALLS,
};

/// The name of a field bit ("velocity"), or NULL; and back (0 if unknown).
const char *sx_series_field_name(unsigned bit);
unsigned sx_series_field_bit(const char *name);

typedef struct sx_series_opts {
    unsigned fields;           ///< SX_OUT_* bits (0: SX_OUT_DEFAULT)
    int compression;           ///< deflate level 0 .. 9
    bool append;               ///< continue an existing series (same dimension) instead of replacing it
    bool check_step;           ///< appending: refuse a series holding a step after `step`
    int64_t step;              ///< the appending model's step (with check_step)
    sx_io_provenance provenance;
} sx_series_opts;

typedef struct sx_series sx_series;

/// Creates the series file (atomically, replacing any file at path) and
/// its XDMF (path with .xmf instead of .h5) for models of dimension dim;
/// with opts->append an existing series is continued. NULL on failure.
sx_series *sx_series_open(const char *path, int dim, const sx_series_opts *opts, char *err, size_t errlen);
/// Appends the state of m as one snapshot, and to the datasets of the
/// histories h (nh of them, h may be NULL) their samples of steps after the
/// last the series holds; flushes the file and updates the XDMF: a crash
/// after this returns loses nothing written so far.
sx_status sx_series_write(sx_series *s, const sx_model *m, const sx_io_history *h, int nh, char *err,
                          size_t errlen);
/// Appends only history samples (as sx_series_write does), e.g. those
/// recorded after the last snapshot, before closing.
sx_status sx_series_write_histories(sx_series *s, const sx_io_history *h, int nh, char *err, size_t errlen);
/// Snapshots in the series.
int64_t sx_series_count(const sx_series *s);
/// Appending: the step of the series' last snapshot when it was opened
/// (-1: none, or a new series).
int64_t sx_series_opened_at(const sx_series *s);
const char *sx_series_path(const sx_series *s);
/// The .xmf beside a series' .h5: path with its .h5 / .hdf5 / .hdf
/// extension replaced by .xmf (or .xmf appended); malloc'd, NULL when out
/// of memory.
char *sx_io_xmf_path(const char *path);
/// Closes the series (NULL is allowed); a failure to close is reported.
sx_status sx_series_close(sx_series *s, char *err, size_t errlen);

/// Rewrites the XDMF of the series at h5path from its complete snapshots.
sx_status sx_series_write_xdmf(const char *h5path, char *err, size_t errlen);

/// Why seixo will not replace what is at path, or NULL (nothing there, or
/// a regular file): every file is written under a temporary name and
/// renamed over the old one, which would put a regular file in place of a
/// symbolic link (its target left as it was), a device such as /dev/null,
/// a pipe or a folder.
const char *sx_io_unreplaceable(const char *path);

/// Number of complete snapshots of the series at path (-1 on error).
int64_t sx_series_read_count(const char *path, char *err, size_t errlen);
