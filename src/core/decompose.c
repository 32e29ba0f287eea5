/* Domain decomposition over ranks (issue 16), with results bit-identical
 * to a serial run for any number of ranks; docs/developer.md, "MPI domain
 * decomposition", has the design and what is left.
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
#include "model_internal.h"
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
     * gho_own, fwd.own, back.own, bb_was, bw_was; and the routes' needs (r per rank) */
    enum { SPANS = 15 + SX_DD_NEED };
    sx_span *s = d ? calloc(SPANS * r, sizeof *s) : NULL, *routes = s ? calloc(2 * r * r, sizeof *routes) : NULL;
    double *pace = routes ? calloc(5 * r, sizeof *pace) : NULL; /* pace (r), sample (2 r), stopping (2 r) */
    if (!pace) {
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
    d->bb_was = s + 12 * r, d->bw_was = s + 13 * r;
    d->fwd.need = routes, d->back.need = routes + r * r;
    d->pace = pace, d->sample = pace + r, d->stopping = pace + 3 * r;
    d->received = &m->prof.received;
    m->dd = d;
    return SX_OK;
}

int sx_model_ranks(const sx_model *m) { return m->dd ? m->dd->x.ranks : 1; }

/* The rank owning ball i (own[] cut as in sx__dd_plan). */
static int owner_of(const sx_dd *d, int64_t i, int64_t n)
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
 * owners to their clumps' owners, or (back) the other way. Each source
 * rank's entries a run, within it a span per destination, each in clump
 * order then pebble order (a counting sort on source and destination);
 * every rank plans every rank's alike. False: out of memory. */
static bool plan_route(sx_model *m, sx_route *rt, bool back)
{
    sx_dd *d = m->dd;
    const sx_clumps *C = m->clumps;
    const int R = d->x.ranks;
    const int64_t n = m->balls.n;
    int64_t *at = calloc((size_t)(R * R + 1), sizeof *at); /* per (source, destination): its first entry */
    if (!at) return false;
    for (int pass = 0; pass < 2; pass++) { /* count, then place */
        for (int64_t c = 0; c < C->n; c++)
            for (int64_t k = 0; k < pebbles(m, c); k++) {
                const int64_t i = pebble_of(m, c, k);
                const int po = owner_of(d, i, n), co = d->cown[c];
                if (po == co) continue;
                const int key = back ? co * R + po : po * R + co;
                if (pass) rt->item[at[key]++] = (int32_t)i;
                else at[key + 1]++;
            }
        if (pass) break;
        for (int key = 0; key < R * R; key++) at[key + 1] += at[key];
        rt->n = at[R * R];
        if (rt->cap < rt->n) {
            int32_t *q = realloc(rt->item, (size_t)rt->n * sizeof *q);
            if (!q) {
                free(at);
                return false;
            }
            rt->item = q, rt->cap = rt->n;
        }
        for (int src = 0; src < R; src++)
            for (int dst = 0; dst < R; dst++) rt->need[dst * R + src] = (sx_span){at[src * R + dst], at[src * R + dst + 1]};
    }
    for (int src = 0; src < R; src++) rt->own[src] = (sx_span){rt->need[src].lo, rt->need[(R - 1) * R + src].hi};
    free(at);
    return true;
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
        d->cown[c] = (int32_t)owner_of(d, best, B->n);
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
        const int r = owner_of(d, o, n);
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
    d->tape.n = 0;
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

/* [0, count) for every rank: what a gather needs. */
static const sx_span *everything(sx_dd *d, int64_t count)
{
    for (int r = 0; r < d->x.ranks; r++) d->all[r] = (sx_span){0, count};
    return d->all;
}

static bool share(sx_dd *d, void *data, size_t size, const sx_span *own, const sx_span *need, int per)
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

/* Rows of per-entry arrays between ranks: field[k] has row[k] bytes an
 * entry, and the rows moved are base + list[e] for the entries e < n of
 * the buffer. Each rank packs the entries own[rank], they are shared
 * (need: nper spans per rank), and each rank unpacks those it needs. */
enum { ROWS_MAX = SX_PAIR_FIELDS_MAX };
typedef struct sx_rows {
    void *field[ROWS_MAX];
    size_t row[ROWS_MAX];
    int nf;
} sx_rows;

static void add_row(sx_rows *f, void *field, size_t row)
{
    if (row) f->field[f->nf] = field, f->row[f->nf++] = row;
}

static bool move_rows(sx_dd *d, const sx_rows *f, const int32_t *list, int64_t base, int64_t n, const sx_span *own,
                      const sx_span *need, int nper)
{
    size_t w = 0;
    for (int k = 0; k < f->nf; k++) w += f->row[k];
    if (!n || !w) return true;
    char *buf = malloc((size_t)n * w);
    if (!buf) return false;
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
        if (!pass) ok = share(d, buf, w, own, need, nper);
    }
    free(buf);
    return ok;
}

