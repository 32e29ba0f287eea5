/* Domain decomposition (issue 16) in one process: threads as ranks, each
 * holding its own copy of the model and exchanging through memory (the
 * sx_exchange an MPI launcher would fill), so that every rank count and
 * every code path of decompose.c runs in the unit suite, under the
 * sanitizers too, and the bits are compared in full: the state hash and
 * every energy term of each rank against the serial run. */
#include "model_internal.h" /* the clumps' owners and routes, to check the scene exercises them */
#include "scenes.h"

#include <check.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_RANKS = 5 };

/* The ranks' meeting point: each posts its array (or value), all wait,
 * each takes what it needs from the others, all wait again (so no rank
 * writes an array another is still reading). */
typedef struct world {
    int ranks;
    pthread_barrier_t bar;
    void *data[MAX_RANKS];
    double value[MAX_RANKS];
    uint64_t key[MAX_RANKS];
} world;

typedef struct rank_ctx {
    world *w;
    int rank, dim;
    bool bonded, clumped;
    int64_t crossing, moved; /* clumps: pebbles routed to another rank's clump; clumps whose owner changed */
    int64_t first_own, last_own; /* the balls of the first and of the last rank, at cycle B's last plan */
    double pace[MAX_RANKS];      /* the ranks' paces after cycle C */
    int64_t builds; /* cycle B's builds (but a first one, inside the cycle, the ranks listing in parts); lazily all */
    int64_t gathers;             /* cycle B's exchanges of the whole state (its end's alone: a build migrates) */
    bool lazy;                   /* the cycles in short runs that leave the state scattered, gathered at the end */
    int64_t runs, resumed;       /* lazy: the runs, and those that went on from a scattered state */
    uint64_t hash;
    uint64_t scattered_hash; /* lazy: the hash before the gather, each rank summing its own rows' digests */
    double scattered_ratio;  /* and the unbalanced-force ratio (chained), the bonds and cracks (summed) */
    int64_t scattered_counts[4]; /* bonds, tension and shear cracks, contacts */
    sx_energy scattered_energy;  /* and the energies (chained), the automatic timestep (the ranks' least) */
    double scattered_dt, scattered_crit; /* and the critical estimate */
    double motion[4][9];         /* balls' position, velocity and force read after sx_ball_fetch (motion_of) */
    bool cut_off;                /* the exchanges fail (every rank alike) */
    char cut_off_error[SX_ERRLEN]; /* an energy query's error then */
    sx_energy energy;
    sx_status st;
} rank_ctx;

static bool share(void *ud, void *data, size_t size, const sx_span *own, const sx_span *need, int per)
{
    rank_ctx *c = ud;
    world *w = c->w;
    if (c->cut_off) return false;
    w->data[c->rank] = data;
    pthread_barrier_wait(&w->bar);
    for (int r = 0; r < w->ranks; r++) {
        if (r == c->rank) continue;
        for (int k = 0; k < per; k++) { /* what rank r holds of this rank's need k */
            const sx_span want = need[c->rank * per + k];
            const int64_t lo = want.lo > own[r].lo ? want.lo : own[r].lo, hi = want.hi < own[r].hi ? want.hi : own[r].hi;
            if (hi > lo)
                memcpy((char *)data + (size_t)lo * size, (const char *)w->data[r] + (size_t)lo * size,
                       (size_t)(hi - lo) * size);
        }
    }
    pthread_barrier_wait(&w->bar);
    return true;
}

static bool largest(void *ud, double *v)
{
    rank_ctx *c = ud;
    world *w = c->w;
    w->value[c->rank] = *v;
    pthread_barrier_wait(&w->bar);
    for (int r = 0; r < w->ranks; r++)
        if (w->value[r] > *v) *v = w->value[r];
    pthread_barrier_wait(&w->bar);
    return true;
}

