/* Clumps: free rotation by Euler's equations (4-42).
 *
 * The body: four spheres at (+-a, 0, 0) and (0, +-b, 0), a > b, so its
 * principal axes are the template's x, y, z with I1 < I2 < I3 (x: the
 * minor, y: the intermediate, z: the major axis). No gravity, no contact.
 *
 * Closed form (Landau & Lifshitz, Mechanics, section 37). With energy E and
 * angular momentum M, for M^2 > 2 E I2
 *     w2 = sqrt((2 E I3 - M^2) / (I2 (I3 - I2))) sn(tau, k),
 *     tau = t sqrt((I3 - I2)(M^2 - 2 E I1) / (I1 I2 I3)),
 *     k^2 = (I2 - I1)(2 E I3 - M^2) / ((I3 - I2)(M^2 - 2 E I1)),
 * and the same with indices 1 and 3 exchanged for M^2 < 2 E I2. Started
 * near the intermediate axis, w2 changes sign every 2 K(k) in tau: the
 * body flips over (the Dzhanibekov effect). Near the separatrix K grows
 * like ln(4 / k'), so a relative energy error e shifts the flip interval by
 * about e (I2 w^2 / (M^2 - 2 E I2)) / ln(4 / k'): with e ~ 1e-6 and the
 * perturbation below, well under 1e-3; the integrator's own phase error is
 * O((w dt)^2) ~ 4e-6 per unit of tau, over 2 K ~ 20 units. The flip
 * interval must match 2 K / rate within 1e-3.
 *
 * Conservation: the drift of the scheme is a product of rotations about
 * body axes, each leaving L in space unchanged, so |L| is conserved to
 * round-off; the energy error of a symplectic second-order map is bounded,
 * O((w dt)^2) ~ 1e-6 here, with no drift. Both must stay within 1e-4
 * relative over 1e5 steps (the bound).
 *
 * About the major or the minor axis the motion is stable: with the same
 * perturbation the body axis stays within a few times the perturbation of
 * L's direction. */
#include "clump_test.h"

static const double R = 0.01, A = 0.03, B = 0.02, RHO = 2500;

static sx_model *jack(int *tpl)
{
    sx_model *m = ct_model(3, 0, 1e7, 0.5, RHO, 0);
    const double pos[12] = {A, 0, 0, -A, 0, 0, 0, B, 0, 0, -B, 0}, rad[4] = {R, R, R, R};
    *tpl = ct_template(m, "jack", pos, rad, 4);
    return m;
}

/* K(k) by the arithmetic-geometric mean: K = pi / (2 agm(1, k')). */
static double ellip_k(double k2)
{
    double a = 1, g = sqrt(1 - k2);
    for (int i = 0; i < 60 && fabs(a - g) > 1e-16 * a; i++) {
        const double an = 0.5 * (a + g);
        g = sqrt(a * g);
        a = an;
    }
    return V_PI / (2 * a);
}

/* Body-frame components (template axes) of a space vector, for orientation q. */
static void to_body(const double *q, const double *v, double *out)
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double Rm[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (int i = 0; i < 3; i++) out[i] = Rm[i] * v[0] + Rm[3 + i] * v[1] + Rm[6 + i] * v[2];
}

typedef struct run {
    double ke_dev, l_dev;        /* largest relative deviations from the start */
    double flips[64];            /* times w_b along `axis` changed sign */
    int nflips;
    double min_align;            /* smallest |body axis . L / |L|| */
    double principal[3];
    double ke0, l0;
} run;

/* Spins the jack at w0 about template axis `axis` with the other two
 * components eps w0 (identity orientation: template = space axes), for
 * `steps` steps of w0 dt = wdt, sampling every `every` steps. */
