/* Verification: linear normal impact, ball-ball and ball-wall, 2D and 3D.
 *
 * Closed form. A linear spring-dashpot contact Fn = Kn Un - c dUn/dt with
 * c = 2 beta sqrt(m* Kn) is a damped harmonic oscillator in the overlap:
 *     omega0 = sqrt(Kn / m*),   omega_d = omega0 sqrt(1 - beta^2),
 *     contact time          t_c = pi / omega_d,
 *     restitution           e   = exp(-beta pi / sqrt(1 - beta^2)),
 * with Kn = knA knB/(knA+knB) (ball-wall: kn_ball kn_wall/(kn_ball+kn_wall)),
 * m* = mA mB/(mA+mB) (ball-wall: m), beta the mean of the two materials'
 * viscous_normal (ball-wall: the ball's). The dashpot is not clipped, so the
 * contact ends when the overlap returns to zero, exactly half a damped period.
 *
 * Measurement. The overlap is computed from the positions after every step
 * (positions are at whole steps); the start and the end of the contact are
 * the zeros of the overlap found by linear interpolation between the two
 * steps that bracket each sign change. e is the ratio of the relative normal
 * velocities after and before the impact (both in free flight, so exact).
 *
 * Tolerances, with h = omega0 dt:
 *  - Undamped. Inside the contact, leapfrog reproduces a sampled sine of
 *    frequency Omega with sin(Omega dt / 2) = h / 2 exactly, so the numerical
 *    half period is t_c (h/2)/asin(h/2) = t_c (1 - h^2/24 + ...). Linear
 *    interpolation of a sine's zero between samples H = Omega dt apart errs by
 *    at most H^3/(18 sqrt 3) in phase at each end. Tolerance for t_c: twice
 *    the leading dispersion, h^2/12 (8.2e-5 at dt = t_c/100).
 *    The velocities before and after are chords of that sine across its two
 *    zeros: v = A omega cos(phi), phi the phase of the chord's midpoint, within
 *    H/2 of the zero; so e = cos(phi_out)/cos(phi_in) = 1 +- h^2/8. (At
 *    dt = t_c/100 exactly the contact lasts an almost integer number of
 *    steps, phi_out ~ phi_in, and the measured error is far smaller.)
 *  - Damped. The dashpot reads the velocity of the previous half step, i.e.
 *    it is a force evaluated dt/2 late: to first order this replaces m* by
 *    m*(1 - beta h), giving a t_c error -(beta h/2)(1 - 2 beta^2)/(1 - beta^2)
 *    (bounded by beta h / 2) and a relative error in ln e of
 *    beta h / (2 (1 - beta^2)). Moreover the dashpot force switches on and off
 *    on the step grid (it jumps from 0 to c vn at contact): the outgoing
 *    velocity carries a phase-dependent first-order error of at most 2 beta h
 *    (the entry and exit of the overlap fall at different fractions of a step).
 *    Tolerances: t_c: beta h/2 + h^2/12; e: beta h (2 + |ln e|/(2(1-beta^2)))
 *    + h^2/8. At beta = 0.1, dt = t_c/100: 1.7e-3 and 6.9e-3. Each case is
 *    run at four entry phases (the fraction of a step at which contact
 *    starts) to sample the phase-dependent part.
 *  - Automatic timestep (about 5 steps per contact): the same undamped
 *    bounds at the largest h used during the contact, without expansion:
 *    t_c: 1 - (h/2)/asin(h/2) + 2 H^3/(18 sqrt(3) pi); e: 1/cos(H/2) - 1,
 *    H = 2 asin(h/2). The automatic timestep is re-estimated when the contact
 *    forms and may change in mid-contact; leapfrog stays second order
 *    through such a change only if the velocity kick spans the time between
 *    the two half-step velocities, (dt_old + dt_new)/2 (see energy.c,
 *    free_fall_changing_timestep).
 */
#include "verify.h"

#include <stdbool.h>

typedef struct impact_case {
    int dim;
    bool wall;             /* ball-wall (true) or ball-ball */
    double beta_a, beta_b; /* viscous_normal of the two materials */
    double steps;          /* dt = t_c / steps; 0 = automatic timestep */
    double phase;          /* fraction of a step in the initial gap */
} impact_case;

typedef struct impact_result {
    double tc, e;             /* measured */
    double tc_exact, e_exact; /* closed form */
    double beta, h;           /* mean damping ratio; largest omega0 dt in contact */
    int contact_steps;
} impact_result;

/* materials: A and B; the wall's stiffness */
static const double KN_A = 1e6, KN_B = 2e6, KN_W = 3e6;
static const double RHO_A = 2650, RHO_B = 7800;
static const double R1 = 0.01, R2 = 0.015;

