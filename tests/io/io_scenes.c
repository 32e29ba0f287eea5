#include "io_scenes.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sx_model *io_scene_granular(int dim, int nballs)
{
    double g[3] = {0, 0, 0};
    g[dim - 1] = -9.81;
    sx_model *m = scene_model(dim, g, 0, 1e5, 0.5, 2650);
    sx_material_def md;
    ck_assert_int_eq(sx_material_get(m, scene_material(m), &md), SX_OK);
    md.damping = 0.3;
    md.viscous_normal = 0.1;
    md.viscous_shear = 0.05;
    scene_material_def(m, "m", &md);
    md.friction = 0.3;
    md.kn = md.ks = 2e5;
    md.density = 2000;
    const int soft = scene_material_def(m, "soft", &md);

    const double lo[3] = {0, 0, 0};
    const double hi[3] = {0.1, dim == 3 ? 0.1 : 0.2, dim == 3 ? 0.12 : 0};
    scene_box_walls(m, lo, hi, 1e5, 0.5);
    int64_t *ids = malloc((size_t)nballs * sizeof *ids);
    ck_assert_ptr_nonnull(ids);
    const double rmin = dim == 3 ? 0.004 : 0.003, rmax = dim == 3 ? 0.007 : 0.005;
    scene_random_balls(m, nballs, lo, hi, rmin, rmax, 0.05, 0.02, 4242, ids);

    /* the lid (last wall added: the upper wall of the last axis) moves down */
    const int64_t lid = sx_wall_id_at(m, sx_wall_count(m) - 1);
    double v[3] = {0, 0, 0};
    v[dim - 1] = -0.02;
    ck_assert_int_eq(sx_wall_set_vel(m, lid, v), SX_OK);
    /* an inclined finite obstacle */
    sx_wall_def w = sx_wall_default_def(dim);
    if (dim == 3) {
        w.kind = SX_WALL_RECT;
        const double p[3] = {0.02, 0.02, 0.03}, e1[3] = {0.06, 0, 0.01}, e2[3] = {0, 0.06, 0};
        memcpy(w.point, p, sizeof p), memcpy(w.edge1, e1, sizeof e1), memcpy(w.edge2, e2, sizeof e2);
    } else {
        w.kind = SX_WALL_SEGMENT;
        const double p[3] = {0.02, 0.05, 0}, e1[3] = {0.06, 0.01, 0};
        memcpy(w.point, p, sizeof p), memcpy(w.edge1, e1, sizeof e1);
    }
    w.friction = 0.4;
    ck_assert_msg(sx_wall_add(m, &w, NULL) == SX_OK, "%s", sx_model_error(m));

    for (int i = 0; i < nballs; i += 5) ck_assert_int_eq(sx_ball_set_material(m, ids[i], soft), SX_OK);
    for (int i = 0; i < nballs; i += 3) ck_assert_int_eq(sx_ball_set_group(m, ids[i], 1 + i % 4), SX_OK);
    const double f[3] = {0.01, -0.02, 0.005}, t[3] = {1e-5, 0, -2e-5};
    ck_assert_int_eq(sx_ball_set_vec(m, ids[1], SX_BALL_APPLIED_FORCE, f), SX_OK);
    ck_assert_int_eq(sx_ball_set_vec(m, ids[2], SX_BALL_APPLIED_MOMENT, t), SX_OK);
    ck_assert_int_eq(sx_ball_set_fixity(m, ids[4], dim == 3 ? SX_FIX_SPIN : SX_FIX_WZ), SX_OK);
    double v6[3];
    ck_assert_int_eq(sx_ball_get_vec(m, ids[6], SX_BALL_VEL, v6), SX_OK);
    v6[0] = 0; /* held still along x, free otherwise */
    ck_assert_int_eq(sx_ball_set_vec(m, ids[6], SX_BALL_VEL, v6), SX_OK);
    ck_assert_int_eq(sx_ball_set_fixity(m, ids[6], SX_FIX_VX), SX_OK);
    ck_assert_int_eq(sx_ball_remove(m, ids[3]), SX_OK);
    ck_assert_int_eq(sx_ball_set(m, ids[8], SX_BALL_DAMPING, 0.05), SX_OK);
    sx_model_track_energy(m, true);
    free(ids);
    return m;
}

