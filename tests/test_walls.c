/* Walls: the contact of a ball with each kind (plane, line, rectangle face,
 * edge and corner, segment middle and end), finiteness, the resultant force
 * and moment recorded on the wall, imposed motion, and validation. */
#include "scenes.h"

#include <check.h>
#include <float.h>
#include <math.h>
#include <string.h>

#define ck_assert_cycle(m, n) \
    ck_assert_msg(sx_model_cycle((m), (n)) == SX_OK, "cycle failed: %s", sx_model_error(m))

#define ck_assert_msg_has(m, needle)                                                          \
    ck_assert_msg(strstr(sx_model_error(m), (needle)) != NULL, "message '%s' does not mention '%s'", \
                  sx_model_error(m), (needle))

/* |a - b| <= tol, with the names in the message */
#define ck_assert_near(a, b, tol)                                                                      \
    do {                                                                                               \
        const double a_ = (a), b_ = (b);                                                               \
        ck_assert_msg(fabs(a_ - b_) <= (tol), "%s = %.17g, expected %.17g (|diff| %.3g > %.3g)", #a, a_, b_, \
                      fabs(a_ - b_), (double)(tol));                                                   \
    } while (0)

enum { KB = 100000000 };       /* ball kn = ks (N/m) */
static const double KW = 3e8;  /* wall kn = ks (N/m) */
static const double R = 0.01;  /* ball radius (m) */
static const double UN = 1e-4; /* overlap (m) */

static double kn_series(void) { return KB * KW / (KB + KW); } /* 4-22 */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void unit(double *v)
{
    const double n = sqrt(dot3(v, v));
    for (int k = 0; k < 3; k++) v[k] /= n;
}

static void cross(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

typedef struct outcome {
    double fb[3], mb[3];   /* force and moment on the ball */
    double fw[3], mw[3];   /* resultant on the wall */
    int64_t contacts;
} outcome;

/* One step of a resting ball against one wall; the forces are those of the
 * ball's position at the start of the step. */
static outcome one_step(int dim, const sx_wall_def *w, const double *x, double mu_ball)
{
    sx_model *m = scene_model(dim, NULL, 1e-9, KB, mu_ball, 2650);
    int64_t wid;
    ck_assert_msg(sx_wall_add(m, w, &wid) == SX_OK, "%s", sx_model_error(m));
    const int64_t id = scene_ball(m, x, NULL, R);
    ck_assert_msg(sx_model_cycle(m, 1) == SX_OK, "%s", sx_model_error(m));
    outcome o;
    memset(&o, 0, sizeof o);
    sx_ball_get_vec(m, id, SX_BALL_FORCE, o.fb);
    sx_ball_get_vec(m, id, SX_BALL_MOMENT, o.mb);
    ck_assert_int_eq(sx_wall_force(m, wid, o.fw, o.mw), SX_OK);
    o.contacts = sx_contact_count(m);
    sx_model_destroy(m);
    return o;
}

/* The ball at `x` touches the wall at `foot` (closest point) along unit n:
 * force Kn Un n on the ball (4-6), -F on the wall, and the wall's moment
 * (xC - ref) x (-F) about `ref` with xC = x - (R - Un/2) n (4-4). */
static void check_contact(int dim, const sx_wall_def *w, const double *foot, const double *n, const double *ref)
{
    double x[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) x[k] = foot[k] + (R - UN) * n[k];
    const outcome o = one_step(dim, w, x, 0.5);
    ck_assert_int_eq(o.contacts, 1);
    const double fmag = kn_series() * UN;
    const double tol = 1e-9 * fmag; /* Un = R - d loses ~log10(R/Un) digits to cancellation */
    double F[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) {
        F[k] = fmag * n[k];
        ck_assert_near(o.fb[k], F[k], tol);
        ck_assert_double_eq(o.fw[k], -o.fb[k]); /* action and reaction, exactly */
    }
    double xc[3] = {0, 0, 0}, arm[3] = {0, 0, 0}, mw[3], minus[3];
    for (int k = 0; k < dim; k++) {
        xc[k] = x[k] - (R - 0.5 * UN) * n[k];
        arm[k] = xc[k] - ref[k];
        minus[k] = -F[k];
    }
    cross(arm, minus, mw);
    const double mtol = tol * (sqrt(dot3(arm, arm)) + R);
    if (dim == 3) {
        for (int k = 0; k < 3; k++) ck_assert_near(o.mw[k], mw[k], mtol);
        for (int k = 0; k < 3; k++) ck_assert_near(o.mb[k], 0.0, 1e-12 * fmag * R); /* F passes through the centre */
    } else {
        ck_assert_near(o.mw[0], mw[2], mtol);
        ck_assert_near(o.mb[0], 0.0, 1e-12 * fmag * R);
    }
}

static void check_no_contact(int dim, const sx_wall_def *w, const double *x)
{
    const outcome o = one_step(dim, w, x, 0.5);
    ck_assert_int_eq(o.contacts, 0);
    for (int k = 0; k < 3; k++) {
        ck_assert_double_eq(o.fb[k], 0);
        ck_assert_double_eq(o.fw[k], 0);
        ck_assert_double_eq(o.mw[k], 0);
    }
}

START_TEST(plane_3d)
{
    sx_wall_def w = sx_wall_default_def(3);
    const double p[3] = {0.1, -0.2, 0.3};
    memcpy(w.point, p, sizeof p);
    w.normal[0] = 1, w.normal[1] = 2, w.normal[2] = 2; /* normalised on input */
    w.kn = w.ks = KW;
    double n[3] = {1, 2, 2};
    unit(n);
    /* a foot point away from def.point, so the moment about it is not zero */
    const double t[3] = {2, -1, 0}; /* orthogonal to n */
    double foot[3];
    for (int k = 0; k < 3; k++) foot[k] = p[k] + 0.05 * t[k];
    check_contact(3, &w, foot, n, p);
    /* behind a plane there is no wall to touch from the far side: the ball is pushed out along n */
    double x[3];
    for (int k = 0; k < 3; k++) x[k] = foot[k] + (R + 1e-4) * n[k];
    check_no_contact(3, &w, x);
    /* the stored definition has the normal normalised */
    sx_model *m = scene_model(3, NULL, 1e-6, KB, 0.5, 2650);
    int64_t id;
    ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_OK);
    sx_wall_def got;
    ck_assert_int_eq(sx_wall_get(m, id, &got), SX_OK);
    for (int k = 0; k < 3; k++) ck_assert_near(got.normal[k], n[k], 2 * DBL_EPSILON);
    sx_model_destroy(m);
}
END_TEST

