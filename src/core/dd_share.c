/* What moves between ranks (decompose.h): the exchange of entries and of
 * rows of per-entry arrays, a step's ghosts, the walls' block sums and the
 * clumps' pebbles, and the gather of the whole state at a cycle's end. */
#include "clumps.h"
#include "decompose.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

/* [0, count) for every rank: what a gather needs. */
const sx_span *sx__dd_everything(sx_dd *d, int64_t count)
{
    for (int r = 0; r < d->x.ranks; r++) d->all[r] = (sx_span){0, count};
    return d->all;
}

bool sx__dd_share(sx_dd *d, void *data, size_t size, const sx_span *own, const sx_span *need, int per)
{
    const int me = d->x.rank;
    int64_t in = 0; /* the entries this rank receives: its needs that others hold */
    for (int k = 0; k < per; k++)
        for (int r = 0; r < d->x.ranks; r++) {
            const sx_span want = need[me * per + k];
            const int64_t lo = want.lo > own[r].lo ? want.lo : own[r].lo, hi = want.hi < own[r].hi ? want.hi : own[r].hi;
            if (r != me && hi > lo) in += hi - lo;
        }
    *d->received += in * (int64_t)size;
    return d->x.share(d->x.ud, data, size, own, need, per);
}

/* (decompose.h, sx_rows) */
void sx__rows_add(sx_rows *f, void *field, size_t row)
{
    if (row) f->field[f->nf] = field, f->row[f->nf++] = row;
}

bool sx__dd_move_rows(sx_dd *d, const sx_rows *f, const int32_t *list, int64_t base, int64_t n, const sx_span *own,
                      const sx_span *need, int nper)
{
    size_t w = 0;
    for (int k = 0; k < f->nf; k++) w += f->row[k];
    if (!n || !w) return true;
    /* kept from call to call (a step's exchanges move rows of about the
     * same sizes every step): grown, not allocated anew each time; freed
     * at a cycle's end when a large move grew it (sx__dd_end) */
    if ((size_t)n * w > d->cap_rowbuf) {
        char *q = realloc(d->rowbuf, (size_t)n * w);
        if (!q) return false;
        d->rowbuf = q, d->cap_rowbuf = (size_t)n * w;
    }
    char *buf = d->rowbuf;
    const int me = d->x.rank;
    bool ok = true;
    for (int pass = 0; ok && pass < 1 + nper; pass++) { /* pack this rank's, then unpack each span it needs */
        const sx_span s = pass ? need[me * nper + pass - 1] : own[me];
        for (int64_t e = s.lo; e < s.hi; e++) {
            char *q = buf + (size_t)e * w;
            for (int k = 0; k < f->nf; k++) {
                char *v = (char *)f->field[k] + (size_t)(base + list[e]) * f->row[k];
                if (pass) memcpy(v, q, f->row[k]);
                else memcpy(q, v, f->row[k]);
                q += f->row[k];
            }
        }
        if (!pass) ok = sx__dd_share(d, buf, w, own, need, nper);
    }
    return ok;
}

/* (decompose.h) A counting sort on (source, destination). */
bool sx__dd_route(sx_dd *d, const sx_hop *hop, int64_t n, sx_route *rt)
{
    const int R = d->x.ranks;
    if (rt->cap < n) {
        int32_t *q = realloc(rt->item, (size_t)n * sizeof *q);
        if (!q) return false;
        rt->item = q, rt->cap = n;
    }
    sx_span *need = rt->need; /* need[t * R + s]: from s to t */
    for (int64_t k = 0; k < (int64_t)R * R; k++) need[k] = (sx_span){0, 0};
    for (int64_t e = 0; e < n; e++) need[(int64_t)hop[e].to * R + hop[e].from].hi++;
    int64_t at = 0;
    for (int s = 0; s < R; s++) {
        rt->own[s].lo = at;
        for (int t = 0; t < R; t++) {
            sx_span *e = &need[(int64_t)t * R + s];
            const int64_t len = e->hi;
            *e = (sx_span){at, at}; /* hi: the span's next entry, then its end */
            at += len;
        }
        rt->own[s].hi = at;
    }
    for (int64_t e = 0; e < n; e++) rt->item[need[(int64_t)hop[e].to * R + hop[e].from].hi++] = hop[e].item;
    rt->n = n;
    return true;
}

