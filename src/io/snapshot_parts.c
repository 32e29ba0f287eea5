/* A snapshot's parts that not every model has a use for: the crack log
 * (/cracks), clumps (/clumps), the periodic cell (/periodic) and smooth
 * joints (/joints). */
#include "snapshot_internal.h"

#include "joints.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* -------------------------------------------------------------- cracks */

/* A column of a part kept as an array of structs (the crack log, the clump
 * templates): gathered into (or scattered from) arrays of its own, read or
 * written with its memory and file types. */
typedef struct column {
    const char *name;
    hid_t mem, file;
    void *data;
    int per;
    const char *units;
} column;

/* Reads (write = false) or writes nc columns of `rows` rows each (`where`:
 * the group's path in messages). */
static void columns_io(sx_h5 *h, hid_t g, const char *where, const column *c, size_t nc, int64_t rows, bool write)
{
    for (size_t k = 0; k < nc; k++) {
        if (write) sx_h5_write(h, g, c[k].name, c[k].mem, c[k].file, c[k].data, rows, c[k].per, c[k].units);
        else sx_h5_read(h, g, where, c[k].name, c[k].mem, c[k].data, rows, c[k].per, true);
    }
}

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
void sx_io_cracks(sx_h5 *h, hid_t g, sx_model *m, bool write)
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
    const column cols[] = {
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
    columns_io(h, g, "/cracks", cols, ncols, n, write);
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

/* The clump store (core clumps.h) in its own group /clumps, written only
 * when the model has one: the templates (/clumps/templates, with their
 * pebbles in /clumps/template_pebbles), every per-clump array, and the
 * clumps' pebbles as ball ids (/clumps/pebbles; clump c owns the rows
 * first_pebble[c] .. first_pebble[c] + its template's count). The balls'
 * clump ids are derived from it on load (clump_store.c). */

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
    const column cols[] = {
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
    columns_io(h, g, "/clumps/templates", cols, sizeof cols / sizeof *cols, n, write);
    if (!write && !h->failed)
        for (int64_t i = 0; i < n; i++) tpl_copy(&C->tpl[i], &c, i, false);
    tpl_cols_free(&c);
}

void sx_io_save_clumps(sx_h5 *h, hid_t f, sx_model *m)
{
    sx_clumps *C = m->clumps;
    if (!C) return;
    field fl[MAX_FIELDS];
    hid_t g = sx_h5_group(h, f, "clumps");
    sx_h5_attr_int(h, g, "count", C->n);
    sx_h5_attr_int(h, g, "next_id", C->next_id);
    sx_io_write_fields(h, g, fl, clump_fields(m, fl), C->n);
    sx_h5_write(h, g, "pebbles", H5T_NATIVE_INT32, H5T_STD_I32LE, C->pebble, C->pn, 1, NULL);
    hid_t t = sx_h5_group(h, g, "templates");
    templates_io(h, t, m, true);
    sx_h5_close(t);
    t = sx_h5_group(h, g, "template_pebbles");
    sx_io_write_fields(h, t, fl, template_pebble_fields(m, fl), C->tp_n);
    sx_h5_close(t);
    sx_h5_close(g);
}

/* The clump store's sizes; all zero when the file has no /clumps. */
bool sx_io_read_clump_sizes(sx_h5 *h, hid_t f, sx_clump_sizes *s)
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

void sx_io_load_clumps(sx_h5 *h, hid_t f, sx_model *m)
{
    sx_clumps *C = m->clumps;
    if (!C) return;
    field fl[MAX_FIELDS];
    sx_io_load_group(h, f, "/clumps", fl, clump_fields(m, fl), C->n);
    hid_t g = sx_h5_open_group(h, f, "/clumps", true);
    if (g >= 0) sx_h5_read(h, g, "/clumps", "pebbles", H5T_NATIVE_INT32, C->pebble, C->pn, 1, true);
    sx_h5_close(g);
    g = sx_h5_open_group(h, f, "/clumps/templates", true);
    if (g >= 0) templates_io(h, g, m, false);
    sx_h5_close(g);
    sx_io_load_group(h, f, "/clumps/template_pebbles", fl, template_pebble_fields(m, fl), C->tp_n);
}

/* ------------------------------------------------------ periodic space */

/* The periodic cell (core model_internal.h, sx_cell) in its own group
 * /periodic, written only when the space is periodic: the cell and its
 * control as attributes, the ghosts' table as datasets (ghost g is ball
 * slot count + g, a pair's b past the balls); the ghosts' own state is
 * derived from their owners on load (sx__cell_finish). */
void sx_io_save_periodic(sx_h5 *h, hid_t f, const sx_model *m)
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

void sx_io_load_periodic(sx_h5 *h, hid_t f, sx_model *m)
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
 * joint_overlap). The last column, radius, came with format 4: a file
 * without it has joints of radius 0 (whole planes). */
