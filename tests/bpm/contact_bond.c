/* A contact bond (seed 4.3.5, figures 4.5 and 4.6) failing in tension and in
 * shear, 2D and 3D.
 *
 * Scene: equal balls R = 1 mm exactly touching (d = 2R), linear springs
 * kn = ks = 1e8 N/m per ball, so Kn = Ks = 5e7 N/m per contact (4-22/4-23),
 * friction 0.5; contact bond of normal strength Fc_n = 10 N and shear strength
 * Fc_s = 20 N. Ball A is held still, B moves at imposed speeds, all spins are
 * held at zero. Closed forms (linear springs, the bond carries tension):
 *   Fn = Kn Un (4-6, Un < 0 in tension), Fs = -Ks Us (4-18 ... 4-20).
 * Tension case: B first slides across by Us so that |Fs| = Fc_s/2 (with
 *   Fn = 0: the friction limit mu Fn = 0 does not apply while bonded), then
 *   is pulled apart; the bond breaks when -Fn = Fc_n, i.e. at Un = -Fc_n/Kn,
 *   and in that step both components become zero (figure 4.5); the crack is
 *   logged with mode tension and Fn = -Fc_n, |Fs| = Fc_s/2.
 * Shear case: B is first pushed in by Un = 1e-7 m (Fn = Kn Un = 5 N), then
 *   slid across; the bond breaks when |Fs| = Fc_s (> mu Fn = 2.5 N: the bond
 *   let the shear force exceed the friction limit), mode shear; from then on
 *   slip governs (figure 4.6): |Fs| <= mu Fn, and |Fs| = mu Fn while sliding,
 *   with Fn unchanged.
 * Tolerance 0.5 % on the break loads: each loading phase is 2000 steps, so
 * the break overshoots the strength by at most one increment, 1/2000 of it.
 * The slip limit and Fn = Kn Un (with Un from the positions) are checked to
 * rounding (1e-12 relative).
 */
#include "bpm.h"

static const double R = 1e-3, KBALL = 1e8, MU = 0.5, FCN = 10, FCS = 20;
static const int PHASE_STEPS = 2000;

typedef struct cb_scene {
    sx_model *m;
    int64_t a, b;
    double kn, ks; /* contact stiffnesses */
} cb_scene;

static cb_scene bonded(int dim)
{
    cb_scene p;
    p.m = bpm_model(dim, 0);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = KBALL;
    md.friction = MU;
    const int mat = bpm_material(p.m, "grain", &md);
    const double xa[3] = {0, 0, 0}, xb[3] = {2 * R, 0, 0};
    p.a = scene_ball_of(p.m, mat, xa, NULL, R);
    p.b = scene_ball_of(p.m, mat, xb, NULL, R);
    p.kn = KBALL * KBALL / (2 * KBALL); /* 4-22 */
    p.ks = p.kn;                         /* 4-23 */
    sx_bond_def bd = sx_bond_default_def();
    bd.kind = SX_BOND_CONTACT;
    bd.gap = 1e-9;
    bd.normal_strength = FCN;
    bd.shear_strength = FCS;
    int64_t n = 0;
    ck_assert_msg(sx_bond_install(p.m, &bd, &n) == SX_OK, "%s", sx_model_error(p.m));
    ck_assert_int_eq(n, 1);
    scene_impose(p.m, p.a, NULL, NULL);
    scene_impose(p.m, p.b, NULL, NULL);
    return p;
}

static void set_vel(cb_scene *p, double vx, double vy)
{
    const double v[3] = {vx, vy, 0};
    ck_assert(sx_ball_set_vec(p->m, p->b, SX_BALL_VEL, v) == SX_OK);
}

/* The force on B of the last step, split along the normal n of the positions
 * it was computed at (the current ones less one step of the imposed
 * velocity): fn = F.n (compression positive), fs the tangential component
 * (signed, along the in-plane tangent); *un the overlap there. */
