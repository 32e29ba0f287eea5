/* Domain decomposition over ranks (issue 16), with results bit-identical
 * to a serial run for any number of ranks; docs/developer.md, "MPI domain
 * decomposition", has the design and what is left. This file makes the
 * plan and the cut and starts and ends a cycle; its parts beside it
 * (decompose.h) move the state (dd_share.c), build and migrate inside a
 * cycle (dd_migrate.c), agree on a step's stop (dd_agree.c) and sum the
 * energies in the serial order (dd_energy.c).
 *
 * The core makes no MPI call: the caller's sx_exchange moves bytes. Between
 * cycles every rank holds the whole model, the same on all ranks (checked
 * by a digest of its bytes when a cycle starts, sx__state_digest), or,
 * lazily, its own balls current and the rest as the last gather left them
 * (scattered: the next cycle goes on from there, sx__dd_agree_replicated).
 * Inside a cycle rank r owns the balls
 * own[r], a contiguous range of dense indices: the broad phase sorts balls
 * by cell with the grid's last axis slowest (the model's last, or one with
 * at least twice its cells), so a range is a slab across that axis, cut to
 * balance the ranks' work (and cut again at every build, which
 * is where balls migrate). Each step it
 *   - refreshes its ghosts, the balls need[4r] below and need[4r + 1]
 *     above its own (and the far ends of a periodic cell), from their
 *     owners (positions, velocities, spins);
 *   - evaluates the ball-ball pairs pairs[r]: every pair of its balls, in
 *     the serial chunks, clipped (a ball's contributions thus arrive in the
 *     serial order, whatever the cut), skipping those between two ghosts
 *     (inpair: they add only to ghosts);
 *   - evaluates whole the wall blocks with a ball of its own, wrun[r]
 *     (their other balls are ghosts), so each block's partial wall
 *     resultant is the serial one; the blocks whose last ball it owns,
 *     wblk[r], are its to share, and every rank adds all blocks' sums in
 *     block order;
 *   - integrates its own balls, and takes the largest displacement of all
 *     ranks (a maximum, exact in any order) for the rebuild criterion;
 *   - with energy tracking, chains the step's energy sums (a chunk's or a
 *     block's, begun on one rank, may go on over the next: each rank keeps
 *     the terms of such a sum on a tape and adds them onto the sum the
 *     lower ranks pass it), and every rank adds them in the serial order.
 * The energy guard sums its energy in chains over the ranks' own balls and
 * pairs (sx__dd_chain), in the serial order. The end of the cycle
 * gathers the whole state on every rank (each ball from its owner, each
 * pair from the owner of its first ball, each bond, and a flat joint's
 * face and elements, from the owner of its pair, and the ranks' cracks
 * merged in the serial order). A build inside the cycle is the serial one,
 * on every rank, from what it reads alone (the positions, the pairs'
 * contact flags and bond links, the bonds' kinds, the clumps' state:
 * sx__dd_build); after its plan the balls, pairs and bonds the new cut
 * gives another rank move to it (sx__dd_migrate), and the rest stays
 * where it was stepped. A smooth joint's state is its pair's and its bond's; a
 * mesh wall is a wall (its rows of a ball lie in the ball's block), moved
 * and turned alike by every rank. Clumps: each is stepped by its owner
 * (the owner of its pebble nearest its centroid), the pebbles of other
 * ranks routed to it and back, point to point (plan_clumps). Periodic
 * space: a ghost's force is folded onto its owner after the pass, so the
 * owner's rank also evaluates the ghost's pairs that lie outside pairs[r]
 * (xpair), keeping current the far end of the cell they reach; the cell's
 * stress (its servo) is summed over the ranks in a chain, in pair order. */
#include "clumps.h"
#include "decompose.h"
#include "state.h"

#include <stdlib.h>
#include <string.h>

void sx__dd_free(sx_model *m)
{
    sx_dd *d = m->dd;
    if (!d) return;
    free(d->own);
    free(d->bslot);
    free(d->cown);
    free(d->cl);
    free(d->cl_at);
    free(d->cterm);
    free(d->fwd.item);
    free(d->back.item);
    free(d->fwd.need);
    free(d->xpair);
    free(d->inpair);
    free(d->gho);
    free(d->low_a);
    free(d->cross);
    free(d->work);
    free(d->pace);
    free(d->sums);
    free(d->rowbuf);
    free(d->xchunk.cracks);
    free(d->tape.e);
    free(d->was);
    free(d->slot_was);
    free(d->src_bb);
    free(d->src_bw);
    free(d);
    m->dd = NULL;
}

