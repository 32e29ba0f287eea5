/* Restarts continue bit-for-bit: 2N steps straight and N steps + save +
 * load + N steps give the same state hash, energies, crack log, bond and
 * contact counts, wall definitions, forces and servo loads, in 2D and 3D,
 * for granular, bonded, Hertz and servo-controlled (cylinder) scenes, saved
 * at several points of the broad phase's cycle. */
#include "io_scenes.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

typedef sx_model *(*scene_fn)(int dim);

static sx_model *granular(int dim) { return io_scene_granular(dim, 150); }

/* Runs the scene 2n steps straight, and n + save + load + n, and compares.
 * `poke` changes a ball's position at step n in both runs (the save then
 * happens with a rebuild pending and a dirty guard). */
static void restart(scene_fn scene, int dim, int n, bool poke)
{
    sx_model *a = scene(dim), *b = scene(dim);
    ck_assert_uint_eq(sx_model_state_hash(a), sx_model_state_hash(b));
    io_cycle(a, n);
    io_cycle(b, n);
    if (poke) {
        const int64_t id = sx_ball_id_at(a, sx_ball_count(a) / 2);
        double x[3];
        ck_assert_int_eq(sx_ball_get_vec(a, id, SX_BALL_POS, x), SX_OK);
        x[0] += 1e-6;
        ck_assert_int_eq(sx_ball_set_vec(a, id, SX_BALL_POS, x), SX_OK);
        ck_assert_int_eq(sx_ball_set_vec(b, id, SX_BALL_POS, x), SX_OK);
    }
    io_cycle(a, n);

    char path[512];
    io_path(path, sizeof path, "restart.h5");
    io_save(b, path);
    sx_model *c = io_load(path, dim);
    ck_assert_uint_eq(sx_model_state_hash(c), sx_model_state_hash(b));
    /* the saved model and its copy continue alike, and like the straight run */
    io_cycle(b, n);
    io_cycle(c, n);
    ck_assert_uint_eq(sx_model_state_hash(b), sx_model_state_hash(a));
    ck_assert_msg(sx_model_state_hash(c) == sx_model_state_hash(a),
                  "%dD restart after %d steps diverged (hash %016llx, straight %016llx)", dim, n,
                  (unsigned long long)sx_model_state_hash(c), (unsigned long long)sx_model_state_hash(a));
    io_assert_same_extras(a, c);
    io_assert_same_energy(a, c);
    sx_model_destroy(a);
    sx_model_destroy(b);
    sx_model_destroy(c);
}

START_TEST(granular_restart)
{
    const int dim = _i;
    const int n[] = {1, 37, 800};
    for (int k = 0; k < 3; k++) restart(granular, dim, n[k], false);
    restart(granular, dim, 300, true);
}
END_TEST

START_TEST(bonded_restart)
{
    const int dim = _i;
    /* the specimen must have cracked before and after the save */
    const int n = dim == 3 ? 150 : 250;
    sx_model *m = io_scene_bonded(dim);
    const int64_t bonds0 = sx_bond_count(m);
    io_cycle(m, n);
    const int64_t cracks1 = sx_crack_count(m);
    io_cycle(m, n);
    printf("%dD bonded: %lld bonds, %lld cracks at %d steps, %lld at %d\n", dim, (long long)bonds0,
           (long long)cracks1, n, (long long)sx_crack_count(m), 2 * n);
    ck_assert(cracks1 > 0 && sx_crack_count(m) > cracks1);
    sx_model_destroy(m);
    restart(io_scene_bonded, dim, n, false);
    restart(io_scene_bonded, dim, 1, true);
}
END_TEST

/* Flat joints: their elements' states, shear forces and the faces' axes
 * and bend rotations (/flatjoints) continue bit for bit. */
