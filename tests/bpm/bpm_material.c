/* Bonded-particle material parameters (4.4) and the Hertz/bond exclusion.
 *
 * 1. Hertz + bond is refused (seed 4.3.3: Hertz-Mindlin is not to be used
 *    with bonds): sx_bond_install on two touching Hertz balls returns
 *    SX_EINVAL for both bond kinds, with a message naming Hertz, and installs
 *    nothing.
 * 2. BPM modulus mode (material `modulus` Ec > 0): each ball's springs are
 *    kn = 4 R Ec (3D) or 2 Ec (2D) (4-49) and ks = kn / (kn/ks) (4-50), put in
 *    series per contact (4-22/4-23):
 *      3D, radii RA, RB:  Kn = 4 Ec RA RB / (RA + RB), Ks = Kn / ratio;
 *      2D:                Kn = Ec,                    Ks = Ec / ratio;
 *      3D BPM ball (RA) against a plain ball of kn = k: Kn = 4 RA Ec k / (4 RA Ec + k);
 *      3D BPM ball against a wall of kn = kw:           Kn = 4 R Ec kw / (4 R Ec + kw).
 *    Measured: A (or the wall) still, B pushed in at an imposed speed for
 *    1000 steps, then slid across for 1000 steps (friction 10, so it sticks);
 *    Kn = Fn / Un and Ks = |Fs| / Us from the force on B, with Un from the
 *    positions the force was computed at and Us the imposed slide. Linear
 *    springs: exact up to rounding, and Fs is taken normal to the current n,
 *    so the turn of n (Us/d < 7e-4) enters only at second order; the
 *    shear displacement normal to n is Us (1 - O((Us/d)^2)). Tolerance 1e-3
 *    (the test asserts the model, not the rounding).
 */
#include "bpm.h"

START_TEST(hertz_refused)
{
    sx_model *m = bpm_model(3, 0);
    sx_material_def md = sx_material_default_def();
    md.model = SX_MODEL_HERTZ;
    const int mat = bpm_material(m, "glass", &md);
    const double xa[3] = {0, 0, 0}, xb[3] = {2e-3, 0, 0};
    scene_ball_of(m, mat, xa, NULL, 1e-3);
    scene_ball_of(m, mat, xb, NULL, 1e-3);
    const sx_bond_kind kinds[2] = {SX_BOND_PARALLEL, SX_BOND_CONTACT};
    for (int k = 0; k < 2; k++) {
        sx_bond_def bd = sx_bond_default_def();
        bd.kind = kinds[k];
        bd.gap = 1e-6;
        bd.radius_multiplier = 1, bd.modulus = 1e9, bd.stiffness_ratio = 1;
        bd.tensile_strength = bd.cohesion = 1e6;
        bd.normal_strength = bd.shear_strength = 10;
        int64_t n = -1;
        const sx_status st = sx_bond_install(m, &bd, &n);
        printf("%s bond on Hertz balls: status %d, \"%s\"\n", k ? "contact" : "parallel", (int)st,
               sx_model_error(m));
        ck_assert_int_eq(st, SX_EINVAL);
        ck_assert_msg(strstr(sx_model_error(m), "Hertz") != NULL, "the message does not mention Hertz: %s",
                      sx_model_error(m));
        ck_assert_int_eq(sx_bond_count(m), 0);
    }
    sx_model_destroy(m);
}
END_TEST

enum partner { BPM_BALL, PLAIN_BALL, WALL };