sx_status sx_model_decompose(sx_model *m, const sx_exchange *x)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "decompose: the model is stepping");
    sx_status st = sx_model_gather(m); /* the ranks' own parts, before the plan that names them goes */
    if (st) return st;
    sx__dd_free(m);
    if (!x || x->ranks <= 1) return SX_OK;
    if (!x->share || !x->max || !x->agree || x->rank < 0 || x->rank >= x->ranks)
        return sx__fail(m, SX_EINVAL, "decompose: an exchange needs share, max, agree and a rank below its ranks");
    sx_dd *d = calloc(1, sizeof *d);
    const size_t r = (size_t)x->ranks;
    /* own, need (SX_DD_NEED per rank), pairs, wblk, wrun, bb_own, bw_own, all, bs_own, scratch, cl_own,
     * gho_own, fwd.own, back.own, bb_was, bw_was, by_rank; and the routes' needs and the clumps' energy's (r per rank) */
    enum { SPANS = 16 + SX_DD_NEED };
    sx_span *s = d ? calloc(SPANS * r, sizeof *s) : NULL, *routes = s ? calloc(3 * r * r, sizeof *routes) : NULL;
    double *pace = routes ? calloc(5 * r, sizeof *pace) : NULL; /* pace (r), sample (2 r), stopping (2 r) */
    uint64_t *sums = pace ? calloc(SX_DD_SUM_MAX * r, sizeof *sums) : NULL;
    if (!sums) {
        free(pace);
        free(routes);
        free(s);
        free(d);
        return sx__fail(m, SX_ENOMEM, "decompose: out of memory");
    }
    d->x = *x;
    d->own = s, d->need = s + r;
    s += (1 + SX_DD_NEED) * r;
    d->pairs = s, d->wblk = s + r, d->wrun = s + 2 * r, d->bb_own = s + 3 * r, d->bw_own = s + 4 * r;
    d->all = s + 5 * r, d->bs_own = s + 6 * r, d->scratch = s + 7 * r, d->cl_own = s + 8 * r;
    d->gho_own = s + 9 * r, d->fwd.own = s + 10 * r, d->back.own = s + 11 * r;
    d->bb_was = s + 12 * r, d->bw_was = s + 13 * r, d->by_rank = s + 14 * r;
    for (int k = 0; k < x->ranks; k++) d->by_rank[k] = (sx_span){k, k + 1};
    d->fwd.need = routes, d->back.need = routes + r * r, d->cterm_need = routes + 2 * r * r;
    d->pace = pace, d->sample = pace + r, d->stopping = pace + 3 * r;
    d->sums = sums;
    d->received = &m->prof.received;
    m->dd = d;
    return SX_OK;
}

int sx_model_ranks(const sx_model *m) { return m->dd ? m->dd->x.ranks : 1; }

/* The rank owning ball i (own[] cut as in sx__dd_plan). */
int sx__dd_owner_of(const sx_dd *d, int64_t i, int64_t n)
{
    const int R = d->x.ranks;
    int r = n ? (int)((i * R) / n) : 0;
    if (r >= R) r = R - 1;
    while (r + 1 < R && d->own[r + 1].lo <= i) r++;
    while (r > 0 && d->own[r].lo > i) r--;
    return r;
}

/* Lists, rank by rank, the entries pick(m, k) >= 0 of the k in range[r]
 * (at most `most` of them): each rank's a contiguous run, spans[r]. */
static bool plan_list(sx_model *m, const sx_span *range, int64_t most, int32_t (*pick)(const sx_model *, int64_t),
                      int32_t **list, int64_t *n, int64_t *cap, sx_span *spans)
{
    *n = 0;
    if (*cap < most) {
        int32_t *q = realloc(*list, (size_t)most * sizeof *q);
        if (!q) return false;
        *list = q, *cap = most;
    }
    for (int r = 0; r < m->dd->x.ranks; r++) {
        spans[r].lo = *n;
        for (int64_t k = range[r].lo; k < range[r].hi; k++) {
            const int32_t v = pick(m, k);
            if (v >= 0) (*list)[(*n)++] = v;
        }
        spans[r].hi = *n;
    }
    return true;
}

