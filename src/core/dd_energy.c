/* The energy sums of a decomposed step in the serial order (decompose.h):
 * the chains over the ranks, their tapes, and the clumps' terms. */
#include "clumps.h"
#include "decompose.h"

#include <stdlib.h>
#include <string.h>

/* The serial step adds, after the balls' blocks, the clumps' blocks'
 * energy sums (size clumps a block, each sum from zero over its clumps'
 * terms in clump order) to m->acc in block order. The owners' terms
 * (w a clump at its entry cl_at, the first nd its damping's, a term
 * absent from the serial sum a zero: adding +0 to a sum from +0 changes
 * no bit) go to the rank that sums their block (the blocks cut evenly
 * over the ranks, in order), and the block sums to every rank, which adds
 * them in block order: two messages a step per pair of ranks, only with
 * energy tracking, each term sent once. The owners write their clumps'
 * terms where the exchange sends them from (sx__dd_clump_terms), in a
 * buffer kept from step to step. */
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

/* The first entry of the run s (in clump order) whose clump is c or after. */
static int64_t first_clump_at(const sx_dd *d, sx_span s, int64_t c)
{
    int64_t lo = s.lo, hi = s.hi;
    while (lo < hi) {
        const int64_t mid = lo + (hi - lo) / 2;
        if (d->cl[mid] < c) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

bool sx__dd_clump_energy(sx_model *m, int w, int nd, int64_t size)
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    const int64_t nc = m->clumps->n, nblk = (nc + size - 1) / size;
    if (!nc) return true; /* every clump removed: no block, on every rank */
    double *t = d->cterm, *sum = t + d->ncl * w;
    sx_span *need = d->cterm_need; /* need[r * R + s]: rank s's terms of r's blocks */
    for (int r = 0; r < R; r++) { /* rank r sums the blocks [nblk r / R, nblk (r + 1) / R) */
        d->scratch[r] = (sx_span){nblk * r / R, nblk * (r + 1) / R};
        const int64_t c0 = d->scratch[r].lo * size, c1 = d->scratch[r].hi * size;
        for (int s = 0; s < R; s++)
            need[r * R + s] = (sx_span){first_clump_at(d, d->cl_own[s], c0), first_clump_at(d, d->cl_own[s], c1)};
    }
    bool ok = sx__dd_share(d, t, (size_t)w * sizeof *t, d->cl_own, need, R);
    for (int64_t k = d->scratch[me].lo; ok && k < d->scratch[me].hi; k++) {
        double damp = 0, load = 0;
        for (int64_t c = k * size; c < (k + 1) * size && c < nc; c++) {
            const double *q = t + (int64_t)d->cl_at[c] * w;
            for (int j = 0; j < nd; j++) damp += q[j];
            for (int j = nd; j < w; j++) load += q[j];
        }
        sum[2 * k] = damp, sum[2 * k + 1] = load;
    }
    ok = ok && sx__dd_share(d, sum, 2 * sizeof *sum, d->scratch, sx__dd_everything(d, nblk), 1);
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
 * terms to acc (len doubles). The running sum moves in acc itself (each
 * step's one entry: rank k's, to rank k + 1, the last to all), so nothing
 * is allocated. False: the ranks could not exchange. */
bool sx__dd_chain(const sx_model *m, double *acc, int len, void (*part)(const sx_model *m, int rank, double *acc))
{
    sx_dd *d = m->dd;
    const int R = d->x.ranks, me = d->x.rank;
    bool ok = true;
    for (int k = 0; ok && k < R; k++) {
        if (k == me) part(m, k, acc); /* onto the sum rank k - 1 sent (rank 0: acc as given) */
        for (int r = 0; r < R; r++) {
            d->scratch[r] = r == k ? (sx_span){0, 1} : (sx_span){0, 0};
            d->all[r] = k + 1 == R || r == k + 1 ? (sx_span){0, 1} : (sx_span){0, 0};
        }
        ok = sx__dd_share(d, acc, (size_t)len * sizeof *acc, d->scratch, d->all, 1);
    }
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
    acc[3 * K + 5 * nb] += d->tape.lost; /* the ranks whose tape ran out of memory: every rank learns of them */
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
    double s[3 * SX_CHUNKS_MAX + 5 * SX_MOTION_BLOCKS + 1] = {0}; /* no allocation in a step's exchange */
    const bool ok = sx__dd_chain(m, s, (int)len + 1, energy_part) && s[len] == 0;
    d->tape.lost = false;
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
    return ok;
}
