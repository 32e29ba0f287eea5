/* Queries of a model's state: its energies, its contacts and the
 * unbalanced-force ratio. */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sx_energy sx_model_energy(sx_model *m)
{
    sx_energy e;
    memset(&e, 0, sizeof e);
    /* materials or positions may have changed since the last cycle: the
     * broad phase the next cycle would build anyway sees every overlap */
    bool split;
    sx_status st = sx__prepare_query(m, &split);
    /* scattered (a lazy cycle's): each rank sums its own rows in chains
     * over the ranks, as the energy guard inside a cycle, the ghosts and
     * clumps first where their owners left them; else the serial sums,
     * which cannot fail */
    /* before the first step the gravitational energy is at the velocities'
     * time by the first step's timestep (sx__half_step): rated here when
     * automatic, and put back, as m:timestep() leaves the state */
    const double dt_kept = m->dt;
    if (!st && !(m->dt_prev > 0) && !(m->dt_user > 0) && m->balls.n > 0) {
        double dt;
        if (sx__next_timestep(m, &dt) == SX_OK) m->dt = dt;
    }
    if (!st && ((split && !sx__dd_refresh(m)) || !sx__kernels(m)->energy(m, &e)))
        st = sx__fail(m, SX_EINVAL, "energy: the ranks could not exchange");
    m->dt = dt_kept;
    if (split) m->dd->active = false;
    if (st) { /* no energy rather than a silent zero */
        double *t = (double *)&e;
        for (size_t k = 0; k < sizeof e / sizeof(double); k++) t[k] = NAN;
    }
    return e;
}

void sx_model_track_energy(sx_model *m, bool on)
{
    m->track_energy = on;
    memset(&m->acc, 0, sizeof m->acc);
}

/* Of a scattered model, each rank counts its own pairs' (current there),
 * and the ranks add their counts. */
int64_t sx_contact_count(const sx_model *m)
{
    if (!sx_model_scattered(m)) return sx__kernels(m)->count_contacts(m);
    const sx_dd *d = m->dd;
    const sx_span bb = d->bb_own[d->x.rank], bw = d->bw_own[d->x.rank];
    uint64_t n = 0;
    for (int64_t c = bb.lo; c < bb.hi; c++) n += m->bb.touching[c];
    for (int64_t c = bw.lo; c < bw.hi; c++) n += m->bw.touching[c];
    return sx__dd_sum(m, &n, 1) ? (int64_t)n : -1;
}

bool sx_contact_each(const sx_model *m, bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    const sx_kernels *k = sx__kernels(m);
    return k->each_contact(m, false, 0, m->bb.n, fn, ud) && k->each_contact(m, true, 0, m->bw.n, fn, ud);
}

typedef struct deepest {
    const sx_model *m;
    int64_t skip_lo, skip_hi;
    sx_overlap o;
} deepest;

static bool deeper(const sx_contact_info *c, void *ud)
{
    deepest *w = ud;
    if (!c->is_wall && c->a >= w->skip_lo && c->a <= w->skip_hi && c->b >= w->skip_lo && c->b <= w->skip_hi) return true;
    const double *rad = w->m->balls.rad, ra = rad[sx__ball_index(w->m, c->a)];
    const double r = c->is_wall ? ra : fmin(ra, rad[sx__ball_index(w->m, c->b)]);
    if (r > 0 && c->overlap / r > w->o.ratio) w->o = (sx_overlap){c->overlap / r, c->overlap, r, c->a, c->b, c->is_wall};
    return true;
}

enum { OVERLAP_WORDS = 6 }; /* an sx_overlap in a rank's exchanged words */

static void overlap_to_words(const sx_overlap *o, uint64_t *w)
{
    memcpy(w, &o->ratio, sizeof *w), memcpy(w + 1, &o->overlap, sizeof *w), memcpy(w + 2, &o->radius, sizeof *w);
    w[3] = (uint64_t)o->a, w[4] = (uint64_t)o->b, w[5] = o->is_wall;
}