/* The bonded lattice of io_scene_bonded, with parallel and contact bonds,
 * or flat joints (a fifth of their elements slit and gapped). */
static sx_model *bonded_lattice(int dim, bool flat)
{
    sx_model *m = scene_model(dim, NULL, 0, 1e7, 0.5, 2600);
    sx_material_def md;
    ck_assert_int_eq(sx_material_get(m, scene_material(m), &md), SX_OK);
    md.damping = 0.05;
    md.viscous_normal = 0.02;
    scene_material_def(m, "m", &md);
    sx_bpm_def bpm;
    memset(&bpm, 0, sizeof bpm);
    bpm.radius_multiplier = 1;
    bpm.modulus = 1e8;
    bpm.stiffness_ratio = 2;
    bpm.tensile_strength = 4e5;
    bpm.tensile_strength_sd = 1e5;
    bpm.cohesion = 8e5;
    bpm.cohesion_sd = 2e5;
    bpm.normal_strength = dim == 3 ? 3000 : 800;
    bpm.shear_strength = dim == 3 ? 3000 : 800;
    ck_assert_int_eq(sx_material_set_bpm(m, scene_material(m), &bpm), SX_OK);

    const double r = 1e-3;
    const int nx = dim == 3 ? 5 : 9, ny = dim == 3 ? 5 : 8, nz = dim == 3 ? 5 : 1;
    int64_t *ids = malloc((size_t)(nx * ny * nz) * sizeof *ids);
    int n = 0;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                double x[3] = {2 * r * i + (j % 2) * 0.3 * r, 2 * r * j, 2 * r * k};
                if (dim == 2) x[2] = 0;
                ids[n++] = scene_ball(m, x, NULL, r * (1 - 0.002 * ((i + j + k) % 3)));
            }
    sx_bond_def bd = sx_bond_default_def();
    bd.gap = 0.5 * r;
    bd.seed = 99;
    int64_t count = 0;
    if (flat) {
        bd.kind = SX_BOND_FLATJOINT;
        bd.friction_angle = 20;
        bd.friction = 0.4;
        bd.unbonded_fraction = 0.2;
        bd.initial_gap = 1e-6;
        bd.elements = dim == 3 ? 2 : 3;
        bd.sectors = 3;
    }
    ck_assert_msg(sx_bond_install(m, &bd, &count) == SX_OK, "%s", sx_model_error(m));
    ck_assert(count > 0);
    bd.kind = SX_BOND_CONTACT;
    if (!flat) ck_assert_msg(sx_bond_install(m, &bd, &count) == SX_OK, "%s", sx_model_error(m));
    /* the last axis: bottom layer held, top layer pulled */
    const int axis = dim - 1;
    for (int q = 0; q < n; q++) {
        double x[3];
        ck_assert_int_eq(sx_ball_get_vec(m, ids[q], SX_BALL_POS, x), SX_OK);
        const int layer = (int)(x[axis] / (2 * r) + 0.5), top = dim == 3 ? nz - 1 : ny - 1;
        if (layer == 0 || layer == top) {
            double v[3] = {0, 0, 0};
            v[axis] = layer == top ? (dim == 3 ? 0.6 : 0.05) : 0;
            ck_assert_int_eq(sx_ball_set_vec(m, ids[q], SX_BALL_VEL, v), SX_OK);
            ck_assert_int_eq(sx_ball_set_fixity(m, ids[q], dim == 3 ? SX_FIX_VEL | SX_FIX_SPIN
                                                                     : SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ),
                             SX_OK);
        }
    }
    /* a wall presses on the first side */
    double p[3] = {-r * 1.05, 0, 0}, nrm[3] = {1, 0, 0};
    const int64_t w = scene_halfspace(m, p, nrm, 1e7, 1e7, 0.3);
    const double vw[3] = {0.05, 0, 0};
    ck_assert_int_eq(sx_wall_set_vel(m, w, vw), SX_OK);
    sx_model_track_energy(m, true);
    free(ids);
    return m;
}

sx_model *io_scene_bonded(int dim) { return bonded_lattice(dim, false); }

sx_model *io_scene_flatjoint(int dim) { return bonded_lattice(dim, true); }

