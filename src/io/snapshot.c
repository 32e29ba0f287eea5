/* Snapshots: the complete state of a model in one HDF5 file, read back
 * into a model that continues bit-for-bit like the saved one.
 *
 * The I/O layer is part of libseixo's implementation: it includes the
 * core's private layout (through state.h) and writes every array a
 * continuing run reads, in the stores' own dense order, so nothing is
 * recomputed on load except what state.c derives (the id map, the bond
 * count, the chunk plan). Doubles are stored as IEEE 754 binary64, so the
 * bits survive. The layout is documented in docs/file-format.md; each
 * array is listed once, in a table of fields used by both the writer and
 * the reader.
 *
 * A save goes to a temporary file beside the target, is flushed to disk
 * and renamed over the target; a load checks the file before it trusts
 * any of it, then lets state.c check every cross reference.
 *
 * This file holds the save, the load and the parts every model has (its
 * scalars, balls, contacts, bonds and flat joints); snapshot_materials.c,
 * snapshot_walls.c and snapshot_parts.c the others (snapshot_internal.h). */
#include "snapshot_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static hid_t mem_type(int t)
{
    switch (t) {
    case T_F64: return H5T_NATIVE_DOUBLE;
    case T_I64: return H5T_NATIVE_INT64;
    case T_I32: return H5T_NATIVE_INT32;
    case T_U16: return H5T_NATIVE_UINT16;
    default: return H5T_NATIVE_UINT8;
    }
}

static hid_t file_type(int t)
{
    switch (t) {
    case T_F64: return H5T_IEEE_F64LE;
    case T_I64: return H5T_STD_I64LE;
    case T_I32: return H5T_STD_I32LE;
    case T_U16: return H5T_STD_U16LE;
    default: return H5T_STD_U8LE;
    }
}
/* The per-ball arrays as a file holds them, whether or not the store has
 * its own: the damping (a ball's own, or its material's) and the group
 * (0 when the store has none). A load reads into the store's own, which
 * sx__state_alloc makes (and sx__state_finish gives back when uniform). */
typedef struct ball_cols {
    double *damping;
    int32_t *group;
    void *owned; /* what was allocated for a save */
} ball_cols;

static bool ball_cols_for_save(const sx_model *m, ball_cols *c)
{
    const sx_balls *b = &m->balls;
    const size_t n = (size_t)(b->n > 0 ? b->n : 1);
    memset(c, 0, sizeof *c);
    c->damping = b->alpha, c->group = b->group;
    if (b->alpha && b->group) return true;
    char *q = c->owned = calloc(n, sizeof(double) + sizeof(int32_t));
    if (!q) return false;
    if (!b->alpha) {
        c->damping = (double *)q;
        for (int64_t i = 0; i < b->n; i++) c->damping[i] = sx__ball_damping(m, i);
    }
    if (!b->group) c->group = (int32_t *)(q + n * sizeof(double)); /* zeros */
    return true;
}

/* Every per-ball array (applied loads only when the store has them). */
static int ball_fields(const sx_model *m, const ball_cols *c, field *f)
{
    const sx_balls *b = &m->balls;
    const int d = m->dim, r = m->rdim;
    int n = 0;
    f[n++] = F("id", T_I32, b->id, 1, NULL);
    f[n++] = F("position", T_F64, b->x, d, "m");
    f[n++] = F("velocity", T_F64, b->v, d, "m/s");
    f[n++] = F("spin", T_F64, b->w, r, "rad/s");
    f[n++] = F("force", T_F64, b->f, d, "N");
    f[n++] = F("moment", T_F64, b->t, r, "N m");
    f[n++] = F("position_at_build", T_F64, b->x_build, d, "m");
    f[n++] = F("radius", T_F64, b->rad, 1, "m");
    f[n++] = F("inv_mass", T_F64, b->inv_mass, 1, "1/kg");
    f[n++] = F("inv_inertia", T_F64, b->inv_inertia, 1, "1/(kg m^2)");
    f[n++] = F("damping", T_F64, c->damping, 1, "1");
    f[n++] = F("material", T_U16, b->mat, 1, NULL);
    f[n++] = F("fixity", T_U8, b->fix, 1, NULL);
    f[n++] = F("group", T_I32, c->group, 1, NULL);
    if (b->fapp) {
        f[n++] = F("applied_force", T_F64, b->fapp, d, "N");
        f[n++] = F("applied_moment", T_F64, b->tapp, r, "N m");
    }
    if (b->unwrap) f[n++] = F("unwrap", T_F64, b->unwrap, d, "m"); /* periodic space: unwrapped positions */
    return n;
}

