/* Files of older format versions keep loading: tests/data/format3.h5 was
 * written by io_make_format3 when format 3 was current (never rewrite it);
 * this checks what it holds, to the bit (ball-ball contacts whose normal
 * and overlap follow from the stored relative position), and that the
 * model runs on. */
#include "io_scenes.h"

#include <stdio.h>
#include <string.h>

#ifndef SX_TEST_DATA
#error "SX_TEST_DATA: the folder of tests/data"
#endif

START_TEST(format3_loads)
{
    sx_snapshot_info info;
    sx_model *m = io_load_sample(SX_TEST_DATA, 3, &info);
    sx_snapshot_info_free(&info);

    /* the values io_make_format3 printed when it wrote the file */
    ck_assert_int_eq(sx_model_dim(m), 3);
    ck_assert(sx_model_time(m) == 0x1.0624dd2f1aa06p-9);
    ck_assert_int_eq(sx_model_step_count(m), 200);
    ck_assert_int_eq(sx_ball_count(m), 36);
    ck_assert_int_eq(sx_contact_count(m), 27);
    sx_contact_info ci;
    io_first_ball_contact(m, &ci);
    ck_assert(ci.a == 1 && ci.b == 10);
    ck_assert(ci.normal[0] == -0x1.960773b8ebae3p-11 && ci.normal[1] == -0x1.abb2cd776536ep-11 &&
              ci.normal[2] == 0x1.ffffeac5d929p-1);
    ck_assert(ci.overlap == 0x1.1f1ba208cep-19);
    ck_assert(ci.shear[0] == -0x1.18a290ce7adcdp-5 && ci.shear[1] == -0x1.92ba3591dcaaep-7 &&
              ci.shear[2] == -0x1.32a7c732f2da4p-15);
    ck_assert(ci.fn == 0x1.678e10423f51p-3);

    /* and it runs on */
    io_cycle(m, 200);
    ck_assert_int_eq(sx_model_step_count(m), 400);
    ck_assert(sx_contact_count(m) > 0);
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

int main(void) { return io_run_test("io_format3", format3_loads); }
