/* Servo-confined random specimens shared by the servo and measurement tests:
 * a polydisperse random packing compacted by servo-controlled walls.
 *
 *  - biaxial (2D): four lines around [0, Lx] x [0, Ly]; the lines at x = Lx
 *    and y = Ly are servo-controlled, the two at the origin are fixed;
 *  - box (3D): six planes; the three at the far faces are servo-controlled;
 *  - cylinder (3D): a cylindrical wall of axis z whose radius is
 *    servo-controlled, a fixed bottom platen and a servo-controlled top one.
 *
 * Each servo's area is the current area of its face (a line: the current
 * length of the specimen's side; the cylinder: 2 pi Rc H; a platen: pi Rc^2),
 * refreshed every SPEC_CHUNK steps as the specimen deforms, as a user does. */
#pragma once

#include "lab.h"

typedef enum spec_kind { SPEC_BIAXIAL, SPEC_BOX, SPEC_CYLINDER } spec_kind;

enum { SPEC_CHUNK = 50 };

typedef struct spec {
    sx_model *m;
    spec_kind kind;
    int dim;
    int64_t walls[6]; /* box: 2 axis + side (side 1 at the far face); cylinder: cylinder, bottom, top */
    int nwalls;
    int64_t servo[3]; /* the servo-controlled walls */
    int nservo;
    double target, alpha, vmax;
    double rmin, rmax;
} spec;

/* Ball radii, stiffnesses and targets of the specimens (SI). The target gives
 * a mean overlap near 1e-3 of the radius: 2D, F ~ sigma 2R = 40 N over
 * Kn = 5e7 N/m is 0.8 um; 3D, F ~ sigma (2R)^2 = 40 N likewise. */
static const double SPEC_RMIN = 0.8e-3, SPEC_RMAX = 1.2e-3;
static const double SPEC_KN = 1e8;     /* ball and wall kn = ks, N/m */
static const double SPEC_MU = 0.5;     /* ball friction; walls are frictionless */
static const double SPEC_DAMP = 0.7;   /* local damping */
static const double SPEC_T2D = 2e4;    /* N/m */
static const double SPEC_T3D = 1e7;    /* Pa */

/* Random sequential addition of n balls in a cylinder of axis z through
 * (0, 0), radius rc, between z = 0 and z = h (no overlap). */
static inline void spec_random_in_cylinder(sx_model *m, int n, double rc, double h, double rmin, double rmax, uint64_t seed)
{
    double *xs = malloc((size_t)n * 4 * sizeof *xs);
    ck_assert_ptr_nonnull(xs);
    uint64_t s = seed;
    for (int i = 0; i < n; i++) {
        double *x = xs + 4 * i;
        for (int tries = 0;; tries++) {
            ck_assert_msg(tries < 100000, "the cylinder is too crowded for %d balls", n);
            x[3] = scene_rng_uniform(&s, rmin, rmax);
            const double rr = rc - x[3];
            x[0] = scene_rng_uniform(&s, -rr, rr);
            x[1] = scene_rng_uniform(&s, -rr, rr);
            x[2] = scene_rng_uniform(&s, x[3], h - x[3]);
            if (x[0] * x[0] + x[1] * x[1] > rr * rr) continue;
            bool ok = true;
            for (int j = 0; j < i && ok; j++) {
                const double *y = xs + 4 * j;
                const double d2 = (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2]);
                ok = d2 > (x[3] + y[3]) * (x[3] + y[3]);
            }
            if (ok) break;
        }
        scene_ball(m, x, NULL, x[3]);
    }
    free(xs);
}

/* Sum of the balls' volumes (2D: areas). */
static inline double spec_solid(const sx_model *m)
{
    const int dim = sx_model_dim(m);
    double v = 0;
    for (int64_t i = 0; i < sx_ball_count(m); i++) {
        double r = 0;
        sx_ball_get(m, sx_ball_id_at(m, i), SX_BALL_RADIUS, &r);
        v += dim == 3 ? 4.0 / 3.0 * LAB_PI * r * r * r : LAB_PI * r * r;
    }
    return v;
}

/* Current extents: box: L[axis] between its two walls; cylinder: L[0] = Rc, L[1] = H. */
static inline void spec_extent(const spec *s, double *L)
{
    if (s->kind == SPEC_CYLINDER) {
        L[0] = lab_wall(s->m, s->walls[0]).radius;
        L[1] = lab_wall(s->m, s->walls[2]).point[2] - lab_wall(s->m, s->walls[1]).point[2];
        return;
    }
    for (int a = 0; a < s->dim; a++) L[a] = lab_wall(s->m, s->walls[2 * a + 1]).point[a] - lab_wall(s->m, s->walls[2 * a]).point[a];
}

