/* Writes tests/data/format3.h5, the committed sample of file format 3 that
 * test_format3 loads (files of older formats must keep loading). Run once
 * when format 3 was current; never again (the file is the fixture):
 *     build/tests/io/io_make_format3 tests/data/format3.h5
 * It prints the values test_format3.c checks. What format 3 changed is in
 * it: ball-ball pairs with a live history, stored as the relative position
 * of their last evaluation (a small 3D bed settling with friction and a
 * normal dashpot on a floor). */
#include "io_scenes.h"

#include <stdio.h>
#include <string.h>

static const char *out_path;

START_TEST(make)
{
    sx_model *m = scene_model(3, (double[3]){0, 0, -9.81}, 1e-5, 2e5, 0.5, 2500);
    sx_material_def md;
    ck_assert_int_eq(sx_material_get(m, 0, &md), SX_OK);
    md.viscous_normal = 0.2;
    scene_material_def(m, "m", &md);
    /* a 3 x 3 x 4 lattice of touching balls, slightly perturbed */
    const double r = 0.01, s = 2 * r - 1e-5;
    uint64_t seed = 3;
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 3; i++) {
                const double x[3] = {r + i * s + scene_rng_uniform(&seed, -2e-6, 2e-6),
                                     r + j * s + scene_rng_uniform(&seed, -2e-6, 2e-6), r + k * s};
                scene_ball(m, x, NULL, r);
            }
    const double p0[3] = {0, 0, 0}, n0[3] = {0, 0, 1};
    scene_halfspace(m, p0, n0, 2e5, 2e5, 0.5);
    io_cycle(m, 200);
    sx_snapshot_opts o;
    memset(&o, 0, sizeof o);
    o.provenance.script = "tests/io/make_format3.c";
    char err[512];
    ck_assert_msg(sx_snapshot_save(m, out_path, &o, err, sizeof err) == SX_OK, "%s", err);

    sx_contact_info ci;
    io_first_ball_contact(m, &ci);
    printf("time %a step %lld balls %lld contacts %lld\n", sx_model_time(m), (long long)sx_model_step_count(m),
           (long long)sx_ball_count(m), (long long)sx_contact_count(m));
    printf("first ball-ball contact %lld-%lld: normal %a %a %a overlap %a shear %a %a %a fn %a\n", (long long)ci.a,
           (long long)ci.b, ci.normal[0], ci.normal[1], ci.normal[2], ci.overlap, ci.shear[0], ci.shear[1],
           ci.shear[2], ci.fn);
    sx_model_destroy(m);
}
END_TEST

int main(int argc, char **argv) { return io_run_writer(argc, argv, "make_format3", make, &out_path); }