START_TEST(line_2d)
{
    sx_wall_def w = sx_wall_default_def(2);
    const double p[3] = {0.5, -1.0, 0};
    memcpy(w.point, p, sizeof p);
    w.normal[0] = 3, w.normal[1] = 4, w.normal[2] = 0;
    w.kn = w.ks = KW;
    const double n[3] = {0.6, 0.8, 0};
    const double foot[3] = {p[0] + 0.1 * 0.8, p[1] - 0.1 * 0.6, 0};
    check_contact(2, &w, foot, n, p);
    const double x[3] = {foot[0] + (R + 1e-4) * n[0], foot[1] + (R + 1e-4) * n[1], 0};
    check_no_contact(2, &w, x);
}
END_TEST

/* Rectangle corner (0,0,0), edges (2,0,0) and (0,1,0): its centre (1, 0.5, 0) is the moment's reference. */
static sx_wall_def rect_def(void)
{
    sx_wall_def w = sx_wall_default_def(3);
    w.kind = SX_WALL_RECT;
    memset(w.point, 0, sizeof w.point);
    const double e1[3] = {2, 0, 0}, e2[3] = {0, 1, 0};
    memcpy(w.edge1, e1, sizeof e1);
    memcpy(w.edge2, e2, sizeof e2);
    w.kn = w.ks = KW;
    return w;
}

