/* Domain decomposition over ranks (issue 16), with results bit-identical
 * to a serial run for any number of ranks; docs/developer.md, "MPI domain
 * decomposition", has the design and what is left.
 *
 * The core makes no MPI call: the caller's sx_exchange moves bytes. Between
 * cycles every rank holds the whole model, the same on all ranks (checked
 * by its hash when a cycle starts). Inside a cycle rank r owns the balls
 * own[r], a contiguous range of dense indices: the broad phase sorts balls
 * by cell with the last axis slowest, so a range is a slab across that
 * axis, cut to balance the ball count (and cut again at every build, which
 * is where balls migrate). Each step it
 *   - refreshes its ghosts, the balls need[2r] below and need[2r + 1]
 *     above its own, from their owners (positions, velocities, spins);
 *   - evaluates the ball-ball pairs pairs[r]: every pair of its balls, in
 *     the serial chunks, clipped (a ball's contributions thus arrive in the
 *     serial order, whatever the cut; pairs between ghosts come along and
 *     are evaluated as their owners evaluate them);
 *   - evaluates whole the wall blocks with a ball of its own, wrun[r]
 *     (their other balls are ghosts), so each block's partial wall
 *     resultant is the serial one; the blocks whose last ball it owns,
 *     wblk[r], are its to share, and every rank adds all blocks' sums in
 *     block order;
 *   - integrates its own balls, and takes the largest displacement of all
 *     ranks (a maximum, exact in any order) for the rebuild criterion.
 * A build, the energy guard and the end of the cycle first gather the
 * whole state on every rank (each ball from its owner, each pair from the
 * owner of its first ball); the build itself is the serial one, on every
 * rank. */
#include "model_internal.h"

#include <stdlib.h>
#include <string.h>

static const char *not_decomposed(const sx_model *m)
{
    if (m->bonds.n) return "bonds";
    if (m->clumps) return "clumps";
    if (m->cell) return "periodic space";
    if (m->njoint) return "smooth joints";
    if (m->track_energy) return "energy tracking";
    for (int64_t w = 0; w < m->nwall; w++)
        if (m->walls[w].mesh) return "mesh walls";
    return NULL;
}

void sx__dd_free(sx_model *m)
{
    sx_dd *d = m->dd;
    if (!d) return;
    free(d->own);
    free(d);
    m->dd = NULL;
}

sx_status sx_model_decompose(sx_model *m, const sx_exchange *x)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "decompose: the model is stepping");
    sx__dd_free(m);
    if (!x || x->ranks <= 1) return SX_OK;
    if (!x->share || !x->max || !x->agree || x->rank < 0 || x->rank >= x->ranks)
        return sx__fail(m, SX_EINVAL, "decompose: an exchange needs share, max, agree and a rank below its ranks");
    sx_dd *d = calloc(1, sizeof *d);
    const size_t r = (size_t)x->ranks;
    /* own, need (2 per rank), pairs, wblk, wrun, bb_own, bw_own, all: 9 spans per rank */
    sx_span *s = d ? calloc(9 * r, sizeof *s) : NULL;
    if (!s) {
        free(d);
        return sx__fail(m, SX_ENOMEM, "decompose: out of memory");
    }
    d->x = *x;
    d->own = s, d->need = s + r, d->pairs = s + 3 * r, d->wblk = s + 4 * r;
    d->wrun = s + 5 * r, d->bb_own = s + 6 * r, d->bw_own = s + 7 * r, d->all = s + 8 * r;
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

/* The spans of every rank from the whole, current pair stores (after a
 * build, or when a cycle starts), and this rank's clipped chunks. */