/* An all-gather: entry r of data (size bytes each), rank r's, to every
 * rank. */
static bool share_by_rank(sx_dd *d, void *data, size_t size)
{
    for (int r = 0; r < d->x.ranks; r++) d->scratch[r] = (sx_span){r, r + 1};
    return share(d, data, size, d->scratch, everything(d, d->x.ranks), 1);
}

bool sx__dd_halo(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_balls *B = &m->balls;
    const size_t v = (size_t)m->dim * sizeof(double), w = (size_t)m->rdim * sizeof(double);
    return share(d, B->x, v, d->own, d->need, SX_DD_NEED) && share(d, B->v, v, d->own, d->need, SX_DD_NEED) &&
           share(d, B->w, w, d->own, d->need, SX_DD_NEED);
}

static bool gather_pairs(sx_model *m, sx_pairs *p, const sx_span *own)
{
    sx_dd *d = m->dd;
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    for (int k = 0; k < nf; k++) /* the ends come from the build, the same on every rank */
        if (!f[k].end && !share(d, *f[k].data, sx__pair_size(&f[k]) * (size_t)f[k].per, own, everything(d, p->n), 1))
            return false;
    return true;
}

/* The bonds' state the step changes (kind; unless kinds_only fn, mn, fs,
 * ms) of the slots list[e], e < n, each rank's entries own[r], to every
 * rank. */
static bool share_bonds(sx_model *m, const int32_t *list, int64_t n, const sx_span *own, bool kinds_only)
{
    sx_bonds *b = &m->bonds;
    const size_t v = sizeof(double), D = (size_t)m->dim * v, RD = (size_t)m->rdim * v;
    sx_rows f = {.nf = 0};
    add_row(&f, b->kind, sizeof *b->kind);
    if (!kinds_only) add_row(&f, b->fn, v), add_row(&f, b->mn, v), add_row(&f, b->fs, D), add_row(&f, b->ms, RD);
    return move_rows(m->dd, &f, list, 0, n, own, everything(m->dd, n), 1);
}

/* Each rank took off the intact count the bonds it saw break, its ghost
 * pairs' included: counted again once the kinds are shared. */
static void count_intact(sx_model *m)
{
    sx_bonds *b = &m->bonds;
    b->intact = 0;
    for (int64_t s = 0; s < b->n; s++) b->intact += b->kind[s] != 0;
}

/* Every bond of the plan from the owner of its pair's first ball. */
static bool gather_bonds(sx_model *m)
{
    const sx_dd *d = m->dd;
    const bool ok = share_bonds(m, d->bslot, d->nbslot, d->bs_own, false);
    count_intact(m);
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
 * exact). */
static bool share_fjoints(sx_model *m, const int32_t *slot, int64_t nb, const sx_span *own)
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
    double *buf = total ? malloc((size_t)total * sizeof *buf) : NULL;
    bool ok = !total || buf;
    for (int r = 0; ok && r < d->x.ranks; r++) d->scratch[r] = (sx_span){at[own[r].lo], at[own[r].hi]};
    for (int pass = 0; ok && total && pass < 2; pass++) { /* pack this rank's, then unpack everyone's */
        const sx_span mine = own[d->x.rank];
        const int64_t e0 = pass ? 0 : mine.lo, e1 = pass ? nb : mine.hi;
        for (int64_t e = e0; e < e1; e++) {
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
        if (!pass) ok = share(d, buf, sizeof *buf, d->scratch, everything(d, total), 1);
    }
    free(buf);
    free(at);
    return ok;
}

static bool gather_fjoints(sx_model *m) { return share_fjoints(m, m->dd->bslot, m->dd->nbslot, m->dd->bs_own); }

/* A list made in parts, one a rank, joined in rank order on every rank (a
 * decomposed build's pairs, a gather's cracks): the ranks' counts are
 * shared, d->scratch becomes each rank's part of the whole, and *total its
 * length; sx__dd_join then gives every rank every part. */
