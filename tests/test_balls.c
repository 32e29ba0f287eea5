/* The ball store: stable ids, fields, mass and inertia, fixities, the
 * leapfrog response to an applied load, and the errors a user can cause.
 * Every case runs in 2D and 3D (the loop index is the dimension). */
#include "scenes.h"

#include <check.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* |a - b| <= rel |b| (rel a few ulps for rounding-only differences) */
#define ck_assert_rel(a, b, rel)                                                                         \
    do {                                                                                                 \
        const double a_ = (a), b_ = (b);                                                                 \
        ck_assert_msg(fabs(a_ - b_) <= (rel) * fabs(b_), "%s = %.17g, expected %.17g (rel. error %.3g > %g)", \
                      #a, a_, b_, fabs(a_ - b_) / fabs(b_), (double)(rel));                              \
    } while (0)

#define ck_assert_msg_has(m, needle)                                                          \
    ck_assert_msg(strstr(sx_model_error(m), (needle)) != NULL, "message '%s' does not mention '%s'", \
                  sx_model_error(m), (needle))

static const double ZERO[3] = {0, 0, 0};

static int rdim(int dim) { return dim == 3 ? 3 : 1; }

/* ids are 1, 2, 3, ...; a removed id is never handed out again */
START_TEST(ids_stable_never_reused)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, 1000);
    int64_t id[5];
    for (int i = 0; i < 5; i++) {
        const double p[3] = {10.0 * i, 0, 0};
        id[i] = scene_ball(m, p, NULL, 1.0);
        ck_assert_int_eq(id[i], i + 1);
    }
    ck_assert_int_eq(sx_ball_count(m), 5);
    ck_assert_int_eq(sx_ball_remove(m, 3), SX_OK);
    ck_assert(!sx_ball_exists(m, 3));
    ck_assert_int_eq(sx_ball_count(m), 4);
    ck_assert_int_eq(sx_ball_remove(m, 3), SX_ENOTFOUND);
    const double p[3] = {100, 0, 0};
    ck_assert_int_eq(scene_ball(m, p, NULL, 1.0), 6);
    ck_assert_int_eq(sx_ball_remove(m, 6), SX_OK);
    ck_assert_int_eq(scene_ball(m, p, NULL, 1.0), 7);
    for (int64_t bad = -2; bad <= 0; bad++) ck_assert(!sx_ball_exists(m, bad));
    ck_assert(!sx_ball_exists(m, 8));
    ck_assert(!sx_ball_exists(m, 1000000));
    /* a cycle re-sorts the dense order; the ids stay the same set */
    ck_assert_int_eq(sx_model_cycle(m, 3), SX_OK);
    const int64_t expect[] = {1, 2, 4, 5, 7};
    bool seen[8] = {false};
    ck_assert_int_eq(sx_ball_count(m), 5);
    for (int64_t i = 0; i < sx_ball_count(m); i++) {
        const int64_t b = sx_ball_id_at(m, i);
        ck_assert(b >= 1 && b <= 7);
        ck_assert_msg(!seen[b], "id %lld listed twice", (long long)b);
        seen[b] = true;
        ck_assert(sx_ball_exists(m, b));
    }
    for (int k = 0; k < 5; k++) ck_assert(seen[expect[k]]);
    ck_assert_int_eq(sx_ball_id_at(m, -1), -1);
    ck_assert_int_eq(sx_ball_id_at(m, 5), -1);
    sx_model_destroy(m);
}
END_TEST

