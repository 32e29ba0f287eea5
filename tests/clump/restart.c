/* Clumps: a snapshot of a clump model continues bit-for-bit. 2N steps
 * straight and N steps + save + load + N steps give the same state hash
 * (which covers every clump's position, velocity, orientation, angular
 * momentum, spin and resultants, and the pebbles as balls), the same
 * energies and contacts, in 2D and 3D, saved while clumps fall, collide
 * and settle on each other, the walls and free balls, with one clump
 * removed, one fixed and energy tracking on. A file without clumps still
 * loads into a model without any; output series carry the clump ids. */
#include "io_scenes.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Clumps of two templates (one of overlapping pebbles) and a few balls
 * falling into a box, at deterministic positions and orientations. */
static sx_model *pour(int dim)
{
    const double g[3] = {0, dim == 2 ? -9.81 : 0, dim == 3 ? -9.81 : 0};
    sx_model *m = scene_model(dim, g, 0, 1e6, 0.4, 2500);
    const int mat = scene_material(m);
    sx_material_def md;
    ck_assert(sx_material_get(m, mat, &md) == SX_OK);
    md.damping = 0.3;
    md.viscous_normal = 0.2;
    scene_material_def(m, "m", &md);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.2, 0.2, 0.2};
    scene_box_walls(m, lo, hi, 1e6, 0.4);
    const double lens[9] = {0, 0, 0, 0.012, 0, 0, 0.006, 0.008, 0}, lens_r[3] = {0.008, 0.008, 0.006};
    const double rod[9] = {-0.018, 0, 0, 0, 0, 0, 0.018, 0, 0}, rod_r[3] = {0.007, 0.007, 0.007};
    double p2[6], r2[3] = {0.008, 0.008, 0.006};
    for (int k = 0; k < 3; k++) p2[2 * k] = lens[3 * k], p2[2 * k + 1] = lens[3 * k + 1];
    double q2[6];
    for (int k = 0; k < 3; k++) q2[2 * k] = rod[3 * k], q2[2 * k + 1] = rod[3 * k + 1];
    sx_clump_template_def a = {dim == 3 ? lens : p2, dim == 3 ? lens_r : r2, 3, dim == 3 ? 64 : 1024};
    sx_clump_template_def b = {dim == 3 ? rod : q2, rod_r, 3, 0};
    int ta, tb;
    ck_assert_msg(sx_clump_template_add(m, "lens", &a, &ta) == SX_OK, "%s", sx_model_error(m));
    ck_assert_msg(sx_clump_template_add(m, "rod", &b, &tb) == SX_OK, "%s", sx_model_error(m));
    uint64_t seed = 11;
    int64_t ids[32];
    int n = 0;
    for (int layer = 0; layer < (dim == 3 ? 2 : 3); layer++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < (dim == 3 ? 3 : 1); j++) {
                sx_clump_def cd = sx_clump_default_def();
                cd.template_index = (i + j + layer) % 2 ? ta : tb;
                cd.material = mat;
                cd.pos[0] = 0.04 + 0.055 * i + scene_rng_uniform(&seed, -0.003, 0.003);
                cd.pos[1] = dim == 3 ? 0.04 + 0.055 * j : 0.04 + 0.055 * layer;
                if (dim == 3) cd.pos[2] = 0.03 + 0.05 * layer + scene_rng_uniform(&seed, -0.005, 0.005);
                const double ang = scene_rng_uniform(&seed, 0, 6.28);
                if (dim == 3) {
                    double ax[3] = {scene_rng_uniform(&seed, -1, 1), scene_rng_uniform(&seed, -1, 1),
                                    scene_rng_uniform(&seed, -1, 1)};
                    const double l = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
                    cd.orientation[0] = cos(ang / 2);
                    for (int k = 0; k < 3; k++) cd.orientation[k + 1] = sin(ang / 2) * ax[k] / l;
                    for (int k = 0; k < 3; k++) cd.spin[k] = scene_rng_uniform(&seed, -5, 5);
                } else {
                    cd.orientation[0] = cos(ang / 2), cd.orientation[3] = sin(ang / 2);
                    cd.spin[0] = scene_rng_uniform(&seed, -5, 5);
                }
                cd.vel[0] = scene_rng_uniform(&seed, -0.1, 0.1);
                ck_assert_msg(sx_clump_add(m, &cd, &ids[n]) == SX_OK, "%s", sx_model_error(m));
                n++;
            }
    /* a few free balls among them */
    for (int k = 0; k < 3; k++) {
        double p[3] = {0.06 + 0.04 * k, 0.17, 0.17};
        scene_ball(m, p, NULL, 0.006);
    }
    ck_assert(sx_clump_remove(m, ids[1]) == SX_OK);
    ck_assert(sx_clump_set_fixity(m, ids[0], dim == 3 ? SX_FIX_SPIN : SX_FIX_WZ) == SX_OK);
    sx_model_track_energy(m, true);
    return m;
}