/* An all-gather: entry r of data (size bytes each), rank r's, to every
 * rank. */
bool sx__dd_share_by_rank(sx_dd *d, void *data, size_t size)
{
    return sx__dd_share(d, data, size, d->by_rank, sx__dd_everything(d, d->x.ranks), 1);
}

/* (model_internal.h) */
const uint64_t *sx__dd_words(const sx_model *m, const uint64_t *v, int n)
{
    sx_dd *d = m->dd;
    assert(n <= SX_DD_SUM_MAX);
    uint64_t *all = d->sums; /* kept from the decomposition: nothing to allocate, nothing to fail alone */
    memcpy(all + (size_t)d->x.rank * (size_t)n, v, (size_t)n * sizeof *v);
    return sx__dd_share_by_rank(d, all, (size_t)n * sizeof *all) ? all : NULL;
}

/* (model_internal.h) */
bool sx__dd_all_ok(const sx_model *m, bool ok)
{
    uint64_t failed = !ok;
    return sx__dd_sum(m, &failed, 1) && !failed;
}

/* (model_internal.h) An all-gather of the ranks' values, each rank adding
 * them alike (integers: in any order). */
bool sx__dd_sum(const sx_model *m, uint64_t *v, int n)
{
    const uint64_t *all = sx__dd_words(m, v, n);
    for (int k = 0; all && k < n; k++) {
        v[k] = 0;
        for (int r = 0; r < m->dd->x.ranks; r++) v[k] += all[(size_t)r * (size_t)n + (size_t)k];
    }
    return all != NULL;
}

bool sx__dd_halo(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_balls *B = &m->balls;
    const size_t v = (size_t)m->dim * sizeof(double), w = (size_t)m->rdim * sizeof(double);
    return sx__dd_share(d, B->x, v, d->own, d->need, SX_DD_NEED) && sx__dd_share(d, B->v, v, d->own, d->need, SX_DD_NEED) &&
           sx__dd_share(d, B->w, w, d->own, d->need, SX_DD_NEED);
}

/* (model_internal.h) */
bool sx__dd_refresh(sx_model *m) { return sx__dd_halo(m) && (!m->clumps || sx__dd_clumps(m)); }

bool sx__dd_fetch_ball(sx_model *m, int64_t i)
{
    sx_dd *d = m->dd;
    const sx_rows f = sx__dd_ball_motion(m, true);
    if (i < 0) { /* every ball's, field by field from the owners' slabs */
        const int64_t n = d->own[d->x.ranks - 1].hi; /* the balls the slabs cover (not a periodic cell's ghost slots) */
        for (int k = 0; k < f.nf; k++)
            if (!sx__dd_share(d, f.field[k], f.row[k], d->own, sx__dd_everything(d, n), 1)) return false;
        return true;
    }
    const int32_t list[1] = {(int32_t)i};
    for (int r = 0; r < d->x.ranks; r++) d->scratch[r] = (sx_span){0, i >= d->own[r].lo && i < d->own[r].hi};
    return sx__dd_move_rows(d, &f, list, 0, 1, d->scratch, sx__dd_everything(d, 1), 1);
}

static bool gather_pairs(sx_model *m, sx_pairs *p, const sx_span *own)
{
    sx_dd *d = m->dd;
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    for (int k = 0; k < nf; k++) /* the ends come from the build, the same on every rank */
        if (!f[k].end && !sx__dd_share(d, *f[k].data, sx__pair_size(&f[k]) * (size_t)f[k].per, own, sx__dd_everything(d, p->n), 1))
            return false;
    return true;
}