static int32_t bond_slot(const sx_model *m, int64_t c) { return m->bb.bond[c] - 1; }

/* Clump c's pebble k: its dense index. */
static int64_t pebble_of(const sx_model *m, int64_t c, int64_t k)
{
    return m->balls.index_of[m->clumps->pebble[m->clumps->first[c] + k]];
}

static int64_t pebbles(const sx_model *m, int64_t c) { return m->clumps->tpl[m->clumps->tpl_of[c]].n; }

/* The route of the pebbles whose owner is not their clump's: from their
 * owners to their clumps' owners, or (back) the other way, each (source,
 * destination) in clump order then pebble order (sx__dd_route); every
 * rank plans every rank's alike. False: out of memory. */
static bool plan_route(sx_model *m, sx_route *rt, bool back)
{
    sx_dd *d = m->dd;
    const sx_clumps *C = m->clumps;
    const int64_t n = m->balls.n;
    int64_t k = 0;
    sx_hop *hop = NULL;
    for (int pass = 0; pass < 2; pass++) { /* count, then list */
        if (pass && !(hop = malloc((size_t)(k + 1) * sizeof *hop))) return false;
        k = 0;
        for (int64_t c = 0; c < C->n; c++)
            for (int64_t j = 0; j < pebbles(m, c); j++) {
                const int64_t i = pebble_of(m, c, j);
                const int po = sx__dd_owner_of(d, i, n), co = d->cown[c];
                if (po == co) continue;
                if (pass) hop[k] = (sx_hop){(int32_t)i, back ? co : po, back ? po : co};
                k++;
            }
    }
    const bool ok = sx__dd_route(d, hop, k, rt);
    free(hop);
    return ok;
}

/* Clumps: each is stepped by one rank, its owner: the owner of its pebble
 * nearest its centroid (the first on a tie). Its centroid lies in that
 * pebble's slab or next to it (the slabs are runs of the cell order, not
 * planes, so the pebble's owner is what places it), and the rank steps
 * the pebble itself: the fewest pebbles cross. The clumps by owner (cl,
 * each rank's a run cl_own in clump order; cl_at: a clump's entry), then
 * the pebbles' routes. False: out of memory. */
static bool plan_clumps(sx_model *m)
{
    sx_dd *d = m->dd;
    const sx_clumps *C = m->clumps;
    const sx_balls *B = &m->balls;
    const int R = d->x.ranks, D = m->dim;
    if (d->cap_cl < C->n) {
        int32_t *own = realloc(d->cown, (size_t)C->n * sizeof *own);
        if (own) d->cown = own;
        int32_t *cl = realloc(d->cl, (size_t)C->n * sizeof *cl);
        if (cl) d->cl = cl;
        int32_t *at = realloc(d->cl_at, (size_t)C->n * sizeof *at);
        if (at) d->cl_at = at;
        if (!own || !cl || !at) return false;
        d->cap_cl = C->n;
    }
    for (int64_t c = 0; c < C->n; c++) {
        int64_t best = pebble_of(m, c, 0);
        double near = INFINITY;
        for (int64_t k = 0; k < pebbles(m, c); k++) {
            const int64_t i = pebble_of(m, c, k);
            double d2 = 0;
            for (int j = 0; j < D; j++) d2 += (B->x[i * D + j] - C->x[c * D + j]) * (B->x[i * D + j] - C->x[c * D + j]);
            if (d2 < near) near = d2, best = i;
        }
        d->cown[c] = (int32_t)sx__dd_owner_of(d, best, B->n);
    }
    d->ncl = 0;
    for (int r = 0; r < R; r++) {
        d->cl_own[r].lo = d->ncl;
        for (int64_t c = 0; c < C->n; c++)
            if (d->cown[c] == r) d->cl_at[c] = (int32_t)d->ncl, d->cl[d->ncl++] = (int32_t)c;
        d->cl_own[r].hi = d->ncl;
    }
    return plan_route(m, &d->fwd, false) && plan_route(m, &d->back, true);
}

/* The bond slots of the bonded pairs in pair order, each rank's own
 * pairs' a contiguous run (bs_own): what a gather takes from each owner
 * (a pair keeps its slot until the next plan, broken or not); and the
 * clumps' owners and routes (plan_clumps). */
