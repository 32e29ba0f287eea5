/* The state hash covers what a restart restores, canonically (docs/lua-api.md,
 * m:hash()): each field a restart restores, written on one of two identical
 * models, changes the hash, and putting it back restores it; a pair flipped
 * by a re-sort, a -0 for a +0, a pending build done by a query and a stale
 * automatic timestep asked for do not change it; a save -> load round trip
 * keeps it. The fields are poked in the core's own arrays (model_internal.h),
 * so none is missed through the public API's reach. */
#include "io_scenes.h"

#include "clumps.h"
#include "model_internal.h"

#include <math.h>
#include <string.h>

typedef enum { F64, I64, I32, U16, U8, BOOL, INT, CHAR } kind;

/* The fields a test has changed, by name: every one must be seen. */
static const char *seen[256];
static int nseen;

static void mark(const char *name)
{
    for (int i = 0; i < nseen; i++)
        if (strcmp(seen[i], name) == 0) return;
    ck_assert_int_lt(nseen, 256);
    seen[nseen++] = name;
}

/* Changes the value at p (of a field of b) and back: the hash must follow. */
static void poke(sx_model *a, sx_model *b, const char *name, void *p, kind k)
{
    const uint64_t ha = sx_model_state_hash(a);
    ck_assert_uint_eq(sx_model_state_hash(b), ha);
    static const size_t size[] = {8, 8, 4, 2, 1, sizeof(bool), sizeof(int), 1};
    unsigned char saved[8];
    memcpy(saved, p, size[k]);
    switch (k) {
    case F64: {
        double *v = p;
        *v = *v + 1 + fabs(*v);
        break;
    }
    case I64: *(int64_t *)p += 1; break;
    case I32: *(int32_t *)p += 1; break;
    case U16: *(uint16_t *)p += 1; break;
    case U8: *(uint8_t *)p ^= 1; break;
    case BOOL: *(bool *)p = !*(bool *)p; break;
    case INT: *(int *)p += 1; break;
    case CHAR: *(char *)p = *(char *)p == 'x' ? 'y' : 'x'; break;
    }
    ck_assert_msg(sx_model_state_hash(b) != ha, "the hash does not cover %s", name);
    memcpy(p, saved, size[k]);
    ck_assert_uint_eq(sx_model_state_hash(b), ha);
    mark(name);
}

#define POKE(field, k) poke(a, b, #field, &b->field, k)

/* The first pair of store p with a live history, -1 if none. */
static int64_t live_pair(const sx_pairs *p)
{
    for (int64_t c = 0; c < p->n; c++)
        if (p->touching[c]) return c;
    return -1;
}

