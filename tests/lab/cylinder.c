/* The cylindrical wall (3D): contact geometry and force, its open ends, the
 * motion of its surface by radial_vel, and the wall's normal load.
 *
 * Closed forms. A cylinder with axis point p, unit axis a, radius Rc and
 * height H holds the balls inside. A ball of radius r whose centre x lies at
 * axial coordinate s = (x - p).a in [0, H] (any s when H = 0) and at distance
 * rho from the axis, rho = |q|, q = (x - p) - s a, is at distance Rc - rho
 * from the surface, so its overlap is Un = r - (Rc - rho) (4-3) and the linear
 * contact gives it the force Kn Un n with n = -q/rho, radially inwards (4-6),
 * Kn = kn_ball kn_wall / (kn_ball + kn_wall) (4-22). The contact point is
 * x - (r - Un/2) n (4-4) on the line through the centre, so the ball feels no
 * moment. A centre beyond an open end (s < 0 or s > H) touches nothing.
 * The radius changes by radial_vel dt every step, so after n steps of dt,
 * Rc(t) = Rc0 + radial_vel t; with dyadic Rc0, radial_vel and dt every sum is
 * exact in binary floating point and the radius is compared with ==.
 * The wall's load (sx_wall_load) is the sum of the normal contact forces,
 * sum Kn Un_i, whatever their directions (for a ring of balls around the
 * axis it is N Kn Un while the resultant force vanishes).
 */
#include "lab.h"

#include <float.h>

static const double KB = 1e8;  /* ball kn = ks (N/m) */
static const double KW = 3e8;  /* wall kn = ks (N/m) */
static const double R = 0.01;  /* ball radius (m) */
static const double UN = 1e-4; /* overlap (m) */

static double kn_series(void) { return KB * KW / (KB + KW); } /* 4-22 */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void unit3(double *v)
{
    const double n = sqrt(dot3(v, v));
    for (int k = 0; k < 3; k++) v[k] /= n;
}

static void cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* An oblique cylinder used by several tests. */
static const double P0[3] = {0.1, -0.2, 0.3};
static const double RC = 0.05, HEIGHT = 0.2;

static sx_wall_def cylinder_def(const double *axis, double radius, double height)
{
    sx_wall_def w = sx_wall_default_def(3);
    w.kind = SX_WALL_CYLINDER;
    memcpy(w.point, P0, sizeof P0);
    memcpy(w.normal, axis, 3 * sizeof *axis);
    w.radius = radius;
    w.height = height;
    w.kn = w.ks = KW;
    return w;
}

/* Two unit vectors e1, e2 completing the unit axis a to an orthonormal frame. */
static void frame(const double *a, double *e1, double *e2)
{
    const double t[3] = {fabs(a[0]) < 0.9 ? 1.0 : 0.0, fabs(a[0]) < 0.9 ? 0.0 : 1.0, 0};
    cross3(a, t, e1);
    unit3(e1);
    cross3(a, e1, e2);
}

/* The centre of a ball at axial coordinate s, distance rho from the axis, in the radial direction at angle th. */
static void place(const double *a, double s, double rho, double th, double *x, double *e)
{
    double e1[3], e2[3];
    frame(a, e1, e2);
    for (int k = 0; k < 3; k++) {
        e[k] = cos(th) * e1[k] + sin(th) * e2[k];
        x[k] = P0[k] + s * a[k] + rho * e[k];
    }
}

typedef struct wall_sum {
    int64_t wall;
    double fn;
    int64_t n;
    double point[3], normal[3];
} wall_sum;

static bool sum_wall(const sx_contact_info *ci, void *ud)
{
    wall_sum *w = ud;
    if (ci->is_wall && ci->b == w->wall) {
        w->fn += ci->fn;
        w->n++;
        memcpy(w->point, ci->point, sizeof w->point);
        memcpy(w->normal, ci->normal, sizeof w->normal);
    }
    return true;
}

/* A ball touching the inside of the cylinder with overlap UN at several
 * radial directions and axial positions gets Kn UN radially inwards; the
 * wall gets exactly the opposite and its load is Kn UN. */