/* The bonds' state the step changes (kind; unless kinds_only fn, mn, fs,
 * ms) of the slots list[e], e < n, each rank's entries own[r], to every
 * rank. */
sx_rows sx__dd_bond_rows(const sx_model *m, bool kinds_only)
{
    const sx_bonds *b = &m->bonds;
    const size_t v = sizeof(double), D = (size_t)m->dim * v, RD = (size_t)m->rdim * v;
    sx_rows f = {.nf = 0};
    sx__rows_add(&f, b->kind, sizeof *b->kind);
    if (!kinds_only) sx__rows_add(&f, b->fn, v), sx__rows_add(&f, b->mn, v), sx__rows_add(&f, b->fs, D), sx__rows_add(&f, b->ms, RD);
    return f;
}

bool sx__dd_share_bonds(sx_model *m, const int32_t *list, int64_t n, const sx_span *own, bool kinds_only)
{
    const sx_rows f = sx__dd_bond_rows(m, kinds_only);
    return sx__dd_move_rows(m->dd, &f, list, 0, n, own, sx__dd_everything(m->dd, n), 1);
}

/* Each rank took off the intact count the bonds it saw break, its ghost
 * pairs' included: counted again once the kinds are shared. */
void sx__dd_count_intact(sx_model *m)
{
    sx_bonds *b = &m->bonds;
    b->intact = 0;
    for (int64_t s = 0; s < b->n; s++) b->intact += b->kind[s] != 0;
}

/* Every bond of the plan from the owner of its pair's first ball. */
static bool gather_bonds(sx_model *m)
{
    const sx_dd *d = m->dd;
    const bool ok = sx__dd_share_bonds(m, d->bslot, d->nbslot, d->bs_own, false);
    sx__dd_count_intact(m);
    return ok;
}

/* The flat joints' state the step changes beyond the bond's (laws/
 * flatjoint.h): the face's bend rotation and (3D) its carried axis, and
 * each element's state, normal force and shear force; each joint from the
 * owner of its pair, as gather_bonds takes the bond. The joints of the
 * plan's bonded pairs (bslot: every slot with elements, a joint broken in
 * this cycle included; a slot a smooth joint took keeps its elements
 * unchanged, and the owner's copy is everyone's) are packed as doubles in
 * plan order, each rank's a contiguous run (a state is a small integer:
 * exact); a rank unpacks the entries of its need spans (nper of them). */
bool sx__dd_share_fjoints(sx_model *m, const int32_t *slot, int64_t nb, const sx_span *own, const sx_span *need, int nper)
{
    sx_dd *d = m->dd;
    sx_bonds *b = &m->bonds;
    sx_fjels *E = &m->fjel;
    const int D = m->dim, T = D - 1, face = T + (D == 3 ? 3 : 0), el = 2 + T;
    int64_t *at = malloc((size_t)(nb + 1) * sizeof *at); /* entry e's first double */
    if (!at) return false;
    at[0] = 0;
    for (int64_t e = 0; e < nb; e++) {
        const int32_t s = slot[e];
        const int nel = b->fj_nr[s] * b->fj_na[s];
        at[e + 1] = at[e] + (nel ? face + nel * el : 0);
    }
    const int64_t total = at[nb];
    const int R = d->x.ranks, me = d->x.rank;
    double *buf = total ? malloc((size_t)total * sizeof *buf) : NULL;
    sx_span *dneed = malloc((size_t)R * (size_t)nper * sizeof *dneed); /* need, in doubles */
    bool ok = (!total || buf) && dneed;
    for (int r = 0; ok && r < R; r++) d->scratch[r] = (sx_span){at[own[r].lo], at[own[r].hi]};
    for (int64_t k = 0; ok && k < (int64_t)R * nper; k++) dneed[k] = (sx_span){at[need[k].lo], at[need[k].hi]};
    for (int pass = 0; ok && total && pass < 1 + nper; pass++) { /* pack this rank's, then unpack each span it needs */
        const sx_span span = pass ? need[me * nper + pass - 1] : own[me];
        for (int64_t e = span.lo; e < span.hi; e++) {
            const int32_t s = slot[e];
            const int nel = b->fj_nr[s] * b->fj_na[s];
            if (!nel) continue;
            double *q = buf + at[e], *rot = b->fj_rot + s * T, *axis = D == 3 ? b->fj_axis + s * 3 : NULL;
            if (pass) {
                memcpy(rot, q, (size_t)T * sizeof *q);
                if (axis) memcpy(axis, q + T, 3 * sizeof *q);
            } else {
                memcpy(q, rot, (size_t)T * sizeof *q);
                if (axis) memcpy(q + T, axis, 3 * sizeof *q);
            }
            q += face;
            for (int64_t x = b->fj_first[s]; x < b->fj_first[s] + nel; x++, q += el) {
                if (pass) {
                    E->state[x] = (uint8_t)q[0], E->fn[x] = q[1];
                    memcpy(E->fs + x * T, q + 2, (size_t)T * sizeof *q);
                } else {
                    q[0] = E->state[x], q[1] = E->fn[x];
                    memcpy(q + 2, E->fs + x * T, (size_t)T * sizeof *q);
                }
            }
        }
        if (!pass) ok = sx__dd_share(d, buf, sizeof *buf, d->scratch, dneed, nper);
    }
    free(dneed);
    free(buf);
    free(at);
    return ok;
}

