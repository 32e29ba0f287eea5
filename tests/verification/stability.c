/* Verification: the stability guard against a known exact critical timestep,
 * 2D and 3D.
 *
 * Closed form. Leapfrog applied to x'' = -omega^2 x gives
 *     x_{n+1} - (2 - h^2) x_n + x_{n-1} = 0,   h = omega dt,
 * whose roots z satisfy z^2 - (2 - h^2) z + 1 = 0: |z| = 1 for h <= 2 and
 * |z1| = ((h^2 - 2) + sqrt((h^2 - 2)^2 - 4))/2 > 1 for h > 2. So
 * dt_crit = 2/omega exactly, and a linear system with the largest
 * eigenfrequency omega_max is stable iff dt <= 2/omega_max.
 *
 * Systems, all without gravity; in (a) and (b) without friction and shear
 * stiffness, so that only the normal springs act and the system is exactly
 * linear while every contact stays closed:
 *  (a) one ball pressed between two parallel walls (normal n, not along an
 *      axis) with overlap U0 on both: omega^2 = 2 Kn/m;
 *  (b) two equal balls in a row between two walls, all three contacts of the
 *      same Kn and overlap U0: stiffness matrix Kn [[2,-1],[-1,2]],
 *      omega^2 in {Kn/m, 3 Kn/m}, so dt_crit = 2/sqrt(3 Kn/m). A compressed
 *      frictionless chain buckles (a physical instability), so the balls'
 *      transverse velocities are fixed; the row is along x for that.
 *  (c) one ball between the two walls of (a), now with shear springs and a
 *      friction (1000) that never slips, set spinning about an axis in the
 *      walls' plane: the spin does not couple to the normal or to the
 *      translation, and the rotational stiffness is 2 Ks R'^2 with the
 *      lever arm R' = R - U0/2 of the contact force: omega^2 = 2 Ks R'^2/I
 *      (I = 2/5 m R^2 sphere, 1/2 m R^2 disk). No overlap changes: this
 *      is the energy guard's case (an unforced system whose energy grows by
 *      more than 100 times its initial scale; it looks every 64 steps).
 * In (a) and (b) the preload U0 is chosen so that the overlap guard
 * (overlap > radius) trips before any contact can open: the motion stays
 * linear up to the trip.
 *
 * Assertions:
 *  - at dt = 0.9 dt_crit, 1e5 steps run without error and the amplitude
 *    stays at its exact discrete value C = v0/(omega sqrt(1 - h^2/4)) (the
 *    leapfrog invariant; tolerance 1e-9 relative), both stepping one step
 *    per cycle call and in a single cycle call;
 *  - at dt = 1.2 dt_crit the run stops with SX_EUNSTABLE, a message naming
 *    the timestep, within ceil(ln(limit/|a|)/ln|z1|) + 2 steps, where
 *    x_n = a (z1^n - z2^n), a = v0 dt/(z1 - z2), grows to the excursion
 *    `limit` at which an overlap exceeds a radius ((a), (b)) or at which the
 *    spring energy exceeds 100 times the initial energy ((c), plus the 64
 *    steps between two looks of the energy guard);
 *  - at dt = 100 dt_crit the same, at once (no silent NaN);
 *  - at 1.2 dt_crit again, driving the model one step per cycle call (as a
 *    script that records a history every step does): the same bound;
 *  - after the error the model is inspectable: positions are readable and
 *    finite (the guard fires before the state is corrupted), and cycling on
 *    either stops again or keeps a finite state (never silent NaNs).
 */
#include "verify.h"

#include <stdbool.h>
#include <string.h>

static const double R = 0.01, RHO = 2650, KB = 1e6;

typedef struct chain {
    sx_model *m;
    int kind, nb; /* kind: 1 ball between walls, 2 two balls between walls, 0 spinning ball between walls */
    int64_t id[2];
    double n[3], x0[2][3], axis[3];
    double omega, v0, limit; /* fastest mode; initial speed (spin); excursion at which the guard must trip */
    int64_t slack;           /* steps the guard may take to look */
} chain;

static void normal_dir(int dim, double *n)
{
    n[0] = n[1] = n[2] = 0;
    if (dim == 3)
        n[0] = 2.0 / 3, n[1] = -1.0 / 3, n[2] = 2.0 / 3;
    else
        n[0] = 0.8, n[1] = -0.6;
}