static void poke_all(sx_model *a, sx_model *b)
{
    const int d = b->dim, r = b->rdim;
    /* the model */
    POKE(gravity[0], F64);
    POKE(gravity[d - 1], F64);
    POKE(dt_user, F64);
    POKE(dt_safety, F64);
    if (b->dt_user == 0 && !b->dt_stale && !b->build_needed) POKE(dt, F64);
    POKE(dt_prev, F64);
    POKE(skin_user, F64);
    POKE(time, F64);
    POKE(step, I64);
    POKE(guard_on, BOOL);
    POKE(guard_dirty, BOOL);
    POKE(guard_e0, F64);
    POKE(guard_scale, F64);
    POKE(track_energy, BOOL);
    POKE(acc.slip, F64);
    POKE(acc.local_damping, F64);
    POKE(acc.viscous, F64);
    POKE(acc.boundary_work, F64);
    POKE(acc.bond_released, F64);
    POKE(acc.kinetic, F64);
    POKE(balls.next_id, I64);
    POKE(next_wall_id, I64);
    /* materials */
    POKE(mats[0].name[0], CHAR);
    POKE(mats[0].def.model, INT);
    POKE(mats[0].def.density, F64);
    POKE(mats[0].def.kn, F64);
    POKE(mats[0].def.ks, F64);
    POKE(mats[0].def.modulus, F64);
    POKE(mats[0].def.stiffness_ratio, F64);
    POKE(mats[0].def.shear_modulus, F64);
    POKE(mats[0].def.poisson, F64);
    POKE(mats[0].def.friction, F64);
    POKE(mats[0].def.damping, F64);
    POKE(mats[0].def.viscous_normal, F64);
    POKE(mats[0].def.viscous_shear, F64);
    POKE(mats[0].def.restitution, F64); /* the registry's parts, hashed when on */
    POKE(mats[0].def.rolling_friction, F64);
    POKE(mats[0].def.total_shear, F64);
    POKE(mats[0].def.hertz_mixing, F64);
    POKE(mats[0].bpm.radius_multiplier, F64);
    POKE(mats[0].bpm.tensile_strength, F64);
    POKE(mats[0].bpm.shear_strength_sd, F64);
    /* a ball in the middle of the dense order, every array */
    const int64_t i = b->balls.n / 2;
    POKE(balls.x[i * d + d - 1], F64);
    if (!b->build_needed) POKE(balls.x_build[i * d], F64);
    POKE(balls.v[i * d], F64);
    POKE(balls.w[i * r + r - 1], F64);
    POKE(balls.f[i * d], F64);
    POKE(balls.t[i * r], F64);
    POKE(balls.rad[i], F64);
    POKE(balls.inv_mass[i], F64);
    POKE(balls.inv_inertia[i], F64);
    if (b->nmat > 1) POKE(balls.mat[i], U16); /* a valid material: the damping is read through it */
    POKE(balls.fix[i], U8);
    if (b->balls.alpha) POKE(balls.alpha[i], F64);
    if (b->balls.group) POKE(balls.group[i], I32);
    if (b->balls.fapp) {
        POKE(balls.fapp[i * d], F64);
        POKE(balls.tapp[i * r], F64);
    }
    /* walls */
    for (int64_t w = 0; w < b->nwall; w++) {
        POKE(walls[w].id, I64);
        POKE(walls[w].def.kind, INT);
        POKE(walls[w].def.point[0], F64);
        POKE(walls[w].def.normal[1], F64);
        POKE(walls[w].def.edge1[0], F64);
        POKE(walls[w].def.edge2[1], F64);
        POKE(walls[w].def.vel[d - 1], F64);
        POKE(walls[w].def.radius, F64);
        POKE(walls[w].def.height, F64);
        POKE(walls[w].def.radial_vel, F64);
        POKE(walls[w].def.kn, F64);
        POKE(walls[w].def.ks, F64);
        POKE(walls[w].def.friction, F64);
        POKE(walls[w].def.material, INT); /* none (-1) to material 0 */
        POKE(walls[w].force[0], F64);
        POKE(walls[w].moment[2], F64);
        POKE(walls[w].load, F64);
        POKE(walls[w].kn_sum, F64);
        POKE(walls[w].contacts, I64);
        if (!b->build_needed) POKE(walls[w].moved, F64);
        POKE(walls[w].servo_on, BOOL);
        if (b->walls[w].servo_on) {
            POKE(walls[w].servo.target, F64);
            POKE(walls[w].servo.area, F64);
            POKE(walls[w].servo.alpha, F64);
            POKE(walls[w].servo.max_speed, F64);
        }
    }
    /* contact histories */
    const int64_t c = live_pair(&b->bb), cw = live_pair(&b->bw);
    if (c >= 0) {
        POKE(bb.fs[c * d], F64);
        POKE(bb.geo[c * d + d - 1], F64);
        POKE(bb.fn[c], F64);
        POKE(bb.touching[c], U8);
        if (b->bb.bond && b->bb.bond[c]) {
            const int64_t s = b->bb.bond[c] - 1;
            POKE(bonds.fs[s * d], F64);
            POKE(bonds.ms[s * r], F64);
        }
    }
    /* the contact-model table (cmodel.c) and a contact's row */
    if (b->ncmodel > 0) {
        POKE(cmodel[0].def.match, INT);
        POKE(cmodel[0].def.a, I32);
        POKE(cmodel[0].def.b, I32);
        POKE(cmodel[0].mat.name[0], CHAR);
        POKE(cmodel[0].mat.def.model, INT);
        POKE(cmodel[0].mat.def.kn, F64);
        POKE(cmodel[0].mat.def.friction, F64);
        POKE(cmodel[0].mat.def.rolling_friction, F64);
        if (c >= 0) POKE(bb.cmodel[c], I32);
    }
    if (cw >= 0) {
        POKE(bw.fs[cw * d], F64);
        POKE(bw.geo[cw * d], F64);
        POKE(bw.fn[cw], F64);
        POKE(bw.un[cw], F64);
    }
    /* bonds, intact or broken, and the crack log */
    for (int64_t s = 0; s < b->bonds.n; s += b->bonds.n - 1 > 0 ? b->bonds.n - 1 : 1) {
        POKE(bonds.kind[s], U8);
        POKE(bonds.ida[s], I32);
        POKE(bonds.idb[s], I32);
        POKE(bonds.cb_n[s], F64);
        POKE(bonds.cb_s[s], F64);
        POKE(bonds.rbar[s], F64);
        POKE(bonds.kn[s], F64);
        POKE(bonds.ks[s], F64);
        POKE(bonds.sigma_c[s], F64);
        POKE(bonds.tau_c[s], F64);
        POKE(bonds.fn[s], F64);
        POKE(bonds.mn[s], F64);
    }
    if (b->cracks.n > 0) {
        POKE(cracks.ev[0].time, F64);
        POKE(cracks.ev[0].step, I64);
        POKE(cracks.ev[0].pos[1], F64);
        POKE(cracks.ev[0].mode, INT);
        POKE(cracks.ev[0].kind, INT);
        POKE(cracks.ev[0].a, I64);
        POKE(cracks.ev[0].b, I64);
        POKE(cracks.ev[0].fn, F64);
        POKE(cracks.ev[0].fs, F64);
        POKE(cracks.ev[0].mn, F64);
        POKE(cracks.ev[0].ms, F64);
    }
    /* flat joints: a joint's face and its elements */
    for (int64_t s = 0; s < b->bonds.n && b->fjel.n > 0; s++) {
        if (!(b->bonds.kind[s] & SX_BOND_FLATJOINT)) continue;
        POKE(bonds.fj_mu[s], F64);
        POKE(bonds.fj_tanphi[s], F64);
        POKE(bonds.fj_d0[s], F64);
        POKE(bonds.fj_rot[s * (d - 1)], F64);
        if (d == 3) POKE(bonds.fj_axis[s * 3 + 1], F64);
        const int64_t e = b->bonds.fj_first[s];
        POKE(fjel.state[e], U8);
        POKE(fjel.sigma_c[e], F64);
        POKE(fjel.coh[e], F64);
        POKE(fjel.gap0[e], F64);
        POKE(fjel.fn[e], F64);
        POKE(fjel.fs[e * (d - 1)], F64);
        break;
    }
    /* clumps: a template and a clump */
    if (b->clumps && b->clumps->n > 0) {
        const int64_t k = b->clumps->n - 1, qd = d == 3 ? 4 : 1;
        POKE(clumps->tpl[0].name[0], CHAR);
        POKE(clumps->tpl[0].lines, I64);
        POKE(clumps->tpl[0].volume, F64);
        POKE(clumps->tpl[0].centroid[0], F64);
        POKE(clumps->tpl[0].inertia[0], F64);
        POKE(clumps->tpl[0].principal[0], F64);
        POKE(clumps->tpl[0].frame[0], F64);
        POKE(clumps->tpl[0].error, F64);
        POKE(clumps->tpl[0].power_sum, F64);
        POKE(clumps->tp_pos[d - 1], F64);
        POKE(clumps->tp_rad[1], F64);
        POKE(clumps->tp_body[0], F64);
        POKE(clumps->next_id, I64);
        POKE(clumps->id[k], I32);
        POKE(clumps->mat[k], U16);
        POKE(clumps->fix[k], U8);
        POKE(clumps->scale[k], F64);
        POKE(clumps->alpha[k], F64);
        POKE(clumps->mass[k], F64);
        POKE(clumps->inertia[k * r + r - 1], F64);
        POKE(clumps->x[k * d + d - 1], F64);
        POKE(clumps->v[k * d], F64);
        POKE(clumps->q[k * qd + qd - 1], F64);
        if (d == 3) POKE(clumps->L[k * 3 + 2], F64);
        POKE(clumps->w[k * r], F64);
        POKE(clumps->f[k * d], F64);
        POKE(clumps->t[k * r], F64);
        POKE(clumps->pebble[b->clumps->first[k] + 1], I32);
    }
    /* periodic space: the cell, its control and its ghosts */
    if (b->cell) {
        POKE(cell->axis[d - 1], BOOL);
        POKE(cell->lo[0], F64);
        POKE(cell->h[1][1], F64);
        POKE(cell->hdot[0][0], F64);
        POKE(cell->ctl.mode[SX_CELL_YY], INT);
        POKE(cell->ctl.rate[SX_CELL_XX], F64);
        POKE(cell->ctl.target[SX_CELL_XY], F64);
        POKE(cell->ctl.alpha, F64);
        POKE(cell->ctl.max_rate, F64);
        if (!b->build_needed) POKE(cell->moved, F64);
        if (b->cell->n > 0) {
            POKE(cell->owner[0], I32);
            POKE(cell->image[0], U8);
        }
    }
}

