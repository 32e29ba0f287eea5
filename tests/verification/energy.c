/* Verification: energy conservation of an undamped elastic system, the
 * exactness of leapfrog for a constant force, and the library's strain
 * energy report.
 *
 * 1. Balls bouncing in a closed box of one-sided walls, gravity on, no
 *    friction, no damping. The continuum conserves
 *        E = sum 1/2 m v^2 + 1/2 I w^2 - m g.x + sum 1/2 Kn Un^2.
 *    E is evaluated at whole steps with synchronous velocities
 *    v_n = (v_{n-1/2} + v_{n+1/2})/2 and with the strain energy computed here
 *    from the positions (independent of the library's report).
 *    Error theory for leapfrog, h = omega0 dt of a contact:
 *      - free flight under gravity is exact (a constant force is integrated
 *        exactly), so all error comes from contacts;
 *      - inside a linear contact the numerical solution is an exact sampled
 *        sine; E_n oscillates by at most (h^2/4) E_rel (E_rel: the kinetic
 *        energy of the pair's relative normal motion);
 *      - the force has a kink at Un = 0 and contact starts and ends at a
 *        fraction g of a step: each contact leaves a permanent error
 *        h^2 [(1/2 - g_in)^2 - (1/2 - g_out)^2] E_rel, |.| <= (h^2/4) E_rel,
 *        of pseudo-random sign (the phases g are not controlled).
 *    Hence (a) drift = max_n |E_n - E_0| <= (h^2/4) (N_contacts + 1) S for
 *    every run, S the kinetic energy plus the potential energy above the
 *    balls' lowest positions (a bound on any E_rel); and (b) drift = h^2 C
 *    with C a random variable of the phases whose distribution does not
 *    depend on h: a single run's ratio drift(dt)/drift(dt/2) is 4 times a
 *    ratio of two draws of C, but the ratio of the means over an ensemble of
 *    initial conditions converges to 4 (plus an O(h) correction from the
 *    next order). Measured on 8 disjoint ensembles at h = 0.063 / 0.031:
 *    2D, 64 runs: 4.3 ... 4.7; 3D, 24 runs: 3.8 ... 4.1; so the ratio of the
 *    ensemble means is asserted in [3, 5].
 *
 * 2. Free fall: leapfrog stores the velocity of the middle of each step, so
 *    the velocity given at the start is v(-dt_0/2), and with
 *        x(t) = x0 + u t + g t^2/2,  u = v_init + g dt_0/2,
 *    the positions x(t_n) and the mid-step velocities u + g (t_n - dt_{n-1}/2)
 *    are reproduced exactly, for any sequence of timesteps, when the kick
 *    between two half-step velocities spans the time between them,
 *    (dt_{n-1} + dt_n)/2. Tolerance: round-off (1e-12 relative).
 *
 * 3. The library's strain energy equals 1/2 Kn Un^2 of the current
 *    positions, at every step of an impact (round-off tolerance).
 */
#include "verify.h"

#include <stdbool.h>
#include <string.h>

enum { NB = 6 };

static const double RHO = 2650, G = 9.81;

typedef struct box {
    sx_model *m;
    int dim;
    int64_t id[NB];
    double mass[NB], inertia[NB], rad[NB];
    double lo[3], hi[3];
    double kn_bb, kn_bw; /* contact stiffnesses (springs in series) */
    double g[3];
    double omega_max; /* largest omega0 over the possible contacts */
} box;

static double lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* Six balls (radii 8 ... 12 mm) in a 0.1 m box, jittered positions and
 * random velocities up to 1.2 m/s per component drawn from seed. The 3D
 * stiffness is lower so that both dimensions have similar contact times. */