static bool agree(void *ud, uint64_t v)
{
    rank_ctx *c = ud;
    world *w = c->w;
    w->key[c->rank] = v;
    pthread_barrier_wait(&w->bar);
    bool same = true;
    for (int r = 0; r < w->ranks; r++) same = same && w->key[r] == v;
    pthread_barrier_wait(&w->bar);
    return same;
}

/* A model under gravity with energy tracking and one material "m" (its
 * index in *mat if not NULL): friction, dashpots and local damping, so
 * that every dissipation acts. */
static sx_model *tracked_model(int dim, int *mat)
{
    const double g[3] = {0, dim == 2 ? -9.81 : 0, dim == 3 ? -9.81 : 0};
    sx_model *m = scene_model(dim, g, 1e-5, 2e5, 0.5, 2500);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = 2e5;
    md.density = 2500;
    md.friction = 0.3;
    md.viscous_normal = 0.2;
    md.viscous_shear = 0.1;
    md.damping = 0.1;
    const int k = scene_material_def(m, "m", &md);
    if (mat) *mat = k;
    sx_model_track_energy(m, true);
    return m;
}

/* A dense bed in a box with energy tracking on: several chunks of pairs
 * and wall blocks, so that chunks and blocks begin on one rank and go on
 * over the next; unforced, so the energy guard runs its chained sums.
 * Bonded: every touching pair gets a weak parallel bond, and the balls'
 * random velocities break many of them (the crack log merged from the
 * ranks in the serial order, the released energy chained). */
static sx_model *bed(int dim, bool bonded)
{
    sx_model *m = tracked_model(dim, NULL);
    m->skin_user = 2e-5; /* a thin skin: builds inside the cycles, where the ranks list the pairs in parts */
    const double r = 0.01, s = 2 * r - 1e-5;
    const int nx = dim == 3 ? 12 : 80, ny = dim == 3 ? 12 : 50, nz = dim == 3 ? 14 : 1;
    uint64_t seed = 11;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                double x[3] = {r + i * s + scene_rng_uniform(&seed, -2e-6, 2e-6), r + j * s, r + k * s};
                if (dim == 3) x[1] += scene_rng_uniform(&seed, -2e-6, 2e-6);
                const double v[3] = {scene_rng_uniform(&seed, -0.05, 0.05), scene_rng_uniform(&seed, -0.05, 0.05),
                                     dim == 3 ? scene_rng_uniform(&seed, -0.05, 0.05) : 0};
                scene_ball(m, x, v, r);
            }
    const double lo[3] = {0, 0, 0}, hi[3] = {nx * s + r, dim == 3 ? ny * s + r : 10, 10};
    scene_box_walls(m, lo, hi, 2e5, 0.5);
    if (bonded) {
        sx_bond_def bd = sx_bond_default_def();
        bd.gap = 1e-6;
        bd.seed = 3;
        bd.radius_multiplier = 1;
        bd.modulus = 1e6;
        bd.stiffness_ratio = 2.5;
        bd.tensile_strength = 2e3, bd.tensile_strength_sd = 1e3;
        bd.cohesion = 4e3, bd.cohesion_sd = 2e3;
        ck_assert_int_eq(sx_bond_install(m, &bd, NULL), SX_OK);
    }
    return m;
}

/* A bed of clumps with energy tracking: asymmetric dumbbells (two
 * touching pebbles, radii r and 0.7 r) on a lattice at random angles,
 * thrown about and spinning in a box under gravity: many lie across the
 * ranks' slabs (their pebbles on two ranks), and the cut moves as they
 * do, so clumps change owner; a load on some pebbles works on them,
 * some clumps are held. 2D: 720 clumps, two of the clump step's
 * energy blocks. */