START_TEST(rect_face_edge_corner)
{
    const sx_wall_def w = rect_def();
    const double centre[3] = {1, 0.5, 0};
    /* face, both sides (a rectangle is two-sided) */
    const double foot_face[3] = {0.3, 0.7, 0};
    const double up[3] = {0, 0, 1}, down[3] = {0, 0, -1};
    check_contact(3, &w, foot_face, up, centre);
    check_contact(3, &w, foot_face, down, centre);
    /* edge x = 2: the normal leaves the edge obliquely */
    const double foot_edge[3] = {2, 0.4, 0};
    double ne[3] = {1, 0, 1};
    unit(ne);
    check_contact(3, &w, foot_edge, ne, centre);
    /* edge y = 0 from below */
    const double foot_edge2[3] = {0.5, 0, 0};
    double ne2[3] = {0, -2, -1};
    unit(ne2);
    check_contact(3, &w, foot_edge2, ne2, centre);
    /* corner (2, 1, 0) */
    const double corner[3] = {2, 1, 0};
    double nc[3] = {1, 1, 1};
    unit(nc);
    check_contact(3, &w, corner, nc, centre);
    /* corner (0, 0, 0) */
    const double origin[3] = {0, 0, 0};
    double nc2[3] = {-1, -2, 2};
    unit(nc2);
    check_contact(3, &w, origin, nc2, centre);
    /* finite: in its plane just beyond an edge, or beyond a corner, nothing */
    const double beyond[3] = {2 + R + 1e-4, 0.5, 0};
    check_no_contact(3, &w, beyond);
    const double beyond2[3] = {0.5, -(R + 1e-4), 0};
    check_no_contact(3, &w, beyond2);
    const double beyond3[3] = {2 + 0.8 * R, 1 + 0.8 * R, 0}; /* within R of both edge lines, not of the corner */
    check_no_contact(3, &w, beyond3);
}
END_TEST

/* Segment from (0,0) to (2,1): normal (-1, 2)/sqrt(5); the moment is about the first end. */
static sx_wall_def segment_def(void)
{
    sx_wall_def w = sx_wall_default_def(2);
    w.kind = SX_WALL_SEGMENT;
    memset(w.point, 0, sizeof w.point);
    w.edge1[0] = 2, w.edge1[1] = 1, w.edge1[2] = 0;
    w.kn = w.ks = KW;
    return w;
}

START_TEST(segment_middle_end)
{
    const sx_wall_def w = segment_def();
    const double first[3] = {0, 0, 0};
    double nrm[3] = {-1, 2, 0};
    unit(nrm);
    const double mid[3] = {0.6, 0.3, 0};
    check_contact(2, &w, mid, nrm, first);
    const double back[3] = {-nrm[0], -nrm[1], 0};
    check_contact(2, &w, mid, back, first);
    /* beyond the second end: the normal comes from the end point */
    const double end[3] = {2, 1, 0};
    double ne[3] = {1, -0.5, 0};
    unit(ne);
    check_contact(2, &w, end, ne, first);
    const double along[3] = {2 / sqrt(5.0), 1 / sqrt(5.0), 0};
    check_contact(2, &w, end, along, first);
    /* beyond the first end */
    double n0[3] = {-1, -1, 0};
    unit(n0);
    check_contact(2, &w, first, n0, first);
    /* finite: beyond the end along the segment's line, nothing */
    const double beyond[3] = {2 + (R + 1e-4) * along[0], 1 + (R + 1e-4) * along[1], 0};
    check_no_contact(2, &w, beyond);
    const double beyond2[3] = {-(R + 1e-4) * along[0], -(R + 1e-4) * along[1], 0};
    check_no_contact(2, &w, beyond2);
}
END_TEST

/* Several balls: the wall's resultant is minus the sum of the balls' forces. */
START_TEST(resultant_of_many)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-9, KB, 0.5, 2650);
    sx_wall_def w = sx_wall_default_def(dim);
    w.kn = w.ks = KW;
    int64_t wid;
    ck_assert_int_eq(sx_wall_add(m, &w, &wid), SX_OK);
    int64_t ids[4];
    for (int i = 0; i < 4; i++) {
        double x[3] = {0.05 * i, 0.03 * i, 0};
        x[dim - 1] = R - UN * (i + 1);
        const double v[3] = {0.1 * i, -0.05, 0.02 * i}; /* sliding: shear forces too */
        ids[i] = scene_ball(m, x, v, R);
    }
    ck_assert_cycle(m, 5);
    double sum[3] = {0, 0, 0}, msum = 0, fw[3], mw[3];
    for (int i = 0; i < 4; i++) {
        double f[3], x[3];
        sx_ball_get_vec(m, ids[i], SX_BALL_FORCE, f);
        sx_ball_get_vec(m, ids[i], SX_BALL_POS, x);
        for (int k = 0; k < 3; k++) sum[k] += f[k];
        msum += fabs(f[dim - 1]);
    }
    ck_assert_int_eq(sx_wall_force(m, wid, fw, mw), SX_OK);
    ck_assert(msum > 0);
    for (int k = 0; k < dim; k++) ck_assert_near(fw[k], -sum[k], 1e-14 * msum);
    ck_assert(fw[dim - 1] < 0); /* the balls press the wall down */
    sx_model_destroy(m);
}
END_TEST