static void box_build(box *b, int dim, uint64_t seed)
{
    memset(b, 0, sizeof *b);
    b->dim = dim;
    b->g[dim - 1] = -G;
    const double kn_ball = dim == 3 ? 1.5e5 : 1e7, kn_wall = 2 * kn_ball;
    b->m = scene_model(dim, b->g, 0, kn_ball, 0.0, RHO); /* no friction */
    for (int k = 0; k < 3; k++) b->lo[k] = 0, b->hi[k] = k < dim ? 0.1 : 0;
    scene_box_walls(b->m, b->lo, b->hi, kn_wall, 0.0);
    b->kn_bb = kn_ball / 2;
    b->kn_bw = kn_ball * kn_wall / (kn_ball + kn_wall);
    uint64_t s = seed * 7919 + 17;
    for (int i = 0; i < NB; i++) {
        const double r = 0.008 + 0.0008 * i;
        double pos[3] = {0.02 + 0.03 * (i % 3) + 0.004 * (lcg(&s) - 0.5),
                         0.03 + 0.04 * (i / 3) + 0.004 * (lcg(&s) - 0.5), 0};
        if (dim == 3) {
            pos[1] = 0.05 + 0.02 * ((i + 1) % 2) + 0.002 * (lcg(&s) - 0.5);
            pos[2] = 0.03 + 0.04 * (i / 3) + 0.004 * (lcg(&s) - 0.5);
        }
        double vel[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++) vel[k] = 2.4 * (lcg(&s) - 0.5);
        b->id[i] = scene_ball(b->m, pos, vel, r);
        b->rad[i] = r;
        b->mass[i] = v_scalar(b->m, b->id[i], SX_BALL_MASS);
        b->inertia[i] = v_scalar(b->m, b->id[i], SX_BALL_INERTIA);
    }
    for (int i = 0; i < NB; i++) {
        b->omega_max = fmax(b->omega_max, sqrt(b->kn_bw / b->mass[i]));
        for (int j = i + 1; j < NB; j++) {
            const double ms = b->mass[i] * b->mass[j] / (b->mass[i] + b->mass[j]);
            b->omega_max = fmax(b->omega_max, sqrt(b->kn_bb / ms));
        }
    }
}

/* Strain energy 1/2 Kn Un^2 from positions x. */
static double strain(const box *b, double x[NB][3])
{
    const int d = b->dim;
    double e = 0;
    for (int i = 0; i < NB; i++) {
        for (int j = i + 1; j < NB; j++) {
            double r[3];
            for (int k = 0; k < d; k++) r[k] = x[j][k] - x[i][k];
            const double un = b->rad[i] + b->rad[j] - v_norm(r, d);
            if (un > 0) e += 0.5 * b->kn_bb * un * un;
        }
        for (int k = 0; k < d; k++) {
            const double lo = b->rad[i] - (x[i][k] - b->lo[k]), hi = b->rad[i] - (b->hi[k] - x[i][k]);
            if (lo > 0) e += 0.5 * b->kn_bw * lo * lo;
            if (hi > 0) e += 0.5 * b->kn_bw * hi * hi;
        }
    }
    return e;
}

typedef struct drift {
    double drift; /* max |E_n - E_0| / S */
    double h;     /* omega_max dt */
    int64_t steps, contacts;
    double kinetic_min, kinetic_max;
} drift;

/* Runs the box for time T at dt = (pi/omega_max)/n_contact. */
static drift run_box(int dim, uint64_t seed, double n_contact, double T)
{
    box b;
    box_build(&b, dim, seed);
    const int d = dim, rd = dim == 3 ? 3 : 1;
    const double dt = V_PI / b.omega_max / n_contact;
    ck_assert(sx_model_set_timestep(b.m, dt) == SX_OK);
    drift out = {0};
    out.h = b.omega_max * dt;
    out.kinetic_min = INFINITY;
    double x[NB][3], v0[NB][3], w0[NB][3], e0 = 0, scale = 1;
    const int64_t n = (int64_t)ceil(T / dt);
    for (int64_t s = 0; s < n; s++) {
        for (int i = 0; i < NB; i++) {
            v_get(b.m, b.id[i], SX_BALL_POS, x[i]);
            v_get(b.m, b.id[i], SX_BALL_VEL, v0[i]);
            v_get(b.m, b.id[i], SX_BALL_SPIN, w0[i]);
        }
        const int64_t c0 = sx_contact_count(b.m);
        v_step(b.m, 1);
        if (sx_contact_count(b.m) > c0) out.contacts += sx_contact_count(b.m) - c0;
        double kin = 0, pot = 0;
        for (int i = 0; i < NB; i++) {
            double v1[3], w1[3], vs[3], ws[3];
            v_get(b.m, b.id[i], SX_BALL_VEL, v1);
            v_get(b.m, b.id[i], SX_BALL_SPIN, w1);
            for (int k = 0; k < 3; k++) vs[k] = 0.5 * (v0[i][k] + v1[k]), ws[k] = 0.5 * (w0[i][k] + w1[k]);
            kin += 0.5 * b.mass[i] * v_dot(vs, vs, d) + 0.5 * b.inertia[i] * v_dot(ws, ws, rd);
            pot -= b.mass[i] * v_dot(b.g, x[i], d);
        }
        const double e = kin + pot + strain(&b, x);
        if (s == 0) {
            e0 = e;
            scale = e;
            for (int i = 0; i < NB; i++) scale -= b.mass[i] * G * b.rad[i];
        }
        out.drift = fmax(out.drift, fabs(e - e0) / scale);
        out.kinetic_min = fmin(out.kinetic_min, kin);
        out.kinetic_max = fmax(out.kinetic_max, kin);
    }
    out.steps = n;
    sx_model_destroy(b.m);
    return out;
}

