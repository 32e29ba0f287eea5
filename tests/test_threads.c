/* Threads: the step's results do not depend on the number of OpenMP
 * threads (work is split in chunks fixed by the model, and partial sums are
 * added in chunk order), so 1 and 2 threads give bit-identical states. */
#include "scenes.h"

#include <check.h>
#include <stdio.h>
#include <stdlib.h>

/* A dense bed big enough to be split into several chunks of pairs. */
static sx_model *bed(int dim, int threads)
{
    const double g[3] = {0, dim == 2 ? -9.81 : 0, dim == 3 ? -9.81 : 0};
    sx_model *m = scene_model(dim, g, 1e-5, 2e5, 0.5, 2500);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = 2e5;
    md.density = 2500;
    md.viscous_normal = 0.2;
    md.damping = 0.1;
    scene_material_def(m, "m", &md);
    ck_assert_int_eq(sx_model_set_threads(m, threads), SX_OK);
    const double r = 0.01, s = 2 * r - 1e-5;
    const int nx = dim == 3 ? 16 : 100, ny = dim == 3 ? 16 : 60, nz = dim == 3 ? 16 : 1;
    uint64_t seed = 7;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                double x[3] = {r + i * s + scene_rng_uniform(&seed, -2e-6, 2e-6), r + j * s, r + k * s};
                if (dim == 3) x[1] += scene_rng_uniform(&seed, -2e-6, 2e-6);
                scene_ball(m, x, NULL, r);
            }
    const double lo[3] = {0, 0, 0}, hi[3] = {nx * s + r, dim == 3 ? ny * s + r : 10, 10};
    scene_box_walls(m, lo, hi, 2e5, 0.5);
    return m;
}

START_TEST(one_and_two_threads_bit_identical)
{
    const int dim = _i;
    sx_model *a = bed(dim, 1), *b = bed(dim, 2);
    ck_assert_int_eq(sx_model_threads(b), 2);
    ck_assert_int_eq(sx_model_cycle(a, 300), SX_OK);
    ck_assert_int_eq(sx_model_cycle(b, 300), SX_OK);
    ck_assert_msg(sx_contact_count(a) > sx_ball_count(a), "the bed must be dense (%lld contacts)",
                  (long long)sx_contact_count(a));
    ck_assert_uint_eq(sx_model_state_hash(a), sx_model_state_hash(b));
    sx_model_destroy(a);
    sx_model_destroy(b);
}
END_TEST

/* Bonded pairs stay in the store whatever their gap: balls of the bed's
 * bottom layer bonded to their neighbours and then lifted to the top pair
 * with balls far away in the sorted order, so the ball-ball pass's chunks
 * are planned around them; the bits still do not depend on the threads. */
static void far_bonded_pairs(int dim, sx_bond_kind kind)
{
    sx_model *ms[2] = {bed(dim, 1), bed(dim, 2)};
    for (int k = 0; k < 2; k++) {
        sx_model *m = ms[k];
        ck_assert_int_eq(sx_model_cycle(m, 1), SX_OK);
        sx_bond_def bd = sx_bond_default_def();
        bd.kind = kind;
        bd.radius_multiplier = 0.5;
        bd.modulus = 1e3; /* weak: the lifted balls pull on their old neighbours without upsetting the bed */
        bd.stiffness_ratio = 1;
        bd.tensile_strength = bd.cohesion = 1e30;
        bd.gap = 1e-6;

        int64_t count = 0;
        ck_assert_int_eq(sx_bond_install(m, &bd, &count), SX_OK);
        ck_assert(count > sx_ball_count(m));
        /* every 7th ball of the first rows goes 5 cm above the bed */
        for (int64_t i = 0; i < sx_ball_count(m) / 8; i += 7) {
            const int64_t id = sx_ball_id_at(m, i);
            double x[3];
            ck_assert_int_eq(sx_ball_get_vec(m, id, SX_BALL_POS, x), SX_OK);
            x[dim - 1] += dim == 3 ? 0.4 : 1.3;
            ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_POS, x), SX_OK);
        }
        ck_assert_msg(sx_model_cycle(m, 100) == SX_OK, "%s", sx_model_error(m));
    }
    ck_assert_int_eq(sx_bond_count(ms[0]), sx_bond_count(ms[1]));
    ck_assert_uint_eq(sx_model_state_hash(ms[0]), sx_model_state_hash(ms[1]));
    sx_model_destroy(ms[0]);
    sx_model_destroy(ms[1]);
}

START_TEST(far_bonded_pairs_bit_identical) { far_bonded_pairs(_i, SX_BOND_PARALLEL); }
END_TEST

/* The bed flat-jointed (laws/flatjoint.h; a third of the elements slit,
 * weak elements) settles under gravity while elements break: the joints'
 * elements, their crack log and the state do not depend on the threads. */
START_TEST(flat_jointed_bed_bit_identical)
{
    const int dim = _i;
    sx_model *ms[2] = {bed(dim, 1), bed(dim, 2)};
    for (int k = 0; k < 2; k++) {
        sx_model *m = ms[k];
        ck_assert_int_eq(sx_model_cycle(m, 1), SX_OK);
        sx_bond_def bd = sx_bond_default_def();
        bd.kind = SX_BOND_FLATJOINT;
        bd.radius_multiplier = 0.8;
        bd.modulus = 2e5;
        bd.stiffness_ratio = 1.5;
        /* weak enough that the first 3 ms of settling break some (2D: the balls fall ~ 40 um, which
         * loads an element of the soft 2D faces to about 0.5 Pa) */
        const double sigma = dim == 3 ? 50 : 0.3;
        bd.tensile_strength = sigma, bd.tensile_strength_sd = 0.2 * sigma;
        bd.cohesion = 2 * sigma, bd.cohesion_sd = 0.4 * sigma;
        bd.friction_angle = 30;
        bd.friction = 0.5;
        bd.unbonded_fraction = 0.3;
        bd.gap = 1e-6;
        int64_t count = 0;
        ck_assert_int_eq(sx_bond_install(m, &bd, &count), SX_OK);
        ck_assert(count > sx_ball_count(m));
        ck_assert_msg(sx_model_cycle(m, 300) == SX_OK, "%s", sx_model_error(m));
    }
    printf("%dD flat-jointed bed: %lld joints, %lld elements broke\n", dim, (long long)sx_bond_count(ms[0]),
           (long long)sx_crack_count(ms[0]));
    ck_assert(sx_crack_count(ms[0]) > 0);
    ck_assert_int_eq(sx_crack_count(ms[0]), sx_crack_count(ms[1]));
    ck_assert_uint_eq(sx_model_state_hash(ms[0]), sx_model_state_hash(ms[1]));
    sx_model_destroy(ms[0]);
    sx_model_destroy(ms[1]);
}
END_TEST

START_TEST(thread_count_validated)
{
    sx_model *m = scene_model(3, NULL, 1e-5, 1e5, 0.5, 2500);
    ck_assert_int_eq(sx_model_set_threads(m, 0), SX_EINVAL);
    ck_assert_int_eq(sx_model_set_threads(m, -3), SX_EINVAL);
    ck_assert_int_eq(sx_model_threads(m), 1);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("threads");
    TCase *tc = tcase_create("threads");
    tcase_set_timeout(tc, 600);
    tcase_add_loop_test(tc, one_and_two_threads_bit_identical, 2, 4);
    tcase_add_loop_test(tc, far_bonded_pairs_bit_identical, 2, 4);
    tcase_add_loop_test(tc, flat_jointed_bed_bit_identical, 2, 4);
    tcase_add_test(tc, thread_count_validated);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