static chain build(int dim, int kind)
{
    chain c;
    memset(&c, 0, sizeof c);
    c.kind = kind;
    const int nb = kind == 2 ? 2 : 1;
    c.nb = nb;
    sx_model_def def = sx_model_default_def();
    def.dim = dim;
    char err[256];
    c.m = sx_model_create(&def, err, sizeof err);
    ck_assert_msg(c.m != NULL, "%s", err);
    sx_material_def md = sx_material_default_def();
    md.density = RHO, md.kn = KB, md.ks = kind == 0 ? KB : 0, md.friction = kind == 0 ? 1000 : 0;
    const int mat = scene_material_def(c.m, "m", &md);
    normal_dir(dim, c.n);
    if (nb == 2) c.n[0] = 1, c.n[1] = c.n[2] = 0; /* axis-aligned so that the fixities below apply */
    const double centre[3] = {0.05, 0.02, -0.03};
    const double mass = dim == 3 ? RHO * 4.0 / 3.0 * V_PI * R * R * R : RHO * V_PI * R * R;
    double kn, u0, wall_at;
    if (nb == 1) {
        /* wall kn = 3 KB: Kn = 3/4 KB on both contacts; U0 = 0.6 R: the
         * compressed side passes the radius at |x| = 0.4 R, the other side
         * would open only at 0.6 R */
        kn = KB * 3 * KB / (4 * KB);
        u0 = 0.6 * R;
        wall_at = R - u0;
        c.omega = sqrt(2 * kn / mass);
        c.limit = R - u0;
        for (int k = 0; k < 3; k++) c.x0[0][k] = k < dim ? centre[k] : 0;
    } else {
        /* wall kn = KB: every contact has Kn = KB/2; U0 = 0.7 R. In the fast
         * (antisymmetric) mode the balls move by -/+x: the ball-ball overlap
         * U0 + 2|x| passes R at |x| = 0.15 R, the wall overlaps U0 + |x| at
         * 0.3 R, before any contact opens (ball-ball at 0.35 R). */
        kn = KB / 2;
        u0 = 0.7 * R;
        const double half = R - u0 / 2; /* ball centres at -/+ half */
        wall_at = half + R - u0;
        c.omega = sqrt(3 * kn / mass);
        c.limit = 0.15 * R;
        for (int k = 0; k < 3; k++) {
            c.x0[0][k] = k < dim ? centre[k] - half * c.n[k] : 0;
            c.x0[1][k] = k < dim ? centre[k] + half * c.n[k] : 0;
        }
    }
    double p[3], mn[3];
    for (int k = 0; k < 3; k++) {
        p[k] = k < dim ? centre[k] - wall_at * c.n[k] : 0;
        mn[k] = -c.n[k];
    }
    const double kw = nb == 1 ? 3 * KB : KB, mu_w = kind == 0 ? 1000 : 0;
    scene_halfspace(c.m, p, c.n, kw, kind == 0 ? kw : 0, mu_w);
    for (int k = 0; k < dim; k++) p[k] = centre[k] + wall_at * c.n[k];
    scene_halfspace(c.m, p, mn, kw, kind == 0 ? kw : 0, mu_w);
    double spin[3] = {0, 0, 0};
    if (kind == 0) {
        /* spin about an axis in the walls' plane (2D: about z, always in it) */
        const double inertia = (dim == 3 ? 0.4 : 0.5) * mass * R * R, arm = R - u0 / 2;
        c.omega = sqrt(2 * kn * arm * arm / inertia);
        if (dim == 3)
            c.axis[0] = 1.0 / sqrt(2.0), c.axis[2] = -1.0 / sqrt(2.0); /* n . axis = 0 */
        else
            c.axis[0] = 1;
        c.v0 = 0.02 * c.omega; /* rad/s: rotation amplitude ~0.02 rad */
        for (int k = 0; k < 3; k++) spin[k] = c.v0 * c.axis[k];
        /* energy guard: the shear springs' energy 1/2 (2 Ks arm^2) theta^2 passes
         * 100 times the initial energy (spin + preload strain) */
        const double e0 = 0.5 * inertia * c.v0 * c.v0 + kn * u0 * u0;
        c.limit = sqrt(2 * 100 * e0 / (2 * kn * arm * arm));
        c.slack = 64;
    }
    /* the fast mode: one ball along n; two balls towards each other */
    if (kind != 0) c.v0 = 0.02 * R * c.omega;
    for (int i = 0; i < nb; i++) {
        double v[3] = {0, 0, 0};
        const double sgn = nb == 1 ? 1 : (i == 0 ? 1 : -1);
        for (int k = 0; k < dim; k++) v[k] = kind == 0 ? 0 : sgn * c.v0 * c.n[k];
        c.id[i] = scene_ball_full(c.m, c.x0[i], v, spin, R, mat);
        /* a compressed frictionless chain buckles sideways (physically): hold it in line */
        if (nb == 2)
            ck_assert_msg(sx_ball_set_fixity(c.m, c.id[i], dim == 3 ? SX_FIX_VY | SX_FIX_VZ : SX_FIX_VY) == SX_OK, "%s",
                          sx_model_error(c.m));
    }
    ck_assert_double_eq_tol(v_scalar(c.m, c.id[0], SX_BALL_MASS), mass, 1e-14 * mass);
    return c;
}