bool sx__dd_parts(sx_model *m, int64_t count, sx_span *mine, int64_t *total)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks;
    int64_t *counts = calloc((size_t)R, sizeof *counts);
    if (!counts) return false;
    counts[d->x.rank] = count;
    const bool ok = share_by_rank(d, counts, sizeof *counts);
    int64_t sum = 0;
    for (int r = 0; ok && r < R; r++) {
        d->scratch[r] = (sx_span){sum, sum + counts[r]};
        sum += counts[r];
    }
    free(counts);
    *mine = d->scratch[d->x.rank];
    *total = sum;
    return ok;
}

bool sx__dd_join(sx_model *m, void *data, size_t size, int64_t total)
{
    sx_dd *d = m->dd;
    return !total || share(d, data, size, d->scratch, everything(d, total), 1);
}

/* The cracks logged since the last gather, made one log in the serial
 * order. Every rank evaluates its own pairs and some of its neighbours'
 * (from a ghost to its balls): it keeps the cracks of its own pairs (a pair is
 * its first ball's), which, the pairs being sorted by that ball, are the
 * serial log's of its pair range. A step's cracks are thus rank 0's, then
 * rank 1's, ...; the ranks' lists are merged by step in that order. */
static bool gather_cracks(sx_model *m)
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
    ok = ok && (!total || all);
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
static sx_rows ball_motion(const sx_model *m, bool with_position)
{
    const sx_balls *B = &m->balls;
    const size_t D = (size_t)m->dim * sizeof(double), RD = (size_t)m->rdim * sizeof(double);
    sx_rows f = {.nf = 0};
    if (with_position) add_row(&f, B->x, D);
    add_row(&f, B->v, D), add_row(&f, B->f, D), add_row(&f, B->w, RD), add_row(&f, B->t, RD);
    return f;
}

/* Periodic space: every ghost's slot (position, velocity, spin, force,
 * moment) from the rank of its owner, in the plan's order. */
static bool gather_ghosts(sx_model *m)
{
    sx_dd *d = m->dd;
    const sx_rows f = ball_motion(m, true);
    return move_rows(d, &f, d->gho, m->cell->base, d->ngho, d->gho_own, everything(d, d->ngho), 1);
}

/* The clumps' state (centroid, velocity, spin, orientation, angular
 * momentum, the last resultants) from their owners to every rank. */
bool sx__dd_clumps(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_clumps *C = m->clumps;
    const size_t D = (size_t)m->dim * sizeof(double), RD = (size_t)m->rdim * sizeof(double);
    sx_rows f = {.nf = 0};
    add_row(&f, C->x, D), add_row(&f, C->v, D), add_row(&f, C->w, RD), add_row(&f, C->f, D), add_row(&f, C->t, RD);
    add_row(&f, C->q, (m->dim == 3 ? 4 : 1) * sizeof(double)), add_row(&f, C->L, m->dim == 3 ? 3 * sizeof(double) : 0);
    return move_rows(d, &f, d->cl, 0, d->ncl, d->cl_own, everything(d, d->ncl), 1);
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
static bool share_pace(sx_model *m)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    double *s = d->sample;
    s[2 * me] = d->busy;
    s[2 * me + 1] = d->busy_work > 0 ? d->busy / d->busy_work : 0;
    if (!share_by_rank(d, s, 2 * sizeof *s)) return false;
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
    if (!share_pace(m)) return false;
    const sx_span *all = everything(d, B->n);
    return share(d, B->x, v, d->own, all, 1) && share(d, B->v, v, d->own, all, 1) &&
           share(d, B->w, w, d->own, all, 1) && share(d, B->f, v, d->own, all, 1) &&
           share(d, B->t, w, d->own, all, 1) && gather_pairs(m, &m->bb, d->bb_own) &&
           gather_pairs(m, &m->bw, d->bw_own) && (!m->bonds.n || (gather_bonds(m) && gather_cracks(m))) &&
           (!m->fjel.n || gather_fjoints(m)) &&
           (!m->cell || !m->cell->n || gather_ghosts(m)) && (!m->clumps || !m->clumps->n || sx__dd_clumps(m));
}

/* Room for n entries in *a (capacity *cap). */
static bool room(int32_t **a, int64_t *cap, int64_t n)
{
    if (*cap >= n) return true;
    int32_t *q = realloc(*a, (size_t)n * sizeof *q);
    if (!q) return false;
    *a = q, *cap = n;
    return true;
}