static bool plan_lists(sx_model *m)
{
    sx_dd *d = m->dd;
    d->nbslot = d->ncl = d->fwd.n = d->back.n = 0;
    for (int r = 0; r < d->x.ranks; r++) d->bs_own[r] = d->cl_own[r] = d->fwd.own[r] = d->back.own[r] = (sx_span){0, 0};
    memset(d->fwd.need, 0, 2 * (size_t)d->x.ranks * (size_t)d->x.ranks * sizeof *d->fwd.need);
    return (!m->bb.bond ||
            plan_list(m, d->bb_own, m->bb.n, bond_slot, &d->bslot, &d->nbslot, &d->cap_bslot, d->bs_own)) &&
           (!m->clumps || !m->clumps->n || plan_clumps(m));
}

/* Widens rank r's ghosts to ball e: in its near spans already, or in the
 * far span on e's side. */
static void reach(sx_dd *d, int r, int64_t e)
{
    const sx_span own = d->own[r];
    sx_span *s = d->need + SX_DD_NEED * r;
    if ((e >= own.lo && e < own.hi) || (e < own.lo && e >= s[0].lo) || (e >= own.hi && e < s[1].hi)) return;
    sx_span *f = e < own.lo ? &s[2] : &s[3];
    if (f->hi == f->lo) *f = (sx_span){e, e + 1};
    if (e < f->lo) f->lo = e;
    if (e + 1 > f->hi) f->hi = e + 1;
}

/* Periodic space: the ghosts by their owner's rank, whose copies (the
 * state the last pass left in them: the owner's, shifted, and the force
 * folded onto it) are the serial run's; a ghost whose owner was removed
 * is no rank's. False: out of memory. */
static bool plan_ghosts(sx_model *m)
{
    sx_dd *d = m->dd;
    const sx_cell *cell = m->cell;
    const int R = d->x.ranks;
    d->ngho = 0;
    if (d->cap_gho < cell->n) {
        int32_t *q = realloc(d->gho, (size_t)cell->n * sizeof *q);
        if (!q) return false;
        d->gho = q, d->cap_gho = cell->n;
    }
    for (int r = 0; r < R; r++) {
        d->gho_own[r].lo = d->ngho;
        for (int64_t g = 0; g < cell->n; g++) {
            const int64_t o = cell->owner[g];
            if (o >= d->own[r].lo && o < d->own[r].hi) d->gho[d->ngho++] = (int32_t)g;
        }
        d->gho_own[r].hi = d->ngho;
    }
    return true;
}

/* Periodic space: a ghost's force is added to its owner after the pass
 * (kernels/ghosts.c, fold_ghosts), so the rank of a ball evaluates every
 * pair whose b is an image of it: those outside its pairs[] are its xpair.
 * Each rank keeps current, besides its near ghosts, the balls imaged by
 * the ghosts of its pairs and the first balls of its xpair: the far ends
 * of the cell (need[4r + 2] below its balls, need[4r + 3] above them;
 * merged into the near spans when they meet). False: out of memory. */
static bool plan_far(sx_model *m)
{
    sx_dd *d = m->dd;
    const sx_pairs *p = &m->bb;
    const sx_cell *cell = m->cell;
    const int R = d->x.ranks, me = d->x.rank;
    const int64_t n = m->balls.n;
    for (int r = 0; r < R; r++)
        for (int64_t c = d->pairs[r].lo; c < d->pairs[r].hi; c++)
            if (p->b[c] >= n && cell->owner[p->b[c] - cell->base] >= 0) reach(d, r, cell->owner[p->b[c] - cell->base]);
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t o = p->b[c] >= n ? cell->owner[p->b[c] - cell->base] : -1;
        if (o < 0) continue;
        const int r = sx__dd_owner_of(d, o, n);
        if (c >= d->pairs[r].lo && c < d->pairs[r].hi) continue;
        reach(d, r, p->a[c]);
        if (r != me) continue;
        if (d->nxpair == d->cap_xpair) {
            const int64_t cap = d->cap_xpair ? 2 * d->cap_xpair : 64;
            int32_t *q = realloc(d->xpair, (size_t)cap * sizeof *q);
            if (!q) return false;
            d->xpair = q, d->cap_xpair = cap;
        }
        d->xpair[d->nxpair++] = (int32_t)c;
        d->nxlow += c < d->pairs[me].lo;
    }
    for (int r = 0; r < R; r++) {
        sx_span *s = d->need + SX_DD_NEED * r;
        if (s[2].hi > s[2].lo && s[2].hi >= s[0].lo) s[0].lo = s[2].lo, s[2] = (sx_span){0, 0};
        if (s[3].hi > s[3].lo && s[3].lo <= s[1].hi) s[1].hi = s[3].hi, s[3] = (sx_span){0, 0};
    }
    return plan_ghosts(m);
}