static run spin(int axis, double eps, double wdt, int64_t steps, int every)
{
    int t;
    sx_model *m = jack(&t);
    const double w0 = 10.0, dt = wdt / w0;
    double w[3] = {eps * w0, eps * w0, eps * w0};
    w[axis] = w0;
    const double zero[3] = {0, 0, 0};
    const int64_t id = ct_clump(m, t, zero, NULL, NULL, w);
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
    run o;
    memset(&o, 0, sizeof o);
    ck_assert(sx_clump_inertia(m, id, o.principal, NULL) == SX_OK);
    double L[3];
    ct_vec(m, id, SX_CLUMP_ANGULAR_MOMENTUM, L);
    o.l0 = v_norm(L, 3);
    o.ke0 = sx_model_energy(m).kinetic;
    o.min_align = 1;
    double prev = NAN, tprev = NAN;
    for (int64_t s = 0; s < steps; s += every) {
        v_step(m, every);
        const double ke = sx_model_energy(m).kinetic;
        ct_vec(m, id, SX_CLUMP_ANGULAR_MOMENTUM, L);
        o.ke_dev = fmax(o.ke_dev, fabs(ke - o.ke0) / o.ke0);
        o.l_dev = fmax(o.l_dev, fabs(v_norm(L, 3) - o.l0) / o.l0);
        double q[4], ws[3], wb[3], Lb[3];
        V_CHECK(sx_clump_orientation(m, id, q) == SX_OK, "orientation");
        ct_vec(m, id, SX_CLUMP_SPIN, ws);
        to_body(q, ws, wb);
        to_body(q, L, Lb);
        o.min_align = fmin(o.min_align, fabs(Lb[axis]) / v_norm(Lb, 3));
        /* the spin is a half-step value: it belongs to t - dt/2 */
        const double tw = sx_model_time(m) - 0.5 * dt;
        if (prev == prev && (prev > 0) != (wb[axis] > 0) && o.nflips < 64)
            o.flips[o.nflips++] = tprev + (tw - tprev) * prev / (prev - wb[axis]);
        prev = wb[axis], tprev = tw;
    }
    sx_model_destroy(m);
    return o;
}

/* The flip interval of the closed form for w = w0 e2 + eps w0 (e1 + e3). */
static double flip_interval(const double *I, double eps)
{
    const double w0 = 10.0, w[3] = {eps * w0, w0, eps * w0};
    double E2 = 0, M2 = 0;
    for (int k = 0; k < 3; k++) E2 += I[k] * w[k] * w[k], M2 += I[k] * I[k] * w[k] * w[k];
    double I1 = I[0], I3 = I[2];
    if (M2 < E2 * I[1]) I1 = I[2], I3 = I[0]; /* the other side of the separatrix: 1 and 3 exchanged */
    const double I2 = I[1];
    const double rate = sqrt((I3 - I2) * (M2 - E2 * I1) / (I1 * I2 * I3));
    const double k2 = (I2 - I1) * (E2 * I3 - M2) / ((I3 - I2) * (M2 - E2 * I1));
    return 2 * ellip_k(k2) / rate;
}

START_TEST(intermediate_axis_flips)
{
    const double eps = 1e-3;
    const run o = spin(1, eps, 2e-3, 100000, 5);
    const double expect = flip_interval(o.principal, eps);
    printf("intermediate axis: %d flips in 1e5 steps; kinetic energy within %.2e, |L| within %.2e relative\n",
           o.nflips, o.ke_dev, o.l_dev);
    ck_assert_msg(o.nflips >= 4, "only %d flips (expected one every %g s)", o.nflips, expect);
    double worst = 0;
    for (int k = 1; k < o.nflips; k++) {
        const double e = fabs((o.flips[k] - o.flips[k - 1]) - expect) / expect;
        printf("  flip interval %d: %.6f s (closed form %.6f s, %.2e relative)\n", k, o.flips[k] - o.flips[k - 1],
               expect, e);
        worst = fmax(worst, e);
    }
    ck_assert_msg(worst < 1e-3, "flip interval off the closed form by %g relative", worst);
    ck_assert_msg(o.ke_dev < 1e-4, "kinetic energy deviates by %g relative", o.ke_dev);
    ck_assert_msg(o.l_dev < 1e-4, "|L| deviates by %g relative", o.l_dev);
}
END_TEST

START_TEST(major_axis_stable)
{
    const run o = spin(2, 1e-3, 2e-3, 100000, 50);
    printf("major axis: body axis within %.2e rad of L; no flip (%d); kinetic energy %.2e, |L| %.2e relative\n",
           acos(o.min_align), o.nflips, o.ke_dev, o.l_dev);
    ck_assert_int_eq(o.nflips, 0);
    ck_assert_msg(acos(o.min_align) < 1e-2, "the major axis wandered %g rad from L", acos(o.min_align));
    ck_assert(o.ke_dev < 1e-4 && o.l_dev < 1e-4);
}
END_TEST

