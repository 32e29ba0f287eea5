/* Two balls joined by one parallel bond (4-32 ... 4-39), 2D and 3D, loaded
 * separately in tension, shear, bending and twisting (3D), and in two
 * combined cases that exercise the sums of 4-38.
 *
 * Scene: equal balls R = 1 mm, centres 2R + g apart (g = 10 um, so the linear
 * contact never touches and only the bond carries load), bond radius
 * multiplier lambda = 0.8, Ec-bar = 1 GPa, kn-bar/ks-bar = 2.5,
 * sigma-bar_c = 2 MPa, tau-bar_c = 3 MPa. Ball A is held still; the load is
 * imposed kinematically with fixities, which makes the closed forms exact:
 *   tension  B moves along n at constant speed, spins held at zero:
 *            Fn = -kn-bar A u (4-33), so the axial stiffness is kn-bar A and
 *            the bond breaks when -Fn/A = sigma_c (4-38), at Fn = -sigma_c A.
 *   shear    B moves across n, spins held at zero, so there is no relative
 *            rotation and no bending moment (4-34): Fs = -ks-bar A us, shear
 *            stiffness ks-bar A; it breaks when |Fs|/A = tau_c, at tau_c A.
 *            (n turns by u/d <= 0.75 %: the force stays along y to O(u/d)^2.)
 *   bending  A and B spin at -w and +w about an axis normal to n: the
 *            contact points do not move relative to each other (equal arms),
 *            so only Ms = -kn-bar I theta (4-34) builds, theta = 2 w t;
 *            stiffness kn-bar I, break at |Ms| R-bar / I = sigma_c, i.e.
 *            |Ms| = sigma_c I / R-bar.
 *   twist    (3D) the same with spins about n: Mn = -ks-bar J theta,
 *            stiffness ks-bar J, break at |Mn| = tau_c J / R-bar.
 *   tension + bending: sigma = kn-bar (u + R-bar theta) (4-38), break when
 *            -Fn/A + |Ms| R-bar/I = sigma_c.
 *   shear + twist (3D): tau = ks-bar (us + R-bar theta), break when
 *            |Fs|/A + |Mn| R-bar/J = tau_c.
 * with kn-bar = Ec-bar/(RA + RB) (4-51), ks-bar = kn-bar/2.5 (4-52),
 * R-bar = lambda min(RA, RB) (4-53); 3D A = pi R^2, I = pi R^4/4,
 * J = pi R^4/2 (4-35); 2D A = 2R, I = 2R^3/3 (unit thickness).
 *
 * Measured: the stiffness as the ratio of the increments of the load on B
 * (ball force, or moment about B's centre) and of the imposed displacement
 * (or relative rotation) between 25 % and 75 % of the break load; the break
 * load as the load recorded in the crack log, and the largest load B carried
 * before the break. Tolerance 0.5 %: the load rate is set so the break takes
 * 2000 steps, so the break overshoots by at most 1/2000 = 0.05 %; the
 * stiffness is exact up to rounding and the O((u/d)^2) turn of n in shear.
 * Also checked: after the break B carries nothing, the crack has the expected
 * mode, and the moments obey 4-39: M_A + M_B + (xB - xA) x F_B = 0.
 */
#include "bpm.h"

enum load { TENSION, SHEAR, BENDING, TWIST, TENSION_BENDING, SHEAR_TWIST };
static const char *const load_name[] = {"tension", "shear", "bending", "twist", "tension+bending", "shear+twist"};

static const double R = 1e-3, GAP = 1e-5;
static const double LAMBDA = 0.8, EBAR = 1e9, RATIO = 2.5, SIGMA_C = 2e6, TAU_C = 3e6;
static const int STEPS_TO_BREAK = 2000;

typedef struct section {
    double kn, ks, rbar, area, inertia, polar;
} section;

static section closed_section(int dim)
{
    section s;
    s.kn = EBAR / (2 * R);     /* 4-51 */
    s.ks = s.kn / RATIO;       /* 4-52 */
    s.rbar = LAMBDA * R;       /* 4-53 */
    if (dim == 3) {            /* 4-35 */
        s.area = BPM_PI * s.rbar * s.rbar;
        s.inertia = 0.25 * BPM_PI * pow(s.rbar, 4);
        s.polar = 0.5 * BPM_PI * pow(s.rbar, 4);
    } else {
        s.area = 2 * s.rbar;
        s.inertia = 2.0 / 3.0 * pow(s.rbar, 3);
        s.polar = 0;
    }
    return s;
}

typedef struct pair_scene {
    sx_model *m;
    int64_t a, b;
} pair_scene;