enum { JOINT_COLS = 15 };

static int joint_fields(field *f, double *cols, int64_t n)
{
    int k = 0;
    f[k++] = F("point", T_F64, cols, 3, "m");
    f[k++] = F("normal", T_F64, cols + 3 * n, 3, "1");
    static const char *const names[] = {"kn", "ks", "friction", "dilation", "tension", "cohesion", "friction_angle",
                                        "radius_multiplier", "radius"};
    static const char *const units[] = {"Pa/m", "Pa/m", "1", "degree", "Pa", "Pa", "degree", "1", "m"};
    for (int q = 0; q < 9; q++) f[k++] = F(names[q], T_F64, cols + (6 + q) * n, 1, units[q]);
    return k;
}

/* Between the definitions and the columns (to_cols: defs to cols). */
static void joint_columns(sx_joint_def *defs, double *cols, int64_t n, bool to_cols)
{
    for (int64_t i = 0; i < n; i++) {
        sx_joint_def *d = &defs[i];
        double *v[JOINT_COLS] = {&d->point[0], &d->point[1], &d->point[2], &d->normal[0], &d->normal[1],
                                 &d->normal[2], &d->kn, &d->ks, &d->friction, &d->dilation, &d->tension,
                                 &d->cohesion, &d->friction_angle, &d->radius_multiplier, &d->radius};
        for (int q = 0; q < JOINT_COLS; q++) {
            double *c = q < 6 ? cols + (q / 3) * 3 * n + i * 3 + q % 3 : cols + (int64_t)q * n + i;
            if (to_cols) *c = *v[q];
            else *v[q] = *c;
        }
    }
}

void sx_io_save_joints(sx_h5 *h, hid_t f, const sx_model *m)
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
        sx_io_write_fields(h, g, fl, joint_fields(fl, cols, n), n);
        sx_h5_close(g);
    }
    free(defs);
    free(cols);
}

void sx_io_load_joints(sx_h5 *h, hid_t f, sx_model *m, int64_t n)
{
    if (n == 0) return;
    sx_joint_def *defs = calloc((size_t)n, sizeof *defs);
    double *cols = calloc((size_t)(n * JOINT_COLS), sizeof *cols);
    if (!defs || !cols) sx_h5_fail(h, "out of memory");
    else {
        field fl[MAX_FIELDS];
        const int nf = joint_fields(fl, cols, n);
        hid_t g = sx_h5_open_group(h, f, "/joints", true);
        if (g >= 0 && sx_io_read_fields(h, g, "/joints", fl, nf - 1, n, true))
            sx_io_read_fields(h, g, "/joints", fl + nf - 1, 1, n, false); /* radius: format 4 on */
        sx_h5_close(g);
        joint_columns(defs, cols, n, false);
        if (!h->failed && sx__joints_restore(m, defs, n)) sx_h5_fail(h, "damaged: %s", sx_model_error(m));
    }
    free(defs);
    free(cols);
}