static sx_overlap overlap_of_words(const uint64_t *w)
{
    sx_overlap o = {.a = (int64_t)w[3], .b = (int64_t)w[4], .is_wall = w[5] != 0};
    memcpy(&o.ratio, w, sizeof *w), memcpy(&o.overlap, w + 1, sizeof *w), memcpy(&o.radius, w + 2, sizeof *w);
    return o;
}

bool sx_contact_deepest(const sx_model *m, int64_t skip_lo, int64_t skip_hi, sx_overlap *out)
{
    const sx_kernels *k = sx__kernels(m);
    deepest w[2] = {{.m = m, .skip_lo = skip_lo, .skip_hi = skip_hi}, {.m = m, .skip_lo = skip_lo, .skip_hi = skip_hi}}; /* ball-ball, ball-wall */
    const bool scattered = sx_model_scattered(m);
    const int me = scattered ? m->dd->x.rank : 0;
    /* scattered, the pairs of this rank's own balls: the rows it holds current */
    const sx_span bb = scattered ? m->dd->bb_own[me] : (sx_span){0, m->bb.n};
    const sx_span bw = scattered ? m->dd->bw_own[me] : (sx_span){0, m->bw.n};
    k->each_contact(m, false, bb.lo, bb.hi, deeper, &w[0]);
    k->each_contact(m, true, bw.lo, bw.hi, deeper, &w[1]);
    if (!scattered) {
        *out = w[1].o.ratio > w[0].o.ratio ? w[1].o : w[0].o;
        return true;
    }
    uint64_t mine[2 * OVERLAP_WORDS];
    overlap_to_words(&w[0].o, mine), overlap_to_words(&w[1].o, mine + OVERLAP_WORDS);
    const uint64_t *all = sx__dd_words(m, mine, 2 * OVERLAP_WORDS);
    if (!all) return false;
    /* the ball-ball contacts before the ball-wall ones, each kind in rank
     * order (the ranks' own balls in the dense order): the serial order */
    sx_overlap best = {.ratio = 0};
    for (int kind = 0; kind < 2; kind++)
        for (int r = 0; r < m->dd->x.ranks; r++) {
            const sx_overlap o = overlap_of_words(all + ((size_t)r * 2 + (size_t)kind) * OVERLAP_WORDS);
            if (o.ratio > best.ratio) best = o;
        }
    *out = best;
    return true;
}

/* A contact's force: its law's and its bond's (a parallel bond's or a flat
 * joint's face), as PFC counts a bonded contact's force. Without the
 * bond's, a structure that bonds alone carry (a bonded beam, balls bonded
 * across a gap) had no contact force and a ratio that never settled. */
static bool add_contact_force(const sx_contact_info *ci, void *ud)
{
    double *acc = ud;
    const double fn = ci->fn + ci->pb_fn;
    double s2 = fn * fn;
    for (int k = 0; k < 3; k++) s2 += (ci->shear[k] + ci->pb_fs[k]) * (ci->shear[k] + ci->pb_fs[k]);
    acc[0] += sqrt(s2);
    acc[1] += 1;
    return true;
}

/* One of the balls [lo, hi) moves. */
static bool balls_move(const sx_model *m, int64_t lo, int64_t hi)
{
    const sx_balls *b = &m->balls;
    for (int64_t i = lo * m->dim; i < hi * m->dim; i++)
        if (b->v[i] != 0) return true;
    for (int64_t i = lo * m->rdim; i < hi * m->rdim; i++)
        if (b->w[i] != 0) return true;
    return false;
}

/* A wall or the periodic cell moves. */
static bool frame_moves(const sx_model *m)
{
    for (int64_t i = 0; i < m->nwall; i++) {
        const sx_wall *w = &m->walls[i];
        if (w->servo_on || w->def.radial_vel != 0) return true;
        for (int k = 0; k < 3; k++)
            if (w->def.vel[k] != 0 || w->def.spin[k] != 0) return true;
    }
    return m->cell && m->cell->controlled;
}