/* Every array of a pair store, from the core's field table (bond slots
 * only when it has them). The last evaluation's geometry: a ball-wall
 * pair's normal and overlap; a ball-ball pair's relative position (format
 * 3), or, reading a file of format 1 or 2, its normal and overlap (into
 * `overlap`, see relative_from_normal). */
static int pair_fields(const sx_model *m, const sx_pairs *p, field *f, double *overlap)
{
    static const int types[] = {[SX_FIELD_I32] = T_I32, [SX_FIELD_F64] = T_F64, [SX_FIELD_U8] = T_U8};
    sx_pair_field s[SX_PAIR_FIELDS_MAX];
    const int ns = sx__pair_fields(m, (sx_pairs *)p, s);
    int n = 0;
    for (int k = 0; k < ns; k++) {
        if (overlap && s[k].data == (void **)&p->geo) {
            f[n++] = F("normal", T_F64, p->geo, m->dim, "1");
            f[n++] = F("overlap", T_F64, overlap, 1, "m");
        } else {
            f[n++] = F(s[k].name, types[s[k].type], *s[k].data, s[k].per, s[k].unit);
        }
    }
    return n;
}

static int bond_fields(const sx_model *m, field *f)
{
    const sx_bonds *b = &m->bonds;
    const int d = m->dim, r = m->rdim;
    int n = 0;
    f[n++] = F("kind", T_U8, b->kind, 1, NULL);
    f[n++] = F("ball_a", T_I32, b->ida, 1, NULL);
    f[n++] = F("ball_b", T_I32, b->idb, 1, NULL);
    f[n++] = F("contact_normal_strength", T_F64, b->cb_n, 1, "N");
    f[n++] = F("contact_shear_strength", T_F64, b->cb_s, 1, "N");
    f[n++] = F("radius", T_F64, b->rbar, 1, "m");
    f[n++] = F("kn", T_F64, b->kn, 1, "Pa/m");
    f[n++] = F("ks", T_F64, b->ks, 1, "Pa/m");
    f[n++] = F("tensile_strength", T_F64, b->sigma_c, 1, "Pa");
    f[n++] = F("cohesion", T_F64, b->tau_c, 1, "Pa");
    f[n++] = F("normal_force", T_F64, b->fn, 1, "N");
    f[n++] = F("shear_force", T_F64, b->fs, d, "N");
    f[n++] = F("twist_moment", T_F64, b->mn, 1, "N m");
    f[n++] = F("bending_moment", T_F64, b->ms, r, "N m");
    return n;
}

/* The flat joints' per-bond arrays (/flatjoints, one row per bond slot)
 * and their elements (/flatjoints/elements), written when the model has
 * flat-joint elements. */
static int flatjoint_fields(const sx_model *m, field *f)
{
    const sx_bonds *b = &m->bonds;
    const int d = m->dim;
    int n = 0;
    f[n++] = F("first_element", T_I32, b->fj_first, 1, NULL);
    f[n++] = F("rings", T_U8, b->fj_nr, 1, NULL);
    f[n++] = F("sectors", T_U8, b->fj_na, 1, NULL);
    f[n++] = F("friction", T_F64, b->fj_mu, 1, "1");
    f[n++] = F("tan_friction_angle", T_F64, b->fj_tanphi, 1, "1");
    f[n++] = F("distance0", T_F64, b->fj_d0, 1, "m");
    f[n++] = F("bend_rotation", T_F64, b->fj_rot, d - 1, "rad");
    if (d == 3) f[n++] = F("axis", T_F64, b->fj_axis, 3, "1");
    return n;
}