static sx_model *clump_bed(int dim)
{
    int mat;
    sx_model *m = tracked_model(dim, &mat);
    const double r = 0.01, pos[6] = {-r, 0, 0, 0.7 * r, 0, 0}, rad[2] = {r, 0.7 * r};
    double p2[4] = {-r, 0, 0.7 * r, 0};
    const sx_clump_template_def td = {dim == 3 ? pos : p2, rad, 2, 0};
    ck_assert_int_eq(sx_clump_template_add(m, "dumbbell", &td, NULL), SX_OK);
    const double s = 4.1 * r; /* a dumbbell turns within 2 r of its centroid */
    const int nx = dim == 3 ? 8 : 24, ny = dim == 3 ? 5 : 30, nz = dim == 3 ? 10 : 1;
    uint64_t seed = 5;
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                sx_clump_def cd = sx_clump_default_def();
                cd.material = mat;
                const double a = scene_rng_uniform(&seed, -3.14, 3.14);
                cd.pos[0] = 2.2 * r + i * s;
                cd.pos[1] = dim == 3 ? 1.1 * r + j * 2.2 * r : 2.2 * r + j * s;
                cd.pos[2] = dim == 3 ? 2.2 * r + k * s : 0;
                /* about the axis normal to the lattice's layers of dumbbells (3D: y; 2D: z) */
                cd.orientation[0] = cos(a / 2), cd.orientation[dim == 3 ? 2 : 3] = sin(a / 2);
                for (int q = 0; q < dim; q++) cd.vel[q] = scene_rng_uniform(&seed, -2, 2);
                cd.spin[dim == 3 ? 1 : 0] = scene_rng_uniform(&seed, -50, 50);
                ck_assert_int_eq(sx_clump_add(m, &cd, NULL), SX_OK);
            }
    /* some clumps held along x or in their spin: a held motion has no
     * energy term (each rank's terms must start from zero every step) */
    for (int64_t id = 3; id <= sx_clump_count(m); id += 11)
        ck_assert_int_eq(sx_clump_set_fixity(m, id, id % 2 ? SX_FIX_VX : dim == 3 ? SX_FIX_SPIN : SX_FIX_WZ), SX_OK);
    /* a load on some pebbles: the clumps' load work (energy tracking) */
    const double push[3] = {0.02, 0.01, 0};
    for (int64_t id = 1; id <= 2 * sx_clump_count(m); id += 7)
        ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_APPLIED_FORCE, push), SX_OK);
    const double lo[3] = {0, 0, 0}, hi[3] = {nx * s + r, dim == 3 ? ny * 2.2 * r + r : ny * s + 1, nz * s + 1};
    scene_box_walls(m, lo, hi, 2e5, 0.5);
    return m;
}

enum { STEPS_A = 150, STEPS_B = 250 };

/* Four balls' position, velocity and force (ids spread over the ranks'
 * slabs), each read as a script reads it: fetched first (the fourth after
 * 16 other fetches, which share every ball's motion). */
static sx_status motion_of(sx_model *m, double out[4][9])
{
    const int64_t n = sx_ball_count(m), id[4] = {1, n / 2, n, n / 3};
    sx_status st = SX_OK;
    for (int k = 0; k < 4 && !st; k++) {
        for (int64_t extra = 0; k == 3 && extra < 16 && !st; extra++) st = sx_ball_fetch(m, 2 + extra);
        if (!st) st = sx_ball_fetch(m, id[k]);
        if (!st) st = sx_ball_get_vec(m, id[k], SX_BALL_POS, out[k]);
        if (!st) st = sx_ball_get_vec(m, id[k], SX_BALL_VEL, out[k] + 3);
        if (!st) st = sx_ball_get_vec(m, id[k], SX_BALL_FORCE, out[k] + 6);
    }
    return st;
}

/* Lazily: cycles A and B in runs of 1 to 7 steps, each going on from the
 * state the last left scattered (builds inside them and at their starts,
 * the plan kept over the runs), the whole state gathered once at the end. */