/* A ball driven along a wall at a fixed velocity slides: |Fs| = mu Fn with
 * mu the smaller of the ball's and the wall's friction (4-30), opposing the motion. */
START_TEST(wall_friction_smaller_mu)
{
    const int dim = _i;
    const double mus[2][2] = {{0.3, 0.7}, {0.9, 0.2}}; /* ball, wall */
    for (int c = 0; c < 2; c++) {
        sx_model *m = scene_model(dim, NULL, 1e-6, KB, mus[c][0], 2650);
        sx_wall_def w = sx_wall_default_def(dim);
        w.kn = w.ks = KW;
        w.friction = mus[c][1];
        ck_assert_int_eq(sx_wall_add(m, &w, NULL), SX_OK);
        double x[3] = {0, 0, 0}, v[3] = {0, 0, 0};
        x[dim - 1] = R - UN;
        v[0] = 0.5;
        const int64_t id = scene_ball(m, x, v, R);
        ck_assert_int_eq(sx_ball_set_fixity(m, id, SX_FIX_VX | SX_FIX_VY | (dim == 3 ? SX_FIX_VZ | SX_FIX_SPIN : SX_FIX_WZ)),
                         SX_OK);
        ck_assert_cycle(m, 200);
        double f[3];
        sx_ball_get_vec(m, id, SX_BALL_FORCE, f);
        const double mu = mus[c][0] < mus[c][1] ? mus[c][0] : mus[c][1];
        const double fn = kn_series() * UN;
        ck_assert_near(f[dim - 1], fn, 1e-9 * fn);
        ck_assert_near(f[0], -mu * fn, 1e-9 * fn);
        sx_model_destroy(m);
    }
}
END_TEST

/* Imposed velocity: with dyadic velocity and timestep every partial sum is
 * exact, so the wall must be at p0 + v t bit for bit. */
START_TEST(moving_wall_exact)
{
    const int dim = _i;
    const double dt = 0x1.0p-12;
    const int n = 1000;
    sx_model *m = scene_model(dim, NULL, dt, KB, 0.5, 2650);
    const double far[3] = {-50, 50, 50};
    scene_ball(m, far, NULL, R); /* on the planes' (lines') side, far from every wall */
    const double v[3] = {0.25, -0.5, 0.125}, p0[3] = {1, 2, 3};
    sx_wall_def w[2] = {sx_wall_default_def(dim), sx_wall_default_def(dim)};
    if (dim == 3) {
        w[1] = rect_def();
    } else {
        w[1] = segment_def();
    }
    int64_t id[2];
    for (int i = 0; i < 2; i++) {
        for (int k = 0; k < dim; k++) w[i].point[k] = p0[k], w[i].vel[k] = v[k];
        ck_assert_int_eq(sx_wall_add(m, &w[i], &id[i]), SX_OK);
    }
    ck_assert_cycle(m, n);
    const double t = sx_model_time(m);
    ck_assert_double_eq(t, n * dt);
    for (int i = 0; i < 2; i++) {
        sx_wall_def got;
        ck_assert_int_eq(sx_wall_get(m, id[i], &got), SX_OK);
        for (int k = 0; k < dim; k++) ck_assert_double_eq(got.point[k], p0[k] + v[k] * t);
        for (int k = 0; k < dim; k++) ck_assert_double_eq(got.edge1[k], w[i].edge1[k]); /* translation only */
    }
    /* a general velocity and timestep: within the rounding of n additions */
    const double v2[3] = {0.1, -0.3, 0.7};
    ck_assert_int_eq(sx_wall_set_vel(m, id[0], v2), SX_OK);
    ck_assert_int_eq(sx_model_set_timestep(m, 1e-4), SX_OK);
    sx_wall_def before;
    sx_wall_get(m, id[0], &before);
    ck_assert_cycle(m, n);
    sx_wall_def got;
    sx_wall_get(m, id[0], &got);
    for (int k = 0; k < dim; k++) ck_assert_near(got.point[k], before.point[k] + v2[k] * n * 1e-4, n * 8 * DBL_EPSILON);
    const double bad[3] = {NAN, 0, 0};
    ck_assert_int_eq(sx_wall_set_vel(m, id[0], bad), SX_EINVAL);
    sx_model_destroy(m);
}
END_TEST