START_TEST(flatjoint_restart)
{
    const int dim = _i;
    const int n = dim == 3 ? 150 : 250;
    sx_model *m = io_scene_flatjoint(dim);
    io_cycle(m, n);
    const int64_t cracks1 = sx_crack_count(m);
    io_cycle(m, n);
    printf("%dD flat-jointed: %lld cracks at %d steps, %lld at %d\n", dim, (long long)cracks1, n,
           (long long)sx_crack_count(m), 2 * n);
    ck_assert(cracks1 > 0 && sx_crack_count(m) > cracks1);
    sx_crack c;
    ck_assert_int_eq(sx_crack_get(m, 0, &c), SX_OK);
    ck_assert(c.kind == SX_BOND_FLATJOINT && c.element >= 0);
    sx_model_destroy(m);
    restart(io_scene_flatjoint, dim, n, false);
    restart(io_scene_flatjoint, dim, 1, true);
}
END_TEST

START_TEST(hertz_restart)
{
    restart(io_scene_hertz, _i, 500, false);
}
END_TEST

/* Servo-controlled walls (a cylinder whose radius is servo-controlled in
 * 3D) continue as they would have: settings, the loads they read and the
 * velocities they set are all in the state hash. */
START_TEST(servo_restart)
{
    const int dim = _i;
    sx_model *m = io_scene_servo(dim);
    double r0 = 0;
    if (dim == 3) {
        sx_wall_def w;
        ck_assert_int_eq(sx_wall_get(m, sx_wall_id_at(m, 0), &w), SX_OK);
        ck_assert_int_eq(w.kind, SX_WALL_CYLINDER);
        r0 = w.radius;
    }
    io_cycle(m, 200);
    /* the servos are acting: their walls carry load and move */
    int moving = 0;
    for (int64_t i = 0; i < sx_wall_count(m); i++) {
        sx_wall_def w;
        double load;
        int64_t nc;
        sx_wall_get(m, sx_wall_id_at(m, i), &w);
        sx_wall_load(m, sx_wall_id_at(m, i), &load, &nc, NULL);
        moving += nc > 0 && load > 0 && (w.radial_vel != 0 || w.vel[0] != 0 || w.vel[1] != 0 || w.vel[2] != 0);
        if (w.kind == SX_WALL_CYLINDER) ck_assert(w.radius != r0);
    }
    ck_assert_int_eq(moving, 2);
    sx_model_destroy(m);
    const int n[] = {1, 150, 400};
    for (int k = 0; k < 3; k++) restart(io_scene_servo, dim, n[k], false);
    restart(io_scene_servo, dim, 100, true);
}
END_TEST

/* Save, load, save again: the second file loads into the same state, and
 * an empty model round-trips too. */
START_TEST(resave)
{
    const int dim = _i;
    sx_model *a = io_scene_bonded(dim);
    io_cycle(a, 200);
    char p1[512], p2[512];
    io_save(a, io_path(p1, sizeof p1, "one.h5"));
    sx_model *b = io_load(p1, dim);
    io_save(b, io_path(p2, sizeof p2, "two.h5"));
    sx_model *c = io_load(p2, 0);
    ck_assert_uint_eq(sx_model_state_hash(c), sx_model_state_hash(a));
    ck_assert_int_eq(sx_model_bytes(b), sx_model_bytes(c));
    io_cycle(a, 100);
    io_cycle(c, 100);
    ck_assert_uint_eq(sx_model_state_hash(c), sx_model_state_hash(a));
    sx_model_destroy(a);
    sx_model_destroy(b);
    sx_model_destroy(c);

    sx_model_def d = sx_model_default_def();
    d.dim = dim;
    d.gravity[dim - 1] = -1;
    sx_model *e = sx_model_create(&d, NULL, 0);
    io_save(e, p1);
    sx_model *f = io_load(p1, dim);
    ck_assert_int_eq(sx_ball_count(f), 0);
    double g[3];
    sx_model_gravity(f, g);
    ck_assert(g[dim - 1] == -1);
    sx_model_destroy(e);
    sx_model_destroy(f);
}
END_TEST