static void run_lazily(rank_ctx *c, sx_model *m)
{
    sx_model_gather_lazily(m, true);
    for (int64_t done = 0, k = 0; done < STEPS_A + STEPS_B && !c->st; done += k, c->runs++) {
        k = c->runs % 7 + 1 < STEPS_A + STEPS_B - done ? c->runs % 7 + 1 : STEPS_A + STEPS_B - done;
        c->st = sx_model_cycle(m, k);
        if (!c->st && !sx_model_scattered(m)) c->st = SX_EINVAL; /* a lazy cycle must not gather */
    }
    c->resumed = sx_model_profile(m).resumed;
    c->builds = m->builds;
    const int64_t gathers = sx_model_profile(m).gathers;
    c->scattered_hash = sx_model_state_hash(m);
    c->scattered_ratio = sx_model_unbalanced_ratio(m);
    if (!sx_model_bond_counts(m, c->scattered_counts)) c->st = SX_ENOMEM;
    c->scattered_counts[3] = sx_contact_count(m);
    c->scattered_energy = sx_model_energy(m);
    if (!c->st) c->st = motion_of(m, c->motion);
    /* the automatic timestep (the scenes' is fixed), then the fixed one again */
    if (!c->st) c->st = sx_model_set_timestep(m, 0);
    c->scattered_dt = sx_model_timestep(m);
    c->scattered_crit = sx_model_critical_timestep(m);
    if (!c->st) c->st = sx_model_set_timestep(m, 1e-5);
    /* ranks that cannot exchange: no hash, ratio or energy, and an error rather than a number */
    c->cut_off = true;
    const sx_energy lost = sx_model_energy(m);
    snprintf(c->cut_off_error, sizeof c->cut_off_error, "%s", sx_model_error(m));
    if (!c->st && (sx_model_state_hash(m) != 0 || !isnan(sx_model_unbalanced_ratio(m)) || !isnan(lost.kinetic)))
        c->st = SX_EINVAL;
    c->cut_off = false;
    if (!c->st && (!sx_model_scattered(m) || sx_model_profile(m).gathers != gathers))
        c->st = SX_EINVAL; /* these queries of a scattered model gather nothing */
    if (!c->st) c->st = sx_model_gather(m);
    if (!c->st && sx_model_scattered(m)) c->st = SX_EINVAL;
    c->hash = sx_model_state_hash(m);
    c->energy = sx_model_energy(m);
}

static void *run_rank(void *arg)
{
    rank_ctx *c = arg;
    sx_model *m = c->clumped ? clump_bed(c->dim) : bed(c->dim, c->bonded);
    const sx_exchange x = {c->rank, c->w->ranks, c, share, largest, agree};
    c->st = sx_model_decompose(m, &x);
    if (c->lazy) {
        if (!c->st) run_lazily(c, m);
        sx_model_destroy(m);
        return NULL;
    }
    if (!c->st) c->st = sx_model_cycle(m, STEPS_A); /* two cycles: a cycle's end and start in between */
    const sx_dd *d = m->dd;
    int32_t *owner = c->clumped && !c->st ? malloc((size_t)d->ncl * sizeof *owner) : NULL; /* at A's last plan */
    if (owner) memcpy(owner, d->cown, (size_t)d->ncl * sizeof *owner);
    /* cycle B is cut as if the ranks above ran slower and slower (their
     * paces, which every rank holds alike): uneven slabs, the same bits */
    for (int r = 0; d && r < c->w->ranks; r++) d->pace[r] = 1 + 3 * r;
    c->builds = m->builds, c->gathers = sx_model_profile(m).gathers;
    if (!c->st) c->st = sx_model_cycle(m, STEPS_B);
    c->builds = m->builds - c->builds, c->gathers = sx_model_profile(m).gathers - c->gathers;
    if (d) c->first_own = d->own[0].hi - d->own[0].lo, c->last_own = d->own[c->w->ranks - 1].hi - d->own[c->w->ranks - 1].lo;
    if (owner) {
        c->crossing = d->fwd.n;
        for (int64_t k = 0; k < d->ncl; k++) c->moved += owner[k] != d->cown[k];
        free(owner);
    }
    c->hash = sx_model_state_hash(m);
    c->energy = sx_model_energy(m);
    /* cycle C: each rank as if it had computed 100 s per rank number (far
     * above what it computes now, even under valgrind) for a fixed work;
     * the first gather shares the samples, which every rank must fold into
     * the same paces */
    if (!c->st && d) {
        for (int r = 0; r < c->w->ranks; r++) d->pace[r] = 0;
        m->dd->busy = 100.0 * (1 + c->rank);
        m->dd->busy_work = 1e6;
        c->st = sx_model_cycle(m, 20);
        memcpy(c->pace, d->pace, (size_t)c->w->ranks * sizeof *d->pace);
    }
    sx_model_destroy(m);
    return NULL;
}