/* Excursion of ball 0 along n from its initial position; kind 0: its spin about the axis. */
static double excursion(const chain *c)
{
    const int dim = sx_model_dim(c->m);
    double x[3], r[3];
    if (c->kind == 0) {
        v_get(c->m, c->id[0], SX_BALL_SPIN, x);
        return dim == 3 ? v_dot(x, c->axis, 3) : x[0];
    }
    v_get(c->m, c->id[0], SX_BALL_POS, x);
    for (int k = 0; k < dim; k++) r[k] = x[k] - c->x0[0][k];
    return v_dot(r, c->n, dim);
}

static const char *name(int kind)
{
    return kind == 1 ? "ball between walls" : kind == 2 ? "two balls between walls" : "spinning ball between walls";
}

static void check_stable(int dim, int kind)
{
    chain c = build(dim, kind);
    const double dt_crit = 2 / c.omega, dt = 0.9 * dt_crit, h = c.omega * dt;
    ck_assert(sx_model_set_timestep(c.m, dt) == SX_OK);
    /* x_n = C sin(n Omega dt), C = v0/(omega sqrt(1 - h^2/4)); the spin (a
     * half-step velocity) peaks at C omega */
    const double amp = c.v0 / (c.omega * sqrt(1 - h * h / 4)) * (kind == 0 ? c.omega : 1);
    double worst = 0;
    for (int s = 0; s < 100000; s++) {
        const sx_status st = sx_model_cycle(c.m, 1);
        V_CHECK(st == SX_OK, "%dD %s at 0.9 dt_crit: step %d failed: %s", dim, name(kind), s, sx_model_error(c.m));
        worst = fmax(worst, fabs(excursion(&c)));
    }
    const char *unit = kind == 0 ? "rad/s" : "m";
    printf(
        "stability %dD %s: 1e5 steps at 0.9 dt_crit (dt_crit = %.4e s, automatic estimate %.4e s): amplitude %.9e %s, "
        "exact discrete %.9e %s (rel err %.1e)\n",
        dim, name(kind), dt_crit, sx_model_critical_timestep(c.m), worst, unit, amp, unit, worst / amp - 1);
    ck_assert_msg(worst <= amp * (1 + 1e-9) && worst >= amp * (1 - 1e-3),
                  "%dD %s at 0.9 dt_crit: amplitude %.9e m, the leapfrog invariant gives %.9e m", dim, name(kind),
                  worst, amp);
    sx_model_destroy(c.m);
    /* the same 1e5 steps in one cycle call, from the start (the guard takes its
     * energy baseline on the preloaded state) */
    c = build(dim, kind);
    ck_assert(sx_model_set_timestep(c.m, dt) == SX_OK);
    const sx_status st = sx_model_cycle(c.m, 100000);
    ck_assert_msg(st == SX_OK, "%dD %s at 0.9 dt_crit, one cycle call: status %d after %lld steps: %s", dim, name(kind),
                  (int)st, (long long)sx_model_step_count(c.m), sx_model_error(c.m));
    ck_assert_msg(fabs(excursion(&c)) <= amp * (1 + 1e-9), "%dD %s: excursion %g beyond the invariant %g", dim,
                  name(kind), fabs(excursion(&c)), amp);
    sx_model_destroy(c.m);
}

/* one_at_a_time: drive the model with cycle(1) calls, as a script recording a
 * history every step does; the guard must work the same way. */