static void check_box(int dim)
{
    const double T = 0.2, n1 = 50;
    const int ensemble = dim == 2 ? 64 : 24;
    double mean_a = 0, mean_c = 0, worst_a = 0, worst_c = 0;
    int64_t contacts = 0, steps = 0;
    double h = 0;
    for (uint64_t seed = 1; seed <= (uint64_t)ensemble; seed++) {
        const drift a = run_box(dim, seed, n1, T), c = run_box(dim, seed, 2 * n1, T);
        /* something happened: kinetic energy was exchanged with the contacts and gravity */
        ck_assert_msg(a.kinetic_max > 1.2 * a.kinetic_min && a.contacts >= 10,
                      "%dD box seed %d: the balls hardly interacted (kinetic %g .. %g J, %lld contacts)", dim,
                      (int)seed, a.kinetic_min, a.kinetic_max, (long long)a.contacts);
        const drift *runs[2] = {&a, &c};
        for (int r = 0; r < 2; r++) {
            const double bound = runs[r]->h * runs[r]->h / 4 * (double)(runs[r]->contacts + 1);
            ck_assert_msg(runs[r]->drift <= bound,
                          "%dD box seed %d: energy drift %.3e of the energy scale exceeds (h^2/4)(N+1) = %.3e "
                          "(h = %.4f, %lld contacts)",
                          dim, (int)seed, runs[r]->drift, bound, runs[r]->h, (long long)runs[r]->contacts);
        }
        mean_a += a.drift / ensemble;
        mean_c += c.drift / ensemble;
        worst_a = fmax(worst_a, a.drift);
        worst_c = fmax(worst_c, c.drift);
        contacts += a.contacts;
        steps += a.steps + c.steps;
        h = a.h;
    }
    const double ratio = mean_a / mean_c;
    printf("energy %dD box (%d runs of %d balls, %g s, %.1f contacts/run, %lld steps): drift/E mean %.2e (max %.2e) "
           "at h = %.4f, mean %.2e (max %.2e) at h = %.4f; ratio %.2f\n",
           dim, ensemble, NB, T, (double)contacts / ensemble, (long long)steps, mean_a, worst_a, h, mean_c, worst_c,
           h / 2, ratio);
    ck_assert_msg(ratio >= 3 && ratio <= 5,
                  "%dD box: halving dt divided the mean energy drift by %.3f, expected 4 (O(dt^2)); drifts %.3e, %.3e",
                  dim, ratio, mean_a, mean_c);
}

START_TEST(energy_box_2d) { check_box(2); }
END_TEST

START_TEST(energy_box_3d) { check_box(3); }
END_TEST

/* Free fall through a sequence of user timesteps: the exact parabola. */
static void check_free_fall(int dim)
{
    double g[3] = {0.3, -9.81, 0};
    if (dim == 3) g[1] = 0.2, g[2] = -9.81;
    sx_model *m = scene_model(dim, g, 1e-3, 1e6, 0.5, RHO);
    const double x0[3] = {0.1, 0.2, 0.3}, v0[3] = {1.5, 2.0, -0.5};
    const int64_t id = scene_ball(m, x0, v0, 0.01);
    const double dts[4] = {1e-3, 0.37e-3, 2.2e-3, 1e-3};
    double t = 0, worst_x = 0, worst_v = 0, last_dt = 0;
    for (int seg = 0; seg < 4; seg++) {
        ck_assert(sx_model_set_timestep(m, dts[seg]) == SX_OK);
        for (int s = 0; s < 100; s++) {
            v_step(m, 1);
            t += dts[seg];
            last_dt = dts[seg];
        }
        ck_assert_double_eq_tol(sx_model_time(m), t, 1e-12 * t);
        double x[3], v[3];
        v_get(m, id, SX_BALL_POS, x);
        v_get(m, id, SX_BALL_VEL, v);
        for (int k = 0; k < dim; k++) {
            const double u = v0[k] + g[k] * dts[0] / 2; /* the velocity at t = 0 */
            const double xe = x0[k] + u * t + 0.5 * g[k] * t * t;
            const double ve = u + g[k] * (t - last_dt / 2);
            const double ex = fabs(x[k] - xe) / (fabs(x[k] - x0[k]) + 1e-300), ev = fabs(v[k] - ve) / (fabs(ve) + 1);
            worst_x = fmax(worst_x, ex);
            worst_v = fmax(worst_v, ev);
            ck_assert_msg(ex <= 1e-12 && ev <= 1e-12,
                          "%dD free fall, after timestep segment %d (dt %g s): component %d: x %.15g (exact %.15g), "
                          "mid-step v %.15g (exact %.15g); rel errors %.2e, %.2e",
                          dim, seg, dts[seg], k, x[k], xe, v[k], ve, ex, ev);
        }
    }
    printf("free fall %dD with dt changes: position rel err %.1e, velocity rel err %.1e\n", dim, worst_x, worst_v);
    sx_model_destroy(m);
}