/* The rank whose span holds entry k, of spans that cut [0, n) in rank
 * order (an empty span's rank owns nothing). */
static int span_owner(const sx_span *s, int R, int64_t k)
{
    int lo = 0, hi = R - 1;
    while (lo < hi) {
        const int mid = (lo + hi + 1) / 2;
        if (s[mid].lo <= k) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* A pair store's contact flags and bond links, from the owners of their
 * pairs: the build's transfer reads them (which old pairs carry a
 * history, which bonds hold), so every rank must see the same. */
static bool share_flags(sx_model *m, sx_pairs *p, const sx_span *own)
{
    sx_dd *d = m->dd;
    return !p->n || (share(d, p->touching, sizeof *p->touching, own, everything(d, p->n), 1) &&
                     (!p->bond || share(d, p->bond, sizeof *p->bond, own, everything(d, p->n), 1)));
}

/* The build inside a cycle is the serial build, on every rank, but not
 * from the whole state: it reads of the step's state only the positions,
 * the pairs' contact flags and bond links, the bonds' kinds and the
 * clumps' state, which every rank takes here (with the cracks, whose
 * owners follow the balls); the rest stays where the ranks stepped it,
 * and what the new cut gives another rank moves after the plan
 * (sx__dd_migrate). About 24 bytes a ball and 5 a pair instead of the
 * whole state (some 100 a ball and 60 a pair in 3D). Periodic space
 * gathers the whole state: a build copies the balls into their ghosts'
 * slots. */
bool sx__dd_build(sx_model *m)
{
    sx_dd *d = m->dd;
    d->migrating = false;
    if (m->cell) return sx__dd_gather(m);
    const sx_balls *B = &m->balls;
    const int R = d->x.ranks;
    const int64_t nb = m->bonds.n;
    if (!share_pace(m) || !share(d, B->x, (size_t)m->dim * sizeof(double), d->own, everything(d, B->n), 1) ||
        !share_flags(m, &m->bb, d->bb_own) || !share_flags(m, &m->bw, d->bw_own) ||
        (nb && (!share_bonds(m, d->bslot, d->nbslot, d->bs_own, true) || !gather_cracks(m))) ||
        (m->clumps && m->clumps->n && !sx__dd_clumps(m)))
        return false;
    count_intact(m);
    /* the last plan's owners, by what the build does not renumber */
    if (!room(&d->was, &d->cap_was, B->index_cap) || !room(&d->slot_was, &d->cap_slot_was, nb)) return false;
    for (int r = 0; r < R; r++)
        for (int64_t i = d->own[r].lo; i < d->own[r].hi; i++) d->was[B->id[i]] = r;
    for (int64_t k = 0; k < nb; k++) d->slot_was[k] = -1;
    for (int r = 0; r < R; r++)
        for (int64_t e = d->bs_own[r].lo; e < d->bs_own[r].hi; e++) d->slot_was[d->bslot[e]] = r;
    memcpy(d->bb_was, d->bb_own, (size_t)R * sizeof *d->bb_was);
    memcpy(d->bw_was, d->bw_own, (size_t)R * sizeof *d->bw_was);
    d->nsrc_bb = d->nsrc_bw = 0;
    d->migrating = true;
    return true;
}

bool sx__dd_keep_sources(sx_model *m, bool walls, const int32_t *src, int64_t n)
{
    sx_dd *d = m->dd;
    if (!d || !d->active || !d->migrating) return true;
    int64_t *len = walls ? &d->nsrc_bw : &d->nsrc_bb;
    *len = 0; /* none: no pair had a history, every new pair's is zeros */
    if (!src || !n) return true;
    if (!room(walls ? &d->src_bw : &d->src_bb, walls ? &d->cap_src_bw : &d->cap_src_bb, n)) return false;
    memcpy(walls ? d->src_bw : d->src_bb, src, (size_t)n * sizeof *src);
    *len = n;
    return true;
}

bool sx__dd_sources_sort(sx_model *m, bool walls, const int32_t *pos, int64_t n)
{
    sx_dd *d = m->dd;
    if (!d || !d->migrating || (walls ? d->nsrc_bw : d->nsrc_bb) != n) return true;
    int32_t *src = walls ? d->src_bw : d->src_bb, *to = malloc((size_t)n * sizeof *to);
    if (!to) return false;
    for (int64_t c = 0; c < n; c++) to[pos[c]] = src[c];
    memcpy(src, to, (size_t)n * sizeof *to);
    free(to);
    return true;
}

/* The fields of a pair store that are not its ends. */
static sx_rows pair_rows(sx_model *m, sx_pairs *p)
{
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    sx_rows r = {.nf = 0};
    for (int k = 0; k < nf; k++)
        if (!f[k].end) add_row(&r, *f[k].data, sx__pair_size(&f[k]) * (size_t)f[k].per);
    return r;
}

/* The entries k < n with from[k] >= 0, by from (each rank's a run, in
 * entry order): into list, its runs into runs; their count. */
static int64_t list_by_owner(const sx_dd *d, const int32_t *from, int64_t n, int32_t *list, sx_span *runs)
{
    const int R = d->x.ranks;
    for (int r = 0; r < R; r++) runs[r] = (sx_span){0, 0};
    for (int64_t k = 0; k < n; k++)
        if (from[k] >= 0) runs[from[k]].hi++;
    int64_t at = 0;
    for (int r = 0; r < R; r++) {
        const int64_t len = runs[r].hi;
        runs[r] = (sx_span){at, at}; /* hi: the run's next entry, then its end */
        at += len;
    }
    for (int64_t k = 0; k < n; k++)
        if (from[k] >= 0) list[runs[from[k]].hi++] = (int32_t)k;
    return at;
}

/* The rows f of the entries k < n with from[k] >= 0, from rank from[k]
 * to every rank (list and runs: room for n entries and for the ranks). */
static bool move_from(sx_dd *d, const sx_rows *f, const int32_t *from, int64_t n, int32_t *list, sx_span *runs)
{
    const int64_t k = list_by_owner(d, from, n, list, runs);
    return move_rows(d, f, list, 0, k, runs, everything(d, k), 1);
}

/* Rank r steps the ball-ball pairs pairs[r] and the ball-wall pairs of
 * the balls of its wall blocks wrun[r]. */
static sx_span wall_pairs_run(const sx_model *m, int r)
{
    const sx_span run = m->dd->wrun[r];
    if (run.hi <= run.lo) return (sx_span){0, 0};
    const int64_t lo = m->blocks[run.lo].b0, hi = m->blocks[run.hi - 1].b1;
    return (sx_span){sx__first_at(m->bw.a, m->bw.n, lo), sx__first_at(m->bw.a, m->bw.n, hi)};
}

/* from[c] for the new pairs a rank steps whose old pair another rank
 * stepped: that rank, which holds its history. */
static void pairs_from(const sx_model *m, const sx_span *run, const int32_t *src, int64_t nsrc, const sx_span *was,
                       int32_t *from, int64_t n, bool walls)
{
    const sx_dd *d = m->dd;
    const int R = d->x.ranks;
    for (int64_t c = 0; c < n; c++) from[c] = -1;
    for (int r = 0; r < R; r++) {
        const sx_span s = walls ? wall_pairs_run(m, r) : run[r];
        for (int64_t c = s.lo; c < s.hi && c < nsrc; c++) {
            if (!src[c]) continue;
            const int o = span_owner(was, R, (src[c] > 0 ? src[c] : -src[c]) - 1);
            if (o != r) from[c] = o;
        }
    }
}

/* After the build's plan: to the ranks that now step them, the balls
 * whose owner changed (velocity, spin, force, moment: the positions every
 * rank took before the build), the pairs whose history another rank
 * holds, and the bonds (with a flat joint's face and elements) another
 * rank stepped, or that left the plan (broken: their last state to every
 * rank). Every rank lists the same entries (from what all hold alike),
 * and each sends the entries it held; every rank receives them all. */
bool sx__dd_migrate(sx_model *m)
{
    sx_dd *d = m->dd;
    if (!d->migrating) return true;
    d->migrating = false;
    const sx_balls *B = &m->balls;
    const sx_bonds *bs = &m->bonds;
    const int R = d->x.ranks;
    int64_t most = B->n > m->bb.n ? B->n : m->bb.n;
    if (m->bw.n > most) most = m->bw.n;
    if (bs->n > most) most = bs->n;
    int32_t *from = malloc((size_t)(most + 1) * sizeof *from), *list = malloc((size_t)(most + 1) * sizeof *list);
    sx_span *runs = malloc((size_t)R * sizeof *runs);
    bool ok = from && list && runs;
    if (ok) { /* the balls */
        for (int64_t i = 0; i < B->n; i++) {
            const int32_t o = d->was[B->id[i]];
            from[i] = o != owner_of(d, i, B->n) ? o : -1;
        }
        const sx_rows f = ball_motion(m, false);
        ok = move_from(d, &f, from, B->n, list, runs);
    }
    if (ok) { /* the ball-ball pairs, then the ball-wall pairs */
        pairs_from(m, d->pairs, d->src_bb, d->nsrc_bb, d->bb_was, from, m->bb.n, false);
        const sx_rows fb = pair_rows(m, &m->bb);
        ok = move_from(d, &fb, from, m->bb.n, list, runs);
        pairs_from(m, NULL, d->src_bw, d->nsrc_bw, d->bw_was, from, m->bw.n, true);
        const sx_rows fw = pair_rows(m, &m->bw);
        ok = ok && move_from(d, &fw, from, m->bw.n, list, runs);
    }
    if (ok && bs->n && m->bb.bond) { /* the bonds: of a pair another rank stepped, or left the plan */
        for (int64_t s = 0; s < bs->n; s++) from[s] = d->slot_was[s]; /* -1: in no pair of the last plan */
        for (int64_t c = 0; c < m->bb.n; c++) /* in a pair of this plan: stays where it is, unless... */
            if (m->bb.bond[c]) from[m->bb.bond[c] - 1] = -1;
        for (int r = 0; r < R; r++)
            for (int64_t c = d->pairs[r].lo; c < d->pairs[r].hi; c++) { /* ...a rank steps it that did not */
                const int32_t s = m->bb.bond[c] - 1;
                if (s >= 0 && d->slot_was[s] >= 0 && d->slot_was[s] != r) from[s] = d->slot_was[s];
            }
        const int64_t k = list_by_owner(d, from, bs->n, list, runs);
        ok = share_bonds(m, list, k, runs, false) && (!m->fjel.n || share_fjoints(m, list, k, runs));
    }
    free(runs);
    free(list);
    free(from);
    return ok;
}

/* An interrupt stops every rank at the same step. Every STOP_EVERY steps
 * the ranks share the number of their process's last unanswered interrupt
 * request and of the last one a stop answered (a Ctrl-C or a SIGUSR1 that
 * mpirun forwards to each rank reaches each at its own step; a rank's run
 * that is not decomposed may have answered its own), and a request above
 * every rank's answered level stops the cycle on every rank there, in
 * step: the cycle ends as any cycle does, and the interruption can be
 * reported, and caught, alike on every rank. The decision is made from
 * the shared numbers alone, so ranks that are threads of one process
 * (tests/test_decompose.c) decide alike too. A rank's late copy of a
 * signal a stop answered is not a new request. One small exchange every
 * STOP_EVERY steps: a running cycle stops within that many steps of the
 * signal. */
enum { STOP_EVERY = 16 };

bool sx__dd_stop(sx_model *m, bool *stop)
{
    sx_dd *d = m->dd;
    *stop = false;
    if (m->step % STOP_EVERY) return true;
    const int R = d->x.ranks, me = d->x.rank;
    double *s = d->stopping;
    s[2 * me] = (double)sx__interrupts_unanswered(), s[2 * me + 1] = (double)sx__interrupts_level();
    if (!share_by_rank(d, s, 2 * sizeof *s)) return false;
    double request = 0, level = 0;
    for (int r = 0; r < R; r++) request = s[2 * r] > request ? s[2 * r] : request, level = s[2 * r + 1] > level ? s[2 * r + 1] : level;
    if (request > level) sx__interrupts_stopped((unsigned)request), *stop = true;
    return true;
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
        !share(d, m->wall_acc, (size_t)m->nwall * sizeof *m->wall_acc, d->wblk, everything(d, m->nblock), 1))
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
        for (int k = 0; k < 4; k++) add_row(&f, sums + k * n, v);
    else
        add_row(&f, B->f, (size_t)m->dim * v), add_row(&f, B->t, (size_t)m->rdim * v);
    return move_rows(d, &f, d->fwd.item, 0, d->fwd.n, d->fwd.own, d->fwd.need, d->x.ranks);
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
    add_row(&f, B->x, (size_t)m->dim * v), add_row(&f, B->v, (size_t)m->dim * v), add_row(&f, B->w, (size_t)m->rdim * v);
    return move_rows(d, &f, d->back.item, 0, d->back.n, d->back.own, d->back.need, d->x.ranks);
}