sx_model *io_scene_hertz(int dim)
{
    double g[3] = {0, 0, 0};
    g[dim - 1] = -9.81;
    sx_model_def d = sx_model_default_def();
    d.dim = dim;
    memcpy(d.gravity, g, sizeof g);
    d.timestep = 2e-6;
    char err[256];
    sx_model *m = sx_model_create(&d, err, sizeof err);
    ck_assert_msg(m, "%s", err);
    sx_material_def md = sx_material_default_def();
    md.model = SX_MODEL_HERTZ;
    md.shear_modulus = 1e8;
    md.poisson = 0.25;
    md.friction = 0.4;
    md.damping = 0.1;
    const int mat = scene_material_def(m, "h", &md);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.06, 0.06, 0.06};
    double p[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    n[dim - 1] = 1;
    scene_halfspace(m, p, n, 1e7, 1e7, 0.4);
    uint64_t s = 11;
    for (int i = 0; i < 40; i++) {
        double x[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++) x[k] = scene_rng_uniform(&s, lo[k] + 0.004, hi[k] - 0.004);
        x[dim - 1] = 0.004 + 0.0081 * (i / (dim == 3 ? 6 : 4));
        if (dim == 3) x[0] = 0.004 + 0.0081 * (i % 6), x[1] = scene_rng_uniform(&s, 0.01, 0.05);
        else x[0] = 0.004 + 0.0081 * (i % 4) + scene_rng_uniform(&s, 0, 0.001);
        scene_ball_full(m, x, NULL, NULL, 0.004, mat);
    }
    sx_model_track_energy(m, true);
    return m;
}

sx_model *io_scene_servo(int dim)
{
    double g[3] = {0, 0, 0};
    g[dim - 1] = -9.81;
    sx_model *m = scene_model(dim, g, 0, 1e8, 0.5, 2650);
    sx_material_def md;
    ck_assert_int_eq(sx_material_get(m, scene_material(m), &md), SX_OK);
    md.damping = 0.7;
    scene_material_def(m, "m", &md);
    /* a jittered lattice of balls (no O(n^2) placement), moving a little */
    const double r = 1e-3, pitch = 2.05 * r;
    const int side = dim == 3 ? 5 : 8, layers = dim == 3 ? 8 : 10;
    uint64_t s = 77;
    double hi[3] = {0, 0, 0}, rho = 0; /* the extent of the balls, and their largest distance from the z axis */
    for (int k = 0; k < layers; k++)
        for (int j = 0; j < side; j++)
            for (int i = 0; i < (dim == 3 ? side : 1); i++) {
                double x[3], v[3];
                for (int q = 0; q < 3; q++) v[q] = dim == 3 || q < 2 ? scene_rng_uniform(&s, -0.05, 0.05) : 0;
                if (dim == 3) {
                    x[0] = (i - 0.5 * (side - 1)) * pitch, x[1] = (j - 0.5 * (side - 1)) * pitch;
                    x[2] = r + k * pitch;
                    /* the cylinder is round: leave out the lattice's corners */
                    if (x[0] * x[0] + x[1] * x[1] > (0.5 * side * pitch - r) * (0.5 * side * pitch - r)) continue;
                } else {
                    x[0] = r + j * pitch, x[1] = r + k * pitch, x[2] = 0;
                }
                const double rad = r * (1 - 0.04 * scene_rng_uniform(&s, 0, 1));
                scene_ball(m, x, v, rad);
                for (int q = 0; q < dim; q++)
                    if (x[q] + rad > hi[q]) hi[q] = x[q] + rad;
                const double d = sqrt(x[0] * x[0] + x[1] * x[1]) + rad;
                if (d > rho) rho = d;
            }
    sx_servo_def sv = sx_servo_default_def();
    sv.alpha = 0.5;
    sv.max_speed = 0.2;
    if (dim == 3) {
        /* radius and top platen pressing slightly on the outer balls */
        sx_wall_def w = sx_wall_default_def(3);
        w.kind = SX_WALL_CYLINDER;
        w.point[2] = -0.5 * r;
        w.radius = rho - 1e-3 * r;
        hi[2] -= 1e-3 * r;
        w.height = hi[2] + 2 * r;
        w.friction = 0.2;
        int64_t cyl;
        ck_assert_msg(sx_wall_add(m, &w, &cyl) == SX_OK, "%s", sx_model_error(m));
        const double p0[3] = {0, 0, 0}, n0[3] = {0, 0, 1}, p1[3] = {0, 0, hi[2]}, n1[3] = {0, 0, -1};
        scene_halfspace(m, p0, n0, 1e8, 1e8, 0.3);
        const int64_t top = scene_halfspace(m, p1, n1, 1e8, 1e8, 0.3);
        sv.target = 1.5e4;
        sv.area = 2 * 3.14159265358979 * w.radius * hi[2];
        ck_assert_msg(sx_wall_set_servo(m, cyl, &sv) == SX_OK, "%s", sx_model_error(m));
        sv.target = 2e4;
        sv.area = 3.14159265358979 * w.radius * w.radius;
        ck_assert_msg(sx_wall_set_servo(m, top, &sv) == SX_OK, "%s", sx_model_error(m));
    } else {
        const double lo[3] = {0, 0, 0};
        scene_box_walls(m, lo, hi, 1e8, 0.3);
        /* walls 2 and 4 of scene_box_walls: the far sides of x and y */
        sv.target = 2e4;
        sv.area = hi[1];
        ck_assert_msg(sx_wall_set_servo(m, sx_wall_id_at(m, 1), &sv) == SX_OK, "%s", sx_model_error(m));
        sv.target = 3e4;
        sv.area = hi[0];
        ck_assert_msg(sx_wall_set_servo(m, sx_wall_id_at(m, 3), &sv) == SX_OK, "%s", sx_model_error(m));
    }
    sx_model_track_energy(m, true);
    return m;
}

