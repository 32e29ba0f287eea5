/* Determinism (a tested feature, STYLE 10): the same scene gives the same
 * bits, whatever else runs in the process, however the run is split into
 * cycles and whatever is queried in between; a 1e-12 m change does not. */
#include "scenes.h"

#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ck_assert_cycle(m, n) \
    ck_assert_msg(sx_model_cycle((m), (n)) == SX_OK, "cycle failed: %s", sx_model_error(m))

enum { NBALLS = 300 };

/* A few hundred balls dropped into a box: gravity, friction, local damping,
 * automatic timestep. `nudge` moves the first ball by that much along x. */
static sx_model *settling(int dim, double nudge, int64_t *first)
{
    double g[3] = {0, 0, 0};
    g[dim - 1] = -9.81;
    sx_model *m = scene_model(dim, g, 0, 1e5, 0.5, 2650);
    sx_material_def md;
    ck_assert_int_eq(sx_material_get(m, scene_material(m), &md), SX_OK);
    md.damping = 0.7;
    ck_assert_int_eq(sx_material_set(m, "m", &md, NULL), SX_OK);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.15, 0.3, 0};
    const double hi3[3] = {0.1, 0.1, 0.12};
    const double *h = dim == 3 ? hi3 : hi;
    scene_box_walls(m, lo, h, 1e5, 0.5);
    int64_t ids[NBALLS];
    scene_random_balls(m, NBALLS, lo, h, dim == 3 ? 0.004 : 0.003, dim == 3 ? 0.007 : 0.005, 0.05, 0.02, 2024, ids);
    if (nudge != 0) {
        double x[3];
        ck_assert_int_eq(sx_ball_get_vec(m, ids[0], SX_BALL_POS, x), SX_OK);
        x[0] += nudge;
        ck_assert_int_eq(sx_ball_set_vec(m, ids[0], SX_BALL_POS, x), SX_OK);
    }
    if (first) *first = ids[0];
    return m;
}

static int steps_for(int dim) { return dim == 3 ? 12000 : 4000; }

START_TEST(same_scene_same_bits)
{
    const int dim = _i;
    const int n = steps_for(dim);
    sx_model *a = settling(dim, 0, NULL), *b = settling(dim, 0, NULL);
    ck_assert_uint_eq(sx_model_state_hash(a), sx_model_state_hash(b));
    const uint64_t h0 = sx_model_state_hash(a);
    /* interleaved in the same process: no hidden shared state */
    for (int s = 0; s < n; s += 100) {
        ck_assert_cycle(a, 100);
        ck_assert_cycle(b, 100);
    }
    ck_assert_uint_eq(sx_model_state_hash(a), sx_model_state_hash(b));
    ck_assert_uint_ne(sx_model_state_hash(a), h0);
    ck_assert_int_eq(sx_model_step_count(a), sx_model_step_count(b));
    ck_assert_double_eq(sx_model_time(a), sx_model_time(b));
    /* the scene did something: the balls fell and touch */
    ck_assert(sx_contact_count(a) > NBALLS / 2);
    for (int64_t i = 0; i < sx_ball_count(a); i++) {
        const int64_t id = sx_ball_id_at(a, i);
        ck_assert_int_eq(sx_ball_id_at(b, i), id);
        double xa[3], xb[3];
        sx_ball_get_vec(a, id, SX_BALL_POS, xa);
        sx_ball_get_vec(b, id, SX_BALL_POS, xb);
        ck_assert(memcmp(xa, xb, sizeof xa) == 0);
    }
    sx_model_destroy(a);
    sx_model_destroy(b);
}
END_TEST

START_TEST(nudge_changes_bits)
{
    const int dim = _i;
    const int n = steps_for(dim);
    int64_t first;
    sx_model *a = settling(dim, 0, &first), *b = settling(dim, 1e-12, NULL);
    ck_assert_uint_ne(sx_model_state_hash(a), sx_model_state_hash(b));
    ck_assert_cycle(a, n);
    ck_assert_cycle(b, n);
    ck_assert_uint_ne(sx_model_state_hash(a), sx_model_state_hash(b));
    /* and the difference has spread to other balls through the contacts */
    int64_t differ = 0;
    for (int64_t i = 0; i < sx_ball_count(a); i++) {
        const int64_t id = sx_ball_id_at(a, i);
        if (id == first) continue;
        double xa[3], xb[3];
        sx_ball_get_vec(a, id, SX_BALL_POS, xa);
        sx_ball_get_vec(b, id, SX_BALL_POS, xb);
        differ += memcmp(xa, xb, sizeof xa) != 0;
    }
    ck_assert_msg(differ > 0, "no other ball felt the 1e-12 m change");
    sx_model_destroy(a);
    sx_model_destroy(b);
}
END_TEST

/* cycle(n) and n split into uneven cycles give the same bits: the split
 * points fall on steps where the broad phase is rebuilt and where it is not. */
static void chunked(int dim, double dt)
{
    const int n = steps_for(dim);
    sx_model *a = settling(dim, 0, NULL), *b = settling(dim, 0, NULL);
    if (dt > 0) {
        ck_assert_int_eq(sx_model_set_timestep(a, dt), SX_OK);
        ck_assert_int_eq(sx_model_set_timestep(b, dt), SX_OK);
    }
    ck_assert_cycle(a, n);
    const int chunks[] = {1, 2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41};
    int done = 0;
    for (int c = 0; done < n; c = (c + 1) % 14) {
        const int k = chunks[c] < n - done ? chunks[c] : n - done;
        ck_assert_cycle(b, k);
        done += k;
    }
    ck_assert_int_eq(sx_model_step_count(b), n);
    ck_assert_msg(sx_model_time(a) == sx_model_time(b), "time %.17g (one cycle) != %.17g (split)", sx_model_time(a),
                  sx_model_time(b));
    ck_assert_uint_eq(sx_model_state_hash(a), sx_model_state_hash(b));
    sx_model_destroy(a);
    sx_model_destroy(b);
}