START_TEST(contact_force)
{
    double a[3] = {1, 2, 2};
    unit3(a);
    const double fmag = kn_series() * UN;
    const double tol = 1e-9 * fmag; /* Un = r - (Rc - rho) loses ~log10(Rc/Un) digits to cancellation */
    const double axial[] = {0.01, 0.1, 0.19};
    int checked = 0;
    for (int is = 0; is < 3; is++)
        for (int it = 0; it < 5; it++) {
            const double th = 2 * LAB_PI * it / 5 + 0.3;
            double x[3], e[3];
            place(a, axial[is], RC - (R - UN), th, x, e);
            sx_model *m = scene_model(3, NULL, 1e-9, KB, 0.5, 2650);
            const sx_wall_def w = cylinder_def(a, RC, HEIGHT);
            int64_t wid;
            LAB_OK(m, sx_wall_add(m, &w, &wid));
            const int64_t id = scene_ball(m, x, NULL, R);
            lab_cycle(m, 1);
            double fb[3], mb[3], fw[3];
            LAB_OK(m, sx_ball_get_vec(m, id, SX_BALL_FORCE, fb));
            LAB_OK(m, sx_ball_get_vec(m, id, SX_BALL_MOMENT, mb));
            LAB_OK(m, sx_wall_force(m, wid, fw, NULL));
            for (int k = 0; k < 3; k++) {
                LAB_NEAR(fb[k], -fmag * e[k], tol); /* n = -e: towards the axis */
                ck_assert_double_eq(fw[k], -fb[k]);
                LAB_NEAR(mb[k], 0.0, 1e-12 * fmag * R);
            }
            int64_t nc = -1;
            double kn = 0;
            const double load = lab_load(m, wid, &nc, &kn);
            ck_assert_int_eq(nc, 1);
            LAB_NEAR(load, fmag, tol);
            LAB_NEAR(kn, kn_series(), 1e-12 * kn_series());
            /* the reported contact: normal from the wall to the ball, point on the surface side */
            wall_sum ws = {.wall = wid};
            sx_contact_each(m, sum_wall, &ws);
            ck_assert_int_eq(ws.n, 1);
            for (int k = 0; k < 3; k++) {
                LAB_NEAR(ws.normal[k], -e[k], 1e-12);
                LAB_NEAR(ws.point[k], x[k] + (R - 0.5 * UN) * e[k], 1e-12);
            }
            sx_model_destroy(m);
            checked++;
        }
    printf("cylinder contact: %d positions, force Kn Un = %.6g N radially inwards\n", checked, fmag);
}
END_TEST

/* A ball clear of the surface, or whose centre lies beyond an open end,
 * touches nothing; with height 0 the cylinder is infinite. */