static int fj_element_fields(const sx_model *m, field *f)
{
    const sx_fjels *e = &m->fjel;
    int n = 0;
    f[n++] = F("state", T_U8, e->state, 1, NULL);
    f[n++] = F("tensile_strength", T_F64, e->sigma_c, 1, "Pa");
    f[n++] = F("cohesion", T_F64, e->coh, 1, "Pa");
    f[n++] = F("gap0", T_F64, e->gap0, 1, "m");
    f[n++] = F("shear_force", T_F64, e->fs, m->dim - 1, "N");
    f[n++] = F("normal_force", T_F64, e->fn, 1, "N");
    return n;
}
bool sx_io_write_fields(sx_h5 *h, hid_t g, const field *f, int nf, int64_t rows)
{
    for (int i = 0; i < nf; i++)
        sx_h5_write(h, g, f[i].name, mem_type(f[i].type), file_type(f[i].type), f[i].data, rows, f[i].per, f[i].units);
    return !h->failed;
}

/* Fields a file must have (required), or may lack because an older format
 * did not write them (the data then keeps its zeros). */
bool sx_io_read_fields(sx_h5 *h, hid_t g, const char *where, const field *f, int nf, int64_t rows, bool required)
{
    for (int i = 0; i < nf; i++)
        sx_h5_read(h, g, where, f[i].name, mem_type(f[i].type), f[i].data, rows, f[i].per, required);
    return !h->failed;
}

/* Reads one group's fields. */
void sx_io_load_group(sx_h5 *h, hid_t f, const char *path, const field *fl, int nf, int64_t rows)
{
    hid_t g = sx_h5_open_group(h, f, path, true);
    if (g >= 0) sx_io_read_fields(h, g, path, fl, nf, rows, true);
    sx_h5_close(g);
}

/* ------------------------------------------------------------- scalars */

/* The model's scalars, as attributes of /model. */
typedef struct scalar {
    const char *name;
    double *f;      /* a double ... */
    int64_t *i;     /* ... or an integer */
    bool *b;        /* ... or a flag (stored as an integer 0/1) */
    int *n;         /* ... or an int */
} scalar;

static int model_scalars(sx_model *m, scalar *s)
{
    int n = 0;
#define D(nm, p) s[n++] = (scalar){nm, p, NULL, NULL, NULL}
#define I(nm, p) s[n++] = (scalar){nm, NULL, p, NULL, NULL}
#define B(nm, p) s[n++] = (scalar){nm, NULL, NULL, p, NULL}
#define N(nm, p) s[n++] = (scalar){nm, NULL, NULL, NULL, p}
    D("timestep_user", &m->dt_user);
    D("timestep", &m->dt);
    D("timestep_prev", &m->dt_prev);
    D("timestep_safety", &m->dt_safety);
    B("timestep_stale", &m->dt_stale);
    D("skin", &m->skin);
    D("skin_user", &m->skin_user);
    D("time", &m->time);
    I("step", &m->step);
    I("builds", &m->builds);
    B("build_needed", &m->build_needed);
    N("threads", &m->threads);
    I("next_wall_id", &m->next_wall_id);
    D("guard_energy", &m->guard_e0);
    D("guard_scale", &m->guard_scale);
    B("guard_on", &m->guard_on);
    B("guard_dirty", &m->guard_dirty);
    B("track_energy", &m->track_energy);
    D("energy_kinetic", &m->acc.kinetic);
    D("energy_gravitational", &m->acc.gravitational);
    D("energy_strain", &m->acc.strain);
    D("energy_bond_strain", &m->acc.bond_strain);
    D("energy_slip", &m->acc.slip);
    D("energy_local_damping", &m->acc.local_damping);
    D("energy_viscous", &m->acc.viscous);
    D("energy_boundary_work", &m->acc.boundary_work);
    D("energy_bond_released", &m->acc.bond_released);
#undef D
#undef I
#undef B
#undef N
    return n;
}

static void write_scalars(sx_h5 *h, hid_t g, sx_model *m)
{
    scalar s[40];
    const int n = model_scalars(m, s);
    for (int k = 0; k < n; k++) {
        if (s[k].f) sx_h5_attr_double(h, g, s[k].name, *s[k].f);
        else if (s[k].i) sx_h5_attr_int(h, g, s[k].name, *s[k].i);
        else if (s[k].b) sx_h5_attr_int(h, g, s[k].name, *s[k].b ? 1 : 0);
        else sx_h5_attr_int(h, g, s[k].name, *s[k].n);
    }
    sx_h5_attr_f64(h, g, "gravity", m->gravity, (size_t)m->dim, false);
}