/* A loaded model keeps its materials, walls, ids, groups, fixities. */
START_TEST(contents)
{
    const int dim = _i;
    sx_model *a = io_scene_granular(dim, 60);
    io_cycle(a, 50);
    char p[512];
    io_save(a, io_path(p, sizeof p, "c.h5"));
    sx_model *b = io_load(p, dim);
    ck_assert_int_eq(sx_material_count(b), 2);
    ck_assert_str_eq(sx_material_name(b, 1), "soft");
    sx_material_def ma, mb;
    sx_material_get(a, 1, &ma);
    sx_material_get(b, 1, &mb);
    ck_assert(memcmp(&ma, &mb, sizeof ma) == 0);
    for (int64_t i = 0; i < sx_ball_count(a); i++) {
        const int64_t id = sx_ball_id_at(a, i);
        ck_assert_int_eq(sx_ball_id_at(b, i), id);
        int32_t ga, gb;
        unsigned fa, fb;
        sx_ball_group(a, id, &ga), sx_ball_group(b, id, &gb);
        sx_ball_fixity(a, id, &fa), sx_ball_fixity(b, id, &fb);
        ck_assert_int_eq(ga, gb);
        ck_assert_uint_eq(fa, fb);
        double va[3], vb[3];
        sx_ball_get_vec(a, id, SX_BALL_APPLIED_FORCE, va);
        sx_ball_get_vec(b, id, SX_BALL_APPLIED_FORCE, vb);
        ck_assert(memcmp(va, vb, sizeof va) == 0);
    }
    ck_assert(!sx_ball_exists(b, 4)); /* removed before the save */
    ck_assert_int_eq(sx_wall_count(b), sx_wall_count(a));
    for (int64_t i = 0; i < sx_wall_count(a); i++) {
        sx_wall_def wa, wb;
        sx_wall_get(a, sx_wall_id_at(a, i), &wa);
        sx_wall_get(b, sx_wall_id_at(b, i), &wb);
        ck_assert(memcmp(&wa, &wb, sizeof wa) == 0);
    }
    /* new balls and walls get fresh ids after a load, as they would have */
    sx_ball_def bd = sx_ball_default_def();
    bd.radius = 0.003;
    bd.pos[0] = bd.pos[1] = 0.05;
    int64_t ida, idb;
    ck_assert_int_eq(sx_ball_add(a, &bd, &ida), SX_OK);
    ck_assert_int_eq(sx_ball_add(b, &bd, &idb), SX_OK);
    ck_assert_int_eq(ida, idb);
    sx_wall_def wd = sx_wall_default_def(dim);
    ck_assert_int_eq(sx_wall_add(a, &wd, &ida), SX_OK);
    ck_assert_int_eq(sx_wall_add(b, &wd, &idb), SX_OK);
    ck_assert_int_eq(ida, idb);
    sx_model_destroy(a);
    sx_model_destroy(b);
}
END_TEST

/* Histories and seeds go into a snapshot and come back as they were (the
 * bits of every sample, the definition, the order), in extendable
 * datasets; a bad history is refused, leaving the file there intact. */