START_TEST(open_ends)
{
    double a[3] = {1, 2, 2};
    unit3(a);
    const double fmag = kn_series() * UN;
    struct {
        double height, s, rho;
        bool touch;
        const char *what;
    } cases[] = {
        {HEIGHT, 0.1, RC - R - 1e-4, false, "clear of the surface"},
        {HEIGHT, HEIGHT + 1e-3, RC - (R - UN), false, "beyond the far end"},
        {HEIGHT, -1e-3, RC - (R - UN), false, "before the near end"},
        {HEIGHT, HEIGHT - 1e-3, RC - (R - UN), true, "just inside the far end"},
        {HEIGHT, 1e-3, RC - (R - UN), true, "just inside the near end"},
        {0.0, 10.0, RC - (R - UN), true, "far along an infinite cylinder"},
        {0.0, -10.0, RC - (R - UN), true, "far behind the point of an infinite cylinder"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double x[3], e[3];
        place(a, cases[c].s, cases[c].rho, 1.0, x, e);
        sx_model *m = scene_model(3, NULL, 1e-9, KB, 0.5, 2650);
        const sx_wall_def w = cylinder_def(a, RC, cases[c].height);
        int64_t wid;
        LAB_OK(m, sx_wall_add(m, &w, &wid));
        const int64_t id = scene_ball(m, x, NULL, R);
        lab_cycle(m, 1);
        double fb[3];
        LAB_OK(m, sx_ball_get_vec(m, id, SX_BALL_FORCE, fb));
        int64_t nc = -1;
        const double load = lab_load(m, wid, &nc, NULL);
        ck_assert_msg(nc == (cases[c].touch ? 1 : 0), "%s: %lld contacts", cases[c].what, (long long)nc);
        ck_assert_int_eq(sx_contact_count(m), cases[c].touch ? 1 : 0);
        const double want = cases[c].touch ? fmag : 0;
        ck_assert_msg(fabs(load - want) <= 1e-9 * fmag, "%s: load %g N, expected %g N", cases[c].what, load, want);
        ck_assert_msg(fabs(sqrt(dot3(fb, fb)) - want) <= 1e-9 * fmag, "%s: |F| = %g N, expected %g N",
                      cases[c].what, sqrt(dot3(fb, fb)), want);
        sx_model_destroy(m);
    }
}
END_TEST

/* radial_vel moves the surface by radial_vel t exactly: the radius after n
 * steps is Rc0 + v n dt (dyadic numbers: exact), and a fixed ball inside
 * feels Kn (r - (Rc(t) - rho)) with the radius of the start of the step;
 * the relative motion is purely normal, so no shear force builds up. A
 * contracting cylinder reaches a ball that was farther than the broad
 * phase's skin, exactly when Rc(t) - rho < r. */
START_TEST(radial_motion)
{
    const double a[3] = {0, 0, 1};
    const double rc0 = 0x1p-4, r = 0x1p-7, dt = 0x1p-20; /* 0.0625 m, 7.8 mm, 0.95 us */
    const double v = _i ? -1.0 : 0x1p-6; /* m/s: 0.95 um or 0.015 um per step */
    const double un0 = _i ? 0 : 0x1p-12;                 /* 0.24 mm */
    sx_model *m = scene_model(3, NULL, dt, KB, 0.5, 2650);
    sx_wall_def w = sx_wall_default_def(3);
    w.kind = SX_WALL_CYLINDER;
    w.normal[0] = a[0], w.normal[1] = a[1], w.normal[2] = a[2];
    w.radius = rc0;
    w.height = 0x1p-2;
    w.kn = w.ks = KW;
    w.friction = 0.5;
    int64_t wid;
    LAB_OK(m, sx_wall_add(m, &w, &wid));
    /* ball 1 touches with overlap un0 (expanding case) or sits 0x1p-10 m clear (contracting case) */
    const double gap1 = _i ? 0x1p-10 : -un0;
    const double x1[3] = {rc0 - r - gap1, 0, 0x1p-3};
    const int64_t b1 = scene_ball(m, x1, NULL, r);
    scene_impose(m, b1, NULL, NULL);
    /* ball 2, opposite, 4 times farther than the automatic skin (0.2 r) */
    const double gap2 = 0.8 * r;
    const double x2[3] = {-(rc0 - r - gap2), 0, 0x1p-3};
    const int64_t b2 = scene_ball(m, x2, NULL, r);
    scene_impose(m, b2, NULL, NULL);
    LAB_OK(m, sx_wall_set_radial_vel(m, wid, v));
    const double kn = kn_series();
    /* contracting: 50 steps past the contact with ball 2 */
    const int nsteps = _i ? (int)(0.8 * r / (-v * dt)) + 50 : 1024;
    int first2 = -1;
    for (int s = 1; s <= nsteps; s++) {
        lab_cycle(m, 1);
        const sx_wall_def got = lab_wall(m, wid);
        LAB_REQUIRE(got.radius == rc0 + v * dt * s, "step %d: radius %.17g, expected %.17g exactly", s, got.radius,
                    rc0 + v * dt * s);
        /* the forces of step s were computed with the radius after s - 1 moves */
        const double rc = rc0 + v * dt * (s - 1);
        double f1[3], f2[3];
        LAB_OK(m, sx_ball_get_vec(m, b1, SX_BALL_FORCE, f1));
        LAB_OK(m, sx_ball_get_vec(m, b2, SX_BALL_FORCE, f2));
        const double u1 = r - (rc - x1[0]), u2 = r - (rc + x2[0]);
        const double w1 = u1 > 0 ? -kn * u1 : 0, w2 = u2 > 0 ? kn * u2 : 0;
        const double tol = 1e-9 * kn * r; /* cancellation in r - (Rc - rho) */
        LAB_REQUIRE(fabs(f1[0] - w1) <= tol && fabs(f2[0] - w2) <= tol,
                    "step %d: radial forces %.12g, %.12g N, expected %.12g, %.12g N", s, f1[0], f2[0], w1, w2);
        LAB_REQUIRE(fabs(f1[1]) <= 1e-12 * kn * r && fabs(f1[2]) <= 1e-12 * kn * r && fabs(f2[1]) <= 1e-12 * kn * r &&
                        fabs(f2[2]) <= 1e-12 * kn * r,
                    "step %d: shear force from a purely radial motion: (%g, %g), (%g, %g) N", s, f1[1], f1[2], f2[1],
                    f2[2]);
        if (first2 < 0 && f2[0] > 0) first2 = s;
    }
    const double t = sx_model_time(m);
    ck_assert_double_eq(t, nsteps * dt);
    ck_assert_double_eq(lab_wall(m, wid).radius, rc0 + v * t);
    if (_i) {
        /* Rc(t) - rho < r first holds after the step at which (s - 1) |v| dt > gap2: the force of step s */
        const int expect = (int)floor(gap2 / (-v * dt)) + 2;
        printf("contracting cylinder: ball beyond the skin first touched at step %d (closed form %d)\n", first2, expect);
        ck_assert_int_eq(first2, expect);
    } else {
        printf("expanding cylinder: radius %.17g m after %d steps = Rc0 + v t exactly\n", lab_wall(m, wid).radius,
               nsteps);
        ck_assert_int_eq(first2, -1);
    }
    sx_model_destroy(m);
}
END_TEST

/* The wall's load is the sum of the normal contact forces: a ring of balls
 * with different overlaps around a cylinder (3D), along a plane (3D) or a
 * line (2D), checked against sum Kn Un_i, against the forces reported by
 * sx_contact_each, and (plane, line) against the resultant's normal component. */
START_TEST(load_is_sum_of_normal_forces)
{
    const int kind = _i; /* 0: 2D line, 1: 3D plane, 2: 3D cylinder */
    const int dim = kind == 0 ? 2 : 3;
    sx_model *m = scene_model(dim, NULL, 1e-9, KB, 0.5, 2650);
    sx_wall_def w = sx_wall_default_def(dim);
    double a[3] = {1, 2, 2};
    unit3(a);
    if (kind == 2) w = cylinder_def(a, RC, HEIGHT);
    w.kn = w.ks = KW;
    int64_t wid;
    LAB_OK(m, sx_wall_add(m, &w, &wid));
    enum { N = 12 };
    double sum = 0;
    for (int i = 0; i < N; i++) {
        const double un = UN * (0.5 + 0.1 * i);
        double x[3] = {0, 0, 0}, e[3];
        if (kind == 2) {
            place(a, 0.02 + 0.013 * i, RC - (R - un), 2 * LAB_PI * i / N, x, e);
        } else {
            x[0] = 3 * R * i;
            x[dim - 1] = R - un;
        }
        scene_ball(m, x, NULL, R);
        sum += kn_series() * un;
    }
    lab_cycle(m, 1);
    int64_t nc = -1;
    double kn = 0;
    const double load = lab_load(m, wid, &nc, &kn);
    ck_assert_int_eq(nc, N);
    LAB_NEAR(kn, kn_series(), 1e-12 * kn_series());
    LAB_NEAR(load, sum, 1e-9 * sum);
    wall_sum ws = {.wall = wid};
    sx_contact_each(m, sum_wall, &ws);
    ck_assert_int_eq(ws.n, N);
    LAB_NEAR(load, ws.fn, 1e-12 * sum);
    double fw[3];
    LAB_OK(m, sx_wall_force(m, wid, fw, NULL));
    if (kind < 2) {
        LAB_NEAR(-fw[dim - 1], load, 1e-12 * sum); /* the resultant on the wall is -load n */
    } else {
        /* the ring's radial forces nearly cancel: the resultant is far below the load */
        printf("cylinder: load %.6g N, |resultant| %.3g N\n", load, sqrt(dot3(fw, fw)));
        ck_assert(sqrt(dot3(fw, fw)) < 0.2 * load);
    }
    /* no contact: zero load, count and stiffness */
    sx_model_destroy(m);
    m = scene_model(dim, NULL, 1e-9, KB, 0.5, 2650);
    LAB_OK(m, sx_wall_add(m, &w, &wid));
    double x[3] = {0, 0, 0};
    if (kind == 2) {
        double e[3];
        place(a, 0.1, 0, 0, x, e);
    } else {
        x[dim - 1] = 2 * R;
    }
    scene_ball(m, x, NULL, R);
    lab_cycle(m, 1);
    nc = -1;
    kn = -1;
    ck_assert_double_eq(lab_load(m, wid, &nc, &kn), 0);
    ck_assert_int_eq(nc, 0);
    ck_assert_double_eq(kn, 0);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("lab_cylinder");
    TCase *tc = tcase_create("cylinder");
    tcase_add_test(tc, contact_force);
    tcase_add_test(tc, open_ends);
    tcase_add_loop_test(tc, radial_motion, 0, 2);
    tcase_add_loop_test(tc, load_is_sum_of_normal_forces, 0, 3);
    suite_add_tcase(s, tc);
    return lab_run(s);
}