/* ------------------------------------------------------------ helpers */

static char tmpdir[256];

const char *io_tmpdir(void)
{
    if (!tmpdir[0]) {
        const char *base = getenv("TMPDIR");
        snprintf(tmpdir, sizeof tmpdir, "%s/seixo-io-XXXXXX", base && *base ? base : "/tmp");
        if (!mkdtemp(tmpdir)) {
            perror("mkdtemp");
            abort();
        }
    }
    return tmpdir;
}

const char *io_path(char *out, size_t len, const char *name)
{
    snprintf(out, len, "%s/%s", io_tmpdir(), name);
    return out;
}

void io_rmdir(void)
{
    if (!tmpdir[0]) return;
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
    tmpdir[0] = 0;
}

void io_drop_checksum(hid_t d)
{
    if (H5Aexists(d, "checksum") > 0) ck_assert(H5Adelete(d, "checksum") >= 0);
}

void io_assert_no_handles(void)
{
    const ssize_t n = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL);
    ck_assert_msg(n == 0, "%zd HDF5 objects left open", n);
}

void io_save(const sx_model *m, const char *path)
{
    char err[1024];
    const sx_status st = sx_snapshot_save(m, path, NULL, err, sizeof err);
    ck_assert_msg(st == SX_OK, "save failed: %s", err);
    io_assert_no_handles();
}

sx_model *io_load(const char *path, int dim)
{
    char err[1024];
    sx_model *m = sx_snapshot_load(path, dim, NULL, err, sizeof err);
    ck_assert_msg(m != NULL, "load failed: %s", err);
    io_assert_no_handles();
    return m;
}

void io_assert_same_energy(sx_model *a, sx_model *b)
{
    const sx_energy ea = sx_model_energy(a), eb = sx_model_energy(b);
    ck_assert_msg(memcmp(&ea, &eb, sizeof ea) == 0,
                  "energies differ: kinetic %.17g / %.17g, slip %.17g / %.17g, damping %.17g / %.17g, "
                  "work %.17g / %.17g",
                  ea.kinetic, eb.kinetic, ea.slip, eb.slip, ea.local_damping, eb.local_damping, ea.boundary_work,
                  eb.boundary_work);
}

