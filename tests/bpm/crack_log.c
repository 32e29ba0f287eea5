/* The crack log of one parallel-bond failure (3D): time, step, contact point,
 * mode, kind, ball ids, and the force and moments at failure.
 *
 * Scene: balls RA = 1 mm (held still) and RB = 1.5 mm, centres RA + RB + g
 * apart (g = 10 um), one parallel bond (lambda 0.8, Ec-bar 1 GPa,
 * kn-bar/ks-bar 2.5, sigma_c 2 MPa, tau_c 3 MPa). B is moved at a constant
 * imposed velocity with a component along n (tension) and across it (shear),
 * and both balls spin at imposed rates with components along n (twist) and
 * across it (bending), so at failure all four of Fn, Fs, Mn, Ms are nonzero.
 * The rates put sigma_max (4-38) at sigma_c after about 2000 steps, when
 * tau_max is about half of tau_c: the mode must be tension.
 *
 * Expected values. The crack is logged in the step whose forces broke the
 * bond, at the positions that step started from, so:
 *   time, step = the model's time and step count before that step;
 *   pos        = xA + (RA - Un/2) n (4-4) at those positions;
 *   a, b       = the two balls' ids; kind parallel, mode tension;
 *   fn, fs, mn, ms = the bond state after that step's increment (4-36/4-37).
 * The bond state is read each step through sx_contact_each; under constant
 * imposed rates its increments are constant up to the slow turn of n
 * (1e-6 rad per step), so the state at failure is the linear extrapolation
 * 2 S(k) - S(k-1) of the last two intact states, to a relative 1e-6 (the
 * second difference is O(turn per step x total turn) ~ 1e-8). The time,
 * step and ids must match exactly, the contact point to rounding (1e-12 m).
 * Also: sigma_max of the logged values is >= sigma_c, that of the last
 * intact state < sigma_c.
 */
#include "bpm.h"

static const double RA = 1e-3, RB = 1.5e-3, GAP = 1e-5;
static const double LAMBDA = 0.8, EBAR = 1e9, RATIO = 2.5, SIGMA_C = 2e6, TAU_C = 3e6;

typedef struct bond_state {
    double fn, fs, mn, ms; /* fn signed (compression positive), magnitudes of the rest */
    double x[3];           /* B's position the state's step started from */
} bond_state;

static void dir(const double *xa, const double *xb, double *n, double *d)
{
    double s = 0;
    for (int k = 0; k < 3; k++) {
        n[k] = xb[k] - xa[k];
        s += n[k] * n[k];
    }
    *d = sqrt(s);
    for (int k = 0; k < 3; k++) n[k] /= *d;
}