/* Clumps of two overlapping pebbles above a granular bed, falling onto it. */
static sx_model *clumped(int dim)
{
    const int up = dim - 1;
    double g[3] = {0, 0, 0};
    g[up] = -9.81;
    sx_model *m = scene_model(dim, g, 0, 1e5, 0.5, 2650);
    double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1}, top[3] = {0.1, 0.1, 0.1};
    top[up] = 0.2;
    scene_box_walls(m, lo, top, 1e5, 0.5);
    scene_random_balls(m, 30, lo, hi, 0.004, 0.007, 0.05, 0.02, 77, NULL);
    const double pos[6] = {0, 0, 0, 0.006, 0, 0}, pos2[4] = {0, 0, 0.006, 0}, rad[2] = {0.005, 0.004};
    const sx_clump_template_def t = {dim == 3 ? pos : pos2, rad, 2, 0};
    ck_assert_int_eq(sx_clump_template_add(m, "pair", &t, NULL), SX_OK);
    for (int k = 0; k < 3; k++) {
        sx_clump_def c = sx_clump_default_def();
        c.pos[0] = 0.025 * (k + 1);
        if (dim == 3) c.pos[1] = 0.05;
        c.pos[up] = 0.15;
        c.spin[0] = 3.0 * (k - 1);
        ck_assert_int_eq(sx_clump_add(m, &c, NULL), SX_OK);
    }
    return m;
}