static void stiffness_case(int dim, enum partner partner)
{
    const double EC = 1e8, RATIO = 2.0, RA = 1e-3, RB = 2e-3, KPLAIN = 5e5, KWALL = 3e5;
    sx_model *m = bpm_model(dim, 0);
    sx_material_def md = sx_material_default_def();
    md.modulus = EC;
    md.stiffness_ratio = RATIO;
    md.kn = md.ks = 1.0; /* ignored in modulus mode */
    md.friction = 10;
    const int bpm = bpm_material(m, "bpm", &md);
    sx_material_def pd = sx_material_default_def();
    pd.kn = KPLAIN, pd.ks = KPLAIN / RATIO;
    pd.friction = 10;
    const int plain = bpm_material(m, "plain", &pd);

    double kn_b, ks_b; /* the partner's springs */
    const double kn_a = dim == 3 ? 4 * RA * EC : 2 * EC, ks_a = kn_a / RATIO; /* 4-49/4-50 */
    int64_t a = 0, b;
    double xa[3] = {0, 0, 0}, rb = RB;
    const char *what;
    if (partner == WALL) {
        sx_wall_def wd = sx_wall_default_def(dim); /* normal +y (2D) / +z (3D) */
        wd.kn = KWALL, wd.ks = KWALL / RATIO;
        wd.friction = 10;
        ck_assert(sx_wall_add(m, &wd, NULL) == SX_OK);
        kn_b = KWALL, ks_b = KWALL / RATIO;
        rb = RA;
        const double x[3] = {0, dim == 2 ? RA : 0, dim == 3 ? RA : 0};
        b = scene_ball_of(m, bpm, x, NULL, RA);
        what = "BPM ball against a wall";
    } else {
        a = scene_ball_of(m, bpm, xa, NULL, RA);
        const double x[3] = {RA + RB, 0, 0};
        b = scene_ball_of(m, partner == BPM_BALL ? bpm : plain, x, NULL, RB);
        if (partner == BPM_BALL) {
            kn_b = dim == 3 ? 4 * RB * EC : 2 * EC, ks_b = kn_b / RATIO;
            what = dim == 3 ? "two BPM balls, RA = 1 mm, RB = 2 mm" : "two BPM disks";
        } else {
            kn_b = KPLAIN, ks_b = KPLAIN / RATIO;
            what = "BPM ball against a plain (kn, ks) ball";
        }
        scene_impose(m, a, NULL, NULL);
    }
    const double kn = kn_a * kn_b / (kn_a + kn_b), ks = ks_a * ks_b / (ks_a + ks_b); /* 4-22/4-23 */
    printf("%dD %s\n", dim, what);

    /* normal axis from the partner to B, and a tangent */
    const int ax = partner == WALL ? dim - 1 : 0, tg = partner == WALL ? 0 : 1;
    const double dt = sx_model_timestep(m), T = 1000 * dt, un = 1e-6, us = 2e-6;
    double v[3] = {0, 0, 0};
    v[ax] = -un / T;
    scene_impose(m, b, v, NULL);
    bpm_cycle(m, 1000);
    v[ax] = 0;
    ck_assert(sx_ball_set_vec(m, b, SX_BALL_VEL, v) == SX_OK);
    bpm_cycle(m, 1);
    double f[3], x[3];
    bpm_vec(m, b, SX_BALL_FORCE, f);
    bpm_vec(m, b, SX_BALL_POS, x);
    const double un_now = partner == WALL ? RA - x[ax] : RA + rb - x[0];
    BPM_CHECK("normal stiffness Kn = Fn/Un (N/m)", f[ax] / un_now, kn, 1e-3);
    v[tg] = us / T;
    ck_assert(sx_ball_set_vec(m, b, SX_BALL_VEL, v) == SX_OK);
    bpm_cycle(m, 1000);
    bpm_vec(m, b, SX_BALL_FORCE, f);
    bpm_vec(m, b, SX_BALL_POS, x);
    /* the normal at the positions the last force was computed at */
    double n[3] = {0, 0, 0}, nn = 0, fdotn = 0, fs2 = 0;
    if (partner == WALL) {
        n[ax] = 1, nn = 1;
    } else {
        for (int k = 0; k < dim; k++) {
            n[k] = x[k] - v[k] * dt - xa[k];
            nn += n[k] * n[k];
        }
        nn = sqrt(nn);
    }
    for (int k = 0; k < dim; k++) fdotn += f[k] * n[k] / nn;
    for (int k = 0; k < dim; k++) fs2 += pow(f[k] - fdotn * n[k] / nn, 2);
    /* the last step's force saw 1000 increments of the slide (the first one at the step the velocity was set) */
    BPM_CHECK("shear stiffness Ks = |Fs|/Us (N/m)", sqrt(fs2) / us, ks, 1e-3);
    sx_model_destroy(m);
}

START_TEST(bpm_pair_3d) { stiffness_case(3, BPM_BALL); }
END_TEST
START_TEST(bpm_pair_2d) { stiffness_case(2, BPM_BALL); }
END_TEST
START_TEST(bpm_plain_3d) { stiffness_case(3, PLAIN_BALL); }
END_TEST
START_TEST(bpm_wall_3d) { stiffness_case(3, WALL); }
END_TEST

int main(void)
{
    Suite *s = suite_create("bpm_material");
    TCase *tc = tcase_create("material");
    tcase_add_test(tc, hertz_refused);
    tcase_add_test(tc, bpm_pair_3d);
    tcase_add_test(tc, bpm_pair_2d);
    tcase_add_test(tc, bpm_plain_3d);
    tcase_add_test(tc, bpm_wall_3d);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
