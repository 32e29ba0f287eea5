/* The clump store's memory (the store is described in clumps.h): its
 * arrays made, grown and given back, all through the model's tracked
 * allocator; and what a restart needs of it: the arrays sized to a saved
 * store, the saved store checked once the I/O layer has filled them, and
 * the hash of what it restores. The store's fields are listed here (and in
 * sx_clump_remove's shift of the rows, clumps.c, and the snapshot's
 * /clumps, src/io/snapshot_parts.c). */
#include "clumps_internal.h"
#include "state.h"

#include <math.h>
#include <string.h>

/* ------------------------------------------------------------ storage */

#define GROW(s, field, per, newcap)                                                                  \
    do {                                                                                             \
        void *q_ = sx_alloc_resize(&m->alloc, (s)->field, (size_t)((s)->cap * (per)),                \
                                   (size_t)((newcap) * (per)), sizeof *(s)->field);                   \
        if (!q_) return SX_ENOMEM;                                                                   \
        (s)->field = q_;                                                                             \
    } while (0)

static sx_status clumps_create(sx_model *m)
{
    if (m->clumps) return SX_OK;
    sx_clumps *C = sx_alloc_resize(&m->alloc, NULL, 0, 1, sizeof *C);
    if (!C) return SX_ENOMEM;
    C->next_id = 1;
    m->clumps = C;
    return SX_OK;
}

/* Every per-clump array to exactly cap clumps. */
static sx_status clumps_resize(sx_model *m, int64_t cap)
{
    sx_clumps *C = m->clumps;
    const int d = m->dim, r = m->rdim, qd = qdim(m);
    GROW(C, id, 1, cap);
    GROW(C, tpl_of, 1, cap);
    GROW(C, mat, 1, cap);
    GROW(C, fix, 1, cap);
    GROW(C, scale, 1, cap);
    GROW(C, x, d, cap);
    GROW(C, v, d, cap);
    GROW(C, q, qd, cap);
    if (d == 3) GROW(C, L, 3, cap);
    GROW(C, w, r, cap);
    GROW(C, f, d, cap);
    GROW(C, t, r, cap);
    GROW(C, alpha, 1, cap);
    GROW(C, mass, 1, cap);
    GROW(C, inertia, r, cap);
    GROW(C, first, 1, cap);
    C->cap = cap;
    return SX_OK;
}

static sx_status clumps_reserve(sx_model *m, int64_t n)
{
    sx_clumps *C = m->clumps;
    if (n <= C->cap) return SX_OK;
    int64_t cap = C->cap * 2 > n ? C->cap * 2 : n;
    if (cap < 16) cap = 16;
    if (cap > INT32_MAX / 4) return SX_ENOMEM;
    return clumps_resize(m, cap);
}

/* The pebble list to hold n ids. */
static sx_status pebbles_reserve(sx_model *m, int64_t n)
{
    sx_clumps *C = m->clumps;
    if (n <= C->pcap) return SX_OK;
    int64_t cap = C->pcap * 2 > n ? C->pcap * 2 : n;
    if (cap < 64) cap = 64;
    if (cap > INT32_MAX) return SX_ENOMEM;
    int32_t *q = sx_alloc_resize(&m->alloc, C->pebble, (size_t)C->pcap, (size_t)cap, sizeof *q);
    if (!q) return SX_ENOMEM;
    C->pebble = q;
    C->pcap = cap;
    return SX_OK;
}

static sx_status index_reserve(sx_model *m, int64_t need)
{
    sx_clumps *C = m->clumps;
    return sx_alloc_reserve_index(&m->alloc, &C->index_of, &C->index_cap, need) ? SX_OK : SX_ENOMEM;
}

/* The template pebble arrays to exactly cap pebbles. All three are made
 * anew before any is given up, so a failure leaves the old ones intact. */