/* The serial step adds, after the balls' blocks, the clumps' blocks'
 * energy sums (size clumps a block, each sum from zero over its clumps'
 * terms in clump order) to m->acc in block order. The owners' terms
 * (w a clump at its entry cl_at, the first nd its damping's, a term
 * absent from the serial sum a zero: adding +0 to a sum from +0 changes
 * no bit) go to rank 0, which folds them in the serial order; the block
 * sums go to every rank, which adds them in block order: two messages a
 * step per rank, only with energy tracking. The owners write their
 * clumps' terms where the exchange sends them from (sx__dd_clump_terms),
 * in a buffer kept from step to step. */
double *sx__dd_clump_terms(sx_model *m, int w, int64_t size)
{
    sx_dd *d = m->dd;
    const int64_t nblk = (m->clumps->n + size - 1) / size, len = d->ncl * w + 2 * nblk;
    if (len > d->cap_cterm) {
        double *q = realloc(d->cterm, (size_t)len * sizeof *q);
        if (!q) return NULL;
        d->cterm = q, d->cap_cterm = len;
    }
    const sx_span own = d->cl_own[d->x.rank];
    memset(d->cterm + own.lo * w, 0, (size_t)((own.hi - own.lo) * w) * sizeof *d->cterm);
    return d->cterm + own.lo * w;
}

