/* Small helpers shared by the verification programs (header-only so that
 * each program stays a single translation unit). */
#pragma once

#include "scenes.h"

#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define V_PI 3.14159265358979323846

static inline double v_dot(const double *a, const double *b, int d)
{
    double s = 0;
    for (int k = 0; k < d; k++) s += a[k] * b[k];
    return s;
}

static inline double v_norm(const double *a, int d) { return sqrt(v_dot(a, a, d)); }

static inline void v_unit(double *a, int d)
{
    const double n = v_norm(a, d);
    for (int k = 0; k < d; k++) a[k] /= n;
}

/* Hot loops check with V_CHECK instead of ck_assert: in fork mode Check
 * records the location of every passing assertion through a system call,
 * which would dominate the run time of a test stepping 10^5 times. */
#define V_CHECK(cond, ...)                                                                                             \
    do {                                                                                                               \
        if (!(cond)) ck_abort_msg(__VA_ARGS__);                                                                        \
    } while (0)

/* A model of dimension dim under gravity g along -axis dim, with the
 * damped material "ball" (density rho, normal and shear stiffness kb,
 * friction mu) whose index goes to *mat: the start of the ball-on-a-wall
 * scenes. */
static inline sx_model *v_ball_model(int dim, double g, double rho, double kb, double mu, int *mat)
{
    sx_model_def def = sx_model_default_def();
    def.dim = dim;
    for (int k = 0; k < 3; k++) def.gravity[k] = k == dim - 1 ? -g : 0;
    char err[256];
    sx_model *m = sx_model_create(&def, err, sizeof err);
    ck_assert_msg(m != NULL, "%s", err);
    sx_material_def md = sx_material_default_def();
    md.density = rho, md.kn = md.ks = kb, md.friction = mu;
    md.viscous_normal = 0.3, md.viscous_shear = 0.3;
    *mat = scene_material_def(m, "ball", &md);
    return m;
}

/* A ball vector field (asserts success). */
static inline void v_get(const sx_model *m, int64_t id, sx_ball_vec which, double out[3])
{
    V_CHECK(sx_ball_get_vec(m, id, which, out) == SX_OK, "%s", sx_model_error(m));
}

static inline double v_scalar(const sx_model *m, int64_t id, sx_ball_scalar which)
{
    double x = 0;
    V_CHECK(sx_ball_get(m, id, which, &x) == SX_OK, "%s", sx_model_error(m));
    return x;
}

/* n steps; the test fails with the model's message if they fail. */
static inline void v_step(sx_model *m, int64_t n)
{
    const sx_status st = sx_model_cycle(m, n);
    V_CHECK(st == SX_OK, "cycle failed (%d): %s", (int)st, sx_model_error(m));
}

/* Runs a suite (forking, so one failing test does not hide the others) and
 * returns the process exit status. */
static inline int v_run(Suite *s)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    return scene_run_suite(s);
}

/* Adds the test function fn to a new test case of suite s named after it. */
#define V_TCASE(s, fn)                                                                                                 \
    do {                                                                                                               \
        TCase *tc_ = tcase_create(#fn);                                                                                \
        tcase_set_timeout(tc_, 600);                                                                                   \
        tcase_add_test(tc_, fn);                                                                                       \
        suite_add_tcase((s), tc_);                                                                                     \
    } while (0)
