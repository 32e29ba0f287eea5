/* Snapshots: the complete state of a model in one HDF5 file, read back
 * into a model that continues bit-for-bit like the saved one.
 *
 * The I/O layer is part of libseixo's implementation: it includes the
 * core's private layout (through state.h) and writes every array a
 * continuing run reads, in the stores' own dense order, so nothing is
 * recomputed on load except what state.c derives (the id map, the bond
 * count, the chunk plan). Doubles are stored as IEEE 754 binary64, so the
 * bits survive. The layout is documented in docs/file-format.md; each
 * array is listed once below and used by both the writer and the reader.
 *
 * A save goes to a temporary file beside the target, is flushed to disk
 * and renamed over the target; a load checks the file before it trusts
 * any of it, then lets state.c check every cross reference. */
#include "io_internal.h"
#include "state.h"

#include "clumps.h"
#include "joints.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { T_F64, T_I64, T_I32, T_U16, T_U8 };

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

/* One array of a store: n rows of `per` components. */
typedef struct field {
    const char *name;
    int type;
    void *data;
    int per;
    const char *units;
} field;

#define F(nm, ty, ptr, p, u) (field){nm, ty, (void *)(ptr), p, u}

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
    return n;
}

/* Every array of a pair store, from the core's field table (bond slots
 * only when it has them). The last evaluation's geometry: a ball-wall
 * pair's normal and overlap; a ball-ball pair's relative position (format
 * 3), or, reading a file of format 1 or 2, its normal and overlap (into
 * `overlap`, see relative_from_normal). */