bool sx__dd_clump_energy(sx_model *m, int w, int nd, int64_t size)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks;
    const int64_t nc = m->clumps->n, nblk = (nc + size - 1) / size;
    if (!nc) return true; /* every clump removed: no block, on every rank */
    double *t = d->cterm, *sum = t + d->ncl * w;
    for (int r = 0; r < R; r++) d->scratch[r] = (sx_span){0, r ? 0 : d->ncl}; /* rank 0 needs them all */
    bool ok = share(d, t, (size_t)w * sizeof *t, d->cl_own, d->scratch, 1);
    for (int64_t k = 0; ok && !d->x.rank && k < nblk; k++) {
        double damp = 0, load = 0;
        for (int64_t c = k * size; c < (k + 1) * size && c < nc; c++) {
            const double *q = t + (int64_t)d->cl_at[c] * w;
            for (int j = 0; j < nd; j++) damp += q[j];
            for (int j = nd; j < w; j++) load += q[j];
        }
        sum[2 * k] = damp, sum[2 * k + 1] = load;
    }
    for (int r = 0; r < R; r++) d->scratch[r] = (sx_span){0, r ? 0 : 2 * nblk}; /* rank 0's sums, to all */
    ok = ok && share(d, sum, sizeof *sum, d->scratch, everything(d, 2 * nblk), 1);
    for (int64_t k = 0; ok && k < nblk; k++) {
        m->acc.local_damping -= sum[2 * k];
        m->acc.boundary_work += sum[2 * k + 1];
    }
    return ok;
}