START_TEST(fields_get_set)
{
    const int dim = _i, r = rdim(dim);
    sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, 1000);
    const int64_t id = scene_ball(m, ZERO, NULL, 0.5);
    const double pos[3] = {1.25, -2.5, 3.75}, vel[3] = {-0.1, 0.2, -0.3}, spin[3] = {4, -5, 6};
    const double fa[3] = {7, -8, 9}, ma[3] = {-0.7, 0.8, -0.9};
    const sx_ball_vec which[5] = {SX_BALL_POS, SX_BALL_VEL, SX_BALL_SPIN, SX_BALL_APPLIED_FORCE, SX_BALL_APPLIED_MOMENT};
    const double *vals[5] = {pos, vel, spin, fa, ma};
    for (int f = 0; f < 5; f++) {
        double out[3] = {NAN, NAN, NAN};
        /* applied loads read as zero before any is set */
        if (which[f] == SX_BALL_APPLIED_FORCE || which[f] == SX_BALL_APPLIED_MOMENT) {
            ck_assert_int_eq(sx_ball_get_vec(m, id, which[f], out), SX_OK);
            for (int k = 0; k < 3; k++) ck_assert_double_eq(out[k], 0);
        }
        ck_assert_int_eq(sx_ball_set_vec(m, id, which[f], vals[f]), SX_OK);
        ck_assert_int_eq(sx_ball_get_vec(m, id, which[f], out), SX_OK);
        const int n = (which[f] == SX_BALL_SPIN || which[f] == SX_BALL_APPLIED_MOMENT) ? r : dim;
        for (int k = 0; k < 3; k++) ck_assert_double_eq(out[k], k < n ? vals[f][k] : 0.0);
    }
    /* results of the step are not settable */
    ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_FORCE, fa), SX_EINVAL);
    ck_assert_msg_has(m, "applied");
    ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_MOMENT, ma), SX_EINVAL);
    ck_assert_msg_has(m, "applied");
    /* non-finite components are refused and leave the field alone */
    const double bad[3] = {1, NAN, 1};
    ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_VEL, bad), SX_EINVAL);
    ck_assert_msg_has(m, "finite");
    double out[3];
    sx_ball_get_vec(m, id, SX_BALL_VEL, out);
    for (int k = 0; k < dim; k++) ck_assert_double_eq(out[k], vel[k]);
    /* an isolated ball's force after a step is exactly the applied force */
    ck_assert_int_eq(sx_model_cycle(m, 1), SX_OK);
    sx_ball_get_vec(m, id, SX_BALL_FORCE, out);
    for (int k = 0; k < 3; k++) ck_assert_double_eq(out[k], k < dim ? fa[k] : 0.0);
    sx_ball_get_vec(m, id, SX_BALL_MOMENT, out);
    for (int k = 0; k < 3; k++) ck_assert_double_eq(out[k], k < r ? ma[k] : 0.0);
    /* scalar damping is settable within [0, 1) */
    double a;
    ck_assert_int_eq(sx_ball_set(m, id, SX_BALL_DAMPING, 0.7), SX_OK);
    ck_assert_int_eq(sx_ball_get(m, id, SX_BALL_DAMPING, &a), SX_OK);
    ck_assert_double_eq(a, 0.7);
    ck_assert_int_eq(sx_ball_set(m, id, SX_BALL_DAMPING, 1.0), SX_EINVAL);
    ck_assert_msg_has(m, "damping");
    ck_assert_int_eq(sx_ball_set(m, id, SX_BALL_DAMPING, -0.1), SX_EINVAL);
    sx_model_destroy(m);
}
END_TEST

/* 4-43: sphere m = 4/3 rho pi R^3, I = 2/5 m R^2; disk of unit thickness m = rho pi R^2, I = 1/2 m R^2 */
static void expected_mass(int dim, double rho, double r, double *mass, double *inertia)
{
    if (dim == 3) {
        *mass = 4.0 / 3.0 * PI * rho * r * r * r;
        *inertia = 2.0 / 5.0 * *mass * r * r;
    } else {
        *mass = rho * PI * r * r;
        *inertia = 0.5 * *mass * r * r;
    }
}

static void check_mass(sx_model *m, int64_t id, double rho)
{
    double r, mass, inertia, em, ei;
    ck_assert_int_eq(sx_ball_get(m, id, SX_BALL_RADIUS, &r), SX_OK);
    ck_assert_int_eq(sx_ball_get(m, id, SX_BALL_MASS, &mass), SX_OK);
    ck_assert_int_eq(sx_ball_get(m, id, SX_BALL_INERTIA, &inertia), SX_OK);
    expected_mass(sx_model_dim(m), rho, r, &em, &ei);
    ck_assert_rel(mass, em, 1e-15);
    ck_assert_rel(inertia, ei, 1e-15);
}

START_TEST(mass_inertia_formulas)
{
    const int dim = _i;
    const double rhos[] = {1.0, 2650.0, 7850.5};
    const double radii[] = {1e-4, 0.0123, 1.0, 3.7};
    for (int a = 0; a < 3; a++) {
        sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, rhos[a]);
        for (int b = 0; b < 4; b++) {
            const double p[3] = {10.0 * b, 0, 0};
            check_mass(m, scene_ball(m, p, NULL, radii[b]), rhos[a]);
        }
        sx_model_destroy(m);
    }
}
END_TEST

