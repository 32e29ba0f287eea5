/* Private declarations of the output series' files: series.c (the file:
 * opened, appended to, recovered, closed), series_xdmf.c (the XDMF beside
 * it) and series_frame.c (one snapshot's groups and datasets). */
#pragma once

#include "io_internal.h"

typedef struct buf {
    char *p;
    size_t n, cap;
    bool oom;
} buf;

/* The XDMF's blocks: one temporal collection each, so that a reader shows
 * each block under its own name at every time (ParaView's XDMF Reader
 * suffixes "[k]" to a name that repeats, as the grids of one spatial
 * collection per snapshot did). */
enum { K_BALLS, K_CONTACTS, K_WALL_CONTACTS, K_BONDS, K_CRACKS, K_WALLS, K_MESHES, NKINDS };

/* The XDMF in memory: each block's grids so far, and the whole text. */
typedef struct xdoc {
    buf kind[NKINDS];
    buf out;
} xdoc;

/* What the XDMF needs to know of a snapshot (stored as its attributes). */
typedef struct snap {
    double time;
    int64_t step, balls, contacts, wall_contacts, bonds, walls, cracks;
    int64_t wall_cells, wall_points; /* a cylinder is drawn with many cells */
    int64_t mesh_cells, mesh_points; /* mesh walls' triangles, a grid of their own */
    unsigned fields;
    int dim;
    bool clumps; /* the balls carry their clump ids (pebbles of a clump, 0 for free balls) */
} snap;

/// The XDMF document of d (its blocks' grids) into d->out; false when out of memory.
bool sx_io_xmf_compose(xdoc *d);
void sx_io_xdoc_free(xdoc *d);
/// Adds the grids of snapshot k (described by s) of the .h5 named base.
void sx_io_xmf_step(xdoc *d, const char *base, int64_t k, const snap *s);
/// The grids of the first `count` snapshots of file (read back from it).
bool sx_io_xmf_body(sx_h5 *h, xdoc *d, const char *base, hid_t file, int dim, int64_t count);
/// The whole document, written whole (temporary name, rename).
bool sx_io_xmf_write(sx_h5 *h, const char *xmf, xdoc *d);

/// Writes the snapshot of m with the fields f into the group snapg and
/// describes it in *s.
void sx_io_frame_write(sx_h5 *h, hid_t snapg, const sx_model *m, unsigned f, snap *s);