static void read_scalars(sx_h5 *h, hid_t g, sx_model *m)
{
    scalar s[40];
    const int n = model_scalars(m, s);
    for (int k = 0; k < n; k++) {
        if (s[k].f) {
            sx_h5_get_f64(h, g, "/model", s[k].name, s[k].f, 1, true);
        } else {
            int64_t v = 0;
            if (!sx_h5_get_i64(h, g, "/model", s[k].name, &v, 1, true)) return;
            if (s[k].i) *s[k].i = v;
            else if (s[k].b) *s[k].b = v != 0;
            else *s[k].n = v >= -1000000 && v <= 1000000 ? (int)v : -1; /* out of range: caught by the check */
        }
    }
    sx_h5_get_f64(h, g, "/model", "gravity", m->gravity, (size_t)m->dim, true);
}
/* ---------------------------------------------------------------- save */

static void save_all(sx_h5 *h, hid_t f, sx_model *m, const sx_snapshot_opts *o)
{
    sx_io_write_provenance(h, f, "snapshot", m->dim, o ? &o->provenance : NULL);
    sx_h5_attr_double(h, f, "time", m->time);
    sx_h5_attr_int(h, f, "step", m->step);
    char hash[17];
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)sx_model_state_hash(m));
    sx_h5_attr_str(h, f, "state_hash", hash); /* for comparing runs; not checked on load */

    hid_t g = sx_h5_group(h, f, "model");
    write_scalars(h, g, m);
    sx_h5_close(g);
    sx_io_save_materials(h, f, m);
    sx_io_save_cmodels(h, f, m);

    field fl[MAX_FIELDS];
    g = sx_h5_group(h, f, "balls");
    sx_h5_attr_int(h, g, "count", m->balls.n);
    sx_h5_attr_int(h, g, "next_id", m->balls.next_id < 1 ? 1 : m->balls.next_id);
    ball_cols bc;
    if (!ball_cols_for_save(m, &bc)) sx_h5_fail(h, "out of memory");
    else sx_io_write_fields(h, g, fl, ball_fields(m, &bc, fl), m->balls.n);
    free(bc.owned);
    sx_h5_close(g);

    g = sx_h5_group(h, f, "contacts");
    hid_t p = sx_h5_group(h, g, "ball_ball");
    sx_h5_attr_int(h, p, "count", m->bb.n);
    sx_io_write_fields(h, p, fl, pair_fields(m, &m->bb, fl, NULL), m->bb.n);
    sx_h5_close(p);
    p = sx_h5_group(h, g, "ball_wall");
    sx_h5_attr_int(h, p, "count", m->bw.n);
    sx_io_write_fields(h, p, fl, pair_fields(m, &m->bw, fl, NULL), m->bw.n);
    sx_h5_close(p);
    sx_h5_close(g);

    g = sx_h5_group(h, f, "bonds");
    sx_h5_attr_int(h, g, "count", m->bonds.n);
    sx_h5_attr_int(h, g, "intact", m->bonds.intact);
    sx_io_write_fields(h, g, fl, bond_fields(m, fl), m->bonds.n);
    sx_h5_close(g);

    if (m->fjel.n > 0) {
        g = sx_h5_group(h, f, "flatjoints");
        sx_io_write_fields(h, g, fl, flatjoint_fields(m, fl), m->bonds.n);
        hid_t e = sx_h5_group(h, g, "elements");
        sx_h5_attr_int(h, e, "count", m->fjel.n);
        sx_io_write_fields(h, e, fl, fj_element_fields(m, fl), m->fjel.n);
        sx_h5_close(e);
        sx_h5_close(g);
    }

    g = sx_h5_group(h, f, "cracks");
    sx_h5_attr_int(h, g, "count", m->cracks.n);
    sx_io_cracks(h, g, m, true);
    sx_h5_close(g);

    sx_io_save_walls(h, f, m);
    sx_io_save_clumps(h, f, m);
    sx_io_save_periodic(h, f, m);
    sx_io_save_joints(h, f, m);
    if (o) sx_io_histories_write(h, f, o->histories, o->nhistories);

    if (o && o->ntrees > 0) {
        g = sx_h5_group(h, f, "lua");
        for (int k = 0; k < o->ntrees; k++) sx_io_write_tree(h, g, o->trees[k].name, &o->trees[k].tree);
        sx_h5_close(g);
    }
}