static void direction(int dim, double u[3])
{
    u[0] = u[1] = u[2] = 0;
    if (dim == 3)
        u[0] = 1.0 / 3, u[1] = 2.0 / 3, u[2] = 2.0 / 3;
    else
        u[0] = 0.6, u[1] = 0.8;
}

typedef struct scene {
    sx_model *m;
    int64_t b1, b2; /* b2 = 0 for ball-wall */
    double u[3], p0[3];
} scene;

/* Overlap at the current positions (ball-wall: against the plane through p0 with normal u). */
static double overlap(const scene *s)
{
    const int d = sx_model_dim(s->m);
    double x1[3], x2[3];
    v_get(s->m, s->b1, SX_BALL_POS, x1);
    if (!s->b2) {
        double r[3];
        for (int k = 0; k < d; k++) r[k] = x1[k] - s->p0[k];
        return R1 - v_dot(r, s->u, d);
    }
    v_get(s->m, s->b2, SX_BALL_POS, x2);
    double r[3];
    for (int k = 0; k < d; k++) r[k] = x2[k] - x1[k];
    return R1 + R2 - v_norm(r, d);
}

/* Relative normal velocity (approach negative). */
static double normal_velocity(const scene *s)
{
    const int d = sx_model_dim(s->m);
    double v1[3], v2[3] = {0, 0, 0};
    v_get(s->m, s->b1, SX_BALL_VEL, v1);
    if (s->b2) v_get(s->m, s->b2, SX_BALL_VEL, v2);
    double r[3];
    for (int k = 0; k < d; k++) r[k] = s->b2 ? v2[k] - v1[k] : v1[k];
    return v_dot(r, s->u, d);
}