static sx_status tp_resize(sx_model *m, int64_t cap)
{
    sx_clumps *C = m->clumps;
    const int d = m->dim;
    double **field[3] = {&C->tp_pos, &C->tp_rad, &C->tp_body};
    const int per[3] = {d, 1, d};
    double *fresh[3] = {NULL, NULL, NULL};
    for (int k = 0; k < 3; k++) {
        fresh[k] = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(cap * per[k]), sizeof(double));
        if (!fresh[k]) {
            for (int j = 0; j < k; j++) sx_alloc_free(&m->alloc, fresh[j], (size_t)(cap * per[j]), sizeof(double));
            return SX_ENOMEM;
        }
    }
    for (int k = 0; k < 3; k++) {
        if (C->tp_n) memcpy(fresh[k], *field[k], (size_t)(C->tp_n * per[k]) * sizeof(double));
        sx_alloc_free(&m->alloc, *field[k], (size_t)(C->tp_cap * per[k]), sizeof(double));
        *field[k] = fresh[k];
    }
    C->tp_cap = cap;
    return SX_OK;
}

sx_status sx__clump_template_reserve(sx_model *m, int64_t n)
{
    if (clumps_create(m)) return SX_ENOMEM;
    sx_clumps *C = m->clumps;
    if (C->ntpl == C->cap_tpl) {
        if (C->ntpl >= INT16_MAX) return SX_ENOMEM;
        const int cap = C->cap_tpl ? 2 * C->cap_tpl : 4;
        sx_clump_tpl *q = sx_alloc_resize(&m->alloc, C->tpl, (size_t)C->cap_tpl, (size_t)cap, sizeof *q);
        if (!q) return SX_ENOMEM;
        C->tpl = q;
        C->cap_tpl = cap;
    }
    const int64_t need = C->tp_n + n;
    if (need <= C->tp_cap) return SX_OK;
    const int64_t cap = C->tp_cap * 2 > need ? C->tp_cap * 2 : need;
    return cap > INT32_MAX ? SX_ENOMEM : tp_resize(m, cap);
}

void sx__clumps_free(sx_model *m)
{
    sx_clumps *C = m->clumps;
    if (!C) return;
    const size_t c = (size_t)C->cap, d = (size_t)m->dim, r = (size_t)m->rdim, qd = (size_t)qdim(m);
    const size_t tp = (size_t)C->tp_cap;
    sx_alloc *a = &m->alloc;
    sx_alloc_free(a, C->tpl, (size_t)C->cap_tpl, sizeof *C->tpl);
    sx_alloc_free(a, C->tp_pos, tp * d, sizeof(double));
    sx_alloc_free(a, C->tp_rad, tp, sizeof(double));
    sx_alloc_free(a, C->tp_body, tp * d, sizeof(double));
    sx_alloc_free(a, C->id, c, sizeof(int32_t));
    sx_alloc_free(a, C->tpl_of, c, sizeof(int32_t));
    sx_alloc_free(a, C->mat, c, sizeof(uint16_t));
    sx_alloc_free(a, C->fix, c, sizeof(uint8_t));
    sx_alloc_free(a, C->scale, c, sizeof(double));
    sx_alloc_free(a, C->x, c * d, sizeof(double));
    sx_alloc_free(a, C->v, c * d, sizeof(double));
    sx_alloc_free(a, C->q, c * qd, sizeof(double));
    sx_alloc_free(a, C->L, C->L ? c * 3 : 0, sizeof(double));
    sx_alloc_free(a, C->w, c * r, sizeof(double));
    sx_alloc_free(a, C->f, c * d, sizeof(double));
    sx_alloc_free(a, C->t, c * r, sizeof(double));
    sx_alloc_free(a, C->alpha, c, sizeof(double));
    sx_alloc_free(a, C->mass, c, sizeof(double));
    sx_alloc_free(a, C->inertia, c * r, sizeof(double));
    sx_alloc_free(a, C->first, c, sizeof(int64_t));
    sx_alloc_free(a, C->pebble, (size_t)C->pcap, sizeof(int32_t));
    sx_alloc_free(a, C->index_of, (size_t)C->index_cap, sizeof(int32_t));
    sx_alloc_free(a, C, 1, sizeof *C);
    m->clumps = NULL;
}