static bool gather_fjoints(sx_model *m)
{
    sx_dd *d = m->dd;
    return sx__dd_share_fjoints(m, d->bslot, d->nbslot, d->bs_own, sx__dd_everything(d, d->nbslot), 1);
}

/* A list made in parts, one a rank, joined in rank order on every rank (a
 * decomposed build's pairs, a gather's cracks): the ranks' counts are
 * shared, d->scratch becomes each rank's part of the whole, and *total its
 * length; sx__dd_join then gives every rank every part. */
bool sx__dd_parts(sx_model *m, int64_t count, sx_span *mine, int64_t *total)
{
    sx_dd *d = m->dd;
    const uint64_t word = (uint64_t)count;
    const uint64_t *counts = sx__dd_words(m, &word, 1);
    int64_t sum = 0;
    for (int r = 0; counts && r < d->x.ranks; r++) {
        d->scratch[r] = (sx_span){sum, sum + (int64_t)counts[r]};
        sum += (int64_t)counts[r];
    }
    *mine = d->scratch[d->x.rank];
    *total = sum;
    return counts != NULL;
}

bool sx__dd_join(sx_model *m, void *data, size_t size, int64_t total)
{
    sx_dd *d = m->dd;
    return !total || sx__dd_share(d, data, size, d->scratch, sx__dd_everything(d, total), 1);
}

/* The cracks logged since the last gather, made one log in the serial
 * order. Every rank evaluates its own pairs and some of its neighbours'
 * (from a ghost to its balls): it keeps the cracks of its own pairs (a pair is
 * its first ball's), which, the pairs being sorted by that ball, are the
 * serial log's of its pair range. A step's cracks are thus rank 0's, then
 * rank 1's, ...; the ranks' lists are merged by step in that order. */