static impact_result run_impact(const impact_case *c)
{
    const int d = c->dim;
    sx_model_def def = sx_model_default_def();
    def.dim = d;
    char err[256];
    scene s = {0};
    s.m = sx_model_create(&def, err, sizeof err);
    ck_assert_msg(s.m != NULL, "%s", err);
    sx_material_def ma = sx_material_default_def(), mb = sx_material_default_def();
    ma.density = RHO_A, ma.kn = ma.ks = KN_A, ma.friction = 0, ma.viscous_normal = c->beta_a;
    mb.density = RHO_B, mb.kn = mb.ks = KN_B, mb.friction = 0, mb.viscous_normal = c->beta_b;
    const int ia = scene_material_def(s.m, "A", &ma), ib = scene_material_def(s.m, "B", &mb);
    direction(d, s.u);
    const double p0[3] = {0.1, -0.05, 0.02};
    for (int k = 0; k < 3; k++) s.p0[k] = k < d ? p0[k] : 0;

    /* masses from the closed forms (also checked against the store) */
    const double m1 = d == 3 ? RHO_A * 4.0 / 3.0 * V_PI * R1 * R1 * R1 : RHO_A * V_PI * R1 * R1;
    const double m2 = d == 3 ? RHO_B * 4.0 / 3.0 * V_PI * R2 * R2 * R2 : RHO_B * V_PI * R2 * R2;
    const double kn = c->wall ? KN_A * KN_W / (KN_A + KN_W) : KN_A * KN_B / (KN_A + KN_B);
    const double mstar = c->wall ? m1 : m1 * m2 / (m1 + m2);
    const double beta = c->wall ? c->beta_a : 0.5 * (c->beta_a + c->beta_b);
    const double w0 = sqrt(kn / mstar);
    impact_result res = {0};
    res.beta = beta;
    res.tc_exact = V_PI / (w0 * sqrt(1 - beta * beta));
    res.e_exact = exp(-beta * V_PI / sqrt(1 - beta * beta));
    if (c->steps > 0) ck_assert(sx_model_set_timestep(s.m, res.tc_exact / c->steps) == SX_OK);

    /* velocities: ball 1 along +u, ball 2 along -u, approach speed 1 m/s */
    const double va = c->wall ? -1.0 : 0.7, vb = -0.3;
    double vel1[3] = {0}, vel2[3] = {0}, pos1[3] = {0}, pos2[3] = {0};
    for (int k = 0; k < d; k++) vel1[k] = va * s.u[k], vel2[k] = vb * s.u[k];
    if (c->wall) {
        scene_halfspace(s.m, s.p0, s.u, KN_W, KN_W, 0.0);
        for (int k = 0; k < d; k++) pos1[k] = s.p0[k] + R1 * s.u[k]; /* gap set below */
        s.b1 = scene_ball_full(s.m, pos1, vel1, NULL, R1, ia);
    } else {
        for (int k = 0; k < d; k++) pos1[k] = s.p0[k], pos2[k] = s.p0[k] + (R1 + R2) * s.u[k];
        s.b1 = scene_ball_full(s.m, pos1, vel1, NULL, R1, ia);
        s.b2 = scene_ball_full(s.m, pos2, vel2, NULL, R2, ib);
        ck_assert_double_eq_tol(v_scalar(s.m, s.b2, SX_BALL_MASS), m2, 1e-14 * m2);
    }
    ck_assert_double_eq_tol(v_scalar(s.m, s.b1, SX_BALL_MASS), m1, 1e-14 * m1);
    /* the initial gap: (10 + phase) steps of free approach */
    const double dt0 = sx_model_timestep(s.m);
    ck_assert_msg(dt0 > 0, "timestep: %s", sx_model_error(s.m));
    const double gap = (10 + c->phase) * dt0 * 1.0;
    if (c->wall) {
        for (int k = 0; k < d; k++) pos1[k] += gap * s.u[k];
        ck_assert(sx_ball_set_vec(s.m, s.b1, SX_BALL_POS, pos1) == SX_OK);
    } else {
        for (int k = 0; k < d; k++) pos2[k] += gap * s.u[k];
        ck_assert(sx_ball_set_vec(s.m, s.b2, SX_BALL_POS, pos2) == SX_OK);
    }

    const double vn_in = normal_velocity(&s);
    double t_prev = sx_model_time(s.m), d_prev = overlap(&s);
    ck_assert_msg(d_prev < 0, "the balls must start apart (overlap %g)", d_prev);
    double t_in = NAN, t_out = NAN;
    int after = 0;
    for (int step = 0; step < 100000 && after < 4; step++) {
        v_step(s.m, 1);
        /* the contact store agrees with the geometry used for the force of that step */
        V_CHECK(sx_contact_count(s.m) == (d_prev > 0 ? 1 : 0), "contact count %lld with overlap %g at the step's start",
                (long long)sx_contact_count(s.m), d_prev);
        const double t = sx_model_time(s.m), dn = overlap(&s);
        if (d_prev > 0 || dn > 0) {
            const double h = w0 * (t - t_prev);
            if (h > res.h) res.h = h;
            res.contact_steps++;
        }
        if (isnan(t_in) && d_prev <= 0 && dn > 0) t_in = t_prev + (t - t_prev) * (-d_prev) / (dn - d_prev);
        if (!isnan(t_in) && isnan(t_out) && d_prev > 0 && dn <= 0)
            t_out = t_prev + (t - t_prev) * d_prev / (d_prev - dn);
        if (!isnan(t_out)) after++;
        t_prev = t;
        d_prev = dn;
    }
    ck_assert_msg(!isnan(t_in) && !isnan(t_out), "no complete contact observed (in %g, out %g)", t_in, t_out);
    res.tc = t_out - t_in;
    res.e = -normal_velocity(&s) / vn_in;
    sx_model_destroy(s.m);
    return res;
}

static const char *label(const impact_case *c)
{
    static char buf[64];
    snprintf(buf, sizeof buf, "impact %dD %s", c->dim, c->wall ? "ball-wall" : "ball-ball");
    return buf;
}

/* Runs a case at four entry phases and checks t_c and e against the closed form. */
static void check_impact(impact_case c)
{
    double worst_tc = 0, worst_e = 0, tol_tc = 0, tol_e = 0, beta = 0;
    const double phases[4] = {0.05, 0.37, 0.62, 0.93};
    for (int p = 0; p < 4; p++) {
        c.phase = phases[p];
        const impact_result r = run_impact(&c);
        const double h = r.h, b = r.beta;
        beta = b;
        tol_tc = b * h / 2 + h * h / 12;
        tol_e = b * h * (2 + fabs(log(r.e_exact)) / (2 * (1 - b * b))) + h * h / 8;
        const double etc = r.tc / r.tc_exact - 1, ee = r.e / r.e_exact - 1;
        ck_assert_msg(fabs(etc) <= tol_tc, "%s beta %g phase %g: t_c %.9g s, expected %.9g s (rel err %.3e > tol %.3e)",
                      label(&c), b, c.phase, r.tc, r.tc_exact, etc, tol_tc);
        ck_assert_msg(fabs(ee) <= tol_e, "%s beta %g phase %g: e %.9g, expected %.9g (rel err %.3e > tol %.3e)",
                      label(&c), b, c.phase, r.e, r.e_exact, ee, tol_e);
        /* the contact is resolved as asked: about `steps` steps */
        ck_assert_msg(r.contact_steps >= (int)c.steps - 2 && r.contact_steps <= (int)c.steps + 3,
                      "%s: %d steps in contact, expected about %g", label(&c), r.contact_steps, c.steps);
        if (fabs(etc) > fabs(worst_tc)) worst_tc = etc;
        if (fabs(ee) > fabs(worst_e)) worst_e = ee;
    }
    printf("%s beta %.2f dt = t_c/%g: t_c rel err %.2e (tol %.2e), e rel err %.2e (tol %.2e)\n", label(&c), beta,
           c.steps, worst_tc, tol_tc, worst_e, tol_e);
}