START_TEST(split_cycles_user_timestep) { chunked(_i, 1e-5); }
END_TEST

START_TEST(split_cycles_auto_timestep) { chunked(_i, 0); }
END_TEST

/* Queries between cycles observe, they do not perturb. */
static bool count_contact(const sx_contact_info *c, void *ud)
{
    (void)c;
    ++*(int64_t *)ud;
    return true;
}

START_TEST(queries_do_not_perturb)
{
    const int dim = _i;
    const int n = steps_for(dim);
    sx_model *a = settling(dim, 0, NULL), *b = settling(dim, 0, NULL);
    for (int s = 0; s < n; s += 50) {
        ck_assert_cycle(a, 50);
        ck_assert_cycle(b, 50);
        int64_t seen = 0;
        sx_contact_each(b, count_contact, &seen);
        ck_assert_int_eq(seen, sx_contact_count(b));
        const sx_energy e = sx_model_energy(b);
        ck_assert(isfinite(e.kinetic + e.gravitational + e.strain));
        ck_assert(sx_model_timestep(b) > 0);
        ck_assert(sx_model_critical_timestep(b) > 0);
        double x[3];
        ck_assert_int_eq(sx_ball_get_vec(b, sx_ball_id_at(b, 0), SX_BALL_POS, x), SX_OK);
        (void)sx_model_state_hash(b);
        (void)sx_model_bytes(b);
    }
    ck_assert_uint_eq(sx_model_state_hash(a), sx_model_state_hash(b));
    sx_model_destroy(a);
    sx_model_destroy(b);
}
END_TEST

/* The step's passes have batched forms for the common cases (contacts
 * with linear laws, no shear dashpot and no bonds; the law of motion of
 * balls without fixities or damping) and full ones that also track
 * energies: both give the same bits, friction and the normal dashpot
 * included, with and without local damping. */
static void batched_and_full(int dim, double damping)
{
    const int n = steps_for(dim) / 2;
    sx_model *ms[2];
    for (int k = 0; k < 2; k++) {
        ms[k] = settling(dim, 0, NULL);
        sx_material_def md;
        ck_assert_int_eq(sx_material_get(ms[k], scene_material(ms[k]), &md), SX_OK);
        md.viscous_normal = 0.3;
        md.damping = damping;
        ck_assert_int_eq(sx_material_set(ms[k], "m", &md, NULL), SX_OK);
        /* a tilted floor, so wall contacts have normals of every component */
        double nrm[3] = {0.4, dim == 3 ? 0.3 : 1, dim == 3 ? 1 : 0};
        const double len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        for (int c = 0; c < 3; c++) nrm[c] /= len;
        const double at[3] = {0, dim == 3 ? 0 : 0.02, dim == 3 ? 0.02 : 0};
        scene_halfspace(ms[k], at, nrm, 1e5, 1e5, 0.5);
        for (int64_t i = sx_ball_count(ms[k]) - 1; i >= 0; i--) { /* the balls it cuts go */
            const int64_t id = sx_ball_id_at(ms[k], i);
            double x[3], r;
            ck_assert_int_eq(sx_ball_get_vec(ms[k], id, SX_BALL_POS, x), SX_OK);
            ck_assert_int_eq(sx_ball_get(ms[k], id, SX_BALL_RADIUS, &r), SX_OK);
            double d = 0;
            for (int c = 0; c < dim; c++) d += (x[c] - at[c]) * nrm[c];
            if (d < r) ck_assert_int_eq(sx_ball_remove(ms[k], id), SX_OK);
        }
    }
    sx_model_track_energy(ms[1], true); /* the full pass */
    for (int s = 0; s < n; s += 100) {
        ck_assert_cycle(ms[0], 100);
        ck_assert_cycle(ms[1], 100);
        /* the hash covers the tracked energy terms too: compared without them */
        sx_model_track_energy(ms[1], false);
        ck_assert_uint_eq(sx_model_state_hash(ms[0]), sx_model_state_hash(ms[1]));
        sx_model_track_energy(ms[1], true);
    }
    ck_assert(sx_contact_count(ms[0]) > sx_ball_count(ms[0]) / 2);
    sx_model_destroy(ms[0]);
    sx_model_destroy(ms[1]);
}

START_TEST(batched_pass_matches_full_pass) { batched_and_full(_i, 0.7); }
END_TEST

START_TEST(batched_motion_matches_full_motion) { batched_and_full(_i, 0); }
END_TEST

int main(void)
{
    Suite *s = suite_create("determinism");
    TCase *tc = tcase_create("determinism");
    tcase_set_timeout(tc, 120);
    tcase_add_loop_test(tc, same_scene_same_bits, 2, 4);
    tcase_add_loop_test(tc, nudge_changes_bits, 2, 4);
    tcase_add_loop_test(tc, split_cycles_user_timestep, 2, 4);
    tcase_add_loop_test(tc, split_cycles_auto_timestep, 2, 4);
    tcase_add_loop_test(tc, queries_do_not_perturb, 2, 4);
    tcase_add_loop_test(tc, batched_pass_matches_full_pass, 2, 4);
    tcase_add_loop_test(tc, batched_motion_matches_full_motion, 2, 4);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
