/* Files of older format versions keep loading: tests/data/format2.h5 was
 * written by io_make_format2 when format 2 was current (never rewrite it);
 * this checks what it holds, to the bit (its servo-controlled cylinder and
 * platen, histories, seeds), and that the model runs on with its servos. */
#include "io_scenes.h"

#include <stdio.h>
#include <string.h>

#ifndef SX_TEST_DATA
#error "SX_TEST_DATA: the folder of tests/data"
#endif

START_TEST(format2_loads)
{
    sx_snapshot_info info;
    sx_model *m = io_load_sample(SX_TEST_DATA, 2, &info);

    /* the values io_make_format2 printed when it wrote the file */
    ck_assert_int_eq(sx_model_dim(m), 3);
    ck_assert(sx_model_time(m) == 0x1.a50ca225a79c2p-15);
    ck_assert_int_eq(sx_model_step_count(m), 300);
    ck_assert_int_eq(sx_ball_count(m), 18);
    ck_assert_int_eq(sx_contact_count(m), 6);
    ck_assert_int_eq(sx_wall_count(m), 3);
    sx_wall_def c, top;
    ck_assert_int_eq(sx_wall_get(m, 1, &c), SX_OK);
    ck_assert_int_eq(sx_wall_get(m, 3, &top), SX_OK);
    ck_assert_int_eq(c.kind, SX_WALL_CYLINDER);
    ck_assert(c.radius == 0x1.95a19eaefb7fp-9 && c.radial_vel == -0x1.1be5673814e58p-5 && c.height == 8e-3);
    ck_assert(top.point[2] == 0x1.8f79092df370cp-8 && top.vel[2] == -0x1.26af1a4f938e9p-5);
    double load;
    int64_t nc;
    ck_assert_int_eq(sx_wall_load(m, 1, &load, &nc, NULL), SX_OK);
    ck_assert(load == 0x1.849e15e8bdf7p-7);
    ck_assert_int_eq(nc, 3);

    /* histories: every kind of source, in their order */
    ck_assert_int_eq(info.nhistories, 4);
    const char *names[4] = {"ke", "z of ball 3", "cylinder fx", "user, \"quoted\""};
    const int64_t every[4] = {5, 10, 5, 50};
    const sx_io_source src[4] = {SX_IO_SOURCE_BUILTIN, SX_IO_SOURCE_BALL, SX_IO_SOURCE_WALL, SX_IO_SOURCE_FUNCTION};
    for (int k = 0; k < 4; k++) {
        const sx_io_history *h = &info.histories[k];
        ck_assert_str_eq(h->name, names[k]);
        ck_assert_int_eq(h->every, every[k]);
        ck_assert_int_eq(h->source, src[k]);
        ck_assert_int_eq(h->n, 300 / every[k]);
        for (int64_t i = 0; i < h->n; i++)
            ck_assert(h->steps[i] == every[k] * (i + 1) && h->values[i] == 0.25 * (double)h->steps[i] &&
                      h->times[i] == 1e-7 * (double)h->steps[i]);
    }
    ck_assert_str_eq(info.histories[0].builtin, "kinetic");
    ck_assert_str_eq(info.histories[1].field, "pos");
    ck_assert_int_eq(info.histories[1].id, 3);
    ck_assert_int_eq(info.histories[1].component, 2);
    ck_assert_str_eq(info.histories[2].field, "force");
    ck_assert_int_eq(info.histories[2].id, 1);
    ck_assert_int_eq(info.nseeds, 2);
    ck_assert(info.seeds[0] == 7 && info.seeds[1] == 99);
    ck_assert_int_eq(info.ntrees, 1);
    ck_assert_str_eq(info.trees[0].name, "vars");
    ck_assert(info.trees[0].tree.n == 1 && info.trees[0].tree.node[0].number == 1.5e4);
    sx_snapshot_info_free(&info);

    /* and it runs on, its servos acting */
    io_cycle(m, 300);
    ck_assert_int_eq(sx_model_step_count(m), 600);
    sx_wall_def c2;
    ck_assert_int_eq(sx_wall_get(m, 1, &c2), SX_OK);
    ck_assert(c2.radius != c.radius && c2.radial_vel != 0);
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

int main(void) { return io_run_test("io_format2", format2_loads); }