START_TEST(ranks_give_the_serial_bits)
{
    for (int scene = 0; scene < 6; scene++) {
        const int dim = 2 + scene % 2;
        const bool bonded = scene >= 2 && scene < 4, clumped = scene >= 4;
        sx_model *serial = clumped ? clump_bed(dim) : bed(dim, bonded);
        ck_assert_int_eq(sx_model_cycle(serial, STEPS_A), SX_OK);
        ck_assert_int_eq(sx_model_cycle(serial, STEPS_B), SX_OK);
        const int64_t contacts = sx_contact_count(serial);
        ck_assert_msg(clumped ? contacts > 20 : contacts > sx_ball_count(serial),
                      "%dD: the bed must be dense, or the clumps collide (%lld contacts)", dim, (long long)contacts);
        const uint64_t hash = sx_model_state_hash(serial);
        const double ratio = sx_model_unbalanced_ratio(serial);
        int64_t counts[4];
        ck_assert(sx_model_bond_counts(serial, counts));
        counts[3] = contacts;
        ck_assert_msg(counts[0] == sx_bond_count(serial) && counts[1] + counts[2] == sx_crack_count(serial),
                      "%dD: the counts must be the model's", dim);
        const sx_energy e = sx_model_energy(serial);
        double motion[4][9];
        memset(motion, 0, sizeof motion);
        ck_assert_int_eq(motion_of(serial, motion), SX_OK);
        ck_assert_int_eq(sx_model_set_timestep(serial, 0), SX_OK);
        const double dt = sx_model_timestep(serial), crit = sx_model_critical_timestep(serial);
        ck_assert_msg(dt > 0 && dt < 1e-3, "%dD: an automatic timestep (%g s)", dim, dt);
        ck_assert_int_eq(sx_model_set_timestep(serial, 1e-5), SX_OK);
        ck_assert_msg(e.slip > 0 && e.viscous > 0 && e.local_damping > 0, "every dissipation must act");
        ck_assert_msg(!clumped || e.boundary_work != 0, "%dD: the loads must work on the clumps", dim);
        if (bonded) {
            const int64_t cracks = sx_crack_count(serial);
            ck_assert_msg(cracks > 10 && sx_bond_count(serial) > 10 && e.bond_released > 0,
                          "%dD: bonds must break, and not all (%lld cracks, %lld bonds left)", dim, (long long)cracks,
                          (long long)sx_bond_count(serial));
        }
        sx_model_destroy(serial);
        int64_t crossing = 0, moved = 0; /* clumps: over the rank counts, at the cycles' last plans */
        for (int ranks = 2; ranks <= 3; ranks++) { /* lazily: the cycles cut short, gathered once */
            world w = {.ranks = ranks};
            pthread_barrier_init(&w.bar, NULL, (unsigned)ranks);
            rank_ctx c[MAX_RANKS];
            pthread_t t[MAX_RANKS];
            for (int r = 0; r < ranks; r++) {
                c[r] = (rank_ctx){.w = &w, .rank = r, .dim = dim, .bonded = bonded, .clumped = clumped, .lazy = true};
                ck_assert_int_eq(pthread_create(&t[r], NULL, run_rank, &c[r]), 0);
            }
            for (int r = 0; r < ranks; r++) pthread_join(t[r], NULL);
            pthread_barrier_destroy(&w.bar);
            for (int r = 0; r < ranks; r++) {
                ck_assert_msg(c[r].st == SX_OK, "%dD lazily, %d ranks: rank %d failed (%d)", dim, ranks, r, c[r].st);
                ck_assert_msg(c[r].hash == hash, "%dD lazily, %d ranks: rank %d's state differs from the serial run's",
                              dim, ranks, r);
                ck_assert_msg(c[r].scattered_hash == hash,
                              "%dD lazily, %d ranks: rank %d's hash of the scattered state differs from the serial run's",
                              dim, ranks, r);
                ck_assert_msg(memcmp(&c[r].scattered_ratio, &ratio, sizeof ratio) == 0,
                              "%dD lazily, %d ranks: rank %d's ratio of the scattered state %.17g, serially %.17g", dim,
                              ranks, r, c[r].scattered_ratio, ratio);
                ck_assert_msg(memcmp(c[r].scattered_counts, counts, sizeof counts) == 0,
                              "%dD lazily, %d ranks: rank %d's bonds, cracks and contacts of the scattered state (%lld, "
                              "%lld, %lld, %lld) differ from the serial run's (%lld, %lld, %lld, %lld)", dim, ranks, r,
                              (long long)c[r].scattered_counts[0], (long long)c[r].scattered_counts[1],
                              (long long)c[r].scattered_counts[2], (long long)c[r].scattered_counts[3],
                              (long long)counts[0], (long long)counts[1], (long long)counts[2], (long long)counts[3]);
                ck_assert_msg(memcmp(&c[r].energy, &e, sizeof e) == 0,
                              "%dD lazily, %d ranks: rank %d's energies differ from the serial run's", dim, ranks, r);
                ck_assert_msg(memcmp(&c[r].scattered_energy, &e, sizeof e) == 0,
                              "%dD lazily, %d ranks: rank %d's energies of the scattered state differ from the serial "
                              "run's (kinetic %.17g, strain %.17g; serially %.17g, %.17g)", dim, ranks, r,
                              c[r].scattered_energy.kinetic, c[r].scattered_energy.strain, e.kinetic, e.strain);
                ck_assert_msg(memcmp(c[r].motion, motion, sizeof motion) == 0,
                              "%dD lazily, %d ranks: rank %d's balls' motion read from the scattered state differs "
                              "from the serial run's", dim, ranks, r);
                ck_assert_msg(strstr(c[r].cut_off_error, "could not exchange"),
                              "%dD lazily, %d ranks: rank %d's energy without exchanges: '%s'", dim, ranks, r,
                              c[r].cut_off_error);
                ck_assert_msg(memcmp(&c[r].scattered_crit, &crit, sizeof crit) == 0,
                              "%dD lazily, %d ranks: rank %d's critical timestep of the scattered state %.17g, "
                              "serially %.17g", dim, ranks, r, c[r].scattered_crit, crit);
                ck_assert_msg(memcmp(&c[r].scattered_dt, &dt, sizeof dt) == 0,
                              "%dD lazily, %d ranks: rank %d's timestep of the scattered state %.17g, serially %.17g",
                              dim, ranks, r, c[r].scattered_dt, dt);
            }
            printf("%dD%s lazily, %d ranks: %lld of %lld runs went on from a scattered state\n", dim,
                   bonded ? " bonded" : clumped ? " clumps" : "", ranks, (long long)c[0].resumed, (long long)c[0].runs);
            /* every run but the first goes on from a scattered state, those
             * that must build first too (the build takes what it reads) */
            ck_assert_msg(c[0].resumed == c[0].runs - 1 && c[0].builds >= 2,
                          "%dD lazily, %d ranks: %lld of %lld runs went on from a scattered state (%lld builds)", dim,
                          ranks, (long long)c[0].resumed, (long long)c[0].runs, (long long)c[0].builds);
        }
        for (int ranks = 2; ranks <= MAX_RANKS; ranks++) {
            world w = {.ranks = ranks};
            pthread_barrier_init(&w.bar, NULL, (unsigned)ranks);
            rank_ctx c[MAX_RANKS];
            pthread_t t[MAX_RANKS];
            for (int r = 0; r < ranks; r++) {
                c[r] = (rank_ctx){.w = &w, .rank = r, .dim = dim, .bonded = bonded, .clumped = clumped};
                ck_assert_int_eq(pthread_create(&t[r], NULL, run_rank, &c[r]), 0);
            }
            for (int r = 0; r < ranks; r++) pthread_join(t[r], NULL);
            pthread_barrier_destroy(&w.bar);
            for (int r = 0; r < ranks; r++) {
                ck_assert_msg(c[r].st == SX_OK, "%dD%s, %d ranks: rank %d failed (%d)", dim, bonded ? " bonded" : "", ranks, r, c[r].st);
                ck_assert_msg(c[r].hash == hash, "%dD, %d ranks: rank %d's state differs from the serial run's", dim,
                              ranks, r);
                ck_assert_msg(memcmp(&c[r].energy, &e, sizeof e) == 0,
                              "%dD, %d ranks: rank %d's energies differ from the serial run's", dim, ranks, r);
            }
            for (int r = 0; r < ranks; r++) {
                ck_assert_msg(memcmp(c[r].pace, c[0].pace, (size_t)ranks * sizeof *c[0].pace) == 0,
                              "%dD, %d ranks: rank %d's paces differ from rank 0's", dim, ranks, r);
                ck_assert_msg(r == 0 || c[0].pace[r] > c[0].pace[r - 1],
                              "%dD, %d ranks: the paces must follow the ranks' times (%g, %g)", dim, ranks,
                              c[0].pace[r - 1 + (r == 0)], c[0].pace[r]);
            }
            ck_assert_msg(c[0].builds >= 2, "%dD, %d ranks: cycle B must build inside the cycle (%lld builds)", dim,
                          ranks, (long long)c[0].builds);
            ck_assert_msg(c[0].gathers == 1, "%dD, %d ranks: cycle B's %lld builds must not gather the whole state "
                          "(%lld gathers)", dim, ranks, (long long)c[0].builds, (long long)c[0].gathers);
            ck_assert_msg(c[0].first_own > 2 * c[0].last_own, "%dD, %d ranks: the paces must skew the cut (%lld, %lld balls)",
                          dim, ranks, (long long)c[0].first_own, (long long)c[0].last_own);
            if (clumped) {
                printf("%dD clumps, %d ranks: %lld pebbles routed to another rank's clump, %lld clumps changed owner\n",
                       dim, ranks, (long long)c[0].crossing, (long long)c[0].moved);
                crossing += c[0].crossing, moved += c[0].moved;
            }
        }
        ck_assert_msg(!clumped || (crossing > 0 && moved > 0),
                      "%dD: clumps must lie across the slabs (%lld pebbles routed) and change owner (%lld)", dim,
                      (long long)crossing, (long long)moved);
    }
}
END_TEST

