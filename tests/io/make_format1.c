/* Writes tests/data/format1.h5, the committed sample of file format 1 that
 * test_format1 loads (files of older formats must keep loading). Run once
 * when format 1 was current; never again (the file is the fixture):
 *     build/tests/io/io_make_format1 tests/data/format1.h5
 * It prints the values test_format1.c checks. */
#include "io_scenes.h"

#include <stdio.h>
#include <string.h>

static const char *out_path;

START_TEST(make)
{
    /* a small 2D bonded specimen: a few cracks, a moving wall, an applied load */
    sx_model *m = scene_model(2, NULL, 0, 1e7, 0.5, 2600);
    sx_bpm_def bpm;
    memset(&bpm, 0, sizeof bpm);
    bpm.radius_multiplier = 1, bpm.modulus = 1e8, bpm.stiffness_ratio = 2;
    bpm.tensile_strength = 2e5, bpm.cohesion = 4e5;
    ck_assert_int_eq(sx_material_set_bpm(m, 0, &bpm), SX_OK);
    const double r = 1e-3;
    int64_t ids[12];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 4; i++) {
            const double x[3] = {2 * r * i, 2 * r * j, 0};
            ids[j * 4 + i] = scene_ball(m, x, NULL, r);
        }
    sx_bond_def bd = sx_bond_default_def();
    bd.gap = 0.1 * r;
    ck_assert_int_eq(sx_bond_install(m, &bd, NULL), SX_OK);
    for (int i = 0; i < 4; i++) {
        const double v[3] = {0, 0.5, 0};
        ck_assert_int_eq(sx_ball_set_vec(m, ids[8 + i], SX_BALL_VEL, v), SX_OK);
        ck_assert_int_eq(sx_ball_set_fixity(m, ids[8 + i], SX_FIX_VX | SX_FIX_VY), SX_OK);
        ck_assert_int_eq(sx_ball_set_fixity(m, ids[i], SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ), SX_OK);
    }
    const double f[3] = {0.5, 0, 0};
    ck_assert_int_eq(sx_ball_set_vec(m, ids[5], SX_BALL_APPLIED_FORCE, f), SX_OK);
    ck_assert_int_eq(sx_ball_set_group(m, ids[6], 2), SX_OK);
    const double p[3] = {-1.2 * r, 0, 0}, n[3] = {1, 0, 0};
    const int64_t w = scene_halfspace(m, p, n, 1e7, 1e7, 0.3);
    const double vw[3] = {0.01, 0, 0};
    ck_assert_int_eq(sx_wall_set_vel(m, w, vw), SX_OK);
    sx_model_track_energy(m, true);
    io_cycle(m, 200);

    sx_io_named_tree t;
    memset(&t, 0, sizeof t);
    snprintf(t.name, sizeof t.name, "vars");
    sx_io_node nd = {.parent = -1, .key_kind = SX_IO_STRING, .key_string = "target", .key_length = 6,
                     .kind = SX_IO_NUMBER, .number = 1.5e6};
    sx_io_tree_add(&t.tree, &nd);
    nd = (sx_io_node){.parent = -1, .key_kind = SX_IO_STRING, .key_string = "label", .key_length = 5,
                      .kind = SX_IO_STRING, .string = "format one", .length = 10};
    sx_io_tree_add(&t.tree, &nd);
    sx_snapshot_opts o;
    memset(&o, 0, sizeof o);
    o.trees = &t;
    o.ntrees = 1;
    o.provenance.script = "tests/io/make_format1.c";
    char err[512];
    ck_assert_msg(sx_snapshot_save(m, out_path, &o, err, sizeof err) == SX_OK, "%s", err);
    sx_io_tree_free(&t.tree);

    double x[3];
    sx_ball_get_vec(m, ids[6], SX_BALL_POS, x);
    printf("time %a step %lld balls %lld contacts %lld bonds %lld cracks %lld hash %016llx\n", sx_model_time(m),
           (long long)sx_model_step_count(m), (long long)sx_ball_count(m), (long long)sx_contact_count(m),
           (long long)sx_bond_count(m), (long long)sx_crack_count(m),
           (unsigned long long)sx_model_state_hash(m));
    printf("ball %lld at %a %a\n", (long long)ids[6], x[0], x[1]);
    sx_model_destroy(m);
}
END_TEST

int main(int argc, char **argv) { return io_run_writer(argc, argv, "make_format1", make, &out_path); }