/* The balls' clump ids, allocated with the first clump at the balls' capacity. */
static sx_status ball_clump_array(sx_model *m)
{
    sx_balls *b = &m->balls;
    if (b->clump || b->cap == 0) return SX_OK;
    b->clump = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)b->cap, sizeof *b->clump);
    return b->clump ? SX_OK : SX_ENOMEM;
}

sx_status sx__clump_reserve(sx_model *m, int64_t n)
{
    sx_clumps *C = m->clumps;
    if (clumps_reserve(m, C->n + 1) || pebbles_reserve(m, C->pn + n) || index_reserve(m, C->next_id + 1) ||
        sx__balls_reserve(m, m->balls.n + n) || ball_clump_array(m))
        return SX_ENOMEM;
    return SX_OK;
}

/* ------------------------------------------------------------- restore */

sx_status sx__clumps_alloc(sx_model *m, const sx_clump_sizes *s)
{
    if (s->templates == 0 && s->clumps == 0 && s->template_pebbles == 0 && s->pebbles == 0) return SX_OK;
    if (m->clumps) return sx__fail(m, SX_EINVAL, "state: the model to restore into already has clumps");
    if (s->templates < 0 || s->templates > INT16_MAX || s->template_pebbles < s->templates ||
        s->template_pebbles > INT32_MAX || s->clumps < 0 || s->clumps > INT32_MAX / 4 || s->pebbles < s->clumps ||
        s->pebbles > m->balls.n || s->next_id < s->clumps + 1 || s->next_id >= INT32_MAX ||
        (s->clumps > 0 && s->templates == 0))
        return sx__fail(m, SX_EINVAL,
                        "state: clump sizes out of range (%d templates of %lld pebbles, %lld clumps of %lld pebbles, "
                        "next id %lld, %lld balls)",
                        s->templates, (long long)s->template_pebbles, (long long)s->clumps, (long long)s->pebbles,
                        (long long)s->next_id, (long long)m->balls.n);
    if (clumps_create(m)) goto nomem;
    sx_clumps *C = m->clumps;
    C->tpl = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)s->templates, sizeof *C->tpl);
    if (s->templates && !C->tpl) goto nomem;
    C->cap_tpl = C->ntpl = s->templates;
    if (s->template_pebbles && tp_resize(m, s->template_pebbles)) goto nomem;
    C->tp_n = s->template_pebbles;
    if (s->clumps && clumps_resize(m, s->clumps)) goto nomem;
    C->n = s->clumps;
    if (s->pebbles && pebbles_reserve(m, s->pebbles)) goto nomem;
    C->pn = s->pebbles;
    if (index_reserve(m, s->next_id) || ball_clump_array(m)) goto nomem;
    C->next_id = s->next_id;
    return SX_OK;
nomem:
    return sx__fail(m, SX_ENOMEM, "state: out of memory for %lld clumps", (long long)s->clumps);
}