/* A sum in the serial order over what the ranks own in turn (the
 * periodic cell's stress: each rank's own pairs, bb_own, whose runs follow
 * each other in pair order; the energy guard's: each rank's own balls and
 * pairs): each rank adds its own terms to the running sum of the ranks
 * before it, in a chain from rank 0 (which starts from acc as given), and
 * the last rank's total goes to every rank: the serial sum's every
 * rounding, in R steps of one message. part(m, r, acc) adds rank r's
 * terms to acc (len doubles). False: the ranks could not exchange. */
bool sx__dd_chain(const sx_model *m, double *acc, int len, void (*part)(const sx_model *m, int rank, double *acc))
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    double *buf = calloc((size_t)R * (size_t)len, sizeof *buf);
    if (!buf) return false;
    for (int r = 0; r < R; r++) d->scratch[r] = (sx_span){r, r + 1}; /* rank r's running sum: entry r */
    bool ok = true;
    for (int k = 0; ok && k < R; k++) {
        if (k == me) {
            if (k) memcpy(acc, buf + (k - 1) * len, (size_t)len * sizeof *acc);
            part(m, k, acc);
            memcpy(buf + k * len, acc, (size_t)len * sizeof *acc);
        }
        for (int r = 0; r < R; r++) /* the next rank takes rank k's sum; the total goes to all */
            d->all[r] = k + 1 == R || r == k + 1 ? (sx_span){k, k + 1} : (sx_span){0, 0};
        ok = share(d, buf, (size_t)len * sizeof *buf, d->scratch, d->all, 1);
    }
    if (ok) memcpy(acc, buf + (R - 1) * len, (size_t)len * sizeof *acc);
    free(buf);
    return ok;
}

