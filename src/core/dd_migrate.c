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
 * whole state (some 100 a ball and 60 a pair in 3D). In periodic space
 * the build copies the balls into their ghosts' slots, the motion stale
 * where the rank does not own the ball: before a contact pass reads a
 * ghost, the step copies it again from its ball (kernels/ghosts.c), which
 * the halo has brought. */
bool sx__dd_build(sx_model *m)
{
    sx_dd *d = m->dd;
    d->migrating = false;
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

/* The rows to move, as hops (decompose.h): a ball has one new owner; a
 * pair may have two new steppers (the ranks of both its balls). */
typedef struct hops {
    sx_hop *h;
    int64_t n, cap;
} hops;

static bool add_hop(hops *q, int64_t k, int from, int to)
{
    if (q->n == q->cap) {
        const int64_t cap = q->cap ? 2 * q->cap : 1024;
        sx_hop *h = realloc(q->h, (size_t)cap * sizeof *h);
        if (!h) return false;
        q->h = h, q->cap = cap;
    }
    q->h[q->n++] = (sx_hop){(int32_t)k, from, to};
    return true;
}

/* The rows f of the hops q, each to its rank alone (sx__dd_route), so
 * the exchange sends a row once to each rank that needs it, where an
 * all-gather sent it to every rank. spans: R * (R + 1). */
static bool move_hops(sx_dd *d, const sx_rows *f, const hops *q, sx_span *spans)
{
    const int R = d->x.ranks;
    sx_route rt = {NULL, 0, 0, spans + (size_t)R * R, spans};
    const bool ok = !q->n || (sx__dd_route(d, q->h, q->n, &rt) && sx__dd_move_rows(d, f, rt.item, 0, rt.n, rt.own, rt.need, R));
    free(rt.item);
    return ok;
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

/* The ranks that step a ball-ball pair: the owners of its balls (the
 * ball a periodic ghost images for its b), both alike when a cut lies
 * between them; the other pairs of a rank's run lie between two of its
 * ghosts and are not its to step. Into r, their count: 0 (a ghost whose
 * ball was removed), 1 or 2. */
static int pair_steppers(const sx_model *m, int64_t c, int *r, int64_t *ball)
{
    const sx_dd *d = m->dd;
    const int64_t n = m->balls.n, a = m->bb.a[c];
    const int64_t b = m->bb.b[c] < n ? m->bb.b[c] : m->cell->owner[m->bb.b[c] - m->cell->base];
    if (b < 0) return 0;
    ball[0] = a, ball[1] = b;
    r[0] = sx__dd_owner_of(d, a, n), r[1] = sx__dd_owner_of(d, b, n);
    return r[1] == r[0] ? 1 : 2;
}

/* The new ball-ball pairs a rank steps whose old pair it did not step,
 * from the rank that holds the old pair's history (the owner of its first
 * ball) to each rank that steps the new pair (pair_steppers). A rank that
 * owned either ball of the old pair stepped it, so its copy is current.
 * old[i]: ball i's owner in the last plan. Every rank lists every pair, so
 * the walk is kept cheap: the pairs run in the order of a, so a's owner
 * follows it, and b's is found from a's; the old pair's holder is sought
 * only for a pair that moves. */
static bool ball_pair_hops(const sx_model *m, const int32_t *old, hops *q)
{
    const sx_dd *d = m->dd;
    const sx_pairs *p = &m->bb;
    const int32_t *src = d->src_bb;
    const int64_t n = d->nsrc_bb < p->n ? d->nsrc_bb : p->n, nb = m->balls.n;
    const int R = d->x.ranks;
    int ra = 0;
    q->n = 0;
    for (int64_t c = 0; c < n; c++) {
        if (!src[c]) continue;
        const int64_t a = p->a[c];
        while (d->own[ra].hi <= a) ra++;
        int64_t b = p->b[c];
        int rb = ra;
        if (b >= nb) { /* a periodic ghost: its ball's owner steps the pair too */
            b = m->cell->owner[b - m->cell->base];
            if (b < 0) continue;
            rb = sx__dd_owner_of(d, b, nb);
        } else if (b >= d->own[ra].lo) {
            while (d->own[rb].hi <= b) rb++;
        } else {
            rb = sx__dd_owner_of(d, b, nb);
        }
        const int r[2] = {ra, rb};
        for (int j = 0; j < (ra == rb ? 1 : 2); j++) {
            if (old[a] == r[j] || old[b] == r[j]) continue;
            const int o = span_owner(d->bb_was, R, (src[c] > 0 ? src[c] : -src[c]) - 1);
            if (o != r[j] && !add_hop(q, c, o, r[j])) return false;
        }
    }
    return true;
}

/* The same for the ball-wall pairs, which every rank steps whose wall
 * blocks hold their ball (a block across a cut, by both), from the owner
 * of the old pair's ball, to each such rank but that one. */
static bool wall_pair_hops(const sx_model *m, hops *q)
{
    const sx_dd *d = m->dd;
    const int R = d->x.ranks;
    q->n = 0;
    for (int r = 0; r < R; r++) {
        const sx_span s = wall_pairs_run(m, r);
        for (int64_t c = s.lo; c < s.hi && c < d->nsrc_bw; c++) {
            if (!d->src_bw[c]) continue;
            const int o = span_owner(d->bw_was, R, (d->src_bw[c] > 0 ? d->src_bw[c] : -d->src_bw[c]) - 1);
            if (o != r && !add_hop(q, c, o, r)) return false;
        }
    }
    return true;
}

/* The bonds of this plan's pairs that a rank now steps and did not (it
 * owned neither ball of the old pair, whose steppers both held the bond
 * current), from the rank whose run held the old pair, as hops; and into
 * from[s] that rank for each bond that left the plan (-1 for the others). */
static bool bond_hops(const sx_model *m, const int32_t *old, int32_t *from, hops *q)
{
    const sx_dd *d = m->dd;
    const sx_pairs *p = &m->bb;
    q->n = 0;
    for (int64_t s = 0; s < m->bonds.n; s++) from[s] = d->slot_was[s]; /* -1: in no pair of the last plan */
    for (int64_t c = 0; c < p->n; c++) {
        const int32_t s = p->bond[c] - 1;
        if (s < 0) continue;
        from[s] = -1; /* in a pair of this plan */
        int r[2];
        int64_t ball[2];
        const int k = d->slot_was[s] >= 0 ? pair_steppers(m, c, r, ball) : 0;
        for (int j = 0; j < k; j++)
            if (d->slot_was[s] != r[j] && old[ball[0]] != r[j] && old[ball[1]] != r[j] && !add_hop(q, s, d->slot_was[s], r[j]))
                return false;
    }
    return true;
}

/* The bonds' state (with a flat joint's face and elements) another rank
 * stepped, to each rank that now steps it alone; a bond that left the plan
 * (broken, its pair gone) to every rank, as it is no rank's to step and
 * every rank's copy is its last state. from, list: room for the bonds. */
static bool move_bonds(sx_model *m, const int32_t *old, int32_t *from, int32_t *list, sx_span *spans, hops *q)
{
    sx_dd *d = m->dd;
    const int64_t nb = m->bonds.n;
    const int R = d->x.ranks;
    const bool joints = m->fjel.n > 0;
    if (!bond_hops(m, old, from, q)) return false;
    sx_route rt = {NULL, 0, 0, spans + (size_t)R * R, spans};
    const sx_rows f = sx__dd_bond_rows(m, false);
    bool ok = !q->n || (sx__dd_route(d, q->h, q->n, &rt) && sx__dd_move_rows(d, &f, rt.item, 0, rt.n, rt.own, rt.need, R) &&
                        (!joints || sx__dd_share_fjoints(m, rt.item, rt.n, rt.own, rt.need, R)));
    free(rt.item);
    if (ok) {
        const int64_t k = list_by_owner(d, from, nb, list, spans);
        ok = sx__dd_share_bonds(m, list, k, spans, false) &&
             (!joints || sx__dd_share_fjoints(m, list, k, spans, sx__dd_everything(d, k), 1));
    }
    return ok;
}

/* After the build's plan: to the ranks that now step them, the balls
 * whose owner changed (velocity, spin, force, moment: the positions every
 * rank took before the build), the pairs whose history another rank
 * holds, and the bonds (with a flat joint's face and elements) another
 * rank stepped, or that left the plan (broken: their last state to every
 * rank). Every rank lists the same entries (from what all hold alike);
 * each sends the rows it held to the ranks that now step them alone (the
 * other ranks' copies are stale, and none reads them: a ghost's motion
 * comes with the step's halo, a pair's or a bond's state from the rank
 * that stepped it last), and a bond that left the plan to every rank. */
bool sx__dd_migrate(sx_model *m)
{
    sx_dd *d = m->dd;
    if (!d->migrating) return true;
    d->migrating = false;
    const sx_balls *B = &m->balls;
    const sx_bonds *bs = &m->bonds;
    const int R = d->x.ranks;
    int32_t *from = malloc((size_t)(bs->n + 1) * sizeof *from), *list = malloc((size_t)(bs->n + 1) * sizeof *list),
            *old = malloc((size_t)(B->n + 1) * sizeof *old);
    sx_span *spans = malloc((size_t)R * (size_t)(R + 1) * sizeof *spans);
    hops q = {NULL, 0, 0};
    bool ok = from && list && old && spans;
    if (ok) { /* the balls */
        int to = 0;
        for (int64_t i = 0; i < B->n && ok; i++) {
            while (d->own[to].hi <= i) to++;
            old[i] = d->was[B->id[i]];
            if (old[i] != to) ok = add_hop(&q, i, old[i], to);
        }
        const sx_rows f = sx__dd_ball_motion(m, false);
        ok = ok && move_hops(d, &f, &q, spans);
    }
    if (ok) { /* the ball-ball pairs, then the ball-wall pairs */
        const sx_rows fb = pair_rows(m, &m->bb), fw = pair_rows(m, &m->bw);
        ok = ball_pair_hops(m, old, &q) && move_hops(d, &fb, &q, spans) && wall_pair_hops(m, &q) &&
             move_hops(d, &fw, &q, spans);
    }
    if (ok && bs->n && m->bb.bond) ok = move_bonds(m, old, from, list, spans, &q);
    free(q.h);
    free(spans);
    free(old);
    free(list);
    free(from);
    return ok;
}