static int pair_fields(const sx_model *m, const sx_pairs *p, field *f, double *overlap)
{
    static const int types[] = {[SX_PAIR_I32] = T_I32, [SX_PAIR_F64] = T_F64, [SX_PAIR_U8] = T_U8};
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

enum { MAX_FIELDS = 24 };

static bool write_fields(sx_h5 *h, hid_t g, const field *f, int nf, int64_t rows)
{
    for (int i = 0; i < nf; i++)
        sx_h5_write(h, g, f[i].name, mem_type(f[i].type), file_type(f[i].type), f[i].data, rows, f[i].per, f[i].units);
    return !h->failed;
}

/* Fields a file must have (required), or may lack because an older format
 * did not write them (the data then keeps its zeros). */
static bool read_fields(sx_h5 *h, hid_t g, const char *where, const field *f, int nf, int64_t rows, bool required)
{
    for (int i = 0; i < nf; i++)
        sx_h5_read(h, g, where, f[i].name, mem_type(f[i].type), f[i].data, rows, f[i].per, required);
    return !h->failed;
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

/* ----------------------------------------------------------- materials */

/* The contact laws' names and numbers, from the registry (the file's enum). */
enum { MAX_LAWS = 32 };
static hid_t law_enum(hid_t base)
{
    const char *names[MAX_LAWS];
    int values[MAX_LAWS];
    int n = 0;
    while (n < MAX_LAWS && sx_law_is_model(n)) names[n] = sx_law_name(n), values[n] = n, n++;
    return sx_h5_enum(base, names, values, n);
}

/* A material's numbers: its definition, its bond micro-parameters (bond_
 * and the key, from the bond registry: sx_bond_key), then every law's
 * parameters (each once, from the law registry). */
#define MAT_FIXED 9
#define MAT_MAX (MAT_FIXED + 96)
static const char *const mat_fixed_names[MAT_FIXED] = {
    "density", "kn", "ks", "modulus", "stiffness_ratio", "friction", "damping", "viscous_normal", "viscous_shear"};
static const char *const mat_fixed_units[MAT_FIXED] = {"kg/m^3", "N/m", "N/m", "Pa", "1", "1", "1", "1", "1"};

enum { COL_FIXED = -1, COL_BOND = -2 };
typedef struct mat_column {
    char name[64];
    const char *unit;
    int law, k; /* a law's parameter k, COL_BOND: bond key k, COL_FIXED: fixed number k */
} mat_column;

static void column(mat_column *c, const char *prefix, const char *name, const char *unit, int law, int k)
{
    snprintf(c->name, sizeof c->name, "%s%s", prefix, name);
    c->unit = unit, c->law = law, c->k = k;
}

static int mat_columns(mat_column *c)
{
    int n = 0;
    for (int k = 0; k < MAT_FIXED; k++) column(&c[n++], "", mat_fixed_names[k], mat_fixed_units[k], COL_FIXED, k);
    for (int k = 0; k < sx_bond_key_count() && n < MAT_MAX; k++) {
        const char *unit, *name = sx_bond_key(k, &unit);
        column(&c[n++], "bond_", name, unit, COL_BOND, k);
    }
    const int laws = n;
    for (int law = 0; law < sx_law_count(); law++)
        for (int k = 0; k < sx_law_param_count(law) && n < MAT_MAX; k++) {
            const char *unit, *name = sx_law_param_name(law, k, &unit);
            bool seen = false;
            for (int j = laws; j < n && !seen; j++) seen = strcmp(c[j].name, name) == 0;
            if (!seen) column(&c[n++], "", name, unit, law, k);
        }
    return n;
}

static double *mat_number(sx_material *t, const mat_column *c)
{
    if (c->law >= 0) return sx_law_param_value(&t->def, c->law, c->k);
    if (c->law == COL_BOND) return sx_bond_key_material(&t->bpm, c->k);
    sx_material_def *d = &t->def;
    double *p[MAT_FIXED] = {&d->density, &d->kn, &d->ks, &d->modulus, &d->stiffness_ratio, &d->friction,
                            &d->damping, &d->viscous_normal, &d->viscous_shear};
    return p[c->k];
}

/* Material i of n stored `stride` bytes apart from the first (the
 * materials, or the contact-model rows' laws). */
#define MAT_AT(first, stride, i) ((sx_material *)((char *)(first) + (size_t)(i) * (stride)))

static void write_mats(sx_h5 *h, hid_t g, sx_material *first, size_t stride, int n)
{
    char *names = calloc((size_t)n + 1, sizeof first->name);
    int *model = calloc((size_t)n + 1, sizeof *model);
    double *col = calloc((size_t)n + 1, sizeof *col);
    hid_t mem = law_enum(H5T_NATIVE_INT);
    hid_t file = law_enum(H5T_STD_U8LE);
    if (!names || !model || !col || mem < 0 || file < 0) {
        sx_h5_fail(h, "out of memory");
    } else {
        for (int i = 0; i < n; i++) {
            memcpy(names + (size_t)i * sizeof first->name, MAT_AT(first, stride, i)->name, sizeof first->name);
            model[i] = (int)MAT_AT(first, stride, i)->def.model;
        }
        sx_io_write_strings(h, g, "name", names, sizeof first->name, n);
        sx_h5_write(h, g, "model", mem, file, model, n, 1, NULL);
        mat_column c[MAT_MAX];
        const int nc = mat_columns(c);
        for (int k = 0; k < nc; k++) {
            for (int i = 0; i < n; i++) col[i] = *mat_number(MAT_AT(first, stride, i), &c[k]);
            sx_h5_write(h, g, c[k].name, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, col, n, 1, c[k].unit);
        }
    }
    sx_h5_close(mem);
    sx_h5_close(file);
    free(names);
    free(model);
    free(col);
}

static void save_materials(sx_h5 *h, hid_t f, sx_model *m)
{
    hid_t g = sx_h5_group(h, f, "materials");
    write_mats(h, g, m->mats, sizeof *m->mats, m->nmat);
    sx_h5_close(g);
}

static void read_mats(sx_h5 *h, hid_t g, const char *where, sx_material *first, size_t stride, int n)
{
    char *names = calloc((size_t)n + 1, sizeof first->name);
    int *model = calloc((size_t)n + 1, sizeof *model);
    double *col = calloc((size_t)n + 1, sizeof *col);
    hid_t mem = law_enum(H5T_NATIVE_INT);
    if (!names || !model || !col || mem < 0) {
        sx_h5_fail(h, "out of memory");
    } else if (sx_io_read_strings(h, g, where, "name", names, sizeof first->name, n) &&
               sx_h5_read(h, g, where, "model", mem, model, n, 1, true)) {
        for (int i = 0; i < n; i++) {
            memcpy(MAT_AT(first, stride, i)->name, names + (size_t)i * sizeof first->name, sizeof first->name);
            MAT_AT(first, stride, i)->def.model = (sx_contact_model)model[i];
        }
        mat_column c[MAT_MAX];
        const int nc = mat_columns(c);
        /* a law's or bond kind's parameter a file predates takes its default (the law is newer than the file) */
        sx_material def = {.def = sx_material_default_def()};
        for (int k = 0; k < nc && !h->failed; k++) {
            const bool newer = c[k].law != COL_FIXED && H5Lexists(g, c[k].name, H5P_DEFAULT) <= 0;
            if (newer)
                for (int i = 0; i < n; i++) *mat_number(MAT_AT(first, stride, i), &c[k]) = *mat_number(&def, &c[k]);
            else if (sx_h5_read(h, g, where, c[k].name, H5T_NATIVE_DOUBLE, col, n, 1, true))
                for (int i = 0; i < n; i++) *mat_number(MAT_AT(first, stride, i), &c[k]) = col[i];
        }
    }
    sx_h5_close(mem);
    free(names);
    free(model);
    free(col);
}

static void load_materials(sx_h5 *h, hid_t g, sx_model *m) { read_mats(h, g, "/materials", m->mats, sizeof *m->mats, m->nmat); }

/* The contact-model table (cmodel.c), when it has rows: each row's law as
 * a material (its name, model and numbers, as /materials), and its match
 * (0 default, 1 groups, 2 materials) with the two group numbers or
 * material indices. */
static void save_cmodels(sx_h5 *h, hid_t f, sx_model *m)
{
    const int n = m->ncmodel;
    if (n == 0) return;
    hid_t g = sx_h5_group(h, f, "contact_models");
    write_mats(h, g, &m->cmodel[0].mat, sizeof *m->cmodel, n);
    int32_t *col = calloc((size_t)n, sizeof *col);
    if (!col) sx_h5_fail(h, "out of memory");
    for (int k = 0; col && k < 3; k++) {
        static const char *const names[] = {"match", "a", "b"};
        for (int r = 0; r < n; r++) {
            const sx_cmodel_def *d = &m->cmodel[r].def;
            col[r] = k == 0 ? (int32_t)d->match : k == 1 ? d->a : d->b;
        }
        sx_h5_write(h, g, names[k], H5T_NATIVE_INT32, H5T_STD_I32LE, col, n, 1, NULL);
    }
    free(col);
    sx_h5_close(g);
}

static void load_cmodels(sx_h5 *h, hid_t f, sx_model *m)
{
    const int n = m->ncmodel;
    if (n == 0) return;
    hid_t g = sx_h5_open_group(h, f, "/contact_models", true);
    if (g < 0) return;
    read_mats(h, g, "/contact_models", &m->cmodel[0].mat, sizeof *m->cmodel, n);
    int32_t *col = calloc((size_t)n, sizeof *col);
    if (!col) sx_h5_fail(h, "out of memory");
    for (int k = 0; col && k < 3 && !h->failed; k++) {
        static const char *const names[] = {"match", "a", "b"};
        if (!sx_h5_read(h, g, "/contact_models", names[k], H5T_NATIVE_INT32, col, n, 1, true)) break;
        for (int r = 0; r < n; r++) {
            sx_cmodel_def *d = &m->cmodel[r].def;
            if (k == 0) d->match = (sx_cmodel_match)col[r];
            else if (k == 1) d->a = col[r];
            else d->b = col[r];
        }
    }
    free(col);
    sx_h5_close(g);
}

/* --------------------------------------------------------------- walls */

static const char *const wall_kind_names[] = {"plane", "line", "rect", "segment", "cylinder", "mesh"};
static const int wall_kind_values[] = {SX_WALL_PLANE,   SX_WALL_LINE,     SX_WALL_RECT,
                                       SX_WALL_SEGMENT, SX_WALL_CYLINDER, SX_WALL_MESH};
enum { WALL_KINDS = sizeof wall_kind_values / sizeof *wall_kind_values };

/* The walls' arrays, gathered from (or scattered to) the array of structs. */
typedef struct wall_cols {
    int64_t *id, *contacts;
    int *kind;
    int32_t *material;
    uint8_t *servo_on;
    double *point, *normal, *edge1, *edge2, *vel, *kn, *ks, *friction;
    double *u, *v, *len_u, *len_v, *seg_len, *force, *moment, *moved;
    double *radius, *height, *radial_vel, *load, *kn_sum;
    double *target, *area, *alpha, *max_speed;
    double *spin;
} wall_cols;

static bool wall_cols_alloc(wall_cols *c, int64_t n)
{
    memset(c, 0, sizeof *c);
    const size_t k = (size_t)(n > 0 ? n : 1);
    c->id = calloc(k, sizeof *c->id);
    c->contacts = calloc(k, sizeof *c->contacts);
    c->kind = calloc(k, sizeof *c->kind);
    c->servo_on = calloc(k, sizeof *c->servo_on);
    c->material = calloc(k, sizeof *c->material);
    double **vec[] = {&c->point, &c->normal, &c->edge1, &c->edge2, &c->vel, &c->u, &c->v, &c->force, &c->moment, &c->spin};
    double **sc[] = {&c->kn,     &c->ks,     &c->friction,   &c->len_u, &c->len_v,  &c->seg_len, &c->moved,
                     &c->radius, &c->height, &c->radial_vel, &c->load,  &c->kn_sum, &c->target,  &c->area,
                     &c->alpha,  &c->max_speed};
    bool ok = c->id && c->contacts && c->kind && c->servo_on && c->material;
    for (size_t i = 0; c->material && i < k; i++) c->material[i] = SX_WALL_NO_MATERIAL; /* a file from before them */
    for (size_t i = 0; i < sizeof vec / sizeof *vec; i++) ok &= (*vec[i] = calloc(3 * k, sizeof(double))) != NULL;
    for (size_t i = 0; i < sizeof sc / sizeof *sc; i++) ok &= (*sc[i] = calloc(k, sizeof(double))) != NULL;
    return ok;
}

static void wall_cols_free(wall_cols *c)
{
    void *p[] = {c->id,       c->contacts, c->kind,    c->servo_on,   c->point,  c->normal, c->edge1,  c->edge2,
                 c->vel,      c->kn,       c->ks,      c->friction,   c->u,      c->v,      c->len_u,  c->len_v,
                 c->seg_len,  c->force,    c->moment,  c->moved,      c->radius, c->height, c->radial_vel,
                 c->load,     c->kn_sum,   c->target,  c->area,       c->alpha,  c->max_speed, c->spin,
                 c->material};
    for (size_t i = 0; i < sizeof p / sizeof *p; i++) free(p[i]);
}

/* The fields of format 2: cylinders, and the servo with the inputs it read
 * in the last step (what sx_wall_load reports). */
static int wall_fields2(const sx_model *m, const wall_cols *c, field *f)
{
    const bool d3 = m->dim == 3; /* a 2D servo acts per unit thickness */
    int n = 0;
    f[n++] = F("radius", T_F64, c->radius, 1, "m");
    f[n++] = F("height", T_F64, c->height, 1, "m");
    f[n++] = F("radial_velocity", T_F64, c->radial_vel, 1, "m/s");
    f[n++] = F("normal_load", T_F64, c->load, 1, "N");
    f[n++] = F("normal_stiffness_sum", T_F64, c->kn_sum, 1, "N/m");
    f[n++] = F("contact_count", T_I64, c->contacts, 1, NULL);
    f[n++] = F("servo", T_U8, c->servo_on, 1, NULL);
    f[n++] = F("servo_target", T_F64, c->target, 1, d3 ? "Pa" : "N/m");
    f[n++] = F("servo_area", T_F64, c->area, 1, d3 ? "m^2" : "m");
    f[n++] = F("servo_alpha", T_F64, c->alpha, 1, "1");
    f[n++] = F("servo_max_speed", T_F64, c->max_speed, 1, "m/s");
    return n;
}

/* Meshes' spin (3D), optional: a file without meshes may lack it. */
static int wall_fields_mesh(const sx_model *m, const wall_cols *c, field *f)
{
    int n = 0;
    if (m->dim == 3) f[n++] = F("spin", T_F64, c->spin, 3, "rad/s");
    return n;
}

/* A wall's material (its index among /materials; -1: none, -2: rigid),
 * optional: a file from before wall materials has none. */
static int wall_fields_material(const wall_cols *c, field *f)
{
    int n = 0;
    f[n++] = F("material", T_I32, c->material, 1, NULL);
    return n;
}

/* The fields of format 1. Vectors of dim components (the moment: rdim); scalars one. */
static int wall_fields(const sx_model *m, const wall_cols *c, field *f)
{
    const int d = m->dim, r = m->rdim;
    int n = 0;
    f[n++] = F("point", T_F64, c->point, d, "m");
    f[n++] = F("normal", T_F64, c->normal, d, "1");
    f[n++] = F("edge1", T_F64, c->edge1, d, "m");
    f[n++] = F("edge2", T_F64, c->edge2, d, "m");
    f[n++] = F("velocity", T_F64, c->vel, d, "m/s");
    f[n++] = F("kn", T_F64, c->kn, 1, "N/m");
    f[n++] = F("ks", T_F64, c->ks, 1, "N/m");
    f[n++] = F("friction", T_F64, c->friction, 1, "1");
    f[n++] = F("frame_u", T_F64, c->u, d, "1");
    f[n++] = F("frame_v", T_F64, c->v, d, "1");
    f[n++] = F("length_u", T_F64, c->len_u, 1, "m");
    f[n++] = F("length_v", T_F64, c->len_v, 1, "m");
    f[n++] = F("segment_length", T_F64, c->seg_len, 1, "m");
    f[n++] = F("force", T_F64, c->force, d, "N");
    f[n++] = F("moment", T_F64, c->moment, r, "N m");
    f[n++] = F("moved", T_F64, c->moved, 1, "m");
    return n;
}

static void wall_copy(const sx_model *m, sx_wall *w, wall_cols *c, int64_t i, bool to_cols)
{
    const int d = m->dim, r = m->rdim;
#define V(arr, fld, k)                                                       \
    do {                                                                     \
        for (int j = 0; j < (k); j++) {                                      \
            if (to_cols) c->arr[i * (k) + j] = fld[j];                       \
            else fld[j] = c->arr[i * (k) + j];                               \
        }                                                                    \
    } while (0)
#define S(arr, fld)                              \
    do {                                         \
        if (to_cols) c->arr[i] = fld;            \
        else fld = c->arr[i];                    \
    } while (0)
    V(point, w->def.point, d);
    V(normal, w->def.normal, d);
    V(edge1, w->def.edge1, d);
    V(edge2, w->def.edge2, d);
    V(vel, w->def.vel, d);
    V(u, w->u, d);
    V(v, w->v, d);
    V(force, w->force, d);
    V(moment, w->moment, r);
    V(spin, w->def.spin, 3);
    S(kn, w->def.kn);
    S(ks, w->def.ks);
    S(friction, w->def.friction);
    S(len_u, w->len_u);
    S(len_v, w->len_v);
    S(seg_len, w->seg_len);
    S(moved, w->moved);
    S(id, w->id);
    S(radius, w->def.radius);
    S(height, w->def.height);
    S(radial_vel, w->def.radial_vel);
    S(load, w->load);
    S(kn_sum, w->kn_sum);
    S(contacts, w->contacts);
    S(target, w->servo.target);
    S(area, w->servo.area);
    S(alpha, w->servo.alpha);
    S(max_speed, w->servo.max_speed);
    S(material, w->def.material);
    if (to_cols) c->kind[i] = (int)w->def.kind, c->servo_on[i] = w->servo_on;
    else w->def.kind = (sx_wall_kind)c->kind[i], w->servo_on = c->servo_on[i] != 0;
#undef V
#undef S
}

/* A mesh wall's group /walls/mesh_<id>: its vertices in its own frame
 * (relative to the wall's point), its triangles and its orientation, from
 * which the vertices where they are follow (sx__mesh_pose). */
static void mesh_group_name(const sx_wall *w, char *name, size_t len)
{
    snprintf(name, len, "mesh_%lld", (long long)w->id);
}

static void save_mesh(sx_h5 *h, hid_t walls, const sx_wall *w)
{
    char name[64];
    mesh_group_name(w, name, sizeof name);
    hid_t g = sx_h5_group(h, walls, name);
    const sx_mesh *s = w->mesh;
    sx_h5_write(h, g, "body_vertices", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, s->body, s->nv, 3, "m");
    sx_h5_write(h, g, "triangles", H5T_NATIVE_INT32, H5T_STD_I32LE, s->tri, s->nt, 3, NULL);
    sx_h5_write(h, g, "orientation", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, s->q, 1, 4, "1");
    sx_h5_close(g);
}

static void load_mesh(sx_h5 *h, hid_t walls, sx_model *m, sx_wall *w)
{
    char name[64], where[96];
    mesh_group_name(w, name, sizeof name);
    snprintf(where, sizeof where, "/walls/%s", name);
    hid_t g = sx_h5_open_group(h, walls, name, true);
    if (g < 0) return;
    const int64_t nv = sx_h5_rows(h, g, where, "body_vertices", 3, true), nt = sx_h5_rows(h, g, where, "triangles", 3, true);
    if (!h->failed && (nv < 3 || nt < 1)) sx_h5_fail(h, "damaged: %s has %lld vertices and %lld triangles", where, (long long)nv, (long long)nt);
    if (!h->failed && !(w->mesh = sx__mesh_alloc(m, nv, nt))) sx_h5_fail(h, "out of memory");
    if (!h->failed) {
        sx_h5_read(h, g, where, "body_vertices", H5T_NATIVE_DOUBLE, w->mesh->body, nv, 3, true);
        sx_h5_read(h, g, where, "triangles", H5T_NATIVE_INT32, w->mesh->tri, nt, 3, true);
        sx_h5_read(h, g, where, "orientation", H5T_NATIVE_DOUBLE, w->mesh->q, 1, 4, true);
    }
    sx_h5_close(g);
}

static void save_walls(sx_h5 *h, hid_t f, const sx_model *m)
{
    hid_t g = sx_h5_group(h, f, "walls");
    const int64_t n = m->nwall;
    wall_cols c;
    hid_t mem = sx_h5_enum(H5T_NATIVE_INT, wall_kind_names, wall_kind_values, WALL_KINDS);
    hid_t file = sx_h5_enum(H5T_STD_U8LE, wall_kind_names, wall_kind_values, WALL_KINDS);
    if (!wall_cols_alloc(&c, n) || mem < 0 || file < 0) {
        sx_h5_fail(h, "out of memory");
    } else {
        for (int64_t i = 0; i < n; i++) wall_copy(m, &m->walls[i], &c, i, true);
        sx_h5_write(h, g, "id", H5T_NATIVE_INT64, H5T_STD_I64LE, c.id, n, 1, NULL);
        sx_h5_write(h, g, "kind", mem, file, c.kind, n, 1, NULL);
        field fl[MAX_FIELDS];
        write_fields(h, g, fl, wall_fields(m, &c, fl), n);
        write_fields(h, g, fl, wall_fields2(m, &c, fl), n);
        write_fields(h, g, fl, wall_fields_mesh(m, &c, fl), n);
        write_fields(h, g, fl, wall_fields_material(&c, fl), n);
        for (int64_t i = 0; i < n; i++)
            if (m->walls[i].mesh) save_mesh(h, g, &m->walls[i]);
    }
    wall_cols_free(&c);
    sx_h5_close(mem);
    sx_h5_close(file);
    sx_h5_close(g);
}

/* A format-1 file has no cylinder and no servo: its walls load with the
 * format-2 fields at zero (no servo). */
static void load_walls(sx_h5 *h, hid_t g, sx_model *m, int version)
{
    const int64_t n = m->nwall;
    wall_cols c;
    hid_t mem = sx_h5_enum(H5T_NATIVE_INT, wall_kind_names, wall_kind_values, WALL_KINDS);
    if (!wall_cols_alloc(&c, n) || mem < 0) {
        sx_h5_fail(h, "out of memory");
    } else {
        field fl[MAX_FIELDS];
        sx_h5_read(h, g, "/walls", "id", H5T_NATIVE_INT64, c.id, n, 1, true);
        sx_h5_read(h, g, "/walls", "kind", mem, c.kind, n, 1, true);
        if (read_fields(h, g, "/walls", fl, wall_fields(m, &c, fl), n, true) &&
            read_fields(h, g, "/walls", fl, wall_fields2(m, &c, fl), n, version >= 2) &&
            read_fields(h, g, "/walls", fl, wall_fields_mesh(m, &c, fl), n, false) &&
            read_fields(h, g, "/walls", fl, wall_fields_material(&c, fl), n, false))
            for (int64_t i = 0; i < n && !h->failed; i++) {
                wall_copy(m, &m->walls[i], &c, i, false);
                if (m->walls[i].def.kind == SX_WALL_MESH) load_mesh(h, g, m, &m->walls[i]);
            }
    }
    wall_cols_free(&c);
    sx_h5_close(mem);
}

/* -------------------------------------------------------------- cracks */

static const char *const mode_names[] = {"tension", "shear"};
static const int mode_values[] = {SX_CRACK_TENSION, SX_CRACK_SHEAR};
static const char *const bond_kind_names[] = {"contact", "parallel", "flatjoint", "smoothjoint"};
static const int bond_kind_values[] = {SX_BOND_CONTACT, SX_BOND_PARALLEL, SX_BOND_FLATJOINT, SX_BOND_SMOOTHJOINT};

typedef struct crack_cols {
    double *time, *pos, *fn, *fs, *mn, *ms;
    int64_t *step, *a, *b;
    int *mode, *kind, *element;
} crack_cols;

static bool crack_cols_alloc(crack_cols *c, int64_t n)
{
    const size_t k = (size_t)(n > 0 ? n : 1);
    c->time = calloc(k, sizeof(double));
    c->pos = calloc(3 * k, sizeof(double));
    c->fn = calloc(k, sizeof(double));
    c->fs = calloc(k, sizeof(double));
    c->mn = calloc(k, sizeof(double));
    c->ms = calloc(k, sizeof(double));
    c->step = calloc(k, sizeof(int64_t));
    c->a = calloc(k, sizeof(int64_t));
    c->b = calloc(k, sizeof(int64_t));
    c->mode = calloc(k, sizeof(int));
    c->kind = calloc(k, sizeof(int));
    c->element = calloc(k, sizeof(int));
    return c->time && c->pos && c->fn && c->fs && c->mn && c->ms && c->step && c->a && c->b && c->mode && c->kind &&
           c->element;
}

static void crack_cols_free(crack_cols *c)
{
    void *p[] = {c->time, c->pos, c->fn, c->fs, c->mn, c->ms, c->step, c->a, c->b, c->mode, c->kind, c->element};
    for (size_t i = 0; i < sizeof p / sizeof *p; i++) free(p[i]);
}

/* Reads (write = false) or writes the crack log through its columns. */
static void crack_io(sx_h5 *h, hid_t g, sx_model *m, bool write)
{
    const int64_t n = m->cracks.n;
    const int d = m->dim;
    crack_cols c;
    hid_t mm = sx_h5_enum(H5T_NATIVE_INT, mode_names, mode_values, 2);
    hid_t mf = sx_h5_enum(H5T_STD_U8LE, mode_names, mode_values, 2);
    /* the flat joint's kind and the element column only in files of models with flat joints */
    const bool fj = write ? m->fjel.n > 0 : H5Lexists(g, "element", H5P_DEFAULT) > 0;
    /* the smooth joint's kind only in files of models with smooth joints; read, any of the four */
    const int nk = !write ? 4 : m->njoint > 0 ? 4 : fj ? 3 : 2;
    hid_t km = sx_h5_enum(H5T_NATIVE_INT, bond_kind_names, bond_kind_values, nk);
    hid_t kf = sx_h5_enum(H5T_STD_U8LE, bond_kind_names, bond_kind_values, nk);
    if (!crack_cols_alloc(&c, n) || mm < 0 || mf < 0 || km < 0 || kf < 0) {
        sx_h5_fail(h, "out of memory");
        goto done;
    }
    if (write)
        for (int64_t i = 0; i < n; i++) {
            const sx_crack *e = &m->cracks.ev[i];
            c.time[i] = e->time, c.step[i] = e->step, c.a[i] = e->a, c.b[i] = e->b;
            c.fn[i] = e->fn, c.fs[i] = e->fs, c.mn[i] = e->mn, c.ms[i] = e->ms;
            c.mode[i] = (int)e->mode, c.kind[i] = (int)e->kind, c.element[i] = e->element;
            for (int k = 0; k < d; k++) c.pos[i * d + k] = e->pos[k];
        }
    struct {
        const char *name;
        hid_t mem, file;
        void *data;
        int per;
        const char *units;
    } cols[] = {
        {"time", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.time, 1, "s"},
        {"step", H5T_NATIVE_INT64, H5T_STD_I64LE, c.step, 1, NULL},
        {"position", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.pos, d, "m"},
        {"mode", mm, mf, c.mode, 1, NULL},
        {"kind", km, kf, c.kind, 1, NULL},
        {"ball_a", H5T_NATIVE_INT64, H5T_STD_I64LE, c.a, 1, NULL},
        {"ball_b", H5T_NATIVE_INT64, H5T_STD_I64LE, c.b, 1, NULL},
        {"normal_force", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.fn, 1, "N"},
        {"shear_force", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.fs, 1, "N"},
        {"twist_moment", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.mn, 1, "N m"},
        {"bending_moment", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.ms, 1, "N m"},
        {"element", H5T_NATIVE_INT, H5T_STD_I32LE, c.element, 1, NULL},
    };
    const size_t ncols = sizeof cols / sizeof *cols - (fj ? 0 : 1);
    for (size_t k = 0; k < ncols; k++) {
        if (write) sx_h5_write(h, g, cols[k].name, cols[k].mem, cols[k].file, cols[k].data, n, cols[k].per, cols[k].units);
        else sx_h5_read(h, g, "/cracks", cols[k].name, cols[k].mem, cols[k].data, n, cols[k].per, true);
    }
    if (!write && !h->failed)
        for (int64_t i = 0; i < n; i++) {
            sx_crack *e = &m->cracks.ev[i];
            memset(e, 0, sizeof *e);
            e->time = c.time[i], e->step = c.step[i], e->a = c.a[i], e->b = c.b[i];
            e->fn = c.fn[i], e->fs = c.fs[i], e->mn = c.mn[i], e->ms = c.ms[i];
            e->mode = (sx_crack_mode)c.mode[i], e->kind = (sx_bond_kind)c.kind[i];
            e->element = fj ? c.element[i] : -1;
            for (int k = 0; k < d; k++) e->pos[k] = c.pos[i * d + k];
        }
done:
    crack_cols_free(&c);
    sx_h5_close(mm);
    sx_h5_close(mf);
    sx_h5_close(km);
    sx_h5_close(kf);
}

/* -------------------------------------------------------------- clumps */

static void load_group(sx_h5 *h, hid_t f, const char *path, const field *fl, int nf, int64_t rows);

/* The clump store (core clumps.h) in its own group /clumps, written only
 * when the model has one: the templates (/clumps/templates, with their
 * pebbles in /clumps/template_pebbles), every per-clump array, and the
 * clumps' pebbles as ball ids (/clumps/pebbles; clump c owns the rows
 * first_pebble[c] .. first_pebble[c] + its template's count). The balls'
 * clump ids are derived from it on load (clumps.c). */

static int clump_fields(const sx_model *m, field *f)
{
    const sx_clumps *C = m->clumps;
    const int d = m->dim, r = m->rdim;
    int n = 0;
    f[n++] = F("id", T_I32, C->id, 1, NULL);
    f[n++] = F("template", T_I32, C->tpl_of, 1, NULL);
    f[n++] = F("material", T_U16, C->mat, 1, NULL);
    f[n++] = F("fixity", T_U8, C->fix, 1, NULL);
    f[n++] = F("scale", T_F64, C->scale, 1, "1");
    f[n++] = F("position", T_F64, C->x, d, "m");
    f[n++] = F("velocity", T_F64, C->v, d, "m/s");
    f[n++] = F(d == 3 ? "orientation" : "angle", T_F64, C->q, d == 3 ? 4 : 1, d == 3 ? "1" : "rad");
    if (d == 3) f[n++] = F("angular_momentum", T_F64, C->L, 3, "kg m^2/s");
    f[n++] = F("spin", T_F64, C->w, r, "rad/s");
    f[n++] = F("force", T_F64, C->f, d, "N");
    f[n++] = F("moment", T_F64, C->t, r, "N m");
    f[n++] = F("damping", T_F64, C->alpha, 1, "1");
    f[n++] = F("mass", T_F64, C->mass, 1, "kg");
    f[n++] = F("inertia", T_F64, C->inertia, r, "kg m^2");
    f[n++] = F("first_pebble", T_I64, C->first, 1, NULL);
    return n;
}

static int template_pebble_fields(const sx_model *m, field *f)
{
    const sx_clumps *C = m->clumps;
    const int d = m->dim;
    int n = 0;
    f[n++] = F("position", T_F64, C->tp_pos, d, "m");
    f[n++] = F("radius", T_F64, C->tp_rad, 1, "m");
    f[n++] = F("body_position", T_F64, C->tp_body, d, "m");
    return n;
}

/* The templates' columns, gathered from (or scattered to) their structs. */
typedef struct tpl_cols {
    char *name;
    int64_t *first, *count, *lines;
    double *volume, *centroid, *inertia, *principal, *frame, *error, *power_sum;
} tpl_cols;

static bool tpl_cols_alloc(tpl_cols *c, int64_t n)
{
    const size_t k = (size_t)(n > 0 ? n : 1);
    c->name = calloc(k, sizeof ((sx_clump_tpl *)0)->name);
    c->first = calloc(k, sizeof(int64_t));
    c->count = calloc(k, sizeof(int64_t));
    c->lines = calloc(k, sizeof(int64_t));
    c->volume = calloc(k, sizeof(double));
    c->centroid = calloc(3 * k, sizeof(double));
    c->inertia = calloc(9 * k, sizeof(double));
    c->principal = calloc(3 * k, sizeof(double));
    c->frame = calloc(4 * k, sizeof(double));
    c->error = calloc(k, sizeof(double));
    c->power_sum = calloc(k, sizeof(double));
    return c->name && c->first && c->count && c->lines && c->volume && c->centroid && c->inertia && c->principal &&
           c->frame && c->error && c->power_sum;
}

static void tpl_cols_free(tpl_cols *c)
{
    void *p[] = {c->name, c->first, c->count, c->lines, c->volume, c->centroid, c->inertia, c->principal,
                 c->frame, c->error, c->power_sum};
    for (size_t i = 0; i < sizeof p / sizeof *p; i++) free(p[i]);
}

static void tpl_copy(sx_clump_tpl *t, tpl_cols *c, int64_t i, bool to_cols)
{
    const size_t w = sizeof t->name;
#define S(arr, fld)                 \
    do {                            \
        if (to_cols) c->arr[i] = fld; \
        else fld = c->arr[i];       \
    } while (0)
#define V(arr, fld, k)                                  \
    do {                                                \
        if (to_cols) memcpy(c->arr + i * (k), fld, (k) * sizeof(double)); \
        else memcpy(fld, c->arr + i * (k), (k) * sizeof(double));         \
    } while (0)
    if (to_cols) memcpy(c->name + (size_t)i * w, t->name, w);
    else memcpy(t->name, c->name + (size_t)i * w, w);
    S(first, t->first);
    S(count, t->n);
    S(lines, t->lines);
    S(volume, t->volume);
    S(error, t->error);
    S(power_sum, t->power_sum);
    V(centroid, t->centroid, 3);
    V(inertia, t->inertia, 9);
    V(principal, t->principal, 3);
    V(frame, t->frame, 4);
#undef S
#undef V
}

/* Reads (write = false) or writes the templates' columns. */
static void templates_io(sx_h5 *h, hid_t g, sx_model *m, bool write)
{
    sx_clumps *C = m->clumps;
    const int64_t n = C->ntpl;
    const size_t w = sizeof C->tpl[0].name;
    tpl_cols c;
    memset(&c, 0, sizeof c);
    if (!tpl_cols_alloc(&c, n)) {
        sx_h5_fail(h, "out of memory");
        tpl_cols_free(&c);
        return;
    }
    if (write)
        for (int64_t i = 0; i < n; i++) tpl_copy(&C->tpl[i], &c, i, true);
    struct {
        const char *name;
        hid_t mem, file;
        void *data;
        int per;
        const char *units;
    } cols[] = {
        {"first_pebble", H5T_NATIVE_INT64, H5T_STD_I64LE, c.first, 1, NULL},
        {"pebble_count", H5T_NATIVE_INT64, H5T_STD_I64LE, c.count, 1, NULL},
        {"lines", H5T_NATIVE_INT64, H5T_STD_I64LE, c.lines, 1, NULL},
        {"volume", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.volume, 1, m->dim == 3 ? "m^3" : "m^2"},
        {"centroid", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.centroid, 3, "m"},
        {"inertia", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.inertia, 9, m->dim == 3 ? "m^5" : "m^4"},
        {"principal", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.principal, 3, m->dim == 3 ? "m^5" : "m^4"},
        {"frame", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.frame, 4, "1"},
        {"error", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.error, 1, "1"},
        {"power_sum", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, c.power_sum, 1, m->dim == 3 ? "m^3" : "m^2"},
    };
    if (write) sx_io_write_strings(h, g, "name", c.name, w, n);
    else sx_io_read_strings(h, g, "/clumps/templates", "name", c.name, w, n);
    for (size_t k = 0; k < sizeof cols / sizeof *cols; k++) {
        if (write) sx_h5_write(h, g, cols[k].name, cols[k].mem, cols[k].file, cols[k].data, n, cols[k].per, cols[k].units);
        else sx_h5_read(h, g, "/clumps/templates", cols[k].name, cols[k].mem, cols[k].data, n, cols[k].per, true);
    }
    if (!write && !h->failed)
        for (int64_t i = 0; i < n; i++) tpl_copy(&C->tpl[i], &c, i, false);
    tpl_cols_free(&c);
}

static void save_clumps(sx_h5 *h, hid_t f, sx_model *m)
{
    sx_clumps *C = m->clumps;
    if (!C) return;
    field fl[MAX_FIELDS];
    hid_t g = sx_h5_group(h, f, "clumps");
    sx_h5_attr_int(h, g, "count", C->n);
    sx_h5_attr_int(h, g, "next_id", C->next_id);
    write_fields(h, g, fl, clump_fields(m, fl), C->n);
    sx_h5_write(h, g, "pebbles", H5T_NATIVE_INT32, H5T_STD_I32LE, C->pebble, C->pn, 1, NULL);
    hid_t t = sx_h5_group(h, g, "templates");
    templates_io(h, t, m, true);
    sx_h5_close(t);
    t = sx_h5_group(h, g, "template_pebbles");
    write_fields(h, t, fl, template_pebble_fields(m, fl), C->tp_n);
    sx_h5_close(t);
    sx_h5_close(g);
}

/* The clump store's sizes; all zero when the file has no /clumps. */
static bool read_clump_sizes(sx_h5 *h, hid_t f, sx_clump_sizes *s)
{
    memset(s, 0, sizeof *s);
    if (H5Lexists(f, "/clumps", H5P_DEFAULT) <= 0) return true;
    hid_t g = sx_h5_open_group(h, f, "/clumps", true);
    s->clumps = sx_h5_rows(h, g, "/clumps", "id", 1, true);
    s->pebbles = sx_h5_rows(h, g, "/clumps", "pebbles", 1, true);
    sx_h5_get_i64(h, g, "/clumps", "next_id", &s->next_id, 1, true);
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/clumps/templates", true);
    const int64_t nt = sx_h5_rows(h, g, "/clumps/templates", "name", 1, true);
    s->templates = nt >= 0 && nt <= INT16_MAX ? (int)nt : -1;
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/clumps/template_pebbles", true);
    s->template_pebbles = sx_h5_rows(h, g, "/clumps/template_pebbles", "radius", 1, true);
    sx_h5_close(g);
    return !h->failed;
}

static void load_clumps(sx_h5 *h, hid_t f, sx_model *m)
{
    sx_clumps *C = m->clumps;
    if (!C) return;
    field fl[MAX_FIELDS];
    load_group(h, f, "/clumps", fl, clump_fields(m, fl), C->n);
    hid_t g = sx_h5_open_group(h, f, "/clumps", true);
    if (g >= 0) sx_h5_read(h, g, "/clumps", "pebbles", H5T_NATIVE_INT32, C->pebble, C->pn, 1, true);
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/clumps/templates", true);
    if (g >= 0) templates_io(h, g, m, false);
    sx_h5_close(g);
    load_group(h, f, "/clumps/template_pebbles", fl, template_pebble_fields(m, fl), C->tp_n);
}

/* ------------------------------------------------------ periodic space */

/* The periodic cell (core model_internal.h, sx_cell) in its own group
 * /periodic, written only when the space is periodic: the cell and its
 * control as attributes, the ghosts' table as datasets (ghost g is ball
 * slot count + g, a pair's b past the balls); the ghosts' own state is
 * derived from their owners on load (sx__cell_finish). */
static void save_periodic(sx_h5 *h, hid_t f, const sx_model *m)
{
    const sx_cell *c = m->cell;
    if (!c) return;
    hid_t g = sx_h5_group(h, f, "periodic");
    int64_t axes[3], modes[SX_CELL_COMPONENTS];
    for (int k = 0; k < 3; k++) axes[k] = c->axis[k];
    for (int k = 0; k < SX_CELL_COMPONENTS; k++) modes[k] = c->ctl.mode[k];
    sx_h5_attr_i64(h, g, "axes", axes, 3, false);
    sx_h5_attr_f64(h, g, "lo", c->lo, 3, false);
    sx_h5_attr_f64(h, g, "h", &c->h[0][0], 9, false);
    sx_h5_attr_f64(h, g, "hdot", &c->hdot[0][0], 9, false);
    sx_h5_attr_double(h, g, "moved", c->moved);
    sx_h5_attr_i64(h, g, "control_mode", modes, SX_CELL_COMPONENTS, false);
    sx_h5_attr_f64(h, g, "control_rate", c->ctl.rate, SX_CELL_COMPONENTS, false);
    sx_h5_attr_f64(h, g, "control_target", c->ctl.target, SX_CELL_COMPONENTS, false);
    sx_h5_attr_double(h, g, "control_alpha", c->ctl.alpha);
    sx_h5_attr_double(h, g, "control_max_rate", c->ctl.max_rate);
    sx_h5_write(h, g, "ghost_owner", H5T_NATIVE_INT32, H5T_STD_I32LE, c->owner, c->n, 1, NULL);
    sx_h5_write(h, g, "ghost_image", H5T_NATIVE_INT8, H5T_STD_I8LE, c->image, c->n, 3, NULL);
    sx_h5_close(g);
}

static void load_periodic(sx_h5 *h, hid_t f, sx_model *m)
{
    if (H5Lexists(f, "/periodic", H5P_DEFAULT) <= 0) return;
    hid_t g = sx_h5_open_group(h, f, "/periodic", true);
    if (g < 0) return;
    sx_cell c;
    memset(&c, 0, sizeof c);
    int64_t axes[3] = {0}, modes[SX_CELL_COMPONENTS] = {0};
    sx_h5_get_i64(h, g, "/periodic", "axes", axes, 3, true);
    sx_h5_get_f64(h, g, "/periodic", "lo", c.lo, 3, true);
    sx_h5_get_f64(h, g, "/periodic", "h", &c.h[0][0], 9, true);
    sx_h5_get_f64(h, g, "/periodic", "hdot", &c.hdot[0][0], 9, true);
    sx_h5_get_f64(h, g, "/periodic", "moved", &c.moved, 1, true);
    sx_h5_get_i64(h, g, "/periodic", "control_mode", modes, SX_CELL_COMPONENTS, true);
    sx_h5_get_f64(h, g, "/periodic", "control_rate", c.ctl.rate, SX_CELL_COMPONENTS, true);
    sx_h5_get_f64(h, g, "/periodic", "control_target", c.ctl.target, SX_CELL_COMPONENTS, true);
    sx_h5_get_f64(h, g, "/periodic", "control_alpha", &c.ctl.alpha, 1, true);
    sx_h5_get_f64(h, g, "/periodic", "control_max_rate", &c.ctl.max_rate, 1, true);
    for (int k = 0; k < 3; k++) c.axis[k] = axes[k] != 0;
    for (int k = 0; k < SX_CELL_COMPONENTS; k++)
        c.ctl.mode[k] = modes[k] >= 0 && modes[k] <= SX_CELL_STRESS ? (sx_cell_mode)modes[k] : (sx_cell_mode)-1;
    c.n = sx_h5_rows(h, g, "/periodic", "ghost_owner", 1, true);
    if (!h->failed && sx_h5_rows(h, g, "/periodic", "ghost_image", 3, true) != c.n)
        sx_h5_fail(h, "damaged: /periodic's ghost_owner and ghost_image differ in rows");
    if (!h->failed && sx__cell_restore(m, &c)) sx_h5_fail(h, "damaged or too large: %s", sx_model_error(m));
    if (!h->failed) {
        sx_h5_read(h, g, "/periodic", "ghost_owner", H5T_NATIVE_INT32, m->cell->owner, c.n, 1, true);
        sx_h5_read(h, g, "/periodic", "ghost_image", H5T_NATIVE_INT8, m->cell->image, c.n, 3, true);
    }
    sx_h5_close(g);
}

/* -------------------------------------------------------- smooth joints */

/* The smooth joints' definitions (core sx_joint_def) in their own group
 * /joints, one row per joint, written only when the model has joints; the
 * contacts' joint fields are the ball-ball store's (joint, joint_normal,
 * joint_overlap). */
enum { JOINT_COLS = 14 };

static int joint_fields(field *f, double *cols, int64_t n)
{
    int k = 0;
    f[k++] = F("point", T_F64, cols, 3, "m");
    f[k++] = F("normal", T_F64, cols + 3 * n, 3, "1");
    static const char *const names[] = {"kn", "ks", "friction", "dilation", "tension", "cohesion", "friction_angle",
                                        "radius_multiplier"};
    static const char *const units[] = {"Pa/m", "Pa/m", "1", "degree", "Pa", "Pa", "degree", "1"};
    for (int q = 0; q < 8; q++) f[k++] = F(names[q], T_F64, cols + (6 + q) * n, 1, units[q]);
    return k;
}

/* Between the definitions and the columns (to_cols: defs to cols). */
static void joint_columns(sx_joint_def *defs, double *cols, int64_t n, bool to_cols)
{
    for (int64_t i = 0; i < n; i++) {
        sx_joint_def *d = &defs[i];
        double *v[JOINT_COLS] = {&d->point[0], &d->point[1], &d->point[2], &d->normal[0], &d->normal[1],
                                 &d->normal[2], &d->kn, &d->ks, &d->friction, &d->dilation, &d->tension,
                                 &d->cohesion, &d->friction_angle, &d->radius_multiplier};
        for (int q = 0; q < JOINT_COLS; q++) {
            double *c = q < 6 ? cols + (q / 3) * 3 * n + i * 3 + q % 3 : cols + (int64_t)q * n + i;
            if (to_cols) *c = *v[q];
            else *v[q] = *c;
        }
    }
}

static void save_joints(sx_h5 *h, hid_t f, const sx_model *m)
{
    const int64_t n = sx_joint_count(m);
    if (n == 0) return;
    sx_joint_def *defs = calloc((size_t)n, sizeof *defs);
    double *cols = calloc((size_t)(n * JOINT_COLS), sizeof *cols);
    if (!defs || !cols) sx_h5_fail(h, "out of memory");
    else {
        for (int64_t i = 0; i < n; i++) sx_joint_get(m, i, &defs[i]);
        joint_columns(defs, cols, n, true);
        hid_t g = sx_h5_group(h, f, "joints");
        sx_h5_attr_int(h, g, "count", n);
        field fl[MAX_FIELDS];
        write_fields(h, g, fl, joint_fields(fl, cols, n), n);
        sx_h5_close(g);
    }
    free(defs);
    free(cols);
}

static void load_joints(sx_h5 *h, hid_t f, sx_model *m, int64_t n)
{
    if (n == 0) return;
    sx_joint_def *defs = calloc((size_t)n, sizeof *defs);
    double *cols = calloc((size_t)(n * JOINT_COLS), sizeof *cols);
    if (!defs || !cols) sx_h5_fail(h, "out of memory");
    else {
        field fl[MAX_FIELDS];
        load_group(h, f, "/joints", fl, joint_fields(fl, cols, n), n);
        joint_columns(defs, cols, n, false);
        if (!h->failed && sx__joints_restore(m, defs, n)) sx_h5_fail(h, "damaged: %s", sx_model_error(m));
    }
    free(defs);
    free(cols);
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
    save_materials(h, f, m);
    save_cmodels(h, f, m);

    field fl[MAX_FIELDS];
    g = sx_h5_group(h, f, "balls");
    sx_h5_attr_int(h, g, "count", m->balls.n);
    sx_h5_attr_int(h, g, "next_id", m->balls.next_id < 1 ? 1 : m->balls.next_id);
    ball_cols bc;
    if (!ball_cols_for_save(m, &bc)) sx_h5_fail(h, "out of memory");
    else write_fields(h, g, fl, ball_fields(m, &bc, fl), m->balls.n);
    free(bc.owned);
    sx_h5_close(g);

    g = sx_h5_group(h, f, "contacts");
    hid_t p = sx_h5_group(h, g, "ball_ball");
    sx_h5_attr_int(h, p, "count", m->bb.n);
    write_fields(h, p, fl, pair_fields(m, &m->bb, fl, NULL), m->bb.n);
    sx_h5_close(p);
    p = sx_h5_group(h, g, "ball_wall");
    sx_h5_attr_int(h, p, "count", m->bw.n);
    write_fields(h, p, fl, pair_fields(m, &m->bw, fl, NULL), m->bw.n);
    sx_h5_close(p);
    sx_h5_close(g);

    g = sx_h5_group(h, f, "bonds");
    sx_h5_attr_int(h, g, "count", m->bonds.n);
    sx_h5_attr_int(h, g, "intact", m->bonds.intact);
    write_fields(h, g, fl, bond_fields(m, fl), m->bonds.n);
    sx_h5_close(g);

    if (m->fjel.n > 0) {
        g = sx_h5_group(h, f, "flatjoints");
        write_fields(h, g, fl, flatjoint_fields(m, fl), m->bonds.n);
        hid_t e = sx_h5_group(h, g, "elements");
        sx_h5_attr_int(h, e, "count", m->fjel.n);
        write_fields(h, e, fl, fj_element_fields(m, fl), m->fjel.n);
        sx_h5_close(e);
        sx_h5_close(g);
    }

    g = sx_h5_group(h, f, "cracks");
    sx_h5_attr_int(h, g, "count", m->cracks.n);
    crack_io(h, g, m, true);
    sx_h5_close(g);

    save_walls(h, f, m);
    save_clumps(h, f, m);
    save_periodic(h, f, m);
    save_joints(h, f, m);
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
    } else if (!sx_h5_temp_name(path, tmp, sizeof tmp)) {
        sx_h5_fail(&h, "the path is too long");
    } else {
        hid_t fapl = sx_h5_fapl(true);
        hid_t fcpl = sx_h5_fcpl();
        hid_t f = fapl >= 0 && fcpl >= 0 ? H5Fcreate(tmp, H5F_ACC_EXCL, fcpl, fapl) : -1;
        if (f < 0) sx_h5_fail_h5(&h, "cannot create a file in its folder");
        sx_h5_close(fapl);
        sx_h5_close(fcpl);
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

/* Reads one group's fields. */
static void load_group(sx_h5 *h, hid_t f, const char *path, const field *fl, int nf, int64_t rows)
{
    hid_t g = sx_h5_open_group(h, f, path, true);
    if (g >= 0) read_fields(h, g, path, fl, nf, rows, true);
    sx_h5_close(g);
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
    if (f >= 0 && read_sizes(&h, f, d, &s) && read_clump_sizes(&h, f, &cs)) {
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
        if (g >= 0) load_materials(&h, g, m);
        sx_h5_close(g);
        load_cmodels(&h, f, m);
        load_periodic(&h, f, m); /* before the balls: the ghosts' slots come with the ball arrays */
        load_joints(&h, f, m, s.joints);

        field fl[MAX_FIELDS];
        const ball_cols bc = {m->balls.alpha, m->balls.group, NULL};
        load_group(&h, f, "/balls", fl, ball_fields(m, &bc, fl), m->balls.n);
        double *overlap = NULL; /* formats 1 and 2 store a ball-ball pair's normal and overlap */
        if (version < 3 && !(overlap = calloc((size_t)(m->bb.n > 0 ? m->bb.n : 1), sizeof *overlap)))
            sx_h5_fail(&h, "out of memory");
        load_group(&h, f, "/contacts/ball_ball", fl, pair_fields(m, &m->bb, fl, overlap), m->bb.n);
        if (overlap && !h.failed) relative_from_normal(m, overlap);
        free(overlap);
        load_group(&h, f, "/contacts/ball_wall", fl, pair_fields(m, &m->bw, fl, NULL), m->bw.n);
        load_group(&h, f, "/bonds", fl, bond_fields(m, fl), m->bonds.n);
        if (m->fjel.n > 0) {
            load_group(&h, f, "/flatjoints", fl, flatjoint_fields(m, fl), m->bonds.n);
            load_group(&h, f, "/flatjoints/elements", fl, fj_element_fields(m, fl), m->fjel.n);
        }
        g = sx_h5_open_group(&h, f, "/cracks", true);
        if (g >= 0) crack_io(&h, g, m, false);
        sx_h5_close(g);
        g = sx_h5_open_group(&h, f, "/walls", true);
        if (g >= 0) load_walls(&h, g, m, version);
        sx_h5_close(g);
        load_clumps(&h, f, m);
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