/* Balls in a periodic box whose cell shrinks along x at a strain rate. */
static sx_model *periodic(int dim)
{
    sx_model *m = scene_model(dim, NULL, 0, 1e5, 0.5, 2650);
    sx_periodic_def pd = {{true, true, dim == 3}, {0, 0, 0}, {0.1, 0.1, 0.1}, {0, 0, 0}};
    ck_assert_int_eq(sx_model_set_periodic(m, &pd), SX_OK);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.1};
    scene_random_balls(m, dim == 3 ? 60 : 40, lo, hi, 0.004, 0.007, 0.2, 0.02, 91, NULL);
    sx_cell_control c = sx_cell_default_control();
    c.mode[SX_CELL_XX] = SX_CELL_RATE;
    c.rate[SX_CELL_XX] = -0.5;
    ck_assert_int_eq(sx_cell_set_control(m, &c), SX_OK);
    return m;
}

typedef sx_model *(*scene_fn)(int dim);
static sx_model *granular(int dim) { return io_scene_granular(dim, 120); }
/* the granular scene whose contacts take a default row of the contact-model table */
static sx_model *granular_table(int dim)
{
    sx_model *m = io_scene_granular(dim, 120);
    sx_cmodel_def row = {.match = SX_CMODEL_DEFAULT};
    ck_assert_int_eq(sx_material_get(m, 0, &row.law), SX_OK);
    row.law.kn *= 2;
    ck_assert_int_eq(sx_cmodel_add(m, "stiffer", &row, NULL), SX_OK);
    return m;
}
static const scene_fn scenes[] = {granular, io_scene_bonded, io_scene_servo, io_scene_hertz, io_scene_flatjoint,
                                  clumped, periodic, granular_table};
enum { NSCENES = sizeof scenes / sizeof *scenes };

static void cycled_pair(int scene, int dim, sx_model **a, sx_model **b)
{
    *a = scenes[scene](dim);
    *b = scenes[scene](dim);
    io_cycle(*a, 150);
    io_cycle(*b, 150);
}

START_TEST(every_restored_field)
{
    nseen = 0;
    for (int scene = 0; scene < NSCENES; scene++)
        for (int dim = 2; dim <= 3; dim++) {
            sx_model *a, *b;
            cycled_pair(scene, dim, &a, &b);
            poke_all(a, b);
            sx_model_destroy(a);
            sx_model_destroy(b);
        }
    /* every field was covered by some scene */
    static const char *const must[] = {"balls.fapp[i * d]", "balls.group[i]", "balls.alpha[i]", "walls[w].servo.target",
                                       "bonds.fs[s * d]", "bonds.ms[s * r]", "cracks.ev[0].fs", "bw.un[cw]",
                                       "bb.fs[c * d]", "dt", "balls.x_build[i * d]", "walls[w].moved",
                                       "cmodel[0].mat.def.kn", "bb.cmodel[c]",
                                       "fjel.fs[e * (d - 1)]", "clumps->pebble[b->clumps->first[k] + 1]",
                                       "clumps->tpl[0].power_sum", "cell->ctl.alpha", "cell->owner[0]"};
    for (size_t k = 0; k < sizeof must / sizeof *must; k++) {
        bool found = false;
        for (int i = 0; i < nseen; i++) found |= strcmp(seen[i], must[k]) == 0;
        ck_assert_msg(found, "no scene exercises %s", must[k]);
    }
}
END_TEST