START_TEST(radius_and_material_change_mass)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, 2000);
    const int64_t id = scene_ball(m, ZERO, NULL, 0.1);
    double m0, m1;
    sx_ball_get(m, id, SX_BALL_MASS, &m0);
    ck_assert_int_eq(sx_ball_set(m, id, SX_BALL_RADIUS, 0.2), SX_OK);
    check_mass(m, id, 2000);
    sx_ball_get(m, id, SX_BALL_MASS, &m1);
    ck_assert_rel(m1 / m0, dim == 3 ? 8.0 : 4.0, 1e-14);
    /* a refused radius leaves the ball as it was */
    const double badr[] = {0.0, -0.1, NAN, INFINITY};
    for (int k = 0; k < 4; k++) {
        ck_assert_int_eq(sx_ball_set(m, id, SX_BALL_RADIUS, badr[k]), SX_EINVAL);
        ck_assert_msg_has(m, "radius");
    }
    double r;
    sx_ball_get(m, id, SX_BALL_RADIUS, &r);
    ck_assert_double_eq(r, 0.2);
    check_mass(m, id, 2000);
    /* mass and inertia are derived, not set */
    ck_assert_int_eq(sx_ball_set(m, id, SX_BALL_MASS, 1.0), SX_EINVAL);
    ck_assert_int_eq(sx_ball_set(m, id, SX_BALL_INERTIA, 1.0), SX_EINVAL);
    /* another material: its density and damping */
    sx_material_def md = sx_material_default_def();
    md.density = 500;
    md.damping = 0.3;
    int heavy;
    ck_assert_int_eq(sx_material_set(m, "light", &md, &heavy), SX_OK);
    ck_assert_int_eq(sx_ball_set_material(m, id, heavy), SX_OK);
    int got;
    ck_assert_int_eq(sx_ball_material(m, id, &got), SX_OK);
    ck_assert_int_eq(got, heavy);
    check_mass(m, id, 500);
    double a;
    sx_ball_get(m, id, SX_BALL_DAMPING, &a);
    ck_assert_double_eq(a, 0.3);
    /* redefining the material recomputes the balls that use it, and only them */
    const double far[3] = {5, 5, 5};
    const int64_t other = scene_ball(m, far, NULL, 0.1);
    md.density = 1500;
    md.damping = 0.6;
    ck_assert_int_eq(sx_material_set(m, "light", &md, NULL), SX_OK);
    check_mass(m, id, 1500);
    sx_ball_get(m, id, SX_BALL_DAMPING, &a);
    ck_assert_double_eq(a, 0.6);
    check_mass(m, other, 2000);
    /* unknown material */
    ck_assert_int_eq(sx_ball_set_material(m, id, 7), SX_ENOTFOUND);
    ck_assert_msg_has(m, "material");
    ck_assert_int_eq(sx_ball_set_material(m, id, -1), SX_ENOTFOUND);
    check_mass(m, id, 1500);
    sx_model_destroy(m);
}
END_TEST

START_TEST(fixity_masks)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, 1000);
    const int64_t id = scene_ball(m, ZERO, NULL, 1.0);
    unsigned mask = 99;
    ck_assert_int_eq(sx_ball_fixity(m, id, &mask), SX_OK);
    ck_assert_uint_eq(mask, 0);
    if (dim == 2) {
        const unsigned good[] = {SX_FIX_VX, SX_FIX_VY, SX_FIX_WZ, SX_FIX_VX | SX_FIX_WZ, SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ, 0};
        for (int k = 0; k < 6; k++) {
            ck_assert_int_eq(sx_ball_set_fixity(m, id, good[k]), SX_OK);
            ck_assert_int_eq(sx_ball_fixity(m, id, &mask), SX_OK);
            ck_assert_uint_eq(mask, good[k]);
        }
        const unsigned bad[] = {SX_FIX_VZ, SX_FIX_WX, SX_FIX_WY, SX_FIX_VX | SX_FIX_VZ, SX_FIX_VEL, SX_FIX_SPIN, 1u << 6};
        ck_assert_int_eq(sx_ball_set_fixity(m, id, SX_FIX_VY), SX_OK);
        for (int k = 0; k < 7; k++) {
            ck_assert_int_eq(sx_ball_set_fixity(m, id, bad[k]), SX_EINVAL);
            ck_assert_msg_has(m, "2D");
            ck_assert_int_eq(sx_ball_fixity(m, id, &mask), SX_OK);
            ck_assert_uint_eq(mask, SX_FIX_VY); /* unchanged */
        }
    } else {
        for (unsigned k = 0; k < 64; k++) {
            ck_assert_int_eq(sx_ball_set_fixity(m, id, k), SX_OK);
            ck_assert_int_eq(sx_ball_fixity(m, id, &mask), SX_OK);
            ck_assert_uint_eq(mask, k);
        }
        ck_assert_int_eq(sx_ball_set_fixity(m, id, 1u << 6), SX_EINVAL);
        ck_assert_int_eq(sx_ball_fixity(m, id, &mask), SX_OK);
        ck_assert_uint_eq(mask, 63);
    }
    ck_assert_int_eq(sx_ball_set_fixity(m, 42, 0), SX_ENOTFOUND);
    ck_assert_int_eq(sx_ball_fixity(m, 42, &mask), SX_ENOTFOUND);
    sx_model_destroy(m);
}
END_TEST

/* Under gravity a fixed velocity component keeps its value exactly while the
 * free ones follow v0 + g t; a fixed spin keeps its value under a moment. */