sx_status sx_snapshot_save(const sx_model *m, const char *path, const sx_snapshot_opts *opts, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, path, err, errlen);
    h.compression = opts && opts->compression > 0 ? (opts->compression > 9 ? 9 : opts->compression) : 0;
    char tmp[4096];
    if (!path || !*path) {
        sx_h5_fail(&h, "an empty path");
    } else if (sx_model_scattered(m)) { /* its state hash would be a collective call */
        sx_h5_fail(&h, "the model is scattered over the ranks: gather it first (sx_model_gather, on every rank)");
    } else if (!sx_h5_temp_for(&h, path, tmp, sizeof tmp)) {
        /* (failed, the reason named) */
    } else if (sx_io_series_open_at(path)) {
        sx_h5_fail(&h, "an output series open in this session writes this file: close it first, or save elsewhere");
    } else {
        hid_t f = sx_h5_create_temp(&h, tmp, true);
        if (f >= 0) {
            /* the model is only read; the arrays are taken as they are */
            save_all(&h, f, (sx_model *)m, opts);
            if (H5Fclose(f) < 0) sx_h5_fail_h5(&h, "cannot complete the file");
            if (!h.failed) sx_h5_commit(&h, tmp, path);
            if (h.failed) remove(tmp);
        }
    }
    const bool failed = h.failed;
    sx_h5_end(&h);
    return failed ? SX_EINVAL : SX_OK;
}

/* ---------------------------------------------------------------- load */

/* The sizes of every store, from the file's datasets (their row counts
 * are what the reads below check against). */
static bool read_sizes(sx_h5 *h, hid_t f, int d, sx_state_sizes *s)
{
    memset(s, 0, sizeof *s);
    hid_t g = sx_h5_open_group(h, f, "/balls", true);
    if (g < 0) return false;
    s->balls = sx_h5_rows(h, g, "/balls", "id", 1, true);
    sx_h5_get_i64(h, g, "/balls", "next_id", &s->next_ball_id, 1, true);
    s->applied = H5Lexists(g, "applied_force", H5P_DEFAULT) > 0;
    s->unwrap = H5Lexists(g, "unwrap", H5P_DEFAULT) > 0;
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/contacts/ball_ball", true);
    s->bb = sx_h5_rows(h, g, "/contacts/ball_ball", "a", 1, true);
    s->bb_bonds = g >= 0 && H5Lexists(g, "bond", H5P_DEFAULT) > 0;
    s->rolling = g >= 0 && H5Lexists(g, "rolling_moment", H5P_DEFAULT) > 0;
    s->total_shear = g >= 0 && H5Lexists(g, "shear_displacement", H5P_DEFAULT) > 0;
    s->bb_cmodel = g >= 0 && H5Lexists(g, "contact_model", H5P_DEFAULT) > 0;
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/contacts/ball_wall", true);
    s->bw = sx_h5_rows(h, g, "/contacts/ball_wall", "a", 1, true);
    s->bw_facets = g >= 0 && H5Lexists(g, "facet", H5P_DEFAULT) > 0;
    s->bw_cmodel = g >= 0 && H5Lexists(g, "contact_model", H5P_DEFAULT) > 0;
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/bonds", true);
    s->bonds = sx_h5_rows(h, g, "/bonds", "kind", 1, true);
    sx_h5_close(g);
    if (H5Lexists(f, "/joints", H5P_DEFAULT) > 0) {
        g = sx_h5_open_group(h, f, "/joints", true);
        s->joints = sx_h5_rows(h, g, "/joints", "kn", 1, true);
        sx_h5_close(g);
    }
    if (H5Lexists(f, "/flatjoints", H5P_DEFAULT) > 0) {
        g = sx_h5_open_group(h, f, "/flatjoints/elements", true);
        s->fj_elements = sx_h5_rows(h, g, "/flatjoints/elements", "state", 1, true);
        sx_h5_close(g);
    }
    g = sx_h5_open_group(h, f, "/cracks", true);
    s->cracks = sx_h5_rows(h, g, "/cracks", "time", 1, true);
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/walls", true);
    s->walls = sx_h5_rows(h, g, "/walls", "id", 1, true);
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/materials", true);
    const int64_t nm = sx_h5_rows(h, g, "/materials", "name", 1, true);
    sx_h5_close(g);
    s->materials = nm >= 0 && nm <= UINT16_MAX ? (int)nm : -1;
    if (H5Lexists(f, "/contact_models", H5P_DEFAULT) > 0) {
        g = sx_h5_open_group(h, f, "/contact_models", true);
        const int64_t nr = sx_h5_rows(h, g, "/contact_models", "name", 1, true);
        sx_h5_close(g);
        s->cmodels = nr >= 0 && nr <= INT32_MAX ? (int)nr : -1;
    }
    (void)d;
    return !h->failed;
}

