/* Helpers shared by the bonded-particle (bpm) verification tests. */
#pragma once

#include "scenes.h"

#include <check.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define BPM_PI 3.14159265358979323846

/* A model of the given dimension, no gravity, automatic timestep (dt 0) or dt. */
static inline sx_model *bpm_model(int dim, double dt)
{
    sx_model_def d = sx_model_default_def();
    d.dim = dim;
    d.timestep = dt;
    char err[256];
    sx_model *m = sx_model_create(&d, err, sizeof err);
    ck_assert_msg(m != NULL, "%s", err);
    return m;
}

static inline int bpm_material(sx_model *m, const char *name, const sx_material_def *md)
{
    int idx = -1;
    ck_assert_msg(sx_material_set(m, name, md, &idx) == SX_OK, "%s", sx_model_error(m));
    return idx;
}

static inline void bpm_cycle(sx_model *m, int64_t n)
{
    const sx_status st = sx_model_cycle(m, n);
    ck_assert_msg(st == SX_OK, "cycle failed (%d): %s", (int)st, sx_model_error(m));
}

static inline void bpm_vec(const sx_model *m, int64_t id, sx_ball_vec which, double out[3])
{
    ck_assert_msg(sx_ball_get_vec(m, id, which, out) == SX_OK, "%s", sx_model_error(m));
}

static inline double bpm_rel(double got, double want) { return fabs(got - want) / fabs(want); }

/* Prints and returns the relative error of a measured quantity. */
static inline double bpm_report(const char *what, double got, double want)
{
    const double e = bpm_rel(got, want);
    printf("  %-52s measured %-14.8g expected %-14.8g rel.err %.3e\n", what, got, want, e);
    fflush(stdout);
    return e;
}

/* Asserts a relative error below tol, after reporting it. */
#define BPM_CHECK(what, got, want, tol)                                                                  \
    do {                                                                                                 \
        const double got_ = (got), want_ = (want);                                                      \
        const double e_ = bpm_report(what, got_, want_);                                                \
        ck_assert_msg(e_ <= (tol), "%s: measured %.10g, expected %.10g, relative error %.3e > %.1e", \
                      what, got_, want_, e_, (double)(tol));                                            \
    } while (0)

typedef struct bpm_find {
    int64_t a, b;
    bool found;
    sx_contact_info ci;
} bpm_find;

static inline bool bpm_find_fn(const sx_contact_info *ci, void *ud)
{
    bpm_find *f = ud;
    if (!ci->is_wall && ((ci->a == f->a && ci->b == f->b) || (ci->a == f->b && ci->b == f->a))) {
        f->ci = *ci;
        f->found = true;
        return false;
    }
    return true;
}

/* The contact between balls a and b, re-expressed for the a -> b orientation.
 * Returns false when the pair is not touching nor bonded. */
static inline bool bpm_contact(const sx_model *m, int64_t a, int64_t b, sx_contact_info *out)
{
    bpm_find f = {.a = a, .b = b};
    sx_contact_each(m, bpm_find_fn, &f);
    if (!f.found) return false;
    *out = f.ci;
    if (f.ci.a != a) { /* stored the other way round: vectors on b become those on a */
        out->a = a, out->b = b;
        for (int k = 0; k < 3; k++) {
            out->normal[k] = -f.ci.normal[k];
            out->shear[k] = -f.ci.shear[k];
            out->pb_fs[k] = -f.ci.pb_fs[k];
        }
        /* the bond moment on b is -(the moment on a) (4-39) */
        for (int k = 0; k < 3; k++) out->pb_moment[k] = -f.ci.pb_moment[k];
    }
    return true;
}