bool sx__dd_gather_cracks(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_cracks *k = &m->cracks;
    const int R = d->x.ranks;
    const sx_span own = d->own[d->x.rank];
    int64_t kept = d->crack0;
    for (int64_t e = d->crack0; e < k->n; e++) {
        const int64_t a = sx__ball_index(m, k->ev[e].a);
        if (a >= own.lo && a < own.hi) k->ev[kept++] = k->ev[e];
    }
    sx_span mine;
    int64_t total = 0;
    bool ok = sx__dd_parts(m, kept - d->crack0, &mine, &total);
    sx_crack *all = ok && total ? malloc((size_t)total * sizeof *all) : NULL;
    ok = ok && sx__dd_all_ok(m, !total || all); /* (a rank without the buffer would miss the join) */
    if (ok && total) {
        if (mine.hi > mine.lo) memcpy(all + mine.lo, k->ev + d->crack0, (size_t)(mine.hi - mine.lo) * sizeof *all);
        ok = sx__dd_join(m, all, sizeof *all, total);
    }
    sx_span *next = d->scratch; /* each rank's part, its first entry not yet merged */
    k->n = d->crack0;
    for (;;) {
        int pick = -1;
        for (int r = 0; ok && r < R; r++) /* the earliest step; on a tie the lower rank */
            if (next[r].lo < next[r].hi && (pick < 0 || all[next[r].lo].step < all[next[pick].lo].step)) pick = r;
        if (pick < 0) break;
        ok = sx__crack_log(m, &all[next[pick].lo++]);
    }
    d->crack0 = k->n;
    free(all);
    return ok;
}

/* A ball's state the step changes: its velocity, spin, force and moment,
 * and (with_position) its position. */
sx_rows sx__dd_ball_motion(const sx_model *m, bool with_position)
{
    const sx_balls *B = &m->balls;
    const size_t D = (size_t)m->dim * sizeof(double), RD = (size_t)m->rdim * sizeof(double);
    sx_rows f = {.nf = 0};
    if (with_position) sx__rows_add(&f, B->x, D);
    sx__rows_add(&f, B->v, D), sx__rows_add(&f, B->f, D), sx__rows_add(&f, B->w, RD), sx__rows_add(&f, B->t, RD);
    return f;
}

/* Periodic space: every ghost's slot (position, velocity, spin, force,
 * moment) from the rank of its owner, in the plan's order. */
static bool gather_ghosts(sx_model *m)
{
    sx_dd *d = m->dd;
    const sx_rows f = sx__dd_ball_motion(m, true);
    return sx__dd_move_rows(d, &f, d->gho, m->cell->base, d->ngho, d->gho_own, sx__dd_everything(d, d->ngho), 1);
}

/* The clumps' state (centroid, velocity, spin, orientation, angular
 * momentum, the last resultants) from their owners to every rank. */
bool sx__dd_clumps(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_clumps *C = m->clumps;
    const size_t D = (size_t)m->dim * sizeof(double), RD = (size_t)m->rdim * sizeof(double);
    sx_rows f = {.nf = 0};
    sx__rows_add(&f, C->x, D), sx__rows_add(&f, C->v, D), sx__rows_add(&f, C->w, RD), sx__rows_add(&f, C->f, D), sx__rows_add(&f, C->t, RD);
    sx__rows_add(&f, C->q, (m->dim == 3 ? 4 : 1) * sizeof(double)), sx__rows_add(&f, C->L, m->dim == 3 ? 3 * sizeof(double) : 0);
    return sx__dd_move_rows(d, &f, d->cl, 0, d->ncl, d->cl_own, sx__dd_everything(d, d->ncl), 1);
}

/* A rank's computing time is trusted as a sample of its pace once every
 * rank has computed this long since its last sample (a short cycle's
 * clock is mostly noise). */
#define PACE_MIN_S 0.05

/* The ranks' paces, shared with every gather (a build, a cycle's end: one
 * exchange of two doubles a rank more): each rank's computing seconds
 * since its last sample and their ratio to its planned work; once every
 * rank has computed PACE_MIN_S,
 * every rank folds the samples into the paces alike (half the old pace,
 * half the new), and the next plan's cut follows them. So the load is
 * balanced again when it drifts from the cut's work model: a pair's cost
 * varies with the scene and with where its balls lie in memory, and a
 * rank whose core another process shares runs slower. The cut changes no
 * bit. */
