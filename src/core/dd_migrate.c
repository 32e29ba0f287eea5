/* The build inside a decomposed cycle and the migration after its plan
 * (decompose.h): every rank's serial build from what it reads alone, and
 * the rows the new cut gives another rank, moved to it. */
#include "clumps.h"
#include "decompose.h"

#include <stdlib.h>
#include <string.h>

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
    return !p->n || (sx__dd_share(d, p->touching, sizeof *p->touching, own, sx__dd_everything(d, p->n), 1) &&
                     (!p->bond || sx__dd_share(d, p->bond, sizeof *p->bond, own, sx__dd_everything(d, p->n), 1)));
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
    if (!sx__dd_share_pace(m) || !sx__dd_share(d, B->x, (size_t)m->dim * sizeof(double), d->own, sx__dd_everything(d, B->n), 1) ||
        !share_flags(m, &m->bb, d->bb_own) || !share_flags(m, &m->bw, d->bw_own) ||
        (nb && (!sx__dd_share_bonds(m, d->bslot, d->nbslot, d->bs_own, true) || !sx__dd_gather_cracks(m))) ||
        (m->clumps && m->clumps->n && !sx__dd_clumps(m)))
        return false;
    sx__dd_count_intact(m);
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
        if (!f[k].end) sx__rows_add(&r, *f[k].data, sx__pair_size(&f[k]) * (size_t)f[k].per);
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
    return sx__dd_move_rows(d, f, list, 0, k, runs, sx__dd_everything(d, k), 1);
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
            from[i] = o != sx__dd_owner_of(d, i, B->n) ? o : -1;
        }
        const sx_rows f = sx__dd_ball_motion(m, false);
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
        ok = sx__dd_share_bonds(m, list, k, runs, false) && (!m->fjel.n || sx__dd_share_fjoints(m, list, k, runs));
    }
    free(runs);
    free(list);
    free(from);
    return ok;
}