static void force_b(const cb_scene *p, double *fn, double *fs, double *un)
{
    double f[3], xa[3], xb[3], vb[3];
    bpm_vec(p->m, p->b, SX_BALL_FORCE, f);
    bpm_vec(p->m, p->a, SX_BALL_POS, xa);
    bpm_vec(p->m, p->b, SX_BALL_POS, xb);
    bpm_vec(p->m, p->b, SX_BALL_VEL, vb);
    const double dt = sx_model_timestep(p->m);
    const double dx = xb[0] - vb[0] * dt - xa[0], dy = xb[1] - vb[1] * dt - xa[1];
    const double d = sqrt(dx * dx + dy * dy), nx = dx / d, ny = dy / d;
    *fn = f[0] * nx + f[1] * ny;
    *fs = -f[0] * ny + f[1] * nx;
    if (un) *un = 2 * R - d;
}

static void tension(int dim)
{
    printf("%dD contact bond, tension failure\n", dim);
    cb_scene p = bonded(dim);
    const double dt = sx_model_timestep(p.m), T = PHASE_STEPS * dt;
    /* phase 1: shear to Fc_s / 2 */
    set_vel(&p, 0, 0.5 * FCS / p.ks / T);
    bpm_cycle(p.m, PHASE_STEPS);
    double fn, fs;
    force_b(&p, &fn, &fs, NULL);
    printf("  after sliding across: Fn = %.4g N, Fs = %.6g N (friction limit mu Fn = %.3g N not applied while "
           "bonded)\n", fn, fs, MU * (fn > 0 ? fn : 0));
    ck_assert_msg(fabs(fs) > MU * (fn > 0 ? fn : 0) + 1, "the bonded contact slipped");
    ck_assert_int_eq(sx_crack_count(p.m), 0);
    /* phase 2: pull apart */
    set_vel(&p, FCN / p.kn / T, 0);
    int64_t broke = -1;
    double fn_before = 0;
    for (int64_t s = 0; s < 2 * PHASE_STEPS && broke < 0; s++) {
        bpm_cycle(p.m, 1);
        if (sx_crack_count(p.m)) {
            broke = s;
        } else {
            force_b(&p, &fn_before, &fs, NULL);
        }
    }
    ck_assert_msg(broke >= 0, "the contact bond did not break");
    sx_crack c;
    ck_assert(sx_crack_get(p.m, 0, &c) == SX_OK);
    ck_assert_int_eq(c.kind, SX_BOND_CONTACT);
    ck_assert_int_eq(c.mode, SX_CRACK_TENSION);
    printf("  broke after %lld steps of pulling, expected about %d\n", (long long)broke, PHASE_STEPS);
    BPM_CHECK("normal force at failure (crack log, tension, N)", -c.fn, FCN, 0.005);
    BPM_CHECK("largest tension carried before the failure (N)", -fn_before, FCN, 0.005);
    BPM_CHECK("shear force at failure (crack log, N)", c.fs, 0.5 * FCS, 0.005);
    /* in the breaking step both force components are already zero */
    force_b(&p, &fn, &fs, NULL);
    printf("  force on B in the breaking step: Fn = %g N, Fs = %g N\n", fn, fs);
    ck_assert_msg(fn == 0 && fs == 0, "forces not zeroed by the tensile failure: Fn = %g, Fs = %g", fn, fs);
    ck_assert_int_eq(sx_bond_count(p.m), 0);
    bpm_cycle(p.m, 10);
    force_b(&p, &fn, &fs, NULL);
    ck_assert_msg(fn == 0 && fs == 0, "forces after the tensile failure: Fn = %g, Fs = %g", fn, fs);
    ck_assert_int_eq(sx_crack_count(p.m), 1);
    sx_model_destroy(p.m);
}