START_TEST(histories_saved)
{
    sx_model *m = io_scene_granular(3, 40);
    io_cycle(m, 30);
    enum { N = 1000 };
    static int64_t st[N];
    static double t[N], v[N];
    for (int i = 0; i < N; i++) st[i] = 3 * i + 1, t[i] = 1e-5 * i, v[i] = i % 7 ? 1.0 / (i + 0.5) : -0.0;
    v[5] = NAN;
    sx_io_history h[4];
    memset(h, 0, sizeof h);
    h[0] = (sx_io_history){.name = "zeta: kinetic", .every = 3, .source = SX_IO_SOURCE_BUILTIN, .builtin = "kinetic",
                           .n = N, .steps = st, .times = t, .values = v};
    h[1] = (sx_io_history){.name = "alpha", .every = 2, .source = SX_IO_SOURCE_BALL, .id = 7, .field = "pos",
                           .component = 2, .n = 10, .steps = st, .times = t, .values = v};
    h[2] = (sx_io_history){.name = "mid", .every = 1, .source = SX_IO_SOURCE_FUNCTION, .n = 0};
    h[3] = (sx_io_history){.name = "w", .every = 5, .source = SX_IO_SOURCE_WALL, .id = 2, .field = "force",
                           .component = 0, .n = 1, .steps = st, .times = t, .values = v};
    const int64_t seeds[2] = {7, 1234567890123};
    sx_snapshot_opts o;
    memset(&o, 0, sizeof o);
    o.histories = h;
    o.nhistories = 4;
    o.provenance.seeds = seeds;
    o.provenance.nseeds = 2;
    o.compression = 3;
    char p[512], err[1024];
    ck_assert_msg(sx_snapshot_save(m, io_path(p, sizeof p, "h.h5"), &o, err, sizeof err) == SX_OK, "%s", err);
    sx_snapshot_info info;
    sx_model *b = sx_snapshot_load(p, 3, &info, err, sizeof err);
    ck_assert_msg(b, "%s", err);
    ck_assert_int_eq(info.nhistories, 4);
    for (int k = 0; k < 4; k++) {
        const sx_io_history *x = &info.histories[k], *y = &h[k];
        ck_assert_str_eq(x->name, y->name); /* creation order, not the names' */
        ck_assert_int_eq(x->every, y->every);
        ck_assert_int_eq(x->source, y->source);
        ck_assert_int_eq(x->n, y->n);
        ck_assert(x->n == 0 || (memcmp(x->steps, y->steps, (size_t)x->n * sizeof *x->steps) == 0 &&
                                memcmp(x->times, y->times, (size_t)x->n * sizeof *x->times) == 0 &&
                                memcmp(x->values, y->values, (size_t)x->n * sizeof *x->values) == 0));
        if (y->builtin) ck_assert_str_eq(x->builtin, y->builtin);
        if (y->field) {
            ck_assert_str_eq(x->field, y->field);
            ck_assert_int_eq(x->id, y->id);
            ck_assert_int_eq(x->component, y->component);
        }
    }
    ck_assert_int_eq(info.nseeds, 2);
    ck_assert(info.seeds[0] == 7 && info.seeds[1] == 1234567890123);
    sx_snapshot_info_free(&info);
    sx_model_destroy(b);
    /* extendable, chunked */
    hid_t f = H5Fopen(p, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t d = H5Dopen2(f, "/histories/zeta: kinetic/value", H5P_DEFAULT);
    hid_t s = H5Dget_space(d), pl = H5Dget_create_plist(d);
    hsize_t dim, max;
    H5Sget_simple_extent_dims(s, &dim, &max);
    ck_assert(dim == N && max == H5S_UNLIMITED && H5Pget_layout(pl) == H5D_CHUNKED);
    H5Pclose(pl);
    H5Sclose(s);
    H5Dclose(d);
    H5Fclose(f);
    /* refused before anything is written */
    h[1].name = "a/b";
    ck_assert_int_ne(sx_snapshot_save(m, p, &o, err, sizeof err), SX_OK);
    ck_assert(strstr(err, "cannot name a group"));
    h[1].name = "alpha";
    st[3] = st[2];
    ck_assert_int_ne(sx_snapshot_save(m, p, &o, err, sizeof err), SX_OK);
    ck_assert(strstr(err, "steps do not increase"));
    sx_model_destroy(io_load(p, 3)); /* the file saved before is intact */
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

/* A mesh saved before meshes were welded (here: a square of two triangles
 * whose diagonal's ends are stored twice, as an open trigonometric seam
 * was) is welded on loading: one vertex per corner, and a ball on the
 * diagonal touches it once, with the force of a plane. */
START_TEST(unwelded_mesh)
{
    const double gravity[3] = {0, 0, 0};
    sx_model *m = scene_model(3, gravity, 1e-6, 1e6, 0.3, 2500);
    /* the second triangle's copies of corners 0 and 2 start 1e-5 m away,
     * more than welding takes, and are moved onto them in the file */
    const double h = 0.1, off = 1e-5;
    const double x[6 * 3] = {-h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0, -h + off, -h, 0, h, h + off, 0};
    const int32_t tri[6] = {0, 1, 2, 4, 5, 3};
    sx_wall_def wd = sx_wall_default_def(3);
    wd.kind = SX_WALL_MESH;
    wd.kn = wd.ks = 1e6;
    const sx_mesh_def md = {x, 6, tri, 2, false};
    int64_t wall;
    ck_assert_int_eq(sx_wall_add_mesh(m, &wd, &md, &wall, NULL), SX_OK);
    int64_t nv, nt;
    ck_assert_int_eq(sx_wall_mesh_size(m, wall, &nv, &nt), SX_OK);
    ck_assert_int_eq(nv, 6);
    const double r = 0.01, dent = 1e-4, at[3] = {0, 0, r - dent};
    scene_ball(m, at, NULL, r);
    char p[512];
    io_save(m, io_path(p, sizeof p, "unwelded.h5"));
    sx_model_destroy(m);

    hid_t f = H5Fopen(p, H5F_ACC_RDWR, H5P_DEFAULT);
    ck_assert(f >= 0);
    hid_t d = H5Dopen2(f, "/walls/mesh_1/body_vertices", H5P_DEFAULT);
    ck_assert(d >= 0);
    double body[6 * 3];
    ck_assert(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, body) >= 0);
    memcpy(body + 3 * 4, body + 3 * 0, 3 * sizeof(double));
    memcpy(body + 3 * 5, body + 3 * 2, 3 * sizeof(double));
    ck_assert(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, body) >= 0);
    io_drop_checksum(d);
    H5Dclose(d);
    H5Fclose(f);

    m = io_load(p, 3);
    ck_assert_int_eq(sx_wall_mesh_size(m, wall, &nv, &nt), SX_OK);
    ck_assert_int_eq(nv, 4);
    ck_assert_int_eq(nt, 2);
    double v[4 * 3];
    int32_t t[6];
    ck_assert_int_eq(sx_wall_mesh_get(m, wall, v, t), SX_OK);
    ck_assert(t[0] == t[3] && t[2] == t[4] && t[5] == 3);
    io_cycle(m, 1);
    double fn, kn;
    int64_t contacts;
    ck_assert_int_eq(sx_wall_load(m, wall, &fn, &contacts, &kn), SX_OK);
    ck_assert_int_eq(contacts, 1);
    ck_assert_double_eq_tol(fn, 0.5e6 * dent, 1e-6 * 0.5e6 * dent); /* kn in series with the wall's */
    /* welding a welded mesh changes nothing: saved again, it loads to the bit */
    io_save(m, io_path(p, sizeof p, "welded.h5"));
    sx_model *c = io_load(p, 3);
    ck_assert_uint_eq(sx_model_state_hash(c), sx_model_state_hash(m));
    sx_model_destroy(c);
    sx_model_destroy(m);
}
END_TEST