/* An instability one rank meets in its own part of a step (a timestep far
 * above the critical one drives balls into each other, into the walls, or
 * clumps' pebbles together) ends the cycle on every rank at the serial
 * run's step with the serial run's error, agreed at the step's last
 * exchange: each rank returns it, and the state is whole. (Before, the
 * failing rank left the cycle alone and the others waited for it at the
 * next exchange: here a hang.) */
typedef struct unstable_ctx {
    world *w;
    int rank, scene;
    bool agreed, scattered;
    sx_status st;
    int64_t step;
    char err[SX_ERRLEN];
} unstable_ctx;

static sx_model *unstable_bed(int scene)
{
    if (scene == 0) { /* the last ball (top row: the last rank's) shot down through the one below it */
        sx_model *m = bed(2, false);
        const double v[3] = {0, -3000, 0};
        ck_assert_int_eq(sx_ball_set_vec(m, sx_ball_count(m), SX_BALL_VEL, v), SX_OK);
        return m;
    }
    sx_model *m = scene == 2 ? clump_bed(2) : bed(3, false);
    ck_assert_int_eq(sx_model_set_timestep(m, 20 * sx_model_critical_timestep(m)), SX_OK);
    return m;
}

static void *run_unstable(void *arg)
{
    unstable_ctx *c = arg;
    sx_model *m = unstable_bed(c->scene);
    const sx_exchange x = {c->rank, c->w->ranks, c, share, largest, agree};
    c->st = sx_model_decompose(m, &x);
    if (!c->st) c->st = sx_model_cycle(m, 400);
    c->agreed = sx_model_error_agreed(m);
    c->scattered = sx_model_scattered(m);
    c->step = sx_model_step_count(m);
    snprintf(c->err, sizeof c->err, "%s", sx_model_error(m));
    sx_model_destroy(m);
    return NULL;
}