/* The pairs of this rank's pairs[] below its own (their a a ghost) that
 * reach its balls: b one of its own or, in periodic space, an image of
 * one (whose force folds onto it), in pair order (inpair). The others lie
 * between two ghosts and add only to ghosts, whose sums are their owners':
 * the rank skips them (kernels/pair_contacts.c, timestep.c). Nothing else
 * needs them on this rank: a gather takes their history, bonds, joints and
 * cracks from their owner (the rank of their a), their energy terms are
 * no sum's here (a chunk's sums begin on the rank of its first pair, and
 * a rank's tape starts at its own pairs, tape_at), and the chained sums
 * (the energy guard's, the cell's stress) run over each rank's own pairs.
 * False: out of memory. */
static bool plan_inpairs(sx_model *m)
{
    sx_dd *d = m->dd;
    const sx_pairs *p = &m->bb;
    const sx_span own = d->own[d->x.rank];
    const int64_t c0 = d->pairs[d->x.rank].lo, c1 = d->bb_own[d->x.rank].lo, n = m->balls.n;
    d->ninpair = 0;
    if (d->cap_inpair < c1 - c0) {
        int32_t *q = realloc(d->inpair, (size_t)(c1 - c0) * sizeof *q);
        if (!q) return false;
        d->inpair = q, d->cap_inpair = c1 - c0;
    }
    for (int64_t c = c0; c < c1; c++) {
        const int64_t b = p->b[c] < n ? p->b[c] : m->cell->owner[p->b[c] - m->cell->base];
        if (b >= own.lo && b < own.hi) d->inpair[d->ninpair++] = (int32_t)c;
    }
    return true;
}

/* Energy tracking: what this rank gives chunk o's energy sums (its own
 * pairs own, sx__dd_energy), from the serial chunk before it is clipped. */
static void plan_energy(sx_chunk *o, sx_span own)
{
    o->tape_at = -1;
    o->part = SX_DD_PART_NONE;
    if (own.hi <= own.lo || o->last <= own.lo || o->first >= own.hi) return;
    o->part = o->first >= own.lo ? SX_DD_PART_START : SX_DD_PART_TAPE;
    if (o->part == SX_DD_PART_TAPE) o->tape_at = own.lo;
}

enum { WORK_PAIR = 4, WORK_WALL_PAIR = 5, WORK_BALL = 2 }; /* cut_by_work's weights */

/* The work of balls [low, e) (work[] is its prefix sum over balls). */
static int64_t work_of(const sx_dd *d, int64_t low, int64_t e) { return d->work[e] - d->work[low]; }

/* A rank's share of the work against an even one is kept within this
 * factor of it, whatever the paces measured (a rank's clock stalled by a
 * busy host for a moment must not starve it of work). */
#define PACE_SPREAD 2.0

/* Each rank's share of the work, against an even one (1): in
 * proportion to the inverse of its pace, so that the ranks' times even
 * out; even until every rank's pace is measured. */
static void shares_of(const sx_dd *d, double *w)
{
    const int R = d->x.ranks;
    double sum = 0;
    bool measured = true;
    for (int r = 0; r < R; r++) {
        measured = measured && d->pace[r] > 0;
        sum += d->pace[r] > 0 ? 1 / d->pace[r] : 0;
    }
    for (int r = 0; r < R; r++) {
        const double share = measured ? R / (d->pace[r] * sum) : 1;
        w[r] = share < 1 / PACE_SPREAD ? 1 / PACE_SPREAD : share > PACE_SPREAD ? PACE_SPREAD : share;
    }
}

/* The ranks filled in turn with balls while each one's work stays within
 * its share (w) of bound (a rank's work: its balls' and, from below, the
 * pairs crossing its first ball, which it evaluates too); the first ball
 * of each rank in first[] (R + 1 entries, the last n). True if they take
 * every ball. */