static void load_trees(sx_h5 *h, hid_t f, sx_snapshot_info *info)
{
    if (H5Lexists(f, "/lua", H5P_DEFAULT) <= 0) return;
    hid_t g = sx_h5_open_group(h, f, "/lua", true);
    H5G_info_t gi;
    if (g < 0 || H5Gget_info(g, &gi) < 0) {
        sx_h5_fail_h5(h, "damaged: cannot list /lua");
        sx_h5_close(g);
        return;
    }
    if (gi.nlinks > 1024) {
        sx_h5_fail(h, "damaged: /lua lists %llu entries", (unsigned long long)gi.nlinks);
        sx_h5_close(g);
        return;
    }
    info->trees = calloc(gi.nlinks + 1, sizeof *info->trees);
    if (!info->trees) sx_h5_fail(h, "out of memory");
    for (hsize_t k = 0; k < gi.nlinks && !h->failed; k++) {
        sx_io_named_tree *t = &info->trees[info->ntrees];
        const ssize_t len = H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, k, t->name, sizeof t->name,
                                               H5P_DEFAULT);
        if (len < 0 || (size_t)len >= sizeof t->name) {
            sx_h5_fail(h, "damaged: a name in /lua is unreadable or too long");
            break;
        }
        if (sx_io_read_tree(h, g, "/lua", t->name, &t->tree)) info->ntrees++;
    }
    sx_h5_close(g);
}

/* The provenance's seeds (an empty attribute: none). */
static void load_seeds(sx_h5 *h, hid_t f, sx_snapshot_info *info)
{
    const size_t n = sx_h5_attr_len(f, "seeds");
    if (h->failed || n == 0) return;
    if (n > 1000000) {
        sx_h5_fail(h, "damaged: the root lists %zu seeds", n);
        return;
    }
    info->seeds = malloc(n * sizeof *info->seeds);
    if (!info->seeds) sx_h5_fail(h, "out of memory");
    else if (sx_h5_get_i64(h, f, "/", "seeds", info->seeds, n, true)) info->nseeds = (int)n;
}

/* A ball-ball pair of a format 1 or 2 file: the relative position from the
 * stored normal and overlap, r = n (RA + RB - Un). The step then takes the
 * normal back from it to within a rounding of the stored one, so a run
 * continued from such a file follows the one that wrote it to round-off,
 * not to the bit (format 3 stores r itself). */
static void relative_from_normal(sx_model *m, const double *overlap)
{
    const int d = m->dim;
    const sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    for (int64_t c = 0; c < p->n; c++) {
        const int32_t a = p->a[c], b = p->b[c];
        if (a < 0 || b < 0 || a >= B->n || b >= B->n) continue; /* sx__state_finish rejects the file */
        const double dist = B->rad[a] + B->rad[b] - overlap[c];
        for (int k = 0; k < d; k++) p->geo[c * d + k] *= dist;
    }
}