/* A wall moving onto a free ball: elastic linear contact with an immovable
 * wall, so the ball leaves at twice the wall's speed; during the contact the
 * wall feels exactly minus the ball's force. */
START_TEST(moving_wall_pushes)
{
    const int dim = _i;
    const double vw = 0.5, gap = 5e-4;
    /* densities giving similar masses, so the contact lasts ~40 steps in both */
    sx_model *m = scene_model(dim, NULL, 1e-6, KB, 0.5, dim == 3 ? 2650 : 26.5);
    sx_wall_def w = sx_wall_default_def(dim);
    w.vel[dim - 1] = vw;
    w.kn = w.ks = KW;
    int64_t wid;
    ck_assert_int_eq(sx_wall_add(m, &w, &wid), SX_OK);
    double x[3] = {0, 0, 0};
    x[dim - 1] = R + gap;
    const int64_t id = scene_ball(m, x, NULL, R);
    double fmin = 0;
    int touching_steps = 0;
    for (int s = 0; s < 3000; s++) {
        ck_assert_cycle(m, 1);
        double fb[3], fw[3];
        sx_ball_get_vec(m, id, SX_BALL_FORCE, fb);
        sx_wall_force(m, wid, fw, NULL);
        for (int k = 0; k < dim; k++) ck_assert_double_eq(fw[k], -fb[k]);
        if (fw[dim - 1] < fmin) fmin = fw[dim - 1];
        touching_steps += fb[dim - 1] > 0;
    }
    ck_assert(fmin < 0);
    ck_assert(touching_steps > 5);
    double v[3], xe[3];
    sx_ball_get_vec(m, id, SX_BALL_VEL, v);
    sx_ball_get_vec(m, id, SX_BALL_POS, xe);
    ck_assert_near(v[dim - 1], 2 * vw, 0.01 * vw);
    for (int k = 0; k < dim - 1; k++) ck_assert_near(v[k], 0.0, 1e-12);
    ck_assert(xe[dim - 1] > x[dim - 1]);
    sx_model_destroy(m);
}
END_TEST

START_TEST(validation)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-6, KB, 0.5, 2650);
    int64_t id = -5;
    sx_wall_def w = sx_wall_default_def(dim);
    memset(w.normal, 0, sizeof w.normal);
    ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
    ck_assert_msg_has(m, "normal");
    if (dim == 2) { /* a normal with only a z component is zero in 2D */
        w.normal[2] = 1;
        ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
        ck_assert_msg_has(m, "normal");
    }
    w = sx_wall_default_def(dim);
    const double kns[] = {0.0, -1e8, NAN};
    for (int k = 0; k < 3; k++) {
        w.kn = kns[k];
        ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
        ck_assert_msg_has(m, "kn");
    }
    w = sx_wall_default_def(dim);
    w.ks = -1;
    ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
    ck_assert_msg_has(m, "ks");
    w = sx_wall_default_def(dim);
    w.friction = -0.1;
    ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
    ck_assert_msg_has(m, "friction");
    w = sx_wall_default_def(dim);
    w.point[0] = NAN;
    ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
    ck_assert_msg_has(m, "finite");
    /* kinds of the other dimension */
    const sx_wall_kind wrong[2] = {dim == 3 ? SX_WALL_LINE : SX_WALL_PLANE, dim == 3 ? SX_WALL_SEGMENT : SX_WALL_RECT};
    for (int k = 0; k < 2; k++) {
        w = dim == 3 ? segment_def() : rect_def();
        w.kind = wrong[k];
        ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
        ck_assert_msg_has(m, "kind");
        ck_assert_msg_has(m, dim == 3 ? "3D" : "2D");
    }
    w = sx_wall_default_def(dim);
    w.kind = (sx_wall_kind)17;
    ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
    ck_assert_msg_has(m, "kind");
    if (dim == 3) {
        w = rect_def();
        w.edge2[0] = 0.1; /* not orthogonal to edge1 */
        ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
        ck_assert_msg_has(m, "orthogonal");
        w = rect_def();
        memset(w.edge2, 0, sizeof w.edge2);
        ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
        ck_assert_msg_has(m, "edge");
    } else {
        w = segment_def();
        memset(w.edge1, 0, sizeof w.edge1);
        ck_assert_int_eq(sx_wall_add(m, &w, &id), SX_EINVAL);
        ck_assert_msg_has(m, "length");
    }
    ck_assert_int_eq(id, -5);
    ck_assert_int_eq(sx_wall_count(m), 0);
    /* unknown wall ids */
    double f[3];
    sx_wall_def got;
    ck_assert_int_eq(sx_wall_get(m, 9, &got), SX_ENOTFOUND);
    ck_assert_msg_has(m, "9");
    ck_assert_int_eq(sx_wall_force(m, 9, f, f), SX_ENOTFOUND);
    ck_assert_int_eq(sx_wall_set_vel(m, 9, f), SX_ENOTFOUND);
    ck_assert_int_eq(sx_wall_remove(m, 9), SX_ENOTFOUND);
    /* ids are stable and not reused */
    w = sx_wall_default_def(dim);
    int64_t a, b, c;
    ck_assert_int_eq(sx_wall_add(m, &w, &a), SX_OK);
    ck_assert_int_eq(sx_wall_add(m, &w, &b), SX_OK);
    ck_assert_int_eq(sx_wall_remove(m, a), SX_OK);
    ck_assert(!sx_wall_exists(m, a));
    ck_assert(sx_wall_exists(m, b));
    ck_assert_int_eq(sx_wall_add(m, &w, &c), SX_OK);
    ck_assert(c != a && c != b);
    ck_assert_int_eq(sx_wall_count(m), 2);
    ck_assert_int_eq(sx_wall_id_at(m, 2), -1);
    sx_model_destroy(m);
}
END_TEST