static void restart(int dim, int n)
{
    sx_model *a = pour(dim), *b = pour(dim);
    ck_assert_uint_eq(sx_model_state_hash(a), sx_model_state_hash(b));
    io_cycle(a, 2 * n);
    io_cycle(b, n);
    char path[512];
    io_path(path, sizeof path, "clumps.h5");
    io_save(b, path);
    if (n > 1) ck_assert_int_gt(sx_contact_count(b), 0); /* saved among contacts */
    sx_model *c = io_load(path, dim);
    ck_assert_uint_eq(sx_model_state_hash(c), sx_model_state_hash(b));
    ck_assert_int_eq(sx_clump_count(c), sx_clump_count(b));
    ck_assert_int_eq(sx_clump_template_count(c), 2);
    io_cycle(b, n);
    io_cycle(c, n);
    ck_assert_uint_eq(sx_model_state_hash(b), sx_model_state_hash(a));
    ck_assert_msg(sx_model_state_hash(c) == sx_model_state_hash(a),
                  "%dD clump restart after %d steps diverged (hash %016llx, straight %016llx)", dim, n,
                  (unsigned long long)sx_model_state_hash(c), (unsigned long long)sx_model_state_hash(a));
    io_assert_same_extras(a, c);
    io_assert_same_energy(a, c);
    /* the loaded clumps answer like the originals */
    for (int64_t i = 0; i < sx_clump_count(a); i++) {
        const int64_t id = sx_clump_id_at(a, i);
        double qa[4], qc[4], ia[3], ic[3];
        ck_assert(sx_clump_orientation(a, id, qa) == SX_OK && sx_clump_orientation(c, id, qc) == SX_OK);
        ck_assert(sx_clump_inertia(a, id, ia, NULL) == SX_OK && sx_clump_inertia(c, id, ic, NULL) == SX_OK);
        ck_assert(memcmp(qa, qc, sizeof qa) == 0 && memcmp(ia, ic, sizeof ia) == 0);
    }
    printf("%dD: %lld clumps, %lld contacts, restart after %d steps continues bit-for-bit (hash %016llx)\n", dim,
           (long long)sx_clump_count(c), (long long)sx_contact_count(c), n,
           (unsigned long long)sx_model_state_hash(c));
    sx_model_destroy(a);
    sx_model_destroy(b);
    sx_model_destroy(c);
}

START_TEST(clump_restart)
{
    const int dim = _i;
    restart(dim, 1);
    restart(dim, dim == 3 ? 6000 : 4000);
}
END_TEST

START_TEST(no_clumps)
{
    sx_model *m = io_scene_granular(3, 40);
    io_cycle(m, 10);
    char path[512];
    io_path(path, sizeof path, "plain.h5");
    io_save(m, path);
    sx_model *c = io_load(path, 3);
    ck_assert_int_eq(sx_clump_count(c), 0);
    ck_assert_int_eq(sx_clump_template_count(c), 0);
    ck_assert_uint_eq(sx_model_state_hash(c), sx_model_state_hash(m));
    sx_model_destroy(m);
    sx_model_destroy(c);
}
END_TEST

/* An output series gives every ball its clump id (0 for a free ball) next
 * to its id, and the XDMF shows it as a point attribute. */
START_TEST(series_clump_ids)
{
    sx_model *m = pour(3);
    io_cycle(m, 10);
    char path[512], err[256];
    io_path(path, sizeof path, "series.h5");
    sx_series *s = sx_series_open(path, 3, NULL, err, sizeof err);
    ck_assert_msg(s != NULL, "%s", err);
    ck_assert_msg(sx_series_write(s, m, NULL, 0, err, sizeof err) == SX_OK, "%s", err);
    ck_assert(sx_series_close(s, err, sizeof err) == SX_OK);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    ck_assert(f >= 0);
    const int64_t n = sx_ball_count(m);
    int64_t *id = malloc((size_t)n * sizeof *id), *clump = malloc((size_t)n * sizeof *clump);
    hid_t d = H5Dopen2(f, "/snapshots/000000/balls/id", H5P_DEFAULT);
    ck_assert(d >= 0 && H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, id) >= 0);
    H5Dclose(d);
    d = H5Dopen2(f, "/snapshots/000000/balls/clump", H5P_DEFAULT);
    ck_assert(d >= 0 && H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, clump) >= 0);
    H5Dclose(d);
    H5Fclose(f);
    int64_t pebbles = 0;
    for (int64_t i = 0; i < n; i++) {
        ck_assert_int_eq(clump[i], sx_ball_clump(m, id[i]));
        pebbles += clump[i] != 0;
    }
    ck_assert_int_eq(pebbles, 3 * sx_clump_count(m));
    free(id);
    free(clump);
    /* the XDMF names the attribute */
    io_path(path, sizeof path, "series.xmf");
    FILE *x = fopen(path, "r");
    ck_assert(x != NULL);
    char buf[1 << 16];
    const size_t len = fread(buf, 1, sizeof buf - 1, x);
    buf[len] = 0;
    fclose(x);
    ck_assert(strstr(buf, "balls/clump") != NULL);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    io_tmpdir();
    Suite *s = suite_create("clump_restart");
    TCase *tc = tcase_create("restart");
    tcase_set_timeout(tc, 600);
    tcase_add_loop_test(tc, clump_restart, 2, 4);
    tcase_add_test(tc, no_clumps);
    tcase_add_test(tc, series_clump_ids);
    suite_add_tcase(s, tc);
    const int status = scene_run_suite(s);
    io_rmdir();
    return status;
}