START_TEST(fixity_under_gravity)
{
    const int dim = _i;
    const double g[3] = {3.0, -9.81, dim == 3 ? 2.0 : 0.0};
    const double dt = 1e-3;
    const int n = 200;
    sx_model *m = scene_model(dim, g, dt, 1e6, 0.5, 1000);
    const double v0[3] = {1.0, 2.0, -0.5}, w0[3] = {0.3, -0.2, 0.1};
    const int64_t id = scene_ball(m, ZERO, v0, 0.1);
    ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_SPIN, w0), SX_OK);
    const double mom[3] = {0.01, 0.02, 0.03};
    ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_APPLIED_MOMENT, mom), SX_OK);
    /* 2D: fix vy and the spin; 3D: fix vy and the z spin, leave wx, wy free */
    const unsigned mask = SX_FIX_VY | SX_FIX_WZ;
    ck_assert_int_eq(sx_ball_set_fixity(m, id, mask), SX_OK);
    ck_assert_int_eq(sx_model_cycle(m, n), SX_OK);
    const double t = n * dt;
    double v[3], x[3], w[3], inertia;
    sx_ball_get_vec(m, id, SX_BALL_VEL, v);
    sx_ball_get_vec(m, id, SX_BALL_POS, x);
    sx_ball_get_vec(m, id, SX_BALL_SPIN, w);
    sx_ball_get(m, id, SX_BALL_INERTIA, &inertia);
    ck_assert_double_eq(v[1], v0[1]);             /* fixed: bit for bit */
    ck_assert_rel(x[1], v0[1] * t, 1e-12);
    for (int k = 0; k < dim; k++) {
        if (k == 1) continue;
        ck_assert_rel(v[k], v0[k] + g[k] * t, 1e-12); /* free: follows gravity */
        ck_assert(v[k] != v0[k]);
    }
    if (dim == 2) {
        ck_assert_double_eq(w[0], w0[0]);
    } else {
        ck_assert_double_eq(w[2], w0[2]);
        for (int k = 0; k < 2; k++) ck_assert_rel(w[k], w0[k] + mom[k] / inertia * t, 1e-12);
    }
    sx_model_destroy(m);
}
END_TEST

/* A constant applied force over one leapfrog step: v1 = v0 + F/m dt (4-46),
 * x1 = x0 + v1 dt (4-48); likewise the spin (4-47). Exact up to rounding. */
START_TEST(applied_load_one_step)
{
    const int dim = _i, r = rdim(dim);
    const double dt = 2.5e-4;
    sx_model *m = scene_model(dim, NULL, dt, 1e6, 0.5, 2650);
    const double x0[3] = {0.1, -0.2, 0.3}, v0[3] = {0.5, -0.25, 1.5};
    const int64_t id = scene_ball(m, x0, v0, 0.05);
    const double F[3] = {12.5, -3.75, 8.0}, M[3] = {0.02, -0.01, 0.005};
    ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_APPLIED_FORCE, F), SX_OK);
    ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_APPLIED_MOMENT, M), SX_OK);
    double mass, inertia;
    sx_ball_get(m, id, SX_BALL_MASS, &mass);
    sx_ball_get(m, id, SX_BALL_INERTIA, &inertia);
    ck_assert_int_eq(sx_model_cycle(m, 1), SX_OK);
    double v[3], x[3], w[3];
    sx_ball_get_vec(m, id, SX_BALL_VEL, v);
    sx_ball_get_vec(m, id, SX_BALL_POS, x);
    sx_ball_get_vec(m, id, SX_BALL_SPIN, w);
    const double ulps = 4 * DBL_EPSILON;
    for (int k = 0; k < dim; k++) {
        const double ev = v0[k] + F[k] / mass * dt;
        ck_assert_rel(v[k], ev, ulps);
        ck_assert_rel(x[k], x0[k] + ev * dt, ulps);
    }
    for (int k = 0; k < r; k++) ck_assert_rel(w[k], M[k] / inertia * dt, ulps);
    /* a second step doubles the velocity increment */
    ck_assert_int_eq(sx_model_cycle(m, 1), SX_OK);
    sx_ball_get_vec(m, id, SX_BALL_VEL, v);
    for (int k = 0; k < dim; k++) ck_assert_rel(v[k], v0[k] + 2 * F[k] / mass * dt, ulps);
    sx_model_destroy(m);
}
END_TEST

START_TEST(errors)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, 1000);
    sx_ball_def b = sx_ball_default_def();
    b.material = scene_material(m);
    int64_t id = -7;
    const double radii[] = {0.0, -1.0, NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 5; k++) {
        b.radius = radii[k];
        ck_assert_int_eq(sx_ball_add(m, &b, &id), SX_EINVAL);
        ck_assert_msg_has(m, "radius");
    }
    b.radius = 1.0;
    b.material = 3;
    ck_assert_int_eq(sx_ball_add(m, &b, &id), SX_ENOTFOUND);
    ck_assert_msg_has(m, "material");
    b.material = -1;
    ck_assert_int_eq(sx_ball_add(m, &b, &id), SX_ENOTFOUND);
    ck_assert_msg_has(m, "material");
    b.material = scene_material(m);
    for (int k = 0; k < dim; k++) {
        b.pos[k] = NAN;
        ck_assert_int_eq(sx_ball_add(m, &b, &id), SX_EINVAL);
        ck_assert_msg_has(m, "position");
        b.pos[k] = 0;
    }
    b.vel[0] = INFINITY;
    ck_assert_int_eq(sx_ball_add(m, &b, &id), SX_EINVAL);
    ck_assert_msg_has(m, "velocity");
    b.vel[0] = 0;
    ck_assert_int_eq(id, -7); /* nothing was written */
    ck_assert_int_eq(sx_ball_count(m), 0);
    /* the next good ball still gets id 1 */
    ck_assert_int_eq(sx_ball_add(m, &b, &id), SX_OK);
    ck_assert_int_eq(id, 1);
    /* unknown ids, each message naming the id */
    double out[3], s;
    int mat;
    unsigned mask;
    ck_assert_int_eq(sx_ball_get_vec(m, 42, SX_BALL_POS, out), SX_ENOTFOUND);
    ck_assert_msg_has(m, "42");
    ck_assert_int_eq(sx_ball_set_vec(m, 43, SX_BALL_POS, out), SX_ENOTFOUND);
    ck_assert_msg_has(m, "43");
    ck_assert_int_eq(sx_ball_get(m, 44, SX_BALL_MASS, &s), SX_ENOTFOUND);
    ck_assert_msg_has(m, "44");
    ck_assert_int_eq(sx_ball_set(m, 0, SX_BALL_RADIUS, 1.0), SX_ENOTFOUND);
    ck_assert_msg_has(m, "id 0");
    ck_assert_int_eq(sx_ball_remove(m, -3), SX_ENOTFOUND);
    ck_assert_msg_has(m, "-3");
    ck_assert_int_eq(sx_ball_material(m, 45, &mat), SX_ENOTFOUND);
    ck_assert_int_eq(sx_ball_set_material(m, 46, 0), SX_ENOTFOUND);
    ck_assert_int_eq(sx_ball_fixity(m, 47, &mask), SX_ENOTFOUND);
    ck_assert_int_eq(sx_ball_set_fixity(m, 48, 0), SX_ENOTFOUND);
    ck_assert_msg_has(m, "48");
    ck_assert_int_eq(sx_ball_count(m), 1);
    sx_model_destroy(m);
}
END_TEST