sx_status sx__clumps_finish(sx_model *m)
{
    sx_clumps *C = m->clumps;
    if (!C) return SX_OK;
    const int d = m->dim, r = m->rdim, qd = qdim(m);
    int64_t next = 0;
    for (int i = 0; i < C->ntpl; i++) {
        const sx_clump_tpl *t = &C->tpl[i];
        if (!memchr(t->name, 0, sizeof t->name) || !t->name[0])
            return sx__fail(m, SX_EINVAL, "state: clump template %d has no valid name", i);
        for (int j = 0; j < i; j++)
            if (strcmp(C->tpl[j].name, t->name) == 0)
                return sx__fail(m, SX_EINVAL, "state: clump template '%s' appears twice", t->name);
        if (t->first != next || t->n < 1 || t->n > C->tp_n - next)
            return sx__fail(m, SX_EINVAL, "state: clump template '%s' has a bad pebble range", t->name);
        next += t->n;
        if (!(t->volume > 0) || !(t->principal[0] > 0) || !(t->power_sum > 0) || !sx__state_finite(t->principal, 3) ||
            !sx__state_finite(t->frame, 4) || !isfinite(t->volume) || !isfinite(t->power_sum))
            return sx__fail(m, SX_EINVAL, "state: clump template '%s' has bad mass properties", t->name);
        for (int64_t k = t->first; k < t->first + t->n; k++)
            if (!(C->tp_rad[k] > 0) || !sx__state_length_finite(C->tp_body + k * d, d))
                return sx__fail(m, SX_EINVAL, "state: clump template '%s' has a bad pebble", t->name);
    }
    if (next != C->tp_n) return sx__fail(m, SX_EINVAL, "state: the clump templates do not cover their pebbles");
    sx_balls *B = &m->balls;
    if (B->clump) memset(B->clump, 0, (size_t)B->n * sizeof *B->clump);
    for (int64_t id = 0; id < C->index_cap; id++) C->index_of[id] = -1;
    next = 0;
    for (int64_t c = 0; c < C->n; c++) {
        const int64_t id = C->id[c];
        const sx_status st = sx__state_map_id(m, "clump", C->index_of, C->next_id, c, id);
        if (st) return st;
        if (C->tpl_of[c] < 0 || C->tpl_of[c] >= C->ntpl || C->mat[c] >= m->nmat)
            return sx__fail(m, SX_EINVAL, "state: clump %lld has a bad template or material", (long long)id);
        const unsigned valid = d == 3 ? (SX_FIX_VEL | SX_FIX_SPIN) : (SX_FIX_VX | SX_FIX_VY | SX_FIX_WX);
        if (C->fix[c] & ~valid) return sx__fail(m, SX_EINVAL, "state: clump %lld has invalid fixity bits", (long long)id);
        const int64_t np = C->tpl[C->tpl_of[c]].n;
        if (C->first[c] != next || np > C->pn - next)
            return sx__fail(m, SX_EINVAL, "state: clump %lld has a bad pebble range", (long long)id);
        next += np;
        if (!(C->scale[c] > 0) || !(C->mass[c] > 0) || !(C->alpha[c] >= 0 && C->alpha[c] < 1) ||
            !sx__state_length_finite(C->x + c * d, d) || !sx__state_length_finite(C->v + c * d, d) ||
            !sx__state_length_finite(C->w + c * r, r) || !sx__state_finite(C->q + c * qd, qd) ||
            (C->L && !sx__state_length_finite(C->L + c * 3, 3)) || !isfinite(C->mass[c]) ||
            !isfinite(C->scale[c]))
            return sx__fail(m, SX_EINVAL, "state: clump %lld has a non-finite or out-of-range state", (long long)id);
        if (qd == 4) { /* a unit quaternion as saved (a zero one made a NaN orientation) */
            const double *q = C->q + c * 4;
            if (!(fabs(sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) - 1) < 1e-6))
                return sx__fail(m, SX_EINVAL, "state: clump %lld has an orientation that is not a unit quaternion",
                                (long long)id);
        }
        for (int k = 0; k < r; k++)
            if (!(C->inertia[c * r + k] > 0) || !isfinite(C->inertia[c * r + k]))
                return sx__fail(m, SX_EINVAL, "state: clump %lld has an inertia <= 0", (long long)id);
        for (int64_t k = 0; k < np; k++) {
            const int64_t i = sx__ball_index(m, C->pebble[C->first[c] + k]);
            if (i < 0) return sx__fail(m, SX_EINVAL, "state: clump %lld has a pebble that is no ball", (long long)id);
            if (B->clump[i]) return sx__fail(m, SX_EINVAL, "state: ball %d is a pebble of two clumps", C->pebble[C->first[c] + k]);
            B->clump[i] = (int32_t)id;
        }
    }
    if (next != C->pn) return sx__fail(m, SX_EINVAL, "state: the clumps do not cover their pebbles");
    return SX_OK;
}