/* The balls [lo, hi)'s unbalanced forces |F + m g| (free components),
 * added to *sum in order; a pebble is balanced with its clump
 * (sx__clumps_unbalanced). */
static void add_unbalanced(const sx_model *m, int64_t lo, int64_t hi, double *sum)
{
    const sx_balls *b = &m->balls;
    const int d = m->dim;
    for (int64_t i = lo; i < hi; i++) {
        if (b->clump && b->clump[i]) continue;
        double s2 = 0;
        for (int k = 0; k < d; k++) {
            if (b->fix[i] & (SX_FIX_VX << k)) continue; /* a fixed component is balanced by its fixity */
            const double f = b->f[i * d + k] + m->gravity[k] / b->inv_mass[i];
            s2 += f * f;
        }
        *sum += sqrt(s2);
    }
}

/* The ratio's sums: the unbalanced forces, the contact forces and their
 * count, and (a scattered model) the balls that move. */
enum { R_UNBALANCED, R_FORCES, R_CONTACTS, R_MOVING, R_SUMS };

/* Of a decomposed model left scattered by a lazy cycle, rank r's part of
 * the sums over its own balls and ball-ball pairs (current there), then
 * over its ball-wall pairs: sx__dd_chain adds the ranks' parts in rank
 * order, the serial order of every sum. */
static void ratio_balls_part(const sx_model *m, int r, double *acc)
{
    const sx_dd *d = m->dd;
    add_unbalanced(m, d->own[r].lo, d->own[r].hi, &acc[R_UNBALANCED]);
    acc[R_MOVING] += balls_move(m, d->own[r].lo, d->own[r].hi);
    sx__kernels(m)->each_contact(m, false, d->bb_own[r].lo, d->bb_own[r].hi, add_contact_force, acc + R_FORCES);
}

static void ratio_walls_part(const sx_model *m, int r, double *acc)
{
    const sx_dd *d = m->dd;
    sx__kernels(m)->each_contact(m, true, d->bw_own[r].lo, d->bw_own[r].hi, add_contact_force, acc + R_FORCES);
}

double sx_model_unbalanced_ratio(const sx_model *m)
{
    double acc[R_SUMS] = {0, 0, 0, 0};
    int64_t bodies = m->balls.n;
    const bool clumps = sx_clump_count(m) > 0;
    if (sx_model_scattered(m)) { /* the ranks' sums in a chain, each rank's own rows */
        /* the clumps after the balls, as serially: their resultants from
         * their owners to every rank (which refreshes the copies of other
         * ranks' clumps: the state is as it was), every rank adding all of
         * them in clump order */
        if (!sx__dd_chain(m, acc, R_SUMS, ratio_balls_part) || (clumps && !sx__dd_clumps((sx_model *)m))) return NAN;
        if (clumps) sx__clumps_unbalanced(m, &acc[R_UNBALANCED], &bodies);
        if (!sx__dd_chain(m, acc, R_SUMS, ratio_walls_part)) return NAN;
    } else {
        add_unbalanced(m, 0, m->balls.n, &acc[R_UNBALANCED]);
        if (clumps) sx__clumps_unbalanced(m, &acc[R_UNBALANCED], &bodies);
        sx_contact_each(m, add_contact_force, acc + R_FORCES);
    }
    if (bodies == 0) return 0;
    /* no contact force to compare with: settled only when nothing moves (a
     * cloud of balls a servo is closing on is not; issue: m:solve{ratio}
     * stopped at once there) */
    if (acc[R_CONTACTS] == 0 || acc[R_FORCES] == 0) {
        const bool moves = (sx_model_scattered(m) ? acc[R_MOVING] > 0 : balls_move(m, 0, m->balls.n)) || frame_moves(m);
        return acc[R_UNBALANCED] > 0 || moves ? INFINITY : 0;
    }
    return (acc[R_UNBALANCED] / (double)bodies) / (acc[R_FORCES] / acc[R_CONTACTS]);
}