/* The applied loads live in arrays allocated on first use: balls added
 * afterwards (through a capacity growth) start unloaded, the loaded keep theirs. */
START_TEST(applied_loads_survive_growth)
{
    const int dim = _i, r = rdim(dim);
    sx_model *m = scene_model(dim, NULL, 1e-4, 1e6, 0.5, 1000);
    const int64_t first = scene_ball(m, ZERO, NULL, 0.1);
    const double F[3] = {1.5, -2.5, 3.5}, M[3] = {0.25, 0.5, -0.75};
    ck_assert_int_eq(sx_ball_set_vec(m, first, SX_BALL_APPLIED_FORCE, F), SX_OK);
    ck_assert_int_eq(sx_ball_set_vec(m, first, SX_BALL_APPLIED_MOMENT, M), SX_OK);
    int64_t last = 0;
    for (int i = 1; i <= 300; i++) {
        const double x[3] = {1.0 * i, 0, 0};
        last = scene_ball(m, x, NULL, 0.1);
    }
    double out[3];
    sx_ball_get_vec(m, first, SX_BALL_APPLIED_FORCE, out);
    for (int k = 0; k < dim; k++) ck_assert_double_eq(out[k], F[k]);
    sx_ball_get_vec(m, first, SX_BALL_APPLIED_MOMENT, out);
    for (int k = 0; k < r; k++) ck_assert_double_eq(out[k], M[k]);
    sx_ball_get_vec(m, last, SX_BALL_APPLIED_FORCE, out);
    for (int k = 0; k < 3; k++) ck_assert_double_eq(out[k], 0);
    /* the unloaded balls stay at rest, the loaded one moves */
    ck_assert_int_eq(sx_model_cycle(m, 3), SX_OK);
    double v[3];
    for (int64_t i = 0; i < sx_ball_count(m); i++) {
        const int64_t id = sx_ball_id_at(m, i);
        sx_ball_get_vec(m, id, SX_BALL_VEL, v);
        if (id == first)
            ck_assert(v[0] > 0);
        else if (v[0] != 0 || v[1] != 0 || v[2] != 0)
            ck_abort_msg("unloaded ball %lld moves", (long long)id);
    }
    sx_model_destroy(m);
}
END_TEST

/* Distinct fields per ball so a mix-up between balls shows. */
static void ball_fields(int dim, int64_t k, double *pos, double *vel, double *spin, double *fa, double *r,
                        unsigned *fix, double *alpha)
{
    for (int c = 0; c < 3; c++) {
        pos[c] = 10.0 * (double)k + c;
        vel[c] = 0.1 * (double)k - 0.01 * c;
        spin[c] = -(double)k + 0.5 * c;
        fa[c] = 100.0 * (double)k + c;
    }
    *r = 0.5 + 0.01 * (double)k;
    *fix = dim == 3 ? (unsigned)(k % 64) : (unsigned)(k % 2 ? SX_FIX_VX | SX_FIX_WZ : SX_FIX_VY);
    *alpha = 0.05 * (double)(k % 10);
}

