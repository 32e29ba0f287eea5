/* Helpers shared by the laboratory (servo, cylinder, measurement) tests.
 * Header-only so that each test program stays one translation unit. */
#pragma once

#include "scenes.h"

#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LAB_PI 3.14159265358979323846

/* Hot loops check with LAB_REQUIRE instead of ck_assert: in fork mode Check
 * records the location of every passing assertion through a system call. */
#define LAB_REQUIRE(cond, ...)                                                                                         \
    do {                                                                                                               \
        if (!(cond)) ck_abort_msg(__VA_ARGS__);                                                                        \
    } while (0)

/* The call returns SX_OK, or the test fails with the model's message. */
#define LAB_OK(m, call)                                                                                                \
    do {                                                                                                               \
        const sx_status st_ = (call);                                                                                  \
        LAB_REQUIRE(st_ == SX_OK, "%s failed (%d): %s", #call, (int)st_, sx_model_error(m));                         \
    } while (0)

/* The call fails with SX_EINVAL and a message that mentions `needle`. */
#define LAB_EINVAL(m, call, needle)                                                                                    \
    do {                                                                                                               \
        const sx_status st_ = (call);                                                                                  \
        ck_assert_msg(st_ == SX_EINVAL, "%s returned %d, expected SX_EINVAL", #call, (int)st_);                       \
        ck_assert_msg(strstr(sx_model_error(m), (needle)) != NULL, "%s: message '%s' does not mention '%s'", #call,  \
                      sx_model_error(m), (needle));                                                                   \
    } while (0)

static inline void lab_cycle(sx_model *m, int64_t n) { LAB_OK(m, sx_model_cycle(m, n)); }

static inline double lab_rel(double got, double want) { return fabs(got - want) / fabs(want); }

/* Prints a measured quantity beside its closed form, with the relative error. */
static inline double lab_report(const char *what, double got, double want)
{
    const double e = lab_rel(got, want);
    printf("  %-58s measured %-15.9g expected %-15.9g rel.err %.3e\n", what, got, want, e);
    fflush(stdout);
    return e;
}

/* Asserts a relative error within tol, after reporting it. */
#define LAB_CHECK(what, got, want, tol)                                                                                \
    do {                                                                                                               \
        const double got_ = (got), want_ = (want);                                                                     \
        const double e_ = lab_report(what, got_, want_);                                                               \
        ck_assert_msg(e_ <= (tol), "%s: measured %.12g, expected %.12g, relative error %.3e > %.1e", what, got_,     \
                      want_, e_, (double)(tol));                                                                       \
    } while (0)

/* |a - b| <= tol, with the expressions in the message. */
#define LAB_NEAR(a, b, tol)                                                                                            \
    do {                                                                                                               \
        const double a_ = (a), b_ = (b);                                                                               \
        ck_assert_msg(fabs(a_ - b_) <= (tol), "%s = %.17g, expected %s = %.17g (|diff| %.3g > %.3g)", #a, a_, #b, b_, \
                      fabs(a_ - b_), (double)(tol));                                                                   \
    } while (0)

static inline sx_model *lab_model(int dim, double dt)
{
    sx_model_def d = sx_model_default_def();
    d.dim = dim;
    d.timestep = dt;
    char err[256];
    sx_model *m = sx_model_create(&d, err, sizeof err);
    ck_assert_msg(m != NULL, "%s", err);
    return m;
}

/* A linear material: kn = ks = k, friction mu, local damping alpha. */
static inline int lab_material(sx_model *m, double k, double mu, double alpha)
{
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = k;
    md.friction = mu;
    md.damping = alpha;
    return scene_material_def(m, "lab", &md);
}

/* A one-sided wall (3D plane, 2D line) through `point` facing the balls along `normal`. */
static inline int64_t lab_plane(sx_model *m, const double *point, const double *normal, double k, double mu)
{
    return scene_halfspace(m, point, normal, k, k, mu);
}

/* The six (2D: four) walls of the box [lo, hi], normals inwards; ids[2 axis + side],
 * side 0 at lo, side 1 at hi. */
static inline void lab_box(sx_model *m, const double *lo, const double *hi, double k, double mu, int64_t *ids)
{
    const int dim = sx_model_dim(m);
    for (int axis = 0; axis < dim; axis++)
        for (int side = 0; side < 2; side++) {
            double p[3] = {0, 0, 0}, n[3] = {0, 0, 0};
            p[axis] = side ? hi[axis] : lo[axis];
            n[axis] = side ? -1.0 : 1.0;
            ids[2 * axis + side] = lab_plane(m, p, n, k, mu);
        }
}

static inline sx_wall_def lab_wall(const sx_model *m, int64_t id)
{
    sx_wall_def w;
    LAB_OK((sx_model *)m, sx_wall_get(m, id, &w));
    return w;
}

/* The normal load (sum of the normal contact forces) on a wall and its contact count. */
static inline double lab_load(const sx_model *m, int64_t id, int64_t *contacts, double *kn)
{
    double f = 0;
    LAB_OK((sx_model *)m, sx_wall_load(m, id, &f, contacts, kn));
    return f;
}

static inline void lab_servo(sx_model *m, int64_t id, double target, double area, double alpha, double vmax)
{
    sx_servo_def s = sx_servo_default_def();
    s.target = target;
    s.area = area;
    s.alpha = alpha;
    s.max_speed = vmax;
    LAB_OK(m, sx_wall_set_servo(m, id, &s));
}

/* The largest |F| over the balls (the unbalanced force; free balls only matter). */
static inline double lab_max_unbalanced(const sx_model *m)
{
    const int dim = sx_model_dim(m);
    double worst = 0;
    for (int64_t i = 0; i < sx_ball_count(m); i++) {
        double f[3];
        LAB_OK((sx_model *)m, sx_ball_get_vec(m, sx_ball_id_at(m, i), SX_BALL_FORCE, f));
        double s = 0;
        for (int k = 0; k < dim; k++) s += f[k] * f[k];
        if (sqrt(s) > worst) worst = sqrt(s);
    }
    return worst;
}

/* The mean normal force of the ball-ball contacts (the scale of the unbalanced force). */
static inline bool lab_fn_sum(const sx_contact_info *ci, void *ud)
{
    double *acc = ud;
    if (!ci->is_wall) acc[0] += fabs(ci->fn), acc[1] += 1;
    return true;
}

static inline double lab_mean_contact_force(const sx_model *m)
{
    double acc[2] = {0, 0};
    sx_contact_each(m, lab_fn_sum, acc);
    return acc[1] > 0 ? acc[0] / acc[1] : 0;
}

static inline int lab_run(Suite *s)
{
    return scene_run_suite(s);
}
