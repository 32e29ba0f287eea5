/* Verification: conservation of linear and angular momentum in ball-ball
 * collisions (no gravity, no walls), 2D and 3D.
 *
 * Closed form. Contact forces are equal and opposite (F on b, -F on a) and
 * both act at the same contact point xC, so
 *     P = sum m v               and
 *     L = sum (m x × v + I w)   (about the origin; 2D: the z component)
 * are constant, whatever the force law (spring, dashpots, Coulomb slip).
 *
 * Discrete claim (verified here). After a step the store holds x_{n+1} and
 * v_{n+1/2}, w_{n+1/2}. With v_{n+1/2} = v_{n-1/2} + F_n/m dt,
 * w_{n+1/2} = w_{n-1/2} + M_n/I dt and x_{n+1} = x_n + v_{n+1/2} dt:
 *     m x_{n+1} × v_{n+1/2} = m x_n × v_{n+1/2}        (v × v = 0)
 *                           = m x_n × v_{n-1/2} + dt x_n × F_n,
 * and x_n × v_{n-1/2} = x_{n-1} × v_{n-1/2} likewise, so
 *     L_{n+1} - L_n = dt sum_i (x_i × F_i + M_i) = dt sum_contacts [xC × F - xC × F] = 0
 * exactly, provided the moments are taken about the same contact point the
 * force is applied at (xC = xA + (RA - Un/2) n = xB - (RB - Un/2) n). So the
 * stored-state L is conserved to round-off (the synchronous velocity
 * (v_{n-1/2}+v_{n+1/2})/2 would give an O(dt^2) oscillation instead; it is
 * printed for comparison). Tolerance, relative to the scale
 * sum (m |x| |v| + I |w|) (resp. sum m |v| for P): 2 N eps after N steps,
 * eps the double precision unit round-off: each step's position update
 * x += v dt rounds by up to eps |x|, and in free flight the same increment
 * is added step after step, so these errors can add up coherently. For the
 * 2400 ... 3600 steps here that is 1e-12 ... 1.6e-12; measured 1e-16 ... 7e-14.
 */
#include "verify.h"

#include <float.h>
#include <stdbool.h>
#include <string.h>

enum { MAXB = 6 };

typedef struct ball_init {
    double pos[3], vel[3], spin[3], radius;
    int mat; /* 0 or 1 */
} ball_init;