static void check_ball(sx_model *m, int64_t id, int64_t k, bool pos_and_vel)
{
    const int dim = sx_model_dim(m), r = rdim(dim);
    double pos[3], vel[3], spin[3], fa[3], rad, alpha, out[3], s;
    unsigned fix, got;
    ball_fields(dim, k, pos, vel, spin, fa, &rad, &fix, &alpha);
    ck_assert_msg(sx_ball_exists(m, id), "ball %lld vanished", (long long)id);
    if (pos_and_vel) {
        sx_ball_get_vec(m, id, SX_BALL_POS, out);
        for (int c = 0; c < dim; c++) ck_assert_double_eq(out[c], pos[c]);
        sx_ball_get_vec(m, id, SX_BALL_VEL, out);
        for (int c = 0; c < dim; c++) ck_assert_double_eq(out[c], vel[c]);
        sx_ball_get_vec(m, id, SX_BALL_SPIN, out);
        for (int c = 0; c < r; c++) ck_assert_double_eq(out[c], spin[c]);
    }
    sx_ball_get_vec(m, id, SX_BALL_APPLIED_FORCE, out);
    for (int c = 0; c < dim; c++) ck_assert_double_eq(out[c], fa[c]);
    sx_ball_get(m, id, SX_BALL_RADIUS, &s);
    ck_assert_double_eq(s, rad);
    sx_ball_get(m, id, SX_BALL_DAMPING, &s);
    ck_assert_double_eq(s, alpha);
    check_mass(m, id, 1000);
    sx_ball_fixity(m, id, &got);
    ck_assert_uint_eq(got, fix);
}

START_TEST(remove_keeps_others)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-6, 1e6, 0.5, 1000);
    const int64_t n = 12;
    int64_t ids[12];
    for (int64_t k = 0; k < n; k++) {
        double pos[3], vel[3], spin[3], fa[3], rad, alpha;
        unsigned fix;
        ball_fields(dim, k, pos, vel, spin, fa, &rad, &fix, &alpha);
        ids[k] = scene_ball(m, pos, vel, rad);
        ck_assert_int_eq(sx_ball_set_vec(m, ids[k], SX_BALL_SPIN, spin), SX_OK);
        ck_assert_int_eq(sx_ball_set_vec(m, ids[k], SX_BALL_APPLIED_FORCE, fa), SX_OK);
        ck_assert_int_eq(sx_ball_set(m, ids[k], SX_BALL_DAMPING, alpha), SX_OK);
        ck_assert_int_eq(sx_ball_set_fixity(m, ids[k], fix), SX_OK);
    }
    /* the middle, then the first and the last of the dense order */
    const int64_t gone[3] = {6, 1, 12};
    for (int g = 0; g < 3; g++) {
        ck_assert_int_eq(sx_ball_remove(m, gone[g]), SX_OK);
        for (int64_t k = 0; k < n; k++) {
            bool removed = false;
            for (int h = 0; h <= g; h++) removed |= ids[k] == gone[h];
            if (removed)
                ck_assert(!sx_ball_exists(m, ids[k]));
            else
                check_ball(m, ids[k], k, true);
        }
    }
    ck_assert_int_eq(sx_ball_count(m), n - 3);
    /* after a cycle (dense order re-sorted), a removal still leaves the rest intact */
    ck_assert_int_eq(sx_model_cycle(m, 2), SX_OK);
    const int64_t victim = sx_ball_id_at(m, sx_ball_count(m) / 2);
    ck_assert_int_eq(sx_ball_remove(m, victim), SX_OK);
    for (int64_t k = 0; k < n; k++) {
        if (ids[k] == victim || ids[k] == 6 || ids[k] == 1 || ids[k] == 12) continue;
        check_ball(m, ids[k], k, false);
    }
    ck_assert_int_eq(sx_ball_count(m), n - 4);
    sx_model_destroy(m);
}
END_TEST

/* ---- bulk removal ---- */

/* A contact by its entities, oriented a < b for ball-ball pairs (the store
 * may hold either orientation: the vectors on b flip with it). */
typedef struct rec {
    int64_t a, b;
    bool wall;
    unsigned bond;
    double fn, overlap, shear[3], normal[3];
} rec;

typedef struct recs {
    rec *r;
    int64_t n, cap;
} recs;

static bool record(const sx_contact_info *c, void *ud)
{
    recs *s = ud;
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 1024;
        s->r = realloc(s->r, (size_t)s->cap * sizeof *s->r);
        ck_assert_ptr_nonnull(s->r);
    }
    rec *r = &s->r[s->n++];
    const bool flip = !c->is_wall && c->a > c->b;
    r->a = flip ? c->b : c->a;
    r->b = flip ? c->a : c->b;
    r->wall = c->is_wall;
    r->bond = c->bond;
    r->fn = c->fn;
    r->overlap = c->overlap;
    for (int k = 0; k < 3; k++) {
        r->shear[k] = flip ? -c->shear[k] : c->shear[k];
        r->normal[k] = flip ? -c->normal[k] : c->normal[k];
    }
    return true;
}

static int by_key(const void *x, const void *y)
{
    const rec *p = x, *q = y;
    if (p->wall != q->wall) return p->wall ? 1 : -1;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    return p->b < q->b ? -1 : p->b > q->b;
}

/* The contacts of the model, sorted by their entities. */
static recs contacts_of(const sx_model *m)
{
    recs s = {NULL, 0, 0};
    sx_contact_each(m, record, &s);
    qsort(s.r, (size_t)s.n, sizeof *s.r, by_key);
    return s;
}

static bool same_rec(const rec *p, const rec *q)
{
    if (by_key(p, q) || p->bond != q->bond || p->fn != q->fn || p->overlap != q->overlap) return false;
    for (int k = 0; k < 3; k++)
        if (p->shear[k] != q->shear[k] || p->normal[k] != q->normal[k]) return false;
    return true;
}