static void check_unstable(int dim, int kind, double factor, bool one_at_a_time)
{
    chain c = build(dim, kind);
    const double dt_crit = 2 / c.omega, dt = factor * dt_crit, h = c.omega * dt;
    ck_assert(sx_model_set_timestep(c.m, dt) == SX_OK);
    const double b = h * h - 2, z1 = -(b + sqrt(b * b - 4)) / 2, z2 = 1 / z1;
    const double a = c.v0 * dt / (z1 - z2);
    const double n_trip = log(c.limit / fabs(a)) / log(fabs(z1));
    const int64_t bound = (int64_t)ceil(fmax(n_trip, 0)) + 2 + c.slack;
    sx_status st = SX_OK;
    if (one_at_a_time)
        for (int q = 0; q < 100000 && st == SX_OK; q++) st = sx_model_cycle(c.m, 1);
    else
        st = sx_model_cycle(c.m, 100000);
    const int64_t steps = sx_model_step_count(c.m);
    const char *msg = sx_model_error(c.m);
    printf("stability %dD %s at %g dt_crit%s: status %d after %lld steps (bound %lld): \"%s\"\n", dim, name(kind),
           factor, one_at_a_time ? ", one step per cycle call" : "", (int)st, (long long)steps, (long long)bound, msg);
    ck_assert_msg(st == SX_EUNSTABLE, "%dD %s at %g dt_crit: status %d, expected SX_EUNSTABLE (%s)", dim, name(kind),
                  factor, (int)st, msg);
    ck_assert_msg(strstr(msg, "timestep") != NULL, "the message does not mention the timestep: \"%s\"", msg);
    ck_assert_msg(steps <= bound, "%dD %s at %g dt_crit: the guard tripped after %lld steps, expected <= %lld", dim,
                  name(kind), factor, (long long)steps, (long long)bound);
    /* inspectable: positions and velocities readable and finite */
    for (int i = 0; i < c.nb; i++) {
        double x[3], v[3];
        ck_assert(sx_ball_get_vec(c.m, c.id[i], SX_BALL_POS, x) == SX_OK);
        ck_assert(sx_ball_get_vec(c.m, c.id[i], SX_BALL_VEL, v) == SX_OK);
        for (int k = 0; k < dim; k++)
            ck_assert_msg(isfinite(x[k]) && isfinite(v[k]), "ball %d: non-finite state after the guard", i);
    }
    const sx_energy e = sx_model_energy(c.m);
    ck_assert(isfinite(e.kinetic) && isfinite(e.strain));
    /* cycling on after the error never produces silent NaNs: either the guard
     * stops it again or the state stays finite (the energy guard measures
     * growth from the start of each cycle call, so it may accept a state that
     * is already wrong but no longer growing) */
    const sx_status again = sx_model_cycle(c.m, 200);
    for (int i = 0; i < c.nb; i++) {
        double x[3], v[3], w[3];
        v_get(c.m, c.id[i], SX_BALL_POS, x);
        v_get(c.m, c.id[i], SX_BALL_VEL, v);
        v_get(c.m, c.id[i], SX_BALL_SPIN, w);
        for (int k = 0; k < dim; k++)
            ck_assert_msg(again == SX_EUNSTABLE || (isfinite(x[k]) && isfinite(v[k]) && isfinite(w[k])),
                          "cycling on after the guard returned %d with a non-finite state", (int)again);
    }
    if (again == SX_EUNSTABLE)
        ck_assert_msg(strstr(sx_model_error(c.m), "timestep") != NULL, "%s", sx_model_error(c.m));
    sx_model_destroy(c.m);
}

START_TEST(stable_below_critical)
{
    for (int d = 2; d <= 3; d++)
        for (int kind = 0; kind <= 2; kind++) check_stable(d, kind);
}
END_TEST

START_TEST(guard_above_critical)
{
    for (int d = 2; d <= 3; d++)
        for (int kind = 0; kind <= 2; kind++) check_unstable(d, kind, 1.2, false);
}
END_TEST

START_TEST(guard_huge_timestep)
{
    for (int d = 2; d <= 3; d++)
        for (int kind = 0; kind <= 2; kind++) check_unstable(d, kind, 100, false);
}
END_TEST

/* The same, stepping with one cycle call per step: the energy guard's case. */
START_TEST(guard_one_step_per_call)
{
    for (int d = 2; d <= 3; d++)
        for (int kind = 0; kind <= 2; kind++) check_unstable(d, kind, 1.2, true);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("stability");
    V_TCASE(s, stable_below_critical);
    V_TCASE(s, guard_above_critical);
    V_TCASE(s, guard_huge_timestep);
    V_TCASE(s, guard_one_step_per_call);
    return v_run(s);
}