/* Threads are a setting of the model: kept, and results do not depend on them. */
START_TEST(threads_kept)
{
    sx_model *a = io_scene_granular(3, 100);
    ck_assert_int_eq(sx_model_set_threads(a, 3), SX_OK);
    io_cycle(a, 20);
    char p[512];
    io_save(a, io_path(p, sizeof p, "t.h5"));
    sx_model *b = io_load(p, 3);
    ck_assert_int_eq(sx_model_threads(b), 3);
    sx_model_destroy(a);
    sx_model_destroy(b);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_restart");
    TCase *tc = tcase_create("restart");
    tcase_set_timeout(tc, 600);
    tcase_add_loop_test(tc, granular_restart, 2, 4);
    tcase_add_loop_test(tc, bonded_restart, 2, 4);
    tcase_add_loop_test(tc, flatjoint_restart, 2, 4);
    tcase_add_loop_test(tc, hertz_restart, 2, 4);
    tcase_add_loop_test(tc, servo_restart, 2, 4);
    tcase_add_loop_test(tc, resave, 2, 4);
    tcase_add_loop_test(tc, contents, 2, 4);
    tcase_add_test(tc, threads_kept);
    tcase_add_test(tc, unwelded_mesh);
    tcase_add_test(tc, histories_saved);
    suite_add_tcase(s, tc);
    return io_run_suite(s);
}