/* A packed, partly bonded assembly in a box, its contacts with shear
 * history: a grid of touching balls (radii 1 mm, spacing 1.998 mm, the
 * walls as close), shaken by random velocities. ids gets n_side^dim ids. */
static sx_model *packed(int dim, int n_side, int64_t *ids)
{
    const double r = 1e-3, a = 1.998e-3, g[3] = {0, -9.81, 0};
    const double lo[3] = {-0.999e-3, -0.999e-3, -0.999e-3};
    const double hi[3] = {lo[0] + n_side * a, lo[1] + n_side * a, lo[2] + n_side * a};
    sx_model *m = scene_model(dim, g, 1e-6, 1e6, 0.5, 2650);
    scene_box_walls(m, lo, hi, 1e6, 0.5);
    uint64_t seed = 17;
    const int n = dim == 2 ? n_side * n_side : n_side * n_side * n_side;
    for (int i = 0; i < n; i++) {
        const int c[3] = {i % n_side, i / n_side % n_side, i / (n_side * n_side)};
        double x[3], v[3];
        for (int k = 0; k < 3; k++) {
            x[k] = c[k] * a;
            v[k] = scene_rng_uniform(&seed, -0.05, 0.05);
        }
        ids[i] = scene_ball(m, x, v, r);
    }
    ck_assert_int_eq(sx_model_cycle(m, 200), SX_OK);
    sx_bond_def b = sx_bond_default_def();
    b.kind = SX_BOND_CONTACT;
    b.gap = 0;
    b.material_a = b.material_b = scene_material(m);
    b.normal_strength = b.shear_strength = 1e9;
    int64_t bonded = 0;
    ck_assert_msg(sx_bond_install(m, &b, &bonded) == SX_OK, "%s", sx_model_error(m));
    ck_assert_int_gt(bonded, 0);
    ck_assert_int_eq(sx_model_cycle(m, 50), SX_OK);
    return m;
}

static bool is_gone(int64_t id) { return id % 5 == 0 || id == 1 || id == 7; }

/* Removing many balls at once leaves exactly the contacts (with their
 * history and bonds) of the balls that stay, like removing them one by one. */
START_TEST(remove_many_keeps_contacts)
{
    const int dim = _i;
    enum { N = 729 }; /* 27 x 27 in 2D, 9 x 9 x 9 in 3D */
    int64_t ids[N], gone[N + 2];
    sx_model *m = packed(dim, dim == 2 ? 27 : 9, ids), *twin = packed(dim, dim == 2 ? 27 : 9, ids);
    const recs before = contacts_of(m);
    int64_t ng = 0;
    for (int64_t i = 0; i < N; i++)
        if (is_gone(ids[i])) gone[ng++] = ids[i];
    gone[ng++] = 7; /* listed twice: removed once */
    const int64_t nbonds = sx_bond_count(m);
    /* all or nothing: one id that is not a ball removes none */
    gone[ng] = N + 100;
    ck_assert_int_eq(sx_ball_remove_many(m, gone, ng + 1), SX_ENOTFOUND);
    ck_assert_msg_has(m, "no ball with id");
    ck_assert_int_eq(sx_ball_count(m), N);
    ck_assert_int_eq(sx_bond_count(m), nbonds);
    ck_assert_int_eq(sx_ball_remove_many(m, gone, -1), SX_EINVAL);
    ck_assert_int_eq(sx_ball_remove_many(m, gone, 0), SX_OK);

    ck_assert_int_eq(sx_ball_remove_many(m, gone, ng), SX_OK);
    for (int64_t j = 0; j < ng - 1; j++) ck_assert_int_eq(sx_ball_remove(twin, gone[j]), SX_OK);
    const int64_t left = N - (ng - 1);
    ck_assert_int_eq(sx_ball_count(m), left);
    /* every id listed once among the dense indices */
    bool seen[N + 1] = {false};
    for (int64_t i = 0; i < left; i++) {
        const int64_t id = sx_ball_id_at(m, i);
        ck_assert(id >= 1 && id <= N && !is_gone(id) && !seen[id]);
        seen[id] = true;
    }
    for (int64_t i = 0; i < N; i++) ck_assert(sx_ball_exists(m, ids[i]) == !is_gone(ids[i]));

    /* the contacts before, less those of a removed ball, unchanged */
    const recs after = contacts_of(m), one_by_one = contacts_of(twin);
    int64_t kept = 0, bonds = 0;
    for (int64_t c = 0; c < before.n; c++) {
        const rec *r = &before.r[c];
        if (is_gone(r->a) || (!r->wall && is_gone(r->b))) continue;
        ck_assert_msg(kept < after.n && same_rec(r, &after.r[kept]), "contact %lld-%lld lost or changed",
                      (long long)r->a, (long long)r->b);
        bonds += r->bond != 0;
        kept++;
    }
    ck_assert_int_eq(after.n, kept);
    ck_assert_int_lt(kept, before.n);
    ck_assert_int_gt(bonds, 0);
    ck_assert_int_eq(sx_bond_count(m), bonds);
    /* the same as removing them one by one */
    ck_assert_int_eq(one_by_one.n, after.n);
    for (int64_t c = 0; c < after.n; c++) ck_assert(same_rec(&after.r[c], &one_by_one.r[c]));
    /* and the model steps on */
    ck_assert_int_eq(sx_model_cycle(m, 50), SX_OK);
    const recs later = contacts_of(m);
    for (int64_t c = 0; c < later.n; c++) ck_assert(!is_gone(later.r[c].a) && (later.r[c].wall || !is_gone(later.r[c].b)));
    free(before.r);
    free(after.r);
    free(one_by_one.r);
    free(later.r);
    sx_model_destroy(m);
    sx_model_destroy(twin);
}
END_TEST