void sx__dd_plan(sx_model *m)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    const int64_t n = m->balls.n;
    const sx_pairs *p = &m->bb;
    for (int r = 0; r < R; r++) d->own[r] = (sx_span){n * r / R, n * (r + 1) / R};
    /* the lowest first ball of a pair whose second ball each rank owns */
    for (int r = 0; r < R; r++) d->pairs[r].lo = d->own[r].lo; /* lo: a ball index until made a pair index */
    for (int64_t c = 0; c < p->n; c++) {
        sx_span *q = &d->pairs[owner_of(d, p->b[c], n)];
        if (p->a[c] < q->lo) q->lo = p->a[c];
    }
    int64_t bl = 0; /* the blocks are in order: the first whose last ball reaches each rank */
    for (int r = 0; r < R; r++) {
        sx_span *own = &d->own[r], *pr = &d->pairs[r], *wb = &d->wblk[r];
        const int64_t lo_a = pr->lo;
        pr->lo = sx__first_at(p->a, p->n, lo_a);
        pr->hi = sx__first_at(p->a, p->n, own->hi);
        int64_t hi = own->hi;
        for (int64_t c = pr->lo; c < pr->hi; c++)
            if (p->b[c] + 1 > hi) hi = p->b[c] + 1;
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
        d->need[2 * r] = (sx_span){lo, own->lo};
        d->need[2 * r + 1] = (sx_span){own->hi, hi};
        d->bb_own[r] = (sx_span){sx__first_at(p->a, p->n, own->lo), sx__first_at(p->a, p->n, own->hi)};
        d->bw_own[r] = (sx_span){sx__first_at(m->bw.a, m->bw.n, own->lo), sx__first_at(m->bw.a, m->bw.n, own->hi)};
    }
    /* this rank's chunks: the serial ones, clipped to its pairs; the balls
     * they clear, to its own and its ghosts */
    const sx_span pr = d->pairs[me], lo = d->need[2 * me], hi = d->need[2 * me + 1];
    for (int64_t c = 0; c < m->nchunk; c++) {
        sx_chunk *o = &m->chunks[c];
        o->first = o->first < pr.lo ? pr.lo : o->first > pr.hi ? pr.hi : o->first;
        o->last = o->last < o->first ? o->first : o->last > pr.hi ? pr.hi : o->last;
        if (o->clear_lo < lo.lo) o->clear_lo = lo.lo;
        if (o->clear_hi > hi.hi) o->clear_hi = hi.hi;
        if (o->clear_hi < o->clear_lo) o->clear_hi = o->clear_lo;
    }
}

/* [0, count) for every rank: what a gather needs. */
static const sx_span *everything(sx_dd *d, int64_t count)
{
    for (int r = 0; r < d->x.ranks; r++) d->all[r] = (sx_span){0, count};
    return d->all;
}

static bool share(sx_dd *d, void *data, size_t size, const sx_span *own, const sx_span *need, int per)
{
    return d->x.share(d->x.ud, data, size, own, need, per);
}

bool sx__dd_halo(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_balls *B = &m->balls;
    const size_t v = (size_t)m->dim * sizeof(double), w = (size_t)m->rdim * sizeof(double);
    return share(d, B->x, v, d->own, d->need, 2) && share(d, B->v, v, d->own, d->need, 2) &&
           share(d, B->w, w, d->own, d->need, 2);
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

bool sx__dd_gather(sx_model *m)
{
    sx_dd *d = m->dd;
    sx_balls *B = &m->balls;
    const size_t v = (size_t)m->dim * sizeof(double), w = (size_t)m->rdim * sizeof(double);
    const sx_span *all = everything(d, B->n);
    return share(d, B->x, v, d->own, all, 1) && share(d, B->v, v, d->own, all, 1) &&
           share(d, B->w, w, d->own, all, 1) && share(d, B->f, v, d->own, all, 1) &&
           share(d, B->t, w, d->own, all, 1) && gather_pairs(m, &m->bb, d->bb_own) &&
           gather_pairs(m, &m->bw, d->bw_own);
}

bool sx__dd_walls(sx_model *m)
{
    sx_dd *d = m->dd;
    if (!m->nwall) return true;
    return share(d, m->wall_acc, (size_t)m->nwall * sizeof *m->wall_acc, d->wblk, everything(d, m->nblock), 1);
}

sx_status sx__dd_begin(sx_model *m)
{
    sx_dd *d = m->dd;
    const char *what = not_decomposed(m);
    if (what)
        return sx__fail(m, SX_EINVAL, "cycle: %s cannot yet run decomposed over %d ranks (issue 16's first milestone: "
                                      "unbonded balls and walls); run it serially",
                        what, d->x.ranks);
    if (!d->x.agree(d->x.ud, sx_model_state_hash(m)))
        return sx__fail(m, SX_EINVAL,
                        "cycle: the model differs between the %d ranks (every rank must make the same calls: "
                        "random numbers without a fixed seed, or a branch on seixo.rank()?)",
                        d->x.ranks);
    sx__dd_plan(m);
    d->active = true;
    return SX_OK;
}

sx_status sx__dd_end(sx_model *m, bool (*replan)(sx_model *))
{
    sx_dd *d = m->dd;
    d->active = false;
    if (!sx__dd_gather(m)) return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the state");
    if (!replan(m)) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    return SX_OK;
}