START_TEST(minor_axis_stable)
{
    const run o = spin(0, 1e-3, 2e-3, 100000, 50);
    printf("minor axis: body axis within %.2e rad of L; no flip (%d); kinetic energy %.2e, |L| %.2e relative\n",
           acos(o.min_align), o.nflips, o.ke_dev, o.l_dev);
    ck_assert_int_eq(o.nflips, 0);
    ck_assert_msg(acos(o.min_align) < 1e-2, "the minor axis wandered %g rad from L", acos(o.min_align));
    ck_assert(o.ke_dev < 1e-4 && o.l_dev < 1e-4);
}
END_TEST

/* A torque applied through a pebble's applied force changes L by exactly
 * M dt per step (the kick of 4-47 for L), whatever the orientation. */
START_TEST(torque_kick)
{
    int t;
    sx_model *m = jack(&t);
    const double zero[3] = {0, 0, 0}, w[3] = {1, 2, -3};
    const int64_t id = ct_clump(m, t, zero, NULL, NULL, w);
    const double dt = 1e-4;
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
    int64_t peb[4], np;
    ck_assert(sx_clump_pebbles(m, id, peb, 4, &np) == SX_OK);
    /* equal and opposite forces on two opposite pebbles: a pure couple */
    double L0[3], x0[3], x1[3];
    ct_vec(m, id, SX_CLUMP_ANGULAR_MOMENTUM, L0);
    const double f[3] = {0, 0, 2.0}, mf[3] = {0, 0, -2.0};
    ck_assert(sx_ball_set_vec(m, peb[0], SX_BALL_APPLIED_FORCE, f) == SX_OK);
    ck_assert(sx_ball_set_vec(m, peb[1], SX_BALL_APPLIED_FORCE, mf) == SX_OK);
    v_get(m, peb[0], SX_BALL_POS, x0);
    v_get(m, peb[1], SX_BALL_POS, x1);
    double arm[3], M[3];
    for (int k = 0; k < 3; k++) arm[k] = x0[k] - x1[k];
    M[0] = arm[1] * f[2] - arm[2] * f[1], M[1] = arm[2] * f[0] - arm[0] * f[2], M[2] = arm[0] * f[1] - arm[1] * f[0];
    v_step(m, 1);
    double L1[3], mo[3], v[3];
    ct_vec(m, id, SX_CLUMP_ANGULAR_MOMENTUM, L1);
    ct_vec(m, id, SX_CLUMP_MOMENT, mo);
    ct_vec(m, id, SX_CLUMP_VEL, v);
    for (int k = 0; k < 3; k++) {
        ck_assert_double_eq_tol(mo[k], M[k], 1e-12);
        ck_assert_double_eq_tol(L1[k] - L0[k], M[k] * dt, 1e-15);
        ck_assert_double_eq_tol(v[k], 0, 1e-15); /* no net force */
    }
    sx_model_destroy(m);
}
END_TEST

/* 2D: a free clump turns at a constant rate (4-47 about z with no moment),
 * and its pebbles keep their distances to the centroid. */
START_TEST(free_spin_2d)
{
    sx_model *m = ct_model(2, 0, 1e7, 0.5, RHO, 0);
    const double pos[6] = {0, 0, 0.025, 0, 0, 0.02}, rad[3] = {0.01, 0.008, 0.006};
    const int t = ct_template(m, "tri", pos, rad, 3);
    const double c[3] = {0.5, 0.2, 0}, w[3] = {7, 0, 0}, vel[3] = {0.1, -0.2, 0};
    const int64_t id = ct_clump(m, t, c, NULL, vel, w);
    const double dt = 1e-4;
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
    double q0[4];
    ck_assert(sx_clump_orientation(m, id, q0) == SX_OK);
    const double e0 = sx_model_energy(m).kinetic;
    v_step(m, 1000);
    double q[4], x[3];
    ck_assert(sx_clump_orientation(m, id, q) == SX_OK);
    ct_vec(m, id, SX_CLUMP_POS, x);
    const double angle = 2 * atan2(q[3], q[0]), expect = remainder(7 * 1000 * dt, 2 * V_PI);
    ck_assert_double_eq_tol(angle, expect, 1e-12);
    ck_assert_double_eq_tol(x[0], 0.5 + 0.1 * 1000 * dt, 1e-13);
    ck_assert_double_eq_tol(sx_model_energy(m).kinetic, e0, 1e-14 * e0);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("clump_rotation");
    V_TCASE(s, intermediate_axis_flips);
    V_TCASE(s, major_axis_stable);
    V_TCASE(s, minor_axis_stable);
    V_TCASE(s, torque_kick);
    V_TCASE(s, free_spin_2d);
    return v_run(s);
}