/* A ball's own damping and its group are stored only once some ball has
 * them: until then each ball takes its material's damping and group 0,
 * and the store costs that much less per ball. */
START_TEST(damping_and_group_stored_when_used)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-4, 1e5, 0.5, 2000);
    sx_material_def md;
    ck_assert_int_eq(sx_material_get(m, scene_material(m), &md), SX_OK);
    md.damping = 0.4;
    ck_assert_int_eq(sx_material_set(m, "m", &md, NULL), SX_OK);
    int64_t ids[3];
    for (int k = 0; k < 3; k++) ids[k] = scene_ball(m, (double[3]){k, 0, 0}, NULL, 0.1);
    const double lean = sx_model_memory(m).bytes_per_ball;
    double a;
    int32_t g;
    ck_assert_int_eq(sx_ball_get(m, ids[1], SX_BALL_DAMPING, &a), SX_OK);
    ck_assert_double_eq(a, 0.4);
    ck_assert_int_eq(sx_ball_group(m, ids[1], &g), SX_OK);
    ck_assert_int_eq(g, 0);
    /* setting what a ball has already stores nothing */
    ck_assert_int_eq(sx_ball_set(m, ids[1], SX_BALL_DAMPING, 0.4), SX_OK);
    ck_assert_int_eq(sx_ball_set_group(m, ids[1], 0), SX_OK);
    ck_assert(sx_model_memory(m).bytes_per_ball == lean);
    /* one ball's own damping and group */
    ck_assert_int_eq(sx_ball_set(m, ids[1], SX_BALL_DAMPING, 0.1), SX_OK);
    ck_assert_int_eq(sx_ball_set_group(m, ids[2], 5), SX_OK);
    ck_assert(sx_model_memory(m).bytes_per_ball > lean);
    ck_assert_int_eq(sx_ball_get(m, ids[0], SX_BALL_DAMPING, &a), SX_OK);
    ck_assert_double_eq(a, 0.4);
    ck_assert_int_eq(sx_ball_get(m, ids[1], SX_BALL_DAMPING, &a), SX_OK);
    ck_assert_double_eq(a, 0.1);
    ck_assert_int_eq(sx_ball_group(m, ids[2], &g), SX_OK);
    ck_assert_int_eq(g, 5);
    ck_assert_int_eq(sx_ball_group(m, ids[0], &g), SX_OK);
    ck_assert_int_eq(g, 0);
    /* a new ball takes its material's damping and no group */
    const int64_t late = scene_ball(m, (double[3]){5, 0, 0}, NULL, 0.1);
    ck_assert_int_eq(sx_ball_get(m, late, SX_BALL_DAMPING, &a), SX_OK);
    ck_assert_double_eq(a, 0.4);
    ck_assert_int_eq(sx_ball_group(m, late, &g), SX_OK);
    ck_assert_int_eq(g, 0);
    /* redefining the material's damping sets it on all its balls, as always */
    md.damping = 0.2;
    ck_assert_int_eq(sx_material_set(m, "m", &md, NULL), SX_OK);
    for (int k = 0; k < 3; k++) {
        ck_assert_int_eq(sx_ball_get(m, ids[k], SX_BALL_DAMPING, &a), SX_OK);
        ck_assert_double_eq(a, 0.2);
    }
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("balls");
    TCase *tc = tcase_create("store");
    tcase_add_loop_test(tc, ids_stable_never_reused, 2, 4);
    tcase_add_loop_test(tc, fields_get_set, 2, 4);
    tcase_add_loop_test(tc, mass_inertia_formulas, 2, 4);
    tcase_add_loop_test(tc, radius_and_material_change_mass, 2, 4);
    tcase_add_loop_test(tc, fixity_masks, 2, 4);
    tcase_add_loop_test(tc, damping_and_group_stored_when_used, 2, 4);
    tcase_add_loop_test(tc, fixity_under_gravity, 2, 4);
    tcase_add_loop_test(tc, applied_load_one_step, 2, 4);
    tcase_add_loop_test(tc, applied_loads_survive_growth, 2, 4);
    tcase_add_loop_test(tc, errors, 2, 4);
    tcase_add_loop_test(tc, remove_keeps_others, 2, 4);
    tcase_add_loop_test(tc, remove_many_keeps_contacts, 2, 4);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