/* Removing a wall keeps the others' contacts and forces. */
/* Writing a wall's point, stiffnesses, friction and (cylinder) radius: the
 * next step's contact force follows (4-6, 4-22), bad values are refused
 * and leave the wall as it was. */
START_TEST(set_fields)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-9, KB, 0.5, 2650);
    sx_wall_def w = sx_wall_default_def(dim);
    w.kn = w.ks = KW;
    int64_t wid;
    ck_assert_int_eq(sx_wall_add(m, &w, &wid), SX_OK);
    double x[3] = {0, 0, 0};
    x[dim - 1] = R - UN;
    const int64_t id = scene_ball(m, x, NULL, R);
    ck_assert_int_eq(sx_ball_set_fixity(m, id, dim == 3 ? SX_FIX_VEL | SX_FIX_SPIN : SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ),
                     SX_OK);
    double f[3];
#define NORMAL_FORCE() (ck_assert_cycle(m, 1), sx_ball_get_vec(m, id, SX_BALL_FORCE, f), f[dim - 1])
    ck_assert_near(NORMAL_FORCE(), kn_series() * UN, 1e-9 * kn_series() * UN);
    /* a stiffer wall */
    ck_assert_int_eq(sx_wall_set(m, wid, SX_WALL_KN, 3 * KW), SX_OK);
    const double k3 = KB * 3 * KW / (KB + 3 * KW);
    ck_assert_near(NORMAL_FORCE(), k3 * UN, 1e-9 * k3 * UN);
    /* the wall raised by UN: twice the overlap */
    double p[3] = {0, 0, 0};
    p[dim - 1] = UN;
    ck_assert_int_eq(sx_wall_set_point(m, wid, p), SX_OK);
    ck_assert_near(NORMAL_FORCE(), 2 * k3 * UN, 1e-8 * k3 * UN);
    /* lowered out of reach: no contact at all */
    p[dim - 1] = -2 * UN;
    ck_assert_int_eq(sx_wall_set_point(m, wid, p), SX_OK);
    ck_assert_double_eq(NORMAL_FORCE(), 0);
    ck_assert_int_eq(sx_contact_count(m), 0);