bool sx__dd_share_pace(sx_model *m)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    double *s = d->sample;
    s[2 * me] = d->busy;
    s[2 * me + 1] = d->busy_work > 0 ? d->busy / d->busy_work : 0;
    if (!sx__dd_share_by_rank(d, s, 2 * sizeof *s)) return false;
    for (int r = 0; r < R; r++)
        if (!(s[2 * r] >= PACE_MIN_S && s[2 * r + 1] > 0)) return true; /* measuring on */
    for (int r = 0; r < R; r++) d->pace[r] = d->pace[r] > 0 ? 0.5 * (d->pace[r] + s[2 * r + 1]) : s[2 * r + 1];
    d->busy = d->busy_work = 0;
    return true;
}

bool sx__dd_gather(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_balls *B = &m->balls;
    const size_t v = (size_t)m->dim * sizeof(double), w = (size_t)m->rdim * sizeof(double);
    m->prof.gathers++;
    if (!sx__dd_share_pace(m)) return false;
    const sx_span *all = sx__dd_everything(d, B->n);
    return sx__dd_share(d, B->x, v, d->own, all, 1) && sx__dd_share(d, B->v, v, d->own, all, 1) &&
           sx__dd_share(d, B->w, w, d->own, all, 1) && sx__dd_share(d, B->f, v, d->own, all, 1) &&
           sx__dd_share(d, B->t, w, d->own, all, 1) && gather_pairs(m, &m->bb, d->bb_own) &&
           gather_pairs(m, &m->bw, d->bw_own) && (!m->bonds.n || (gather_bonds(m) && sx__dd_gather_cracks(m))) &&
           (!m->fjel.n || gather_fjoints(m)) &&
           (!m->cell || !m->cell->n || gather_ghosts(m)) && (!m->clumps || !m->clumps->n || sx__dd_clumps(m));
}

/* Only a servo and energy tracking read the walls' resultants inside a
 * step (sx__walls_read_in_step): without them the step leaves its blocks'
 * sums where they are and the cycle's end makes the last step's
 * resultants, one exchange a cycle instead of one a step. */
bool sx__dd_walls(sx_model *m, bool in_step)
{
    sx_dd *d = m->dd;
    /* inside a step (a servo's, energy tracking's) the rank waits here for
     * the others, within the time its pace counts as computing (share_pace) */
    const double t0 = in_step ? sx__now() : 0;
    if (m->nwall &&
        !sx__dd_share(d, m->wall_acc, (size_t)m->nwall * sizeof *m->wall_acc, d->wblk, sx__dd_everything(d, m->nblock), 1))
        return false;
    if (in_step) d->busy -= sx__now() - t0;
    sx__walls_sum(m);
    d->walls_stale = false;
    return true;
}

/* The pebbles whose owner is not their clump's, from their owners to
 * their clumps' owners: with sums NULL their forces and moments (before
 * the clumps' step), else the timestep's four sums (kt, kr, ct, cr: n
 * each, from sums). */
bool sx__dd_pebbles(sx_model *m, double *sums, int64_t n)
{
    sx_dd *d = m->dd;
    sx_balls *B = &m->balls;
    const size_t v = sizeof(double);
    sx_rows f = {.nf = 0};
    if (sums)
        for (int k = 0; k < 4; k++) sx__rows_add(&f, sums + k * n, v);
    else
        sx__rows_add(&f, B->f, (size_t)m->dim * v), sx__rows_add(&f, B->t, (size_t)m->rdim * v);
    return sx__dd_move_rows(d, &f, d->fwd.item, 0, d->fwd.n, d->fwd.own, d->fwd.need, d->x.ranks);
}

/* The pebbles the clumps' owners placed (position, velocity, spin), to
 * the pebbles' owners, whose ghosts' ranks then take them as any ball's
 * (sx__dd_halo). */
bool sx__dd_placed(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_balls *B = &m->balls;
    const size_t v = sizeof(double);
    sx_rows f = {.nf = 0};
    sx__rows_add(&f, B->x, (size_t)m->dim * v), sx__rows_add(&f, B->v, (size_t)m->dim * v), sx__rows_add(&f, B->w, (size_t)m->rdim * v);
    return sx__dd_move_rows(d, &f, d->back.item, 0, d->back.n, d->back.own, d->back.need, d->x.ranks);
}