void sx__tape_add(sx_tape *t, int64_t k, double v)
{
    if (t->n == t->cap) {
        const int64_t cap = t->cap ? 2 * t->cap : 1024;
        struct sx_tape_term *q = realloc(t->e, (size_t)cap * sizeof *q);
        if (!q) {
            t->lost = true;
            return;
        }
        t->e = q, t->cap = cap;
    }
    t->e[t->n++] = (struct sx_tape_term){v, k};
}

/* Rank r's part of the step's energy sums (r is this rank: the chain asks
 * only its own): the sums of the chunks and motion blocks that begin among
 * its balls (each a sum from zero in the serial order, which the lower
 * ranks' parts do not touch) and of the wall blocks it shares (wblk: run
 * whole, their sums are the serial ones), then its tape's terms, in their
 * order, onto the sums the lower ranks began. The sums: three per chunk
 * (slip, viscous, released), two per wall block (slip, viscous), three per
 * motion block (damping, loads, the dashpots' share). */
static void energy_part(const sx_model *m, int r, double *acc)
{
    const sx_dd *d = m->dd;
    const int64_t K = m->nchunk, nb = m->nblock;
    double *wall = acc + 3 * K, *motion = wall + 2 * nb;
    for (int64_t c = 0; c < K; c++) {
        const sx_chunk *o = &m->chunks[c];
        if (o->part != SX_DD_PART_START) continue;
        acc[3 * c] = o->slip, acc[3 * c + 1] = o->viscous, acc[3 * c + 2] = o->released;
    }
    for (int64_t b = d->wblk[r].lo; b < d->wblk[r].hi; b++)
        wall[2 * b] = m->blocks[b].slip, wall[2 * b + 1] = m->blocks[b].viscous;
    const sx_span own = d->own[r];
    for (int64_t b = 0; b < nb; b++) {
        const sx_block *o = &m->blocks[b];
        if (o->b0 >= own.lo && o->b0 < own.hi)
            motion[3 * b] = o->damp_work, motion[3 * b + 1] = o->load_work, motion[3 * b + 2] = o->visc_work;
    }
    for (int64_t e = 0; e < d->tape.n; e++) acc[d->tape.e[e].k] += d->tape.e[e].v;
}

/* The serial step adds its chunks' energy sums to m->acc in chunk order,
 * then its wall blocks', then its motion blocks', each sum from zero over
 * its pairs or balls in order; decomposed, a chunk or block may begin on
 * one rank and go on over the next ones. So, after the law of motion (the
 * clumps' terms follow: sx__dd_clump_energy), the sums are chained
 * over the ranks in rank order (energy_part: each rank starts the sums
 * that begin among its own and continues, term by term from its tape,
 * those begun below it), and every rank adds the totals in the serial
 * order: the serial bits in R messages of a few hundred doubles a step.
 * False: out of memory or the ranks could not exchange. */
bool sx__dd_energy(sx_model *m)
{
    sx_dd *d = m->dd;
    const int64_t K = m->nchunk, nb = m->nblock, len = 3 * K + 5 * nb;
    double *s = calloc((size_t)len, sizeof *s);
    const bool ok = s && !d->tape.lost && sx__dd_chain(m, s, (int)len, energy_part);
    d->tape.n = 0;
    for (int64_t c = 0; ok && c < K; c++) {
        m->acc.slip += s[3 * c];
        m->acc.viscous += s[3 * c + 1];
        m->acc.bond_released += s[3 * c + 2];
    }
    for (int64_t b = 0; ok && b < nb; b++) {
        m->acc.slip += s[3 * K + 2 * b];
        m->acc.viscous += s[3 * K + 2 * b + 1];
    }
    for (int64_t b = 0; ok && b < nb; b++) {
        m->acc.local_damping -= s[3 * K + 2 * nb + 3 * b];
        m->acc.boundary_work += s[3 * K + 2 * nb + 3 * b + 1];
        m->acc.viscous += s[3 * K + 2 * nb + 3 * b + 2];
    }
    free(s);
    return ok;
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

sx_status sx__dd_whole(sx_model *m, bool (*replan)(sx_model *))
{
    sx_dd *d = m->dd;
    if (!sx__dd_gather(m)) return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the state");
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
    return d->lazy ? SX_OK : sx__dd_whole(m, replan);
}

void sx_model_gather_lazily(sx_model *m, bool lazily)
{
    if (m->dd) m->dd->lazy = lazily;
}

bool sx_model_scattered(const sx_model *m) { return m->dd && m->dd->scattered; }