START_TEST(crack_fields)
{
    sx_model *m = bpm_model(3, 0);
    sx_material_def md = sx_material_default_def();
    const int mat = bpm_material(m, "rock", &md);
    const double xa[3] = {0, 0, 0}, xb0[3] = {RA + RB + GAP, 0, 0};
    const int64_t a = scene_ball_of(m, mat, xa, NULL, RA);
    const int64_t b = scene_ball_of(m, mat, xb0, NULL, RB);
    sx_bond_def bd = sx_bond_default_def();
    bd.gap = 2 * GAP;
    bd.radius_multiplier = LAMBDA;
    bd.modulus = EBAR;
    bd.stiffness_ratio = RATIO;
    bd.tensile_strength = SIGMA_C;
    bd.cohesion = TAU_C;
    int64_t nb = 0;
    ck_assert_msg(sx_bond_install(m, &bd, &nb) == SX_OK, "%s", sx_model_error(m));
    ck_assert_int_eq(nb, 1);

    const double kn = EBAR / (RA + RB), ks = kn / RATIO, rbar = LAMBDA * RA;
    const double area = BPM_PI * rbar * rbar, inertia = 0.25 * BPM_PI * pow(rbar, 4), polar = 2 * inertia;
    const double T = 2000 * sx_model_timestep(m);
    /* sigma: 40 % from tension, 60 % from bending; tau: 25 % shear, 25 % twist (approximately:
     * B's spin moves its contact point, which adds to the shear) */
    const double vb[3] = {0.4 * SIGMA_C / kn / T, 0.25 * TAU_C / ks / T, 0};
    const double th_s = 0.6 * SIGMA_C / (kn * rbar), th_n = 0.25 * TAU_C / (ks * rbar);
    const double wa[3] = {-0.3 * th_n / T, 0, -0.5 * th_s / T}, wb[3] = {0.7 * th_n / T, 0, 0.5 * th_s / T};
    scene_impose(m, a, NULL, wa);
    scene_impose(m, b, vb, wb);

    bond_state prev = {0}, last = {0};
    int have = 0;
    double t_before = 0, x_before[3] = {0, 0, 0};
    int64_t step_before = 0;
    for (int s = 0; s < 4000; s++) {
        t_before = sx_model_time(m);
        step_before = sx_model_step_count(m);
        bpm_vec(m, b, SX_BALL_POS, x_before);
        bpm_cycle(m, 1);
        if (sx_crack_count(m)) break;
        sx_contact_info ci;
        ck_assert(bpm_contact(m, a, b, &ci));
        ck_assert(ci.bond == SX_BOND_PARALLEL);
        double n[3], d;
        dir(xa, x_before, n, &d);
        const double mn = ci.pb_moment[0] * n[0] + ci.pb_moment[1] * n[1] + ci.pb_moment[2] * n[2];
        double ms2 = 0, fs2 = 0;
        for (int k = 0; k < 3; k++) {
            ms2 += pow(ci.pb_moment[k] - mn * n[k], 2);
            fs2 += ci.pb_fs[k] * ci.pb_fs[k];
        }
        prev = last;
        last = (bond_state){.fn = ci.pb_fn, .fs = sqrt(fs2), .mn = fabs(mn), .ms = sqrt(ms2)};
        memcpy(last.x, x_before, sizeof last.x);
        have++;
    }
    ck_assert_msg(sx_crack_count(m) == 1, "expected one crack, got %lld", (long long)sx_crack_count(m));
    ck_assert(have >= 2);
    sx_crack c;
    ck_assert(sx_crack_get(m, 0, &c) == SX_OK);
    printf("3D parallel bond crack log (broke in step %lld):\n", (long long)c.step);
    printf("  time %.9g s, step %lld, pos (%.9g, %.9g, %.9g) m, mode %d, kind %d, balls %lld-%lld\n", c.time,
           (long long)c.step, c.pos[0], c.pos[1], c.pos[2], (int)c.mode, (int)c.kind, (long long)c.a,
           (long long)c.b);
    printf("  Fn %.9g N, Fs %.9g N, Mn %.9g N m, Ms %.9g N m\n", c.fn, c.fs, c.mn, c.ms);

    ck_assert_msg(c.time == t_before, "crack time %.17g, the breaking step started at %.17g", c.time, t_before);
    ck_assert_int_eq(c.step, step_before);
    ck_assert_int_eq(c.kind, SX_BOND_PARALLEL);
    ck_assert_int_eq(c.mode, SX_CRACK_TENSION);
    ck_assert((c.a == a && c.b == b) || (c.a == b && c.b == a));

    double n[3], d, pos[3];
    dir(xa, x_before, n, &d);
    const double un = RA + RB - d;
    for (int k = 0; k < 3; k++) pos[k] = xa[k] + (RA - 0.5 * un) * n[k]; /* 4-4 */
    for (int k = 0; k < 3; k++)
        ck_assert_msg(fabs(c.pos[k] - pos[k]) <= 1e-12, "crack pos[%d] = %.17g, contact point %.17g", k, c.pos[k],
                      pos[k]);
    printf("  contact point (4-4): (%.9g, %.9g, %.9g) m\n", pos[0], pos[1], pos[2]);

    BPM_CHECK("Fn at failure (N)", c.fn, 2 * last.fn - prev.fn, 1e-6);
    BPM_CHECK("|Fs| at failure (N)", c.fs, 2 * last.fs - prev.fs, 1e-6);
    BPM_CHECK("|Mn| at failure (N m)", c.mn, 2 * last.mn - prev.mn, 1e-6);
    BPM_CHECK("|Ms| at failure (N m)", c.ms, 2 * last.ms - prev.ms, 1e-6);
    const double sigma_c = -c.fn / area + c.ms * rbar / inertia, tau_c = c.fs / area + c.mn * rbar / polar;
    const double sigma_l = -last.fn / area + last.ms * rbar / inertia;
    printf("  sigma_max at failure %.9g Pa (last intact %.9g Pa, strength %g Pa); tau_max %.4g Pa (strength %g Pa)\n",
           sigma_c, sigma_l, SIGMA_C, tau_c, TAU_C);
    ck_assert(sigma_c >= SIGMA_C && sigma_l < SIGMA_C && tau_c < TAU_C);
    ck_assert(c.fn < 0 && c.fs > 0 && c.mn > 0 && c.ms > 0);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("crack_log");
    TCase *tc = tcase_create("log");
    tcase_add_test(tc, crack_fields);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