/* What a restart restores of the clumps (the snapshot's /clumps): every
 * template, the clumps' count, and (sx__clumps_bag) each clump's digest
 * (its pebbles as ball ids), each double with -0 as +0, as the state hash
 * takes the rest (state.c). */
uint64_t sx__clumps_hash(const sx_model *m, uint64_t h)
{
    const sx_clumps *C = m->clumps;
    const int d = m->dim;
    h = sx__fnv(h, &C->ntpl, sizeof C->ntpl);
    for (int i = 0; i < C->ntpl; i++) {
        const sx_clump_tpl *t = &C->tpl[i];
        h = sx__fnv(h, t->name, strnlen(t->name, sizeof t->name));
        h = sx__fnv(h, &t->n, sizeof t->n);
        h = sx__fnv(h, &t->lines, sizeof t->lines);
        const double props[] = {t->volume, t->error, t->power_sum};
        h = sx__fnv_doubles(h, props, 3, 1);
        h = sx__fnv_doubles(h, t->centroid, 3, 1);
        h = sx__fnv_doubles(h, t->inertia, 9, 1);
        h = sx__fnv_doubles(h, t->principal, 3, 1);
        h = sx__fnv_doubles(h, t->frame, 4, 1);
        h = sx__fnv_doubles(h, C->tp_pos + t->first * d, t->n * d, 1);
        h = sx__fnv_doubles(h, C->tp_rad + t->first, t->n, 1);
        h = sx__fnv_doubles(h, C->tp_body + t->first * d, t->n * d, 1);
    }
    h = sx__fnv(h, &C->n, sizeof C->n);
    return sx__fnv(h, &C->next_id, sizeof C->next_id);
}

/* (model_internal.h) Each clump's digest: its id and state, its pebbles. */
void sx__clumps_bag(const sx_model *m, const sx_rows_held *part, sx_hash_bag *out)
{
    const sx_clumps *C = m->clumps;
    const int d = m->dim, r = m->rdim;
    for (int64_t c = 0; c < C->n; c++) {
        if (!part->all && part->clump_owner[c] != part->rank) continue;
        uint64_t h = sx__fnv(SX_FNV_BASIS, C->id + c, sizeof *C->id);
        h = sx__fnv(h, C->tpl_of + c, sizeof *C->tpl_of);
        h = sx__fnv(h, C->mat + c, sizeof *C->mat);
        h = sx__fnv(h, C->fix + c, sizeof *C->fix);
        const double scalars[] = {C->scale[c], C->alpha[c], C->mass[c]};
        h = sx__fnv_doubles(h, scalars, 3, 1);
        h = sx__fnv_doubles(h, C->inertia + c * r, r, 1);
        h = sx__fnv_doubles(h, C->x + c * d, d, 1);
        h = sx__fnv_doubles(h, C->v + c * d, d, 1);
        h = sx__fnv_doubles(h, C->q + c * qdim(m), qdim(m), 1);
        if (C->L) h = sx__fnv_doubles(h, C->L + c * 3, 3, 1);
        h = sx__fnv_doubles(h, C->w + c * r, r, 1);
        h = sx__fnv_doubles(h, C->f + c * d, d, 1);
        h = sx__fnv_doubles(h, C->t + c * r, r, 1);
        const int64_t np = C->tpl[C->tpl_of[c]].n;
        h = sx__fnv(h, C->pebble + C->first[c], (size_t)np * sizeof *C->pebble);
        sx__hash_bag_add(out, h);
    }
}