/* The current area of wall k of the specimen (index into s->walls). */
static inline double spec_area(const spec *s, int k)
{
    double L[3] = {0, 0, 0};
    spec_extent(s, L);
    if (s->kind == SPEC_CYLINDER) return k == 0 ? 2 * LAB_PI * L[0] * L[1] : LAB_PI * L[0] * L[0];
    const int axis = k / 2;
    double a = 1;
    for (int b = 0; b < s->dim; b++)
        if (b != axis) a *= L[b];
    return a;
}

/* The stress on wall k (index into s->walls): its normal load over its current area. */
static inline double spec_stress(const spec *s, int k) { return lab_load(s->m, s->walls[k], NULL, NULL) / spec_area(s, k); }

/* The index into s->walls of servo j. */
static inline int spec_servo_wall(const spec *s, int j)
{
    for (int k = 0; k < s->nwalls; k++)
        if (s->walls[k] == s->servo[j]) return k;
    return -1;
}

static inline void spec_update_servos(spec *s)
{
    for (int j = 0; j < s->nservo; j++)
        lab_servo(s->m, s->servo[j], s->target, spec_area(s, spec_servo_wall(s, j)), s->alpha, s->vmax);
}

/* A specimen of n balls at an initial solid fraction phi0 (random
 * sequential addition, at rest), its servos on with the given target. */
static inline spec spec_make(spec_kind kind, int n, double phi0, double vmax, uint64_t seed)
{
    spec s;
    memset(&s, 0, sizeof s);
    s.kind = kind;
    s.dim = kind == SPEC_BIAXIAL ? 2 : 3;
    s.alpha = 0.5;
    s.vmax = vmax;
    s.rmin = SPEC_RMIN, s.rmax = SPEC_RMAX;
    s.target = s.dim == 2 ? SPEC_T2D : SPEC_T3D;
    s.m = lab_model(s.dim, 0);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = SPEC_KN;
    md.friction = SPEC_MU;
    md.damping = SPEC_DAMP;
    const int mat = scene_material_def(s.m, "m", &md); /* the name scene_ball uses */
    (void)mat;
    /* the mean ball volume of radii uniform in [rmin, rmax] */
    const double a = s.rmin, b = s.rmax;
    const double r2 = (b * b + a * b + a * a) / 3, r3 = (a + b) * (a * a + b * b) / 4;
    const double vball = s.dim == 3 ? 4.0 / 3.0 * LAB_PI * r3 : LAB_PI * r2;
    const double vol = n * vball / phi0;
    if (kind == SPEC_CYLINDER) {
        /* height twice the diameter: pi rc^2 (4 rc) = vol */
        const double rc = cbrt(vol / (4 * LAB_PI)), h = 4 * rc;
        sx_wall_def w = sx_wall_default_def(3);
        w.kind = SX_WALL_CYLINDER;
        w.radius = rc;
        w.height = 0; /* infinite: the platens close it */
        w.kn = w.ks = SPEC_KN;
        w.friction = 0;
        LAB_OK(s.m, sx_wall_add(s.m, &w, &s.walls[0]));
        const double p0[3] = {0, 0, 0}, n0[3] = {0, 0, 1}, p1[3] = {0, 0, h}, n1[3] = {0, 0, -1};
        s.walls[1] = lab_plane(s.m, p0, n0, SPEC_KN, 0);
        s.walls[2] = lab_plane(s.m, p1, n1, SPEC_KN, 0);
        s.nwalls = 3;
        s.servo[0] = s.walls[0], s.servo[1] = s.walls[2];
        s.nservo = 2;
        spec_random_in_cylinder(s.m, n, rc, h, s.rmin, s.rmax, seed);
    } else {
        const double side = s.dim == 3 ? cbrt(vol) : sqrt(vol);
        const double lo[3] = {0, 0, 0}, hi[3] = {side, side, s.dim == 3 ? side : 0};
        lab_box(s.m, lo, hi, SPEC_KN, 0, s.walls);
        s.nwalls = 2 * s.dim;
        for (int axis = 0; axis < s.dim; axis++) s.servo[axis] = s.walls[2 * axis + 1];
        s.nservo = s.dim;
        scene_random_balls(s.m, n, lo, hi, s.rmin, s.rmax, 0, 0, seed, NULL);
    }
    spec_update_servos(&s);
    return s;
}