#undef NORMAL_FORCE
    ck_assert_int_eq(sx_wall_set(m, wid, SX_WALL_KS, 0), SX_OK);
    ck_assert_int_eq(sx_wall_set(m, wid, SX_WALL_FRICTION, 0.1), SX_OK);
    /* refused, and nothing changes */
    const struct {
        sx_wall_scalar which;
        double value;
        const char *says;
    } bad[] = {
        {SX_WALL_KN, 0, "kn"},          {SX_WALL_KN, NAN, "kn"},  {SX_WALL_KN, INFINITY, "kn"},
        {SX_WALL_KS, -1, "ks"},         {SX_WALL_FRICTION, -0.5, "friction"},
        {SX_WALL_FRICTION, NAN, "friction"}, {SX_WALL_RADIUS, 1, "not a cylinder"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ck_assert_int_eq(sx_wall_set(m, wid, bad[i].which, bad[i].value), SX_EINVAL);
        ck_assert_msg_has(m, bad[i].says);
    }
    const double inf[3] = {INFINITY, INFINITY, INFINITY};
    ck_assert_int_eq(sx_wall_set_point(m, wid, inf), SX_EINVAL);
    ck_assert_int_eq(sx_wall_set_point(m, wid + 100, p), SX_ENOTFOUND);
    ck_assert_int_eq(sx_wall_set(m, wid + 100, SX_WALL_KN, 1), SX_ENOTFOUND);
    sx_wall_def got;
    ck_assert_int_eq(sx_wall_get(m, wid, &got), SX_OK);
    ck_assert_double_eq(got.kn, 3 * KW);
    ck_assert_double_eq(got.ks, 0);
    ck_assert_double_eq(got.friction, 0.1);
    ck_assert_double_eq(got.point[dim - 1], -2 * UN);
    if (dim == 3) { /* a cylinder's radius: the ball on its axis touches it once the radius is R - UN */
        sx_wall_def c = sx_wall_default_def(3);
        c.kind = SX_WALL_CYLINDER;
        c.point[2] = -1;
        c.radius = 10 * R;
        c.kn = c.ks = KW;
        int64_t cid;
        ck_assert_int_eq(sx_wall_add(m, &c, &cid), SX_OK);
        ck_assert_cycle(m, 1);
        ck_assert_int_eq(sx_contact_count(m), 0);
        ck_assert_int_eq(sx_wall_set(m, cid, SX_WALL_RADIUS, R - UN), SX_OK);
        ck_assert_cycle(m, 1);
        ck_assert_int_gt(sx_contact_count(m), 0);
        ck_assert_int_eq(sx_wall_set(m, cid, SX_WALL_RADIUS, 0), SX_EINVAL);
        ck_assert_int_eq(sx_wall_get(m, cid, &got), SX_OK);
        ck_assert_double_eq(got.radius, R - UN);
    }
    sx_model_destroy(m);
}
END_TEST

START_TEST(remove_wall_keeps_others)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-7, KB, 0.5, 2650);
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    scene_box_walls(m, lo, hi, KW, 0.5);
    double x[3] = {R - UN, 0.5, 0.5};
    if (dim == 2) x[2] = 0;
    const int64_t id = scene_ball(m, x, NULL, R);
    ck_assert_cycle(m, 1);
    double f[3];
    sx_ball_get_vec(m, id, SX_BALL_FORCE, f);
    ck_assert_near(f[0], kn_series() * UN, 1e-9 * kn_series() * UN);
    /* remove every wall but the one at x = 0 (the first added) */
    const int64_t keep = sx_wall_id_at(m, 0);
    while (sx_wall_count(m) > 1) ck_assert_int_eq(sx_wall_remove(m, sx_wall_id_at(m, sx_wall_count(m) - 1)), SX_OK);
    ck_assert_cycle(m, 1);
    double fw[3];
    sx_ball_get_vec(m, id, SX_BALL_FORCE, f);
    ck_assert_int_eq(sx_wall_force(m, keep, fw, NULL), SX_OK);
    ck_assert(f[0] > 0.9 * kn_series() * UN);
    ck_assert_double_eq(fw[0], -f[0]);
    ck_assert_int_eq(sx_contact_count(m), 1);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("walls");
    TCase *tc = tcase_create("walls");
    tcase_add_test(tc, plane_3d);
    tcase_add_test(tc, line_2d);
    tcase_add_test(tc, rect_face_edge_corner);
    tcase_add_test(tc, segment_middle_end);
    tcase_add_loop_test(tc, resultant_of_many, 2, 4);
    tcase_add_loop_test(tc, wall_friction_smaller_mu, 2, 4);
    tcase_add_loop_test(tc, moving_wall_exact, 2, 4);
    tcase_add_loop_test(tc, moving_wall_pushes, 2, 4);
    tcase_add_loop_test(tc, validation, 2, 4);
    tcase_add_loop_test(tc, remove_wall_keeps_others, 2, 4);
    tcase_add_loop_test(tc, set_fields, 2, 4);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