START_TEST(impact_ball_ball_undamped)
{
    for (int d = 2; d <= 3; d++) check_impact((impact_case){.dim = d, .wall = false, .steps = 100});
}
END_TEST

START_TEST(impact_ball_wall_undamped)
{
    for (int d = 2; d <= 3; d++) check_impact((impact_case){.dim = d, .wall = true, .steps = 100});
}
END_TEST

/* beta = mean(0.05, 0.15) = 0.1: also checks that the contact uses the mean */
START_TEST(impact_ball_ball_damped)
{
    for (int d = 2; d <= 3; d++)
        check_impact((impact_case){.dim = d, .wall = false, .beta_a = 0.05, .beta_b = 0.15, .steps = 100});
}
END_TEST

/* ball-wall: the ball's beta (0.1); material B's is irrelevant */
START_TEST(impact_ball_wall_damped)
{
    for (int d = 2; d <= 3; d++)
        check_impact((impact_case){.dim = d, .wall = true, .beta_a = 0.1, .beta_b = 0.7, .steps = 100});
}
END_TEST

/* A contact lasting a non-integer number of steps (70.5): the entry and exit
 * fall at different fractions of a step, exercising the h^2/8 bound on e. */
START_TEST(impact_off_grid)
{
    for (int d = 2; d <= 3; d++)
        for (int wall = 0; wall <= 1; wall++) check_impact((impact_case){.dim = d, .wall = wall, .steps = 70.5});
}
END_TEST

/* A stronger dashpot, beta = 0.3 (e = 0.37) */
START_TEST(impact_strongly_damped)
{
    for (int d = 2; d <= 3; d++) {
        check_impact((impact_case){.dim = d, .wall = false, .beta_a = 0.3, .beta_b = 0.3, .steps = 100});
        check_impact((impact_case){.dim = d, .wall = true, .beta_a = 0.3, .steps = 100});
    }
}
END_TEST

/* The automatic timestep resolves the impact: stable, and the contact time
 * within the leapfrog dispersion bound at the h it actually used. */
START_TEST(impact_automatic_timestep)
{
    for (int d = 2; d <= 3; d++)
        for (int wall = 0; wall <= 1; wall++) {
            impact_case c = {.dim = d, .wall = wall, .steps = 0, .phase = 0.4};
            const impact_result r = run_impact(&c);
            const double h = r.h, H = 2 * asin(h / 2);
            const double tol = 1 - (h / 2) / asin(h / 2) + 2 * H * H * H / (18 * sqrt(3.0) * V_PI);
            const double tol_e = 1 / cos(H / 2) - 1;
            const double etc = r.tc / r.tc_exact - 1, ee = r.e - 1;
            printf("%s automatic dt (omega0 dt <= %.3f, %d steps in contact): t_c rel err %.2e (tol %.2e), "
                   "e - 1 = %.2e (tol %.2e)\n",
                   label(&c), h, r.contact_steps, etc, tol, ee, tol_e);
            ck_assert_msg(h < 2, "%s: the automatic timestep is beyond the stability limit (omega0 dt = %g)", label(&c),
                          h);
            ck_assert_msg(fabs(etc) <= tol, "%s automatic dt: t_c %.9g s, expected %.9g s (rel err %.3e > tol %.3e)",
                          label(&c), r.tc, r.tc_exact, etc, tol);
            ck_assert_msg(fabs(ee) <= tol_e, "%s automatic dt: e = %.9g, expected 1 (tol %.3e)", label(&c), r.e, tol_e);
        }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("impact");
    V_TCASE(s, impact_ball_ball_undamped);
    V_TCASE(s, impact_ball_wall_undamped);
    V_TCASE(s, impact_ball_ball_damped);
    V_TCASE(s, impact_ball_wall_damped);
    V_TCASE(s, impact_off_grid);
    V_TCASE(s, impact_strongly_damped);
    V_TCASE(s, impact_automatic_timestep);
    return v_run(s);
}