sx_model *sx_snapshot_load(const char *path, int want_dim, sx_snapshot_info *info, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, path ? path : "", err, errlen);
    sx_snapshot_info local;
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    sx_model *m = NULL;
    int d = 0, version = 0;
    hid_t f = path && *path ? sx_io_open(&h, path, false, "snapshot", want_dim, &d, &version)
                            : (sx_h5_fail(&h, "an empty path"), -1);
    sx_state_sizes s;
    sx_clump_sizes cs;
    if (f >= 0 && read_sizes(&h, f, d, &s) && sx_io_read_clump_sizes(&h, f, &cs)) {
        sx_model_def def = sx_model_default_def();
        def.dim = d;
        char cerr[256];
        m = sx_model_create(&def, cerr, sizeof cerr);
        if (!m) sx_h5_fail(&h, "%s", cerr);
        else if (sx__state_alloc(m, &s) || sx__clumps_alloc(m, &cs))
            sx_h5_fail(&h, "damaged or too large: %s", sx_model_error(m));
    }
    if (m && !h.failed) {
        info->format_version = version;
        sx_h5_get_str(f, "seixo_version", info->seixo_version, sizeof info->seixo_version);
        sx_h5_get_str(f, "git_commit", info->git_commit, sizeof info->git_commit);
        sx_h5_get_str(f, "script", info->script, sizeof info->script);
        sx_h5_get_str(f, "script_sha256", info->script_sha256, sizeof info->script_sha256);

        hid_t g = sx_h5_open_group(&h, f, "/model", true);
        if (g >= 0) read_scalars(&h, g, m);
        sx_h5_close(g);
        g = sx_h5_open_group(&h, f, "/materials", true);
        if (g >= 0) sx_io_load_materials(&h, g, m);
        sx_h5_close(g);
        sx_io_load_cmodels(&h, f, m);
        sx_io_load_periodic(&h, f, m); /* before the balls: the ghosts' slots come with the ball arrays */
        sx_io_load_joints(&h, f, m, s.joints);

        field fl[MAX_FIELDS];
        const ball_cols bc = {m->balls.alpha, m->balls.group, NULL};
        sx_io_load_group(&h, f, "/balls", fl, ball_fields(m, &bc, fl), m->balls.n);
        double *overlap = NULL; /* formats 1 and 2 store a ball-ball pair's normal and overlap */
        if (version < 3 && !(overlap = calloc((size_t)(m->bb.n > 0 ? m->bb.n : 1), sizeof *overlap)))
            sx_h5_fail(&h, "out of memory");
        sx_io_load_group(&h, f, "/contacts/ball_ball", fl, pair_fields(m, &m->bb, fl, overlap), m->bb.n);
        if (overlap && !h.failed) relative_from_normal(m, overlap);
        free(overlap);
        sx_io_load_group(&h, f, "/contacts/ball_wall", fl, pair_fields(m, &m->bw, fl, NULL), m->bw.n);
        sx_io_load_group(&h, f, "/bonds", fl, bond_fields(m, fl), m->bonds.n);
        if (m->fjel.n > 0) {
            sx_io_load_group(&h, f, "/flatjoints", fl, flatjoint_fields(m, fl), m->bonds.n);
            sx_io_load_group(&h, f, "/flatjoints/elements", fl, fj_element_fields(m, fl), m->fjel.n);
        }
        g = sx_h5_open_group(&h, f, "/cracks", true);
        if (g >= 0) sx_io_cracks(&h, g, m, false);
        sx_h5_close(g);
        g = sx_h5_open_group(&h, f, "/walls", true);
        if (g >= 0) sx_io_load_walls(&h, g, m, version);
        sx_h5_close(g);
        sx_io_load_clumps(&h, f, m);
        load_trees(&h, f, info);
        sx_io_histories_read(&h, f, &info->histories, &info->nhistories);
        load_seeds(&h, f, info);
        if (!h.failed && sx__state_finish(m)) sx_h5_fail(&h, "damaged: %s", sx_model_error(m));
    }
    if (f >= 0 && H5Fclose(f) < 0) sx_h5_fail_h5(&h, "cannot close the file");
    const bool failed = h.failed;
    sx_h5_end(&h);
    if (failed) {
        sx_model_destroy(m);
        sx_snapshot_info_free(info);
        return NULL;
    }
    if (info == &local) sx_snapshot_info_free(info);
    if (m) m->err[0] = 0;
    return m;
}

void sx_snapshot_info_free(sx_snapshot_info *info)
{
    if (!info) return;
    for (int k = 0; k < info->ntrees; k++) sx_io_tree_free(&info->trees[k].tree);
    free(info->trees);
    info->trees = NULL;
    info->ntrees = 0;
    sx_io_histories_free(info->histories, info->nhistories);
    info->histories = NULL;
    info->nhistories = 0;
    free(info->seeds);
    info->seeds = NULL;
    info->nseeds = 0;
}
