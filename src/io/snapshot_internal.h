/* Private declarations of the snapshot's files: snapshot.c (a save and a
 * load: the model's scalars, balls, contacts and bonds, and the order of
 * it all), snapshot_materials.c (materials and contact models),
 * snapshot_walls.c (walls and meshes) and snapshot_parts.c (the crack log,
 * clumps, the periodic cell, smooth joints). Each part's arrays are listed
 * once, in a table of fields that its writer and its reader both use. */
#pragma once

#include "io_internal.h"
#include "state.h"

#include "clumps.h"

enum { T_F64, T_I64, T_I32, T_U16, T_U8 };

/* One array of a store: n rows of `per` components. */
typedef struct field {
    const char *name;
    int type;
    void *data;
    int per;
    const char *units;
} field;

#define F(nm, ty, ptr, p, u) (field){nm, ty, (void *)(ptr), p, u}

enum { MAX_FIELDS = 24 };

/// Writes nf fields of `rows` rows each into g.
bool sx_io_write_fields(sx_h5 *h, hid_t g, const field *f, int nf, int64_t rows);
/// Reads nf fields of `rows` rows each from g (`where`: its path in
/// messages); when not required, a field the file lacks keeps its zeros.
bool sx_io_read_fields(sx_h5 *h, hid_t g, const char *where, const field *f, int nf, int64_t rows, bool required);
/// Reads the fields of the group at path (all required).
void sx_io_load_group(sx_h5 *h, hid_t f, const char *path, const field *fl, int nf, int64_t rows);

/* snapshot_materials.c */
void sx_io_save_materials(sx_h5 *h, hid_t f, sx_model *m);
void sx_io_load_materials(sx_h5 *h, hid_t g, sx_model *m);
void sx_io_save_cmodels(sx_h5 *h, hid_t f, sx_model *m);
void sx_io_load_cmodels(sx_h5 *h, hid_t f, sx_model *m);

/* snapshot_walls.c */
void sx_io_save_walls(sx_h5 *h, hid_t f, const sx_model *m);
void sx_io_load_walls(sx_h5 *h, hid_t g, sx_model *m, int version);

/* snapshot_parts.c */
/// Reads (write = false) or writes the crack log in the group g.
void sx_io_cracks(sx_h5 *h, hid_t g, sx_model *m, bool write);
void sx_io_save_clumps(sx_h5 *h, hid_t f, sx_model *m);
/// The clump store's sizes; all zero when the file has no /clumps.
bool sx_io_read_clump_sizes(sx_h5 *h, hid_t f, sx_clump_sizes *s);
void sx_io_load_clumps(sx_h5 *h, hid_t f, sx_model *m);
void sx_io_save_periodic(sx_h5 *h, hid_t f, const sx_model *m);
void sx_io_load_periodic(sx_h5 *h, hid_t f, sx_model *m);
void sx_io_save_joints(sx_h5 *h, hid_t f, const sx_model *m);
void sx_io_load_joints(sx_h5 *h, hid_t f, sx_model *m, int64_t n);