void io_assert_same_extras(const sx_model *a, const sx_model *b)
{
    ck_assert_int_eq(sx_model_step_count(a), sx_model_step_count(b));
    ck_assert(sx_model_time(a) == sx_model_time(b));
    ck_assert_int_eq(sx_ball_count(a), sx_ball_count(b));
    ck_assert_int_eq(sx_contact_count(a), sx_contact_count(b));
    ck_assert_int_eq(sx_bond_count(a), sx_bond_count(b));
    ck_assert_int_eq(sx_crack_count(a), sx_crack_count(b));
    for (int64_t i = 0; i < sx_crack_count(a); i++) {
        sx_crack ca, cb;
        ck_assert_int_eq(sx_crack_get(a, i, &ca), SX_OK);
        ck_assert_int_eq(sx_crack_get(b, i, &cb), SX_OK);
        ck_assert(memcmp(&ca, &cb, sizeof ca) == 0);
    }
    ck_assert_int_eq(sx_wall_count(a), sx_wall_count(b));
    for (int64_t i = 0; i < sx_wall_count(a); i++) {
        double fa[3], ma[3], fb[3], mb[3];
        ck_assert_int_eq(sx_wall_id_at(a, i), sx_wall_id_at(b, i));
        sx_wall_force(a, sx_wall_id_at(a, i), fa, ma);
        sx_wall_force(b, sx_wall_id_at(b, i), fb, mb);
        ck_assert(memcmp(fa, fb, sizeof fa) == 0 && memcmp(ma, mb, sizeof ma) == 0);
        sx_wall_def wa, wb;
        sx_wall_get(a, sx_wall_id_at(a, i), &wa);
        sx_wall_get(b, sx_wall_id_at(b, i), &wb);
        ck_assert_int_eq(wa.kind, wb.kind);
        ck_assert(memcmp(wa.point, wb.point, sizeof wa.point) == 0 && memcmp(wa.vel, wb.vel, sizeof wa.vel) == 0);
        ck_assert(memcmp(&wa.radius, &wb.radius, sizeof wa.radius) == 0 &&
                  memcmp(&wa.height, &wb.height, sizeof wa.height) == 0 &&
                  memcmp(&wa.radial_vel, &wb.radial_vel, sizeof wa.radial_vel) == 0);
        double la, lb, ka, kb;
        int64_t na, nb;
        sx_wall_load(a, sx_wall_id_at(a, i), &la, &na, &ka);
        sx_wall_load(b, sx_wall_id_at(b, i), &lb, &nb, &kb);
        ck_assert(memcmp(&la, &lb, sizeof la) == 0 && memcmp(&ka, &kb, sizeof ka) == 0);
        ck_assert_int_eq(na, nb);
    }
}

sx_model *io_load_sample(const char *dir, int version, sx_snapshot_info *info)
{
    char path[4096], script[64], err[1024];
    snprintf(path, sizeof path, "%s/format%d.h5", dir, version);
    snprintf(script, sizeof script, "tests/io/make_format%d.c", version);
    sx_model *m = sx_snapshot_load(path, 0, info, err, sizeof err);
    ck_assert_msg(m, "%s", err);
    ck_assert_int_eq(info->format_version, version);
    ck_assert_str_eq(info->seixo_version, "0.1.0");
    ck_assert_str_eq(info->script, script);
    return m;
}

static bool first_ball_contact(const sx_contact_info *ci, void *ud)
{
    if (ci->is_wall) return true;
    *(sx_contact_info *)ud = *ci;
    return false;
}

void io_first_ball_contact(const sx_model *m, sx_contact_info *ci)
{
    memset(ci, 0, sizeof *ci);
    ci->a = -1;
    sx_contact_each(m, first_ball_contact, ci);
    ck_assert_msg(ci->a >= 0, "no ball-ball contact");
}

static int run_suite(Suite *s, bool fork, enum print_output print)
{
    SRunner *r = srunner_create(s);
    if (!fork) srunner_set_fork_status(r, CK_NOFORK);
    srunner_run_all(r, print);
    const int failed = srunner_ntests_failed(r);
    srunner_free(r);
    return failed ? 1 : 0;
}

static int run_one(const char *name, const TTest *test, bool fork, enum print_output print)
{
    Suite *s = suite_create(name);
    TCase *tc = tcase_create(name);
    tcase_add_test(tc, test);
    suite_add_tcase(s, tc);
    return run_suite(s, fork, print);
}

int io_run_suite(Suite *s)
{
    io_tmpdir(); /* one folder for every test (they run in child processes), removed at the end */
    const int failed = run_suite(s, true, CK_NORMAL);
    io_rmdir();
    return failed;
}

int io_run_test(const char *name, const TTest *test) { return run_one(name, test, true, CK_NORMAL); }

int io_run_writer(int argc, char **argv, const char *name, const TTest *writer, const char **out_path)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s out.h5\n", argv[0]);
        return 2;
    }
    *out_path = argv[1];
    return run_one(name, writer, false, CK_SILENT);
}
