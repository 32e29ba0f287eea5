/* A snapshot's materials (/materials) and contact-model table
 * (/contact_models): each material's numbers from the law and bond
 * registries, so a law added later reads older files with its defaults. */
#include "snapshot_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

void sx_io_save_materials(sx_h5 *h, hid_t f, sx_model *m)
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

void sx_io_load_materials(sx_h5 *h, hid_t g, sx_model *m) { read_mats(h, g, "/materials", m->mats, sizeof *m->mats, m->nmat); }

/* The contact-model table (cmodel.c), when it has rows: each row's law as
 * a material (its name, model and numbers, as /materials), and its match
 * (0 default, 1 groups, 2 materials) with the two group numbers or
 * material indices. */
void sx_io_save_cmodels(sx_h5 *h, hid_t f, sx_model *m)
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

void sx_io_load_cmodels(sx_h5 *h, hid_t f, sx_model *m)
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