static void shear(int dim)
{
    printf("%dD contact bond, shear failure\n", dim);
    cb_scene p = bonded(dim);
    const double dt = sx_model_timestep(p.m), T = PHASE_STEPS * dt;
    const double un = 1e-7;
    /* phase 1: push in by un */
    set_vel(&p, -un / T, 0);
    bpm_cycle(p.m, PHASE_STEPS);
    set_vel(&p, 0, 0);
    bpm_cycle(p.m, 1);
    double fn, fs, un_now;
    force_b(&p, &fn, &fs, &un_now);
    printf("  pushed in by %.10g m (nominal %g m, the rest is rounding of the positions)\n", un_now, un);
    BPM_CHECK("normal force after pushing in: Kn Un (N)", fn, p.kn * un_now, 1e-12);
    /* phase 2: slide across */
    set_vel(&p, 0, FCS / p.ks / T);
    int64_t broke = -1;
    double fs_before = 0;
    double un_break = 0;
    for (int64_t s = 0; s < 2 * PHASE_STEPS && broke < 0; s++) {
        bpm_cycle(p.m, 1);
        force_b(&p, &fn, &fs, &un_break);
        if (sx_crack_count(p.m)) broke = s;
        else fs_before = fabs(fs);
    }
    ck_assert_msg(broke >= 0, "the contact bond did not break");
    printf("  broke after %lld steps of sliding, expected about %d\n", (long long)broke, PHASE_STEPS);
    ck_assert_msg(fs_before > MU * fn, "the bond should hold a shear force above the friction limit");
    sx_crack c;
    ck_assert(sx_crack_get(p.m, 0, &c) == SX_OK);
    ck_assert_int_eq(c.kind, SX_BOND_CONTACT);
    ck_assert_int_eq(c.mode, SX_CRACK_SHEAR);
    BPM_CHECK("shear force at failure (crack log, N)", c.fs, FCS, 0.005);
    BPM_CHECK("largest shear force carried before the failure (N)", fs_before, FCS, 0.005);
    BPM_CHECK("normal force at failure (crack log): Kn Un (N)", c.fn, p.kn * un_break, 1e-12);
    ck_assert_int_eq(sx_bond_count(p.m), 0);
    /* slip takes over, from the breaking step on; the normal force stays */
    double worst = 0;
    for (int s = 0; s < 200; s++) {
        double un_s;
        force_b(&p, &fn, &fs, &un_s);
        ck_assert_msg(fabs(fn - p.kn * un_s) <= 1e-12 * p.kn * un_s, "normal force %.12g != Kn Un = %.12g after the shear failure",
                      fn, p.kn * un_s);
        const double e = fabs(fabs(fs) - MU * fn) / (MU * fn);
        if (e > worst) worst = e;
        ck_assert_msg(fabs(fs) <= MU * fn * (1 + 1e-12), "|Fs| = %.12g > mu Fn = %.12g after the shear failure",
                      fabs(fs), MU * fn);
        bpm_cycle(p.m, 1);
    }
    printf("  after the failure, sliding: |Fs| = mu Fn to %.2e (Fs = %.6g N, mu Fn = %.6g N)\n", worst, fabs(fs),
           MU * fn);
    ck_assert_msg(worst <= 1e-12, "sliding contact off the Coulomb limit by %g", worst);
    ck_assert_int_eq(sx_crack_count(p.m), 1);
    sx_model_destroy(p.m);
}

START_TEST(tension_3d) { tension(3); }
END_TEST
START_TEST(tension_2d) { tension(2); }
END_TEST
START_TEST(shear_3d) { shear(3); }
END_TEST
START_TEST(shear_2d) { shear(2); }
END_TEST

int main(void)
{
    Suite *s = suite_create("contact_bond");
    TCase *tc = tcase_create("failure");
    tcase_add_test(tc, tension_3d);
    tcase_add_test(tc, tension_2d);
    tcase_add_test(tc, shear_3d);
    tcase_add_test(tc, shear_2d);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