/* Representation, not state: none of these changes the hash. */
START_TEST(canonical)
{
    const int dim = _i;
    for (int scene = 0; scene < NSCENES; scene++) {
        sx_model *a, *b;
        cycled_pair(scene, dim, &a, &b);
        const uint64_t h = sx_model_state_hash(a);
        /* a pair flipped (the other ball first) and its rows moved */
        sx_pairs *p = &b->bb;
        for (int64_t c = 0; c < p->n; c++) sx__pair_flip(b, p, c);
        ck_assert_uint_eq(sx_model_state_hash(b), h);
        for (int64_t c = 0; c < p->n; c++) sx__pair_flip(b, p, c);
        if (p->n >= 2 && p->cap > p->n) {
            sx__pair_move(b, p, p->n, 0);
            sx__pair_move(b, p, 0, p->n - 1);
            sx__pair_move(b, p, p->n - 1, p->n);
            ck_assert_uint_eq(sx_model_state_hash(b), h);
        }
        /* -0 for +0 */
        const int64_t id = sx_ball_id_at(b, 0);
        double v[3] = {0, 0, 0}, nv[3] = {-0.0, -0.0, -0.0};
        ck_assert_int_eq(sx_ball_set_vec(a, id, SX_BALL_VEL, v), SX_OK);
        ck_assert_int_eq(sx_ball_set_vec(b, id, SX_BALL_VEL, nv), SX_OK);
        ck_assert_uint_eq(sx_model_state_hash(b), sx_model_state_hash(a));
        /* queries that prepare the model: a pending build and a stale automatic timestep */
        ck_assert_int_eq(sx_model_set_timestep(a, 0), SX_OK);
        ck_assert_int_eq(sx_model_set_timestep(b, 0), SX_OK);
        double x[3];
        ck_assert_int_eq(sx_ball_get_vec(a, id, SX_BALL_POS, x), SX_OK);
        ck_assert_int_eq(sx_ball_set_vec(a, id, SX_BALL_POS, x), SX_OK);
        ck_assert_int_eq(sx_ball_set_vec(b, id, SX_BALL_POS, x), SX_OK);
        const uint64_t h2 = sx_model_state_hash(a);
        ck_assert(b->build_needed && b->dt_stale);
        ck_assert(isfinite(sx_model_timestep(b)));
        sx_energy e = sx_model_energy(b);
        ck_assert(isfinite(e.kinetic));
        ck_assert(sx_contact_count(b) >= 0);
        ck_assert(!b->build_needed);
        ck_assert_uint_eq(sx_model_state_hash(b), h2);
        /* and the two continue alike */
        io_cycle(a, 20);
        io_cycle(b, 20);
        ck_assert_uint_eq(sx_model_state_hash(b), sx_model_state_hash(a));
        sx_model_destroy(a);
        sx_model_destroy(b);
    }
}
END_TEST

/* A restart keeps the hash, however the file's rows come back. */
START_TEST(restart_keeps_it)
{
    const int dim = _i;
    char path[512];
    for (int scene = 0; scene < NSCENES; scene++) {
        sx_model *a = scenes[scene](dim);
        io_cycle(a, 150);
        io_save(a, io_path(path, sizeof path, "hash.h5"));
        sx_model *b = io_load(path, dim);
        ck_assert_uint_eq(sx_model_state_hash(b), sx_model_state_hash(a));
        io_cycle(a, 30);
        io_cycle(b, 30);
        ck_assert_uint_eq(sx_model_state_hash(b), sx_model_state_hash(a));
        sx_model_destroy(a);
        sx_model_destroy(b);
    }
    io_rmdir();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("hash");
    TCase *t = tcase_create("hash");
    tcase_set_timeout(t, 600);
    tcase_add_test(t, every_restored_field);
    tcase_add_loop_test(t, canonical, 2, 4);
    tcase_add_loop_test(t, restart_keeps_it, 2, 4);
    suite_add_tcase(s, t);
    return scene_run_suite(s);
}