static pair_scene bonded_pair(int dim)
{
    pair_scene p;
    p.m = bpm_model(dim, 0);
    sx_material_def md = sx_material_default_def();
    const int mat = bpm_material(p.m, "rock", &md);
    const double xa[3] = {0, 0, 0}, xb[3] = {2 * R + GAP, 0, 0};
    p.a = scene_ball_of(p.m, mat, xa, NULL, R);
    p.b = scene_ball_of(p.m, mat, xb, NULL, R);
    sx_bond_def bd = sx_bond_default_def();
    bd.kind = SX_BOND_PARALLEL;
    bd.gap = 2 * GAP;
    bd.radius_multiplier = LAMBDA;
    bd.modulus = EBAR;
    bd.stiffness_ratio = RATIO;
    bd.tensile_strength = SIGMA_C;
    bd.cohesion = TAU_C;
    int64_t n = 0;
    ck_assert_msg(sx_bond_install(p.m, &bd, &n) == SX_OK, "%s", sx_model_error(p.m));
    ck_assert_int_eq(n, 1);
    ck_assert_int_eq(sx_bond_count(p.m), 1);
    return p;
}

/* The load on B that opposes the imposed motion: minus the force or moment
 * component along the imposed direction. */
static double load_on_b(const pair_scene *p, int dim, enum load ld)
{
    double f[3], t[3];
    bpm_vec(p->m, p->b, SX_BALL_FORCE, f);
    bpm_vec(p->m, p->b, SX_BALL_MOMENT, t);
    switch (ld) {
    case TENSION: return -f[0];
    case SHEAR: return -f[1];
    case BENDING: return dim == 3 ? -t[1] : -t[0];
    case TWIST: return -t[0];
    default: return 0;
    }
}

/* 4-39: the bond's force and moments leave the pair's angular momentum unchanged. */
static void check_moment_balance(const pair_scene *p, int dim)
{
    double fa[3], fb[3], ta[3], tb[3], xa[3], xb[3];
    bpm_vec(p->m, p->a, SX_BALL_FORCE, fa);
    bpm_vec(p->m, p->b, SX_BALL_FORCE, fb);
    bpm_vec(p->m, p->a, SX_BALL_MOMENT, ta);
    bpm_vec(p->m, p->b, SX_BALL_MOMENT, tb);
    bpm_vec(p->m, p->a, SX_BALL_POS, xa);
    bpm_vec(p->m, p->b, SX_BALL_POS, xb);
    /* the moments were computed at the positions before the last step: go back one step */
    double va[3], vb[3];
    bpm_vec(p->m, p->a, SX_BALL_VEL, va);
    bpm_vec(p->m, p->b, SX_BALL_VEL, vb);
    const double dt = sx_model_timestep(p->m);
    double d[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) d[k] = (xb[k] - vb[k] * dt) - (xa[k] - va[k] * dt);
    double scale = 0, res[3];
    for (int k = 0; k < 3; k++) scale += fabs(fb[k]) * R + fabs(tb[k]);
    ck_assert(fabs(fa[0] + fb[0]) + fabs(fa[1] + fb[1]) + fabs(fa[2] + fb[2]) <= 1e-12 * scale / R + 1e-300);
    if (dim == 3) {
        res[0] = ta[0] + tb[0] + d[1] * fb[2] - d[2] * fb[1];
        res[1] = ta[1] + tb[1] + d[2] * fb[0] - d[0] * fb[2];
        res[2] = ta[2] + tb[2] + d[0] * fb[1] - d[1] * fb[0];
    } else {
        res[0] = ta[0] + tb[0] + d[0] * fb[1] - d[1] * fb[0];
        res[1] = res[2] = 0;
    }
    ck_assert_msg(fabs(res[0]) + fabs(res[1]) + fabs(res[2]) <= 1e-9 * scale,
                  "angular momentum balance (4-39) violated: residual %g, %g, %g (scale %g)", res[0], res[1], res[2],
                  scale);
}

