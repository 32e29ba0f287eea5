/* Writes tests/data/format2.h5, the committed sample of file format 2 that
 * test_format2 loads (files of older formats must keep loading). Run once
 * when format 2 was current; never again (the file is the fixture):
 *     build/tests/io/io_make_format2 tests/data/format2.h5
 * It prints the values test_format2.c checks. What format 2 added is all
 * in it: a cylinder of finite height whose radius is servo-controlled, a
 * servo-controlled platen, histories of every kind of source, seeds. */
#include "io_scenes.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *out_path;

START_TEST(make)
{
    sx_model *m = scene_model(3, (double[3]){0, 0, -9.81}, 0, 1e8, 0.5, 2650);
    sx_material_def md;
    ck_assert_int_eq(sx_material_get(m, 0, &md), SX_OK);
    md.damping = 0.7;
    scene_material_def(m, "m", &md);
    /* 18 balls in three layers of six around the axis */
    const double r = 1e-3;
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 6; j++) {
            const double a = 2 * 3.14159265358979 * (j + 0.5 * k) / 6;
            const double x[3] = {2.1 * r * cos(a), 2.1 * r * sin(a), r + 2.05 * r * k};
            scene_ball(m, x, NULL, r * (1 - 0.001 * j));
        }
    sx_wall_def w = sx_wall_default_def(3);
    w.kind = SX_WALL_CYLINDER;
    w.point[2] = -0.5 * r;
    w.radius = 3.1 * r - 3e-6;
    w.height = 8 * r;
    w.friction = 0.2;
    int64_t cyl;
    ck_assert_msg(sx_wall_add(m, &w, &cyl) == SX_OK, "%s", sx_model_error(m));
    const double p0[3] = {0, 0, 0}, n0[3] = {0, 0, 1}, p1[3] = {0, 0, 6.1 * r - 3e-6}, n1[3] = {0, 0, -1};
    scene_halfspace(m, p0, n0, 1e8, 1e8, 0.3);
    const int64_t top = scene_halfspace(m, p1, n1, 1e8, 1e8, 0.3);
    sx_servo_def sv = sx_servo_default_def();
    sv.target = 1.5e4, sv.area = 2 * 3.14159265358979 * w.radius * 6 * r, sv.max_speed = 0.2;
    ck_assert_int_eq(sx_wall_set_servo(m, cyl, &sv), SX_OK);
    sv.target = 2e4, sv.area = 3.14159265358979 * w.radius * w.radius;
    ck_assert_int_eq(sx_wall_set_servo(m, top, &sv), SX_OK);
    io_cycle(m, 300);

    /* histories as the Lua layer would have recorded them: samples at the
     * multiples of `every` up to step 300, value 0.25 x step */
    static int64_t st[3][60];
    static double t[3][60], v[3][60];
    const int every[3] = {5, 10, 50};
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 300 / every[k]; i++)
            st[k][i] = every[k] * (i + 1), t[k][i] = 1e-7 * (double)st[k][i], v[k][i] = 0.25 * (double)st[k][i];
    sx_io_history h[4] = {
        {.name = "ke", .every = 5, .source = SX_IO_SOURCE_BUILTIN, .builtin = "kinetic", .n = 60, .steps = st[0],
         .times = t[0], .values = v[0]},
        {.name = "z of ball 3", .every = 10, .source = SX_IO_SOURCE_BALL, .id = 3, .field = "pos", .component = 2,
         .n = 30, .steps = st[1], .times = t[1], .values = v[1]},
        {.name = "cylinder fx", .every = 5, .source = SX_IO_SOURCE_WALL, .id = cyl, .field = "force",
         .component = 0, .n = 60, .steps = st[0], .times = t[0], .values = v[0]},
        {.name = "user, \"quoted\"", .every = 50, .source = SX_IO_SOURCE_FUNCTION, .n = 6, .steps = st[2],
         .times = t[2], .values = v[2]},
    };
    const int64_t seeds[2] = {7, 99};
    sx_io_named_tree tr;
    memset(&tr, 0, sizeof tr);
    snprintf(tr.name, sizeof tr.name, "vars");
    sx_io_node nd = {.parent = -1, .key_kind = SX_IO_STRING, .key_string = "target", .key_length = 6,
                     .kind = SX_IO_NUMBER, .number = 1.5e4};
    sx_io_tree_add(&tr.tree, &nd);
    sx_snapshot_opts o;
    memset(&o, 0, sizeof o);
    o.trees = &tr;
    o.ntrees = 1;
    o.histories = h;
    o.nhistories = 4;
    o.provenance.script = "tests/io/make_format2.c";
    o.provenance.seeds = seeds;
    o.provenance.nseeds = 2;
    char err[512];
    ck_assert_msg(sx_snapshot_save(m, out_path, &o, err, sizeof err) == SX_OK, "%s", err);
    sx_io_tree_free(&tr.tree);

    sx_wall_def c, pt;
    sx_wall_get(m, cyl, &c);
    sx_wall_get(m, top, &pt);
    double load;
    int64_t nc;
    sx_wall_load(m, cyl, &load, &nc, NULL);
    printf("time %a step %lld balls %lld contacts %lld hash %016llx\n", sx_model_time(m),
           (long long)sx_model_step_count(m), (long long)sx_ball_count(m), (long long)sx_contact_count(m),
           (unsigned long long)sx_model_state_hash(m));
    printf("cylinder %lld radius %a radial_vel %a load %a contacts %lld; top %lld z %a vz %a\n", (long long)cyl,
           c.radius, c.radial_vel, load, (long long)nc, (long long)top, pt.point[2], pt.vel[2]);
    sx_model_destroy(m);
}
END_TEST

int main(int argc, char **argv) { return io_run_writer(argc, argv, "make_format2", make, &out_path); }