START_TEST(free_fall_constant_timestep)
{
    /* one segment at a constant timestep: must be exact whatever the kick convention */
    for (int dim = 2; dim <= 3; dim++) {
        double g[3] = {0, 0, 0};
        g[dim - 1] = -9.81;
        sx_model *m = scene_model(dim, g, 1e-3, 1e6, 0.5, RHO);
        const double x0[3] = {0.1, 0.2, 0.3}, v0[3] = {1.5, 2.0, -0.5};
        const int64_t id = scene_ball(m, x0, v0, 0.01);
        v_step(m, 500);
        const double t = sx_model_time(m), dt = 1e-3;
        double x[3];
        v_get(m, id, SX_BALL_POS, x);
        for (int k = 0; k < dim; k++) {
            const double u = v0[k] + g[k] * dt / 2;
            const double xe = x0[k] + u * t + 0.5 * g[k] * t * t;
            ck_assert_msg(fabs(x[k] - xe) <= 1e-12 * fabs(x[k] - x0[k]),
                          "%dD free fall: component %d at t = %g s: %.15g, exact %.15g", dim, k, t, x[k], xe);
        }
        printf("free fall %dD constant dt: exact to %.1e m\n", dim,
               fabs(x[dim - 1] - (x0[dim - 1] + (v0[dim - 1] + g[dim - 1] * dt / 2) * t + 0.5 * g[dim - 1] * t * t)));
        sx_model_destroy(m);
    }
}
END_TEST

START_TEST(free_fall_changing_timestep)
{
    check_free_fall(2);
    check_free_fall(3);
}
END_TEST

/* sx_model_energy().strain is 1/2 Kn Un^2 at the current positions, at every
 * step of an impact, including the step on which the overlap appears. */
START_TEST(energy_report_strain)
{
    for (int dim = 2; dim <= 3; dim++) {
        sx_model *m = scene_model(dim, NULL, 0, 1e6, 0.0, RHO);
        double n[3] = {0, 0, 0}, p[3] = {0, 0, 0};
        n[dim - 1] = 1;
        scene_halfspace(m, p, n, 3e6, 3e6, 0.0);
        const double R = 0.01, kn = 1e6 * 3e6 / 4e6;
        double x0[3] = {0, 0, 0}, v0[3] = {0, 0, 0};
        x0[dim - 1] = R;
        v0[dim - 1] = -1.0;
        const int64_t id = scene_ball(m, x0, v0, R);
        const double mass = v_scalar(m, id, SX_BALL_MASS), dt = V_PI * sqrt(mass / kn) / 100;
        ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
        x0[dim - 1] = R + 20.3 * dt * 1.0; /* contact after 20.3 steps */
        ck_assert(sx_ball_set_vec(m, id, SX_BALL_POS, x0) == SX_OK);
        double worst = 0;
        int touching_steps = 0;
        for (int s = 0; s < 400; s++) {
            v_step(m, 1);
            double x[3];
            v_get(m, id, SX_BALL_POS, x);
            const double un = R - x[dim - 1];
            const double expected = un > 0 ? 0.5 * kn * un * un : 0;
            const double got = sx_model_energy(m).strain;
            touching_steps += un > 0;
            const double err = fabs(got - expected) / (0.5 * mass); /* relative to the impact energy 1/2 m v^2 */
            worst = fmax(worst, err);
            V_CHECK(err <= 1e-12,
                    "%dD: step %d: strain energy reported %.9e J, 1/2 Kn Un^2 = %.9e J (Un = %.3e m); the report "
                    "misses %.2e of the impact energy",
                    dim, s, got, expected, un, err);
        }
        ck_assert_msg(touching_steps > 50, "no impact happened");
        printf("energy report %dD: strain matches 1/2 Kn Un^2 to %.1e of the impact energy\n", dim, worst);
        sx_model_destroy(m);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("energy");
    V_TCASE(s, energy_box_2d);
    V_TCASE(s, energy_box_3d);
    V_TCASE(s, free_fall_constant_timestep);
    V_TCASE(s, free_fall_changing_timestep);
    V_TCASE(s, energy_report_strain);
    return v_run(s);
}