static void run_load(int dim, enum load ld)
{
    printf("%dD parallel bond, %s\n", dim, load_name[ld]);
    const section s = closed_section(dim);
    pair_scene p = bonded_pair(dim);
    const double dt = sx_model_timestep(p.m);
    ck_assert(dt > 0);

    /* closed forms: stiffness, break load, and break value of the imposed coordinate */
    double stiff = 0, brk = 0;
    double vel[3] = {0, 0, 0}, spin[3] = {0, 0, 0};
    const double T = STEPS_TO_BREAK * dt; /* time to the break */
    switch (ld) {
    case TENSION:
        stiff = s.kn * s.area, brk = SIGMA_C * s.area;
        vel[0] = brk / stiff / T;
        break;
    case SHEAR:
        stiff = s.ks * s.area, brk = TAU_C * s.area;
        vel[1] = brk / stiff / T;
        break;
    case BENDING:
        stiff = s.kn * s.inertia, brk = SIGMA_C * s.inertia / s.rbar;
        spin[dim == 3 ? 1 : 0] = 0.5 * brk / stiff / T; /* relative rotation 2 w t */
        break;
    case TWIST:
        stiff = s.ks * s.polar, brk = TAU_C * s.polar / s.rbar;
        spin[0] = 0.5 * brk / stiff / T;
        break;
    case TENSION_BENDING: /* half of sigma_c from each term */
        vel[0] = 0.5 * SIGMA_C / s.kn / T;
        spin[dim == 3 ? 1 : 0] = 0.5 * 0.5 * SIGMA_C / (s.kn * s.rbar) / T;
        break;
    case SHEAR_TWIST:
        vel[1] = 0.5 * TAU_C / s.ks / T;
        spin[0] = 0.5 * 0.5 * TAU_C / (s.ks * s.rbar) / T;
        break;
    }
    const double mspin[3] = {-spin[0], -spin[1], -spin[2]};
    scene_impose(p.m, p.a, NULL, mspin);
    scene_impose(p.m, p.b, vel, spin);
    const double rate = ld == TENSION ? vel[0] : ld == SHEAR ? vel[1] : 2 * (spin[0] + spin[1]);

    double q1 = NAN, q2 = NAN, p1 = NAN, p2 = NAN, peak = 0;
    int64_t broke_at = -1;
    for (int64_t step = 0; step < 2 * STEPS_TO_BREAK; step++) {
        const double q = rate * sx_model_time(p.m); /* the imposed coordinate at this step's positions */
        bpm_cycle(p.m, 1);
        if (sx_crack_count(p.m) > 0) {
            broke_at = step;
            break;
        }
        check_moment_balance(&p, dim);
        if (ld <= TWIST) {
            const double load = load_on_b(&p, dim, ld);
            if (load > peak) peak = load;
            if (isnan(p1) && load >= 0.25 * brk) q1 = q, p1 = load;
            if (isnan(p2) && load >= 0.75 * brk) q2 = q, p2 = load;
        }
    }
    ck_assert_msg(broke_at > 0, "the bond did not break");
    sx_crack c;
    ck_assert(sx_crack_get(p.m, 0, &c) == SX_OK);
    ck_assert_int_eq(c.kind, SX_BOND_PARALLEL);
    const bool tensile = ld == TENSION || ld == BENDING || ld == TENSION_BENDING;
    ck_assert_int_eq(c.mode, tensile ? SX_CRACK_TENSION : SX_CRACK_SHEAR);
    printf("  broke at step %lld (%s), expected about %d\n", (long long)broke_at,
           c.mode == SX_CRACK_TENSION ? "tension" : "shear", STEPS_TO_BREAK);

    if (ld <= TWIST) {
        BPM_CHECK("stiffness (N/m or N m/rad)", (p2 - p1) / (q2 - q1), stiff, 0.005);
        const double logged = ld == TENSION ? -c.fn : ld == SHEAR ? c.fs : ld == BENDING ? c.ms : c.mn;
        BPM_CHECK("break load in the crack log (4-38)", logged, brk, 0.005);
        BPM_CHECK("largest load carried before the break", peak, brk, 0.005);
    } else if (ld == TENSION_BENDING) {
        BPM_CHECK("sigma_max at the break: -Fn/A + |Ms| R/I (Pa)", -c.fn / s.area + c.ms * s.rbar / s.inertia,
                  SIGMA_C, 0.005);
        BPM_CHECK("axial part -Fn/A (Pa)", -c.fn / s.area, 0.5 * SIGMA_C, 0.005);
        BPM_CHECK("bending part |Ms| R/I (Pa)", c.ms * s.rbar / s.inertia, 0.5 * SIGMA_C, 0.005);
    } else {
        BPM_CHECK("tau_max at the break: |Fs|/A + |Mn| R/J (Pa)", c.fs / s.area + c.mn * s.rbar / s.polar, TAU_C,
                  0.005);
        BPM_CHECK("shear part |Fs|/A (Pa)", c.fs / s.area, 0.5 * TAU_C, 0.005);
        BPM_CHECK("twist part |Mn| R/J (Pa)", c.mn * s.rbar / s.polar, 0.5 * TAU_C, 0.005);
    }

    /* broken: nothing holds B any more (the balls do not touch) */
    ck_assert_int_eq(sx_bond_count(p.m), 0);
    bpm_cycle(p.m, 2);
    double f[3], t[3];
    bpm_vec(p.m, p.b, SX_BALL_FORCE, f);
    bpm_vec(p.m, p.b, SX_BALL_MOMENT, t);
    ck_assert_msg(f[0] == 0 && f[1] == 0 && f[2] == 0 && t[0] == 0 && t[1] == 0 && t[2] == 0,
                  "B still loaded after the break: F = (%g, %g, %g), M = (%g, %g, %g)", f[0], f[1], f[2], t[0],
                  t[1], t[2]);
    ck_assert_int_eq(sx_crack_count(p.m), 1);
    sx_model_destroy(p.m);
}

START_TEST(bond_3d) { run_load(3, (enum load)_i); }
END_TEST

static const enum load loads_2d[] = {TENSION, SHEAR, BENDING, TENSION_BENDING};
START_TEST(bond_2d) { run_load(2, loads_2d[_i]); }
END_TEST

int main(void)
{
    Suite *s = suite_create("parallel_bond");
    TCase *tc = tcase_create("loads");
    tcase_add_loop_test(tc, bond_3d, TENSION, SHEAR_TWIST + 1);
    tcase_add_loop_test(tc, bond_2d, 0, 4);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