/* The error's step and cause: up to the critical estimate (the ranks'
 * least, made after the other ranks' balls went on through the step:
 * dd_agree.c; lua_mpi_caught cause compares a whole message). */
static size_t cause_length(const char *err) { return strcspn(err, ";,("); }

START_TEST(a_rank_instability_stops_every_rank)
{
    static const char *const name[] = {"2D, a ball shot down", "3D", "2D clumps"};
    for (int scene = 0; scene < 3; scene++) {
        sx_model *serial = unstable_bed(scene);
        const sx_status st = sx_model_cycle(serial, 400);
        const int64_t step = sx_model_step_count(serial);
        char err[SX_ERRLEN];
        snprintf(err, sizeof err, "%s", sx_model_error(serial));
        sx_model_destroy(serial);
        ck_assert_msg(st == SX_EUNSTABLE && strncmp(err, "unstable at step", 16) == 0,
                      "%s: the serial run must be unstable (%d: %s)", name[scene], st, err);
        printf("%s, serially: %.*s\n", name[scene], (int)cause_length(err), err);
        for (int ranks = 2; ranks <= 4; ranks++) {
            world w = {.ranks = ranks};
            pthread_barrier_init(&w.bar, NULL, (unsigned)ranks);
            unstable_ctx c[MAX_RANKS];
            pthread_t t[MAX_RANKS];
            for (int r = 0; r < ranks; r++) {
                c[r] = (unstable_ctx){.w = &w, .rank = r, .scene = scene};
                ck_assert_int_eq(pthread_create(&t[r], NULL, run_unstable, &c[r]), 0);
            }
            for (int r = 0; r < ranks; r++) pthread_join(t[r], NULL);
            pthread_barrier_destroy(&w.bar);
            for (int r = 0; r < ranks; r++) {
                ck_assert_msg(c[r].st == st && c[r].agreed && !c[r].scattered && c[r].step == step,
                              "%s, %d ranks: rank %d must stop with the serial error at step %lld, agreed, the "
                              "state whole (%d at step %lld, agreed %d, scattered %d: %s)",
                              name[scene], ranks, r, (long long)step, c[r].st, (long long)c[r].step, c[r].agreed,
                              c[r].scattered, c[r].err);
                ck_assert_msg(cause_length(c[r].err) == cause_length(err) &&
                                  strncmp(c[r].err, err, cause_length(err)) == 0,
                              "%s, %d ranks: rank %d's error differs from the serial run's:\n  %s\n  %s", name[scene],
                              ranks, r, c[r].err, err);
            }
        }
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("decompose");
    TCase *tc = tcase_create("threads as ranks");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, ranks_give_the_serial_bits);
    tcase_add_test(tc, a_rank_instability_stops_every_rank);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