static void cross(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

typedef struct state {
    double P[3], L[3], Lspin[3], scale_p, scale_l, scale_spin;
} state;

/* P and L of the stored state; x_override (NULL or per-ball positions) and
 * v_override replace the stored x and v (for the synchronous comparison). */
static state measure(sx_model *m, const int64_t *id, int nb, double (*xo)[3], double (*vo)[3])
{
    const int d = sx_model_dim(m);
    state s;
    memset(&s, 0, sizeof s);
    for (int i = 0; i < nb; i++) {
        double x[3], v[3], w[3], mv[3], r[3];
        v_get(m, id[i], SX_BALL_POS, x);
        v_get(m, id[i], SX_BALL_VEL, v);
        v_get(m, id[i], SX_BALL_SPIN, w);
        if (xo) memcpy(x, xo[i], sizeof x);
        if (vo) memcpy(v, vo[i], sizeof v);
        const double mass = v_scalar(m, id[i], SX_BALL_MASS), I = v_scalar(m, id[i], SX_BALL_INERTIA);
        if (d == 2) x[2] = v[2] = 0, w[2] = w[0], w[0] = w[1] = 0; /* 2D spin is about z */
        for (int k = 0; k < 3; k++) mv[k] = mass * v[k];
        cross(x, mv, r);
        for (int k = 0; k < 3; k++) {
            s.P[k] += mv[k];
            s.L[k] += r[k] + I * w[k];
            s.Lspin[k] += I * w[k];
        }
        s.scale_p += mass * v_norm(v, 3);
        s.scale_l += mass * v_norm(x, 3) * v_norm(v, 3) + I * v_norm(w, 3);
        s.scale_spin += mass * v_scalar(m, id[i], SX_BALL_RADIUS) * v_norm(v, 3);
    }
    return s;
}

static double diff3(const double *a, const double *b)
{
    double r[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return v_norm(r, 3);
}

/* Runs the collision scene for a time T, asserting conservation at every step. */
static void run_collisions(int dim, const char *what, const ball_init *init, int nb, double T, bool frictional)
{
    sx_model_def def = sx_model_default_def();
    def.dim = dim;
    char err[256];
    sx_model *m = sx_model_create(&def, err, sizeof err);
    ck_assert_msg(m != NULL, "%s", err);
    /* two materials: unequal densities, stiffnesses, friction and dashpots */
    sx_material_def a = sx_material_default_def(), b = sx_material_default_def();
    const double kscale = dim == 3 ? 0.0134 : 1; /* 3D: similar contact times to 2D (lighter balls) */
    a.density = 2650, a.kn = 1e6 * kscale, a.ks = 0.7e6 * kscale, a.friction = 0.4, a.viscous_normal = 0.1,
    a.viscous_shear = 0.2;
    b.density = 7800, b.kn = 3e6 * kscale, b.ks = 2e6 * kscale, b.friction = 0.6, b.viscous_normal = 0.3,
    b.viscous_shear = 0.0;
    const int mats[2] = {scene_material_def(m, "a", &a), scene_material_def(m, "b", &b)};
    int64_t id[MAXB];
    for (int i = 0; i < nb; i++)
        id[i] = scene_ball_full(m, init[i].pos, init[i].vel, init[i].spin, init[i].radius, mats[init[i].mat]);
    /* resolve the stiffest contact by ~50 steps */
    double mmin = INFINITY;
    for (int i = 0; i < nb; i++) mmin = fmin(mmin, v_scalar(m, id[i], SX_BALL_MASS));
    const double dt = V_PI * sqrt(mmin / 2 / (1.5e6 * kscale)) / 50;
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
    const int64_t nsteps = (int64_t)ceil(T / dt);

    const state s0 = measure(m, id, nb, NULL, NULL);
    double worst_p = 0, worst_l = 0, worst_sync = 0, spin_change = 0;
    int64_t contact_steps = 0, max_contacts = 0;
    double xprev[MAXB][3], vprev[MAXB][3];
    for (int64_t s = 0; s < nsteps; s++) {
        for (int i = 0; i < nb; i++) {
            v_get(m, id[i], SX_BALL_POS, xprev[i]);
            v_get(m, id[i], SX_BALL_VEL, vprev[i]);
        }
        v_step(m, 1);
        const int64_t nc = sx_contact_count(m);
        contact_steps += nc > 0;
        if (nc > max_contacts) max_contacts = nc;
        const state st = measure(m, id, nb, NULL, NULL);
        const double ep = diff3(st.P, s0.P) / s0.scale_p, el = diff3(st.L, s0.L) / s0.scale_l;
        worst_p = fmax(worst_p, ep);
        worst_l = fmax(worst_l, el);
        spin_change = fmax(spin_change, diff3(st.Lspin, s0.Lspin) / s0.scale_spin);
        const double tol = 2 * (double)(s + 1) * DBL_EPSILON;
        V_CHECK(ep <= tol, "%s %dD: step %lld: linear momentum changed by %.3e (relative; tol %.1e), P = (%g, %g, %g)",
                what, dim, (long long)s, ep, tol, st.P[0], st.P[1], st.P[2]);
        V_CHECK(el <= tol, "%s %dD: step %lld: angular momentum changed by %.3e (relative; tol %.1e), L = (%g, %g, %g)",
                what, dim, (long long)s, el, tol, st.L[0], st.L[1], st.L[2]);
        /* for comparison: L from x_n and the synchronous velocity at t_n */
        double vsync[MAXB][3];
        for (int i = 0; i < nb; i++) {
            double v[3];
            v_get(m, id[i], SX_BALL_VEL, v);
            for (int k = 0; k < 3; k++) vsync[i][k] = 0.5 * (vprev[i][k] + v[k]);
        }
        const state sy = measure(m, id, nb, xprev, vsync);
        worst_sync = fmax(worst_sync, diff3(sy.L, s0.L) / s0.scale_l);
    }
    printf("momentum %dD %s: |dP|/P %.1e, |dL|/L %.1e (stored x_{n+1}, v_{n+1/2}); synchronous-velocity L would "
           "deviate by %.1e; spin exchanged %.2f of sum m R |v|; %lld steps, %lld in contact, up to %lld contacts at "
           "once (tol 2 N eps = %.1e)\n",
           dim, what, worst_p, worst_l, worst_sync, spin_change, (long long)nsteps, (long long)contact_steps,
           (long long)max_contacts, 2 * (double)nsteps * DBL_EPSILON);
    /* the test must have exercised collisions */
    ck_assert_msg(contact_steps > 20, "%s %dD: no collision happened", what, dim);
    if (frictional)
        ck_assert_msg(spin_change > 0.02, "%s %dD: friction exchanged too little spin (%.3g) to test L", what, dim,
                      spin_change);
    if (nb > 2) ck_assert_msg(max_contacts >= 2, "%s %dD: no simultaneous contacts", what, dim);
    sx_model_destroy(m);
}

/* Head-on, unequal radii and masses, normal dashpot, off the origin so that
 * m x × v is not zero. */
START_TEST(momentum_head_on)
{
    for (int d = 2; d <= 3; d++) {
        const ball_init b[2] = {
            {.pos = {0.3, -0.2, 0.5}, .vel = {1.0, 0, 0}, .radius = 0.01, .mat = 0},
            {.pos = {0.35, -0.2, 0.5}, .vel = {-0.5, 0, 0}, .radius = 0.015, .mat = 1},
        };
        run_collisions(d, "head-on", b, 2, 0.08, false);
    }
}
END_TEST

/* Oblique, with spins, friction (slip and stick) and both dashpots. */
START_TEST(momentum_oblique)
{
    for (int d = 2; d <= 3; d++) {
        const ball_init b[2] = {
            {.pos = {0.3, -0.2, 0.5}, .vel = {1.0, 0.1, -0.2}, .spin = {30, -50, 80}, .radius = 0.01, .mat = 0},
            {.pos = {0.35, -0.188, 0.505}, .vel = {-0.5, 0.05, 0.1}, .spin = {-20, 40, 10}, .radius = 0.015, .mat = 1},
        };
        run_collisions(d, "oblique", b, 2, 0.08, true);
    }
}
END_TEST

/* Four balls converging on a fifth at once: simultaneous and repeated
 * contacts, each approach slightly off-centre and spinning. */
START_TEST(momentum_cluster)
{
    for (int d = 2; d <= 3; d++) {
        ball_init b[5] = {
            {.pos = {0.3, -0.2, 0.5}, .vel = {0.05, -0.03, 0.02}, .spin = {5, -10, 20}, .radius = 0.012, .mat = 1}};
        const double ang[4] = {0.1, 1.7, 3.3, 4.6}, tilt[4] = {0.3, -0.2, 0.1, -0.4};
        for (int i = 1; i < 5; i++) {
            const double a = ang[i - 1], t = d == 3 ? tilt[i - 1] : 0, r = 0.008 + 0.001 * i;
            const double u[3] = {cos(a) * cos(t), sin(a) * cos(t), sin(t)}, side[3] = {-sin(a), cos(a), 0};
            const double dist = b[0].radius + r + 0.01;
            for (int k = 0; k < 3; k++) {
                b[i].pos[k] = b[0].pos[k] + dist * u[k];
                b[i].vel[k] = -1.0 * u[k] + 0.15 * side[k];
                b[i].spin[k] = 20.0 * (i % 2 ? 1 : -1) * (k + 1);
            }
            b[i].radius = r;
            b[i].mat = i % 2;
        }
        run_collisions(d, "cluster", b, 5, 0.12, true);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("momentum");
    V_TCASE(s, momentum_head_on);
    V_TCASE(s, momentum_oblique);
    V_TCASE(s, momentum_cluster);
    return v_run(s);
}