static bool fill(const sx_dd *d, int64_t n, int64_t bound, const double *w, int64_t *first)
{
    const int R = d->x.ranks;
    int64_t e = 0;
    for (int r = 0; r < R; r++) {
        const int64_t lo = first[r] = e, below = WORK_PAIR * d->cross[lo];
        while (e < n && (r == R - 1 || (double)(below + work_of(d, lo, e + 1)) <= (double)bound * w[r])) e++;
    }
    first[R] = n;
    return (double)(WORK_PAIR * d->cross[first[R - 1]] + work_of(d, first[R - 1], n)) <= (double)bound * w[R - 1];
}

/* The ranks' ranges of balls, cut to even their time rather than their
 * ball count: besides its balls' pairs a rank evaluates the pairs from
 * the layer below that reach its balls (counted as those crossing its
 * first ball, cross[]: with the few that span a rank thinner than a
 * pair's reach, which it skips), and the lowest rank has the floor's wall
 * pairs. The work is weighed by the SC-bed's costs per item (WORK_*;
 * callgrind, 1 thread: about 250 instructions a ball-ball pair, 320 a
 * ball-wall pair, 120 a ball's integration and clearing), and shared out
 * by the ranks' measured paces (shares_of). The largest rank's work
 * against its share is bisected down to the smallest bound whose ranks,
 * filled in turn, take every ball. Any cut gives the same bits (every sum
 * keeps the serial order, whatever rank makes it): this one evens the
 * ranks' time. False: out of memory. */
static bool cut_by_work(sx_model *m)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    const int64_t n = m->balls.n;
    const sx_pairs *p = &m->bb;
    if (d->cap_cut < n + 1) {
        int32_t *low = realloc(d->low_a, (size_t)(n + 1) * sizeof *low);
        if (low) d->low_a = low;
        int32_t *cross = realloc(d->cross, (size_t)(n + 1) * sizeof *cross);
        if (cross) d->cross = cross;
        int64_t *work = realloc(d->work, (size_t)(n + 1) * sizeof *work);
        if (work) d->work = work;
        if (!low || !cross || !work) return false;
        d->cap_cut = n + 1;
    }
    int64_t *first = malloc((size_t)(R + 1) * sizeof *first);
    double *w = malloc((size_t)R * sizeof *w);
    if (!first || !w) {
        free(first);
        free(w);
        return false;
    }
    for (int64_t i = 0; i <= n; i++) d->low_a[i] = (int32_t)i, d->cross[i] = 0, d->work[i] = 0;
    for (int64_t c = 0; c < p->n; c++) {
        if (p->b[c] < n && p->a[c] < d->low_a[p->b[c]]) d->low_a[p->b[c]] = p->a[c];
        if (p->b[c] < n) d->cross[p->a[c] + 1]++, d->cross[p->b[c] + 1]--; /* a < first ball <= b */
        d->work[p->a[c] + 1] += WORK_PAIR;
    }
    for (int64_t c = 0; c < m->bw.n; c++) d->work[m->bw.a[c] + 1] += WORK_WALL_PAIR;
    for (int64_t i = 0; i < n; i++) d->work[i + 1] += d->work[i] + WORK_BALL, d->cross[i + 1] += d->cross[i];
    shares_of(d, w);
    double sum = 0, least = w[0];
    for (int r = 0; r < R; r++) sum += w[r], least = w[r] < least ? w[r] : least;
    /* lo: no cut does better; hi: the least share could take all */
    int64_t lo = (int64_t)((double)d->work[n] / sum), hi = (int64_t)((double)d->work[n] / least) + 1;
    while (hi - lo > 1 + d->work[n] / 4096) {
        const int64_t mid = lo + (hi - lo) / 2;
        if (fill(d, n, mid, w, first)) hi = mid;
        else lo = mid;
    }
    fill(d, n, hi, w, first);
    for (int r = 0; r < R; r++) d->own[r] = (sx_span){first[r], first[r + 1]};
    d->planned = WORK_PAIR * d->cross[first[me]] + work_of(d, first[me], first[me + 1]);
    free(first);
    free(w);
    return true;
}

/* The spans of every rank from the whole, current pair stores (after a
 * build, or when a cycle starts), and this rank's clipped chunks. False:
 * out of memory. */
