/* Files of older format versions keep loading: tests/data/format1.h5 was
 * written by io_make_format1 when format 1 was current (never rewrite it);
 * this checks what it holds, to the bit, and that the model runs on. */
#include "io_scenes.h"

#include <stdio.h>
#include <string.h>

#ifndef SX_TEST_DATA
#error "SX_TEST_DATA: the folder of tests/data"
#endif

static bool pb_contacts(const sx_contact_info *ci, void *ud)
{
    int *n = ud;
    n[0] += ci->bond != 0;
    n[1] += ci->is_wall;
    return true;
}

START_TEST(format1_loads)
{
    sx_snapshot_info info;
    sx_model *m = io_load_sample(SX_TEST_DATA, 1, &info);

    /* the values io_make_format1 printed when it wrote the file */
    ck_assert_int_eq(sx_model_dim(m), 2);
    ck_assert(sx_model_time(m) == 0x1.450e56fc8a674p-11);
    ck_assert_int_eq(sx_model_step_count(m), 200);
    ck_assert_int_eq(sx_ball_count(m), 12);
    ck_assert_int_eq(sx_contact_count(m), 13);
    ck_assert_int_eq(sx_bond_count(m), 13);
    ck_assert_int_eq(sx_crack_count(m), 4);
    ck_assert_int_eq(sx_wall_count(m), 1);
    double x[3];
    ck_assert_int_eq(sx_ball_get_vec(m, 7, SX_BALL_POS, x), SX_OK);
    ck_assert(x[0] == 0x1.0624f08be1608p-8 && x[1] == 0x1.0639ac8ff9938p-9);
    int32_t g;
    ck_assert_int_eq(sx_ball_group(m, 7, &g), SX_OK);
    ck_assert_int_eq(g, 2);
    double f[3];
    ck_assert_int_eq(sx_ball_get_vec(m, 6, SX_BALL_APPLIED_FORCE, f), SX_OK);
    ck_assert(f[0] == 0.5 && f[1] == 0);
    unsigned fix;
    ck_assert_int_eq(sx_ball_fixity(m, 1, &fix), SX_OK);
    ck_assert_uint_eq(fix, SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ);
    sx_wall_def w;
    ck_assert_int_eq(sx_wall_get(m, sx_wall_id_at(m, 0), &w), SX_OK);
    ck_assert(w.vel[0] == 0.01 && w.kind == SX_WALL_LINE);
    sx_bpm_def bpm;
    ck_assert_int_eq(sx_material_get_bpm(m, 0, &bpm), SX_OK);
    ck_assert(bpm.tensile_strength == 2e5 && bpm.cohesion == 4e5);
    ck_assert_str_eq(sx_material_name(m, 0), "m");
    sx_crack c;
    ck_assert_int_eq(sx_crack_get(m, 0, &c), SX_OK);
    ck_assert(c.kind == SX_BOND_PARALLEL && c.step > 0 && c.step <= 200);
    int n[2] = {0, 0};
    sx_contact_each(m, pb_contacts, n);
    ck_assert_int_eq(n[0], 13);
    /* the user's variables */
    ck_assert_int_eq(info.ntrees, 1);
    ck_assert_str_eq(info.trees[0].name, "vars");
    const sx_io_tree *t = &info.trees[0].tree;
    ck_assert_int_eq(t->n, 2);
    for (int64_t i = 0; i < t->n; i++) {
        if (strcmp(t->node[i].key_string, "target") == 0) ck_assert(t->node[i].number == 1.5e6);
        else ck_assert_str_eq(t->node[i].string, "format one");
    }
    sx_snapshot_info_free(&info);
    /* and it runs on */
    io_cycle(m, 300);
    ck_assert_int_eq(sx_model_step_count(m), 500);
    ck_assert(sx_crack_count(m) >= 4);
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

int main(void) { return io_run_test("io_format1", format1_loads); }