bool sx__dd_plan(sx_model *m)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    const int64_t n = m->balls.n;
    const sx_pairs *p = &m->bb;
    if (!cut_by_work(m)) return false;
    /* the lowest first ball of a pair whose second ball each rank owns,
     * from the cut's low_a (a ghost's pairs reach its owner through the
     * fold: plan_far) */
    for (int r = 0; r < R; r++) {
        d->pairs[r].lo = d->own[r].lo; /* lo: a ball index until made a pair index */
        for (int64_t i = d->own[r].lo; i < d->own[r].hi; i++)
            if (d->low_a[i] < d->pairs[r].lo) d->pairs[r].lo = d->low_a[i];
    }
    int64_t bl = 0; /* the blocks are in order: the first whose last ball reaches each rank */
    for (int r = 0; r < R; r++) {
        sx_span *own = &d->own[r], *pr = &d->pairs[r], *wb = &d->wblk[r];
        const int64_t lo_a = pr->lo;
        pr->lo = sx__first_at(p->a, p->n, lo_a);
        pr->hi = sx__first_at(p->a, p->n, own->hi);
        int64_t hi = own->hi;
        for (int64_t c = pr->lo; c < pr->hi; c++)
            if (p->b[c] < n && p->b[c] + 1 > hi) hi = p->b[c] + 1;
        while (bl < m->nblock && m->blocks[bl].b1 - 1 < own->lo) bl++;
        wb->lo = wb->hi = bl;
        while (wb->hi < m->nblock && m->blocks[wb->hi].b1 - 1 < own->hi) wb->hi++;
        /* the wall pass runs whole every block with a ball of its own
         * (a block's lanes as in the serial pass), so their ghosts too */
        sx_span *run = &d->wrun[r];
        run->lo = bl, run->hi = wb->hi;
        if (own->hi > own->lo && run->hi < m->nblock && m->blocks[run->hi].b0 < own->hi) run->hi++;
        int64_t lo = lo_a;
        if (run->hi > run->lo && m->blocks[run->lo].b0 < lo) lo = m->blocks[run->lo].b0;
        if (run->hi > run->lo && m->blocks[run->hi - 1].b1 > hi) hi = m->blocks[run->hi - 1].b1;
        if (own->hi == own->lo) lo = hi = own->lo; /* a rank without balls needs none */
        sx_span *need = d->need + SX_DD_NEED * r;
        need[0] = (sx_span){lo, own->lo};
        need[1] = (sx_span){own->hi, hi};
        need[2] = need[3] = (sx_span){0, 0};
        d->bb_own[r] = (sx_span){sx__first_at(p->a, p->n, own->lo), sx__first_at(p->a, p->n, own->hi)};
        d->bw_own[r] = (sx_span){sx__first_at(m->bw.a, m->bw.n, own->lo), sx__first_at(m->bw.a, m->bw.n, own->hi)};
    }
    d->nxpair = d->nxlow = d->ngho = 0;
    if ((m->cell && m->cell->n && !plan_far(m)) || !plan_inpairs(m)) return false;
    /* this rank's chunks: the serial ones, clipped to its pairs; the balls
     * they clear, to its own and its near ghosts */
    const sx_span pr = d->pairs[me], lo = d->need[SX_DD_NEED * me], hi = d->need[SX_DD_NEED * me + 1];
    d->xchunk.tape_at = -1;
    d->tape.n = 0, d->tape.lost = false;
    for (int64_t c = 0; c < m->nchunk; c++) {
        sx_chunk *o = &m->chunks[c];
        plan_energy(o, d->bb_own[me]);
        o->first = o->first < pr.lo ? pr.lo : o->first > pr.hi ? pr.hi : o->first;
        o->last = o->last < o->first ? o->first : o->last > pr.hi ? pr.hi : o->last;
        if (o->clear_lo < lo.lo) o->clear_lo = lo.lo;
        if (o->clear_hi > hi.hi) o->clear_hi = hi.hi;
        if (o->clear_hi < o->clear_lo) o->clear_hi = o->clear_lo;
    }
    return plan_lists(m);
}

/* The ranks hold the same digest of what they must hold alike; else every
 * rank stops, naming what differs and the likely cause. */
static sx_status agree(sx_model *m, uint64_t digest, const char *what, const char *cause)
{
    sx_dd *d = m->dd;
    if (d->x.agree(d->x.ud, digest)) return SX_OK;
    return sx__fail(m, SX_EINVAL, "cycle: %s between the %d ranks (every rank must make the same calls: %s?)", what,
                    d->x.ranks, cause);
}

sx_status sx__dd_begin(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_status st = agree(m, sx__state_digest(m), "the model differs",
                         "random numbers without a fixed seed, calls made in the order of pairs() over a "
                         "table's names (an order each process draws), or a branch on seixo.rank()");
    if (st) return st;
    if (!sx__dd_plan(m)) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    d->crack0 = m->cracks.n;
    d->active = true;
    return SX_OK;
}

/* A cycle's start on a scattered state. It goes on with the plan, the
 * ghosts' ranges and the crack log's shared part of the last cycle, as if
 * that had not ended (or gathers first, when it must build), and nothing
 * but the walls, the materials and the scalars can have changed since
 * (the caller gathers first for anything else): the ranks compare those
 * alone. */
sx_status sx__dd_agree_replicated(sx_model *m)
{
    return agree(m, sx__replicated_digest(m), "the walls or settings differ", "a branch on seixo.rank()");
}

/* The moves' buffer serves a cycle's steps, kept from cycle to cycle (a
 * script of one-step cycles moves the same rows at each), but not at the
 * size of the whole state a build's migration or a gather may have grown
 * it to. */
enum { ROWBUF_KEEP = 1 << 20 };

static void drop_rowbuf(sx_dd *d)
{
    if (d->cap_rowbuf <= ROWBUF_KEEP) return;
    free(d->rowbuf);
    d->rowbuf = NULL, d->cap_rowbuf = 0;
}

sx_status sx__dd_whole(sx_model *m, bool (*replan)(sx_model *))
{
    sx_dd *d = m->dd;
    const bool ok = sx__dd_gather(m);
    drop_rowbuf(d);
    if (!ok) return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the state");
    d->scattered = false;
    if (!replan(m)) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    return SX_OK;
}

sx_status sx__dd_end(sx_model *m, bool (*replan)(sx_model *))
{
    sx_dd *d = m->dd;
    if (d->walls_stale && !sx__dd_walls(m, false))
        return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange wall forces");
    d->active = false;
    d->scattered = true;
    d->fetched = 0, d->motion_whole = d->cracks_merged = false;
    drop_rowbuf(d);
    return d->lazy ? SX_OK : sx__dd_whole(m, replan);
}

void sx_model_gather_lazily(sx_model *m, bool lazily)
{
    if (m->dd) m->dd->lazy = lazily;
}

bool sx_model_scattered(const sx_model *m) { return m->dd && m->dd->scattered; }

/* The ranks' cracks merged as a build merges them (from crack0 on, its own
 * balls' on each rank): every rank then holds the whole log and crack0 is
 * its end, so the scattered hash and counts, which take the merged entries
 * from rank 0 alone, add the same rows. No step logs a crack until the next
 * cycle: merged once, the log stays whole until then. */
sx_status sx_model_share_cracks(sx_model *m)
{
    if (!sx_model_scattered(m) || m->dd->cracks_merged) return SX_OK;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "the crack log: the model is stepping");
    if (!sx__dd_gather_cracks(m)) return sx__fail(m, SX_EINVAL, "the ranks could not exchange their cracks (out of memory?)");
    m->dd->cracks_merged = true;
    return SX_OK;
}

/* (model_internal.h) The last plan's (a scattered model keeps it, as a
 * resumed cycle does): a rank holds its balls current, their pairs, the
 * bonds of its pairs and the clumps it owns; a bond in no pair of the plan
 * is every rank's last state alike, rank 0's to hash. */
bool sx__dd_rows_held(const sx_model *m, sx_rows_held *part)
{
    const sx_dd *d = m->dd;
    const int me = d->x.rank;
    *part = (sx_rows_held){.all = false, .first = me == 0, .balls = d->own[me], .bb = d->bb_own[me],
                           .bw = d->bw_own[me], .crack0 = d->crack0, .clump_owner = d->cown, .rank = me};
    const int64_t nb = m->bonds.n;
    if (!nb) return true;
    part->bond = malloc((size_t)nb);
    if (!part->bond) return false;
    memset(part->bond, part->first, (size_t)nb);
    for (int64_t e = 0; e < d->nbslot; e++) part->bond[d->bslot[e]] = e >= d->bs_own[me].lo && e < d->bs_own[me].hi;
    return true;
}

bool sx_model_error_agreed(const sx_model *m) { return m->dd && m->dd->agreed; }
