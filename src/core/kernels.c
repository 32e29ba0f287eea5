/* The step's kernels, compiled once per dimension (SEIXO_DIM = 2 or 3) so
 * that every vector loop has a constant trip count and a 2D scene never
 * touches a third component. The dimension-independent layer (model.c)
 * calls them through sx_kernels_2d / sx_kernels_3d.
 *
 * Broad phase: a uniform grid of cells at least one diameter plus the skin
 * wide; balls are sorted by cell at every build (cache locality and a
 * deterministic pair order); a forward half stencil gives each pair once
 * with a < b. History (shear force and the last evaluation's geometry) is
 * carried across builds from each new pair's old one, found through the
 * sort's permutation among the old pairs of its lower ball (transfer).
 *
 * Contacts and the law of motion have batched forms for the common cases,
 * four pairs, wall contacts or balls at a time in vector lanes (GCC
 * vector extensions), beside the full scalar forms; both give the same
 * bits (tests/test_determinism.c).
 */
#include "laws/registry.h"
#include "model_internal.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#if SEIXO_DIM == 2
#define D 2
#define RD 1
#define KERNEL(name) name##_2d
#elif SEIXO_DIM == 3
#define D 3
#define RD 3
#define KERNEL(name) name##_3d
#else
#error "SEIXO_DIM must be 2 or 3"
#endif

static inline double dot(const double *a, const double *b)
{
    double s = 0;
    for (int k = 0; k < D; k++) s += a[k] * b[k];
    return s;
}

/* w x r: the velocity of a point at arm r on a body spinning at w. */
static inline void spin_cross(const double *w, const double *r, double *out)
{
#if D == 3
    out[0] = w[1] * r[2] - w[2] * r[1];
    out[1] = w[2] * r[0] - w[0] * r[2];
    out[2] = w[0] * r[1] - w[1] * r[0];
#else
    out[0] = -w[0] * r[1];
    out[1] = w[0] * r[0];
#endif
}

/* r x F: the moment of F applied at arm r (2D: the scalar about z). */
static inline void moment_of(const double *r, const double *f, double *out)
{
#if D == 3
    out[0] = r[1] * f[2] - r[2] * f[1];
    out[1] = r[2] * f[0] - r[0] * f[2];
    out[2] = r[0] * f[1] - r[1] * f[0];
#else
    out[0] = r[0] * f[1] - r[1] * f[0];
#endif
}

/* ---------------------------------------------------------- broad phase */

/* History across a build. The old stores stay as they are (grouped by a,
 * as plan_chunks leaves them) while the build lists its pairs; a new pair
 * finds its old one among the few pairs of its lower-indexed ball, through
 * the sort's permutation. Each array of a store is then gathered in turn
 * into one the size of the new store, so a build needs one array more,
 * not a copy of every history (the memory of a build is the memory of the
 * model plus little). The history (shear force, geometry, overlap, normal
 * force, bond) of a pair whose balls swapped places in the order is
 * re-expressed for the new orientation, as sx__pair_flip does. */
typedef struct transfer {
    bool history;             /* some old pair has a history (touching; else the rest is not needed) */
    int32_t *order;           /* new index i <- old index order[i] (the sort's permutation) */
    int64_t nold;             /* balls of the old stores (before the sort) */
    int32_t *row_bb, *row_bw; /* the old stores' first pair of each old ball (nold + 1) */
    /* the new pairs as listed: src is the old pair + 1 (negated when the
     * pair turned round), 0 when it had no history (src NULL: none had) */
    int32_t *a, *b, *src;
    int64_t n, cap;
    uint8_t *seen;            /* per bond slot: found again by the grid */
} transfer;

/* First pair of each ball in a store grouped by a, into row (nb + 1). */
static void rows_of(const sx_pairs *p, int64_t nb, int32_t *row)
{
    memset(row, 0, (size_t)(nb + 1) * sizeof *row);
    for (int64_t c = 0; c < p->n; c++) row[p->a[c] + 1]++;
    for (int64_t i = 0; i < nb; i++) row[i + 1] += row[i];
}

static bool transfer_begin(sx_model *m, transfer *tr)
{
    memset(tr, 0, sizeof *tr);
    for (int64_t c = 0; c < m->bb.n && !tr->history; c++) tr->history = m->bb.touching[c];
    for (int64_t c = 0; c < m->bw.n && !tr->history; c++) tr->history = m->bw.touching[c];
    if (!tr->history) return true;
    tr->nold = m->balls.n;
    const size_t rows = (size_t)tr->nold + 1;
    tr->row_bb = sx_alloc_resize(&m->alloc, NULL, 0, rows, sizeof *tr->row_bb);
    tr->row_bw = sx_alloc_resize(&m->alloc, NULL, 0, rows, sizeof *tr->row_bw);
    tr->seen = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)m->bonds.n + 1, 1);
    /* a removal may have left the stores out of order */
    if (!tr->row_bb || !tr->row_bw || !tr->seen || !sx__pairs_sort(m, &m->bb) || !sx__pairs_sort(m, &m->bw))
        return false;
    rows_of(&m->bb, tr->nold, tr->row_bb);
    rows_of(&m->bw, tr->nold, tr->row_bw);
    return true;
}

static void transfer_end(sx_model *m, transfer *tr)
{
    const size_t rows = (size_t)tr->nold + 1;
    sx_alloc_free(&m->alloc, tr->order, tr->order ? (size_t)m->balls.n : 0, sizeof *tr->order);
    sx_alloc_free(&m->alloc, tr->row_bb, tr->row_bb ? rows : 0, sizeof *tr->row_bb);
    sx_alloc_free(&m->alloc, tr->row_bw, tr->row_bw ? rows : 0, sizeof *tr->row_bw);
    sx_alloc_free(&m->alloc, tr->seen, tr->seen ? (size_t)m->bonds.n + 1 : 0, 1);
    sx_alloc_free(&m->alloc, tr->a, (size_t)tr->cap, sizeof *tr->a);
    sx_alloc_free(&m->alloc, tr->b, (size_t)tr->cap, sizeof *tr->b);
    sx_alloc_free(&m->alloc, tr->src, (size_t)tr->cap, sizeof *tr->src);
}

/* Room for cap listed pairs (the list emptied when fresh). */
static bool transfer_list(sx_model *m, transfer *tr, int64_t cap, bool fresh)
{
    if (fresh) tr->n = 0;
    if (cap < 16) cap = 16; /* never an empty allocation */
    if (cap > INT32_MAX) return false;
    if (cap == tr->cap) return true;
    int32_t **q[3] = {&tr->a, &tr->b, &tr->src};
    for (int k = 0; k < (tr->history ? 3 : 2); k++) {
        int32_t *r = sx_alloc_resize(&m->alloc, *q[k], (size_t)tr->cap, (size_t)cap, sizeof *r);
        if (!r) return false;
        *q[k] = r;
    }
    tr->cap = cap;
    return true;
}

/* The old pair of new pair (a, b) in old store p (rows row): old pair + 1,
 * negated when the pair turned round; 0 without history (not found, or
 * not touching). A ball-ball pair is kept under its lower old index, a
 * ball-wall pair (wall) under its ball. */
static int32_t old_pair(const transfer *tr, const sx_pairs *p, const int32_t *row, int64_t a, int64_t b, bool wall)
{
    if (!tr->history) return 0;
    const int64_t oa = tr->order[a], ob = wall ? b : tr->order[b];
    const int64_t lo = wall || oa < ob ? oa : ob, hi = wall || oa < ob ? ob : oa;
    for (int32_t c = row[lo]; c < row[lo + 1]; c++)
        if (p->b[c] == hi) return p->touching[c] ? (oa == lo ? c + 1 : -(c + 1)) : 0;
    return 0;
}

static void transfer_push(transfer *tr, int32_t a, int32_t b, int32_t src)
{
    tr->a[tr->n] = a, tr->b[tr->n] = b;
    if (tr->src) tr->src[tr->n] = src;
    tr->n++;
}

/* Replaces *field (old_cap rows of per elements of size bytes) by the
 * listed pairs' rows, gathered from their old pairs (zero without);
 * flipped doubles are negated (sign: the vectors of a pair's orientation). */
static bool gather_field(sx_model *m, void **field, int64_t old_cap, const transfer *tr, int per, size_t size,
                         bool sign)
{
    char *to = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(tr->cap * per), size);
    if (!to) return false;
    const char *from = *field;
    const size_t row = (size_t)per * size;
    for (int64_t c = 0; c < tr->n && tr->src; c++) {
        const int32_t s = tr->src[c];
        if (!s) continue; /* zeros */
        const int64_t o = s > 0 ? s - 1 : -s - 1;
        memcpy(to + (size_t)c * row, from + (size_t)o * row, row);
        if (sign && s < 0)
            for (int k = 0; k < per; k++) ((double *)(to + (size_t)c * row))[k] *= -1;
    }
    sx_alloc_free(&m->alloc, *field, (size_t)(old_cap * per), size);
    *field = to;
    return true;
}

/* The store p becomes the listed pairs, their history carried over. Out of
 * memory, it is emptied (the history is lost; the next build lists the
 * pairs again, bonded ones included). */
static bool transfer_store(sx_model *m, sx_pairs *p, transfer *tr)
{
    const int64_t old = p->cap;
    /* the list's ends become the store's (the old ones are no longer needed) */
    sx_alloc_free(&m->alloc, p->a, (size_t)old, sizeof *p->a);
    sx_alloc_free(&m->alloc, p->b, (size_t)old, sizeof *p->b);
    p->a = tr->a, p->b = tr->b;
    tr->a = tr->b = NULL;
    if (p->bond && tr->src) /* a bond's vectors follow its pair's orientation */
        for (int64_t c = 0; c < tr->n; c++) {
            const int32_t s = tr->src[c], bond = s ? p->bond[s > 0 ? s - 1 : -s - 1] : 0;
            if (bond && s < 0) sx__bond_flip(m, bond - 1);
        }
    sx_pair_field fields[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, fields);
    for (int k = 0; k < nf; k++) {
        const size_t size = sx__pair_size(&fields[k]);
        if (fields[k].end || gather_field(m, fields[k].data, old, tr, fields[k].per, size, fields[k].sign)) continue;
        for (int j = 0; j < nf; j++) /* gathered ones (and the ends) at the new size, the others at the old */
            if (*fields[j].data)
                sx_alloc_free(&m->alloc, *fields[j].data,
                              (size_t)((j < k || fields[j].end ? tr->cap : old) * fields[j].per),
                              sx__pair_size(&fields[j]));
        memset(p, 0, sizeof *p);
        return false;
    }
    p->n = tr->n, p->cap = tr->cap;
    /* the list starts afresh for the next store */
    sx_alloc_free(&m->alloc, tr->src, (size_t)tr->cap, sizeof *tr->src);
    tr->src = NULL;
    tr->n = tr->cap = 0;
    return true;
}

/* Bonded pairs stay in the store whatever their gap: those the grid did
 * not find again are listed too (after the grid's pairs, in slot order). */
static bool keep_bonded_pairs(sx_model *m, transfer *tr)
{
    const sx_bonds *bs = &m->bonds;
    int64_t lost = 0;
    for (int64_t s = 0; s < bs->n; s++) lost += bs->kind[s] && !tr->seen[s];
    if (lost && !transfer_list(m, tr, tr->n + lost, false)) return false;
    for (int64_t s = 0; s < bs->n; s++) {
        if (!bs->kind[s] || tr->seen[s]) continue;
        int32_t a = m->balls.index_of[bs->ida[s]], b = m->balls.index_of[bs->idb[s]];
        if (a > b) {
            const int32_t t = a;
            a = b, b = t;
        }
        transfer_push(tr, a, b, old_pair(tr, &m->bb, tr->row_bb, a, b, false));
    }
    return true;
}

/* Distance from ball centre x to wall w: fills the unit normal from the wall
 * to the ball and returns the (signed, for planes) distance. Infinite walls
 * inline, the others in finite_wall_distance. */
static double finite_wall_distance(const sx_wall *w, const double *x, double *n);

static inline double wall_distance(const sx_wall *w, const double *x, double *n)
{
    const sx_wall_def *d = &w->def;
    if (d->kind == SX_WALL_PLANE || d->kind == SX_WALL_LINE) {
        double r[D];
        for (int k = 0; k < D; k++) r[k] = x[k] - d->point[k];
        for (int k = 0; k < D; k++) n[k] = d->normal[k];
        return dot(r, d->normal);
    }
    return finite_wall_distance(w, x, n);
}

static double finite_wall_distance(const sx_wall *w, const double *x, double *n)
{
    const sx_wall_def *d = &w->def;
    double r[D];
    for (int k = 0; k < D; k++) r[k] = x[k] - d->point[k];
    double q[D];
#if D == 3
    if (d->kind == SX_WALL_CYLINDER) { /* balls inside; n points from the surface towards the axis */
        const double axial = dot(r, d->normal);
        if (d->height > 0 && (axial < 0 || axial > d->height)) { /* beyond its open ends */
            for (int k = 0; k < D; k++) n[k] = d->normal[k];
            return INFINITY;
        }
        for (int k = 0; k < D; k++) q[k] = r[k] - axial * d->normal[k];
        const double rho = sqrt(dot(q, q));
        if (rho > 0) {
            for (int k = 0; k < D; k++) n[k] = -q[k] / rho;
        } else { /* on the axis: any radial direction */
            const double e[3] = {fabs(d->normal[0]) < 0.9 ? 1.0 : 0.0, fabs(d->normal[0]) < 0.9 ? 0.0 : 1.0, 0};
            double t[3];
            spin_cross(d->normal, e, t);
            const double tn = sqrt(dot(t, t));
            for (int k = 0; k < D; k++) n[k] = t[k] / tn;
        }
        return d->radius - rho;
    }
    double s = dot(r, w->u), t = dot(r, w->v);
    s = s < 0 ? 0 : s > w->len_u ? w->len_u : s;
    t = t < 0 ? 0 : t > w->len_v ? w->len_v : t;
    for (int k = 0; k < D; k++) q[k] = r[k] - s * w->u[k] - t * w->v[k];
#else
    double s = dot(r, d->edge1) / (w->seg_len * w->seg_len);
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    for (int k = 0; k < D; k++) q[k] = r[k] - s * d->edge1[k];
#endif
    const double dist = sqrt(dot(q, q));
    if (dist > 0) {
        for (int k = 0; k < D; k++) n[k] = q[k] / dist;
    } else { /* centre exactly on the wall: push along its normal */
        for (int k = 0; k < D; k++) n[k] = d->normal[k];
    }
    return dist;
}

/* Grid over the balls' bounding box; cells at least a diameter plus the
 * skin wide, widened if a sparse scene would need more cells than ~2 per ball. */
static bool grid_setup(sx_model *m)
{
    sx_grid *g = &m->grid;
    const sx_balls *b = &m->balls;
    double lo[D], hi[D], rmax = 0;
    for (int k = 0; k < D; k++) lo[k] = hi[k] = b->x[k];
    for (int64_t i = 0; i < b->n; i++) {
        for (int k = 0; k < D; k++) {
            const double v = b->x[i * D + k];
            if (v < lo[k]) lo[k] = v;
            if (v > hi[k]) hi[k] = v;
        }
        if (b->rad[i] > rmax) rmax = b->rad[i];
    }
    /* a scene spread wider than a double can hold (e.g. balls at +-1e300)
     * has an infinite extent: take the largest finite one, so the cells
     * widen until they fit (at worst one cell, still correct) */
    double extent[D];
    for (int k = 0; k < D; k++) extent[k] = isfinite(hi[k] - lo[k]) ? hi[k] - lo[k] : DBL_MAX;
    double cell = 2 * rmax + m->skin;
    const double limit = 2.0 * (double)b->n + 64;
    for (;;) {
        double cells = 1;
        for (int k = 0; k < D; k++) cells *= floor(extent[k] / cell) + 1;
        if (cells <= limit) break;
        cell *= 1.5;
    }
    g->cell = cell;
    g->ncells = 1;
    for (int k = 0; k < 3; k++) {
        g->lo[k] = k < D ? lo[k] : 0;
        g->nc[k] = k < D ? (int64_t)floor(extent[k] / cell) + 1 : 1;
        g->ncells *= g->nc[k];
    }
    if (g->ncells + 1 > g->cap_cells) {
        int32_t *q = sx_alloc_resize(&m->alloc, g->start, (size_t)g->cap_cells, (size_t)(g->ncells + 1), sizeof *q);
        if (!q) return false;
        g->start = q;
        g->cap_cells = g->ncells + 1;
    }
    return true;
}

static inline void cell_coords(const sx_grid *g, const double *x, int64_t *c)
{
    for (int k = 0; k < D; k++) {
        const double q = (x[k] - g->lo[k]) / g->cell; /* NaN when both are infinite: cell 0 */
        c[k] = q >= (double)g->nc[k] ? g->nc[k] - 1 : q >= 0 ? (int64_t)q : 0;
    }
}

/* Sorts balls by cell (counting sort, stable) and fills g->start; the
 * permutation goes to tr->order. */
static bool sort_balls(sx_model *m, transfer *tr)
{
    sx_grid *g = &m->grid;
    sx_balls *b = &m->balls;
    const int64_t n = b->n;
    int32_t *order = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)n, sizeof *order);
    double *scratch = sx__scratch(m, n * D);
    if (!order || !scratch) {
        sx_alloc_free(&m->alloc, order, order ? (size_t)n : 0, sizeof *order);
        return false;
    }
    /* the cell of each ball lives in the scratch until the permutation needs it */
    int32_t *cell_of = (int32_t *)scratch;
    memset(g->start, 0, (size_t)(g->ncells + 1) * sizeof *g->start);
    for (int64_t i = 0; i < n; i++) {
        int64_t c[3] = {0, 0, 0};
        cell_coords(g, b->x + i * D, c);
        const int64_t cell = c[0] + g->nc[0] * (c[1] + g->nc[1] * c[2]);
        cell_of[i] = (int32_t)cell;
        g->start[cell + 1]++;
    }
    for (int64_t c = 0; c < g->ncells; c++) g->start[c + 1] += g->start[c];
    for (int64_t i = 0; i < n; i++) order[g->start[cell_of[i]]++] = (int32_t)i;
    /* start[c] now holds the end of cell c: shift back to starts */
    for (int64_t c = g->ncells; c > 0; c--) g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    sx__balls_permute(m, order, scratch);
    sx__scratch_release(m); /* not kept between builds: the pairs come next */
    if (tr->history) tr->order = order; /* the transfer's */
    else sx_alloc_free(&m->alloc, order, (size_t)n, sizeof *order);
    return true;
}

/* The forward half of the neighbour stencil: offsets whose linear cell
 * index is greater, so every pair of cells is visited once. */
static int half_stencil(int64_t (*off)[3])
{
    int n = 0;
#if D == 3
    for (int z = 0; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                if (z == 0 && (y < 0 || (y == 0 && x <= 0))) continue;
                off[n][0] = x, off[n][1] = y, off[n][2] = z, n++;
            }
#else
    for (int y = 0; y <= 1; y++)
        for (int x = -1; x <= 1; x++) {
            if (y == 0 && x <= 0) continue;
            off[n][0] = x, off[n][1] = y, off[n][2] = 0, n++;
        }
#endif
    return n;
}

/* A candidate pair (i, j), i < j: counted when count is given, else listed
 * with its old pair (a bond it carries is found again). */
static inline void candidate(sx_model *m, transfer *tr, int32_t i, int32_t j, int64_t *count)
{
    const int32_t *cl = m->balls.clump; /* clumps: pebbles of one clump never pair (NULL without clumps) */
    if (cl && cl[i] && cl[i] == cl[j]) return;
    if (count) {
        (*count)++;
        return;
    }
    const int32_t src = old_pair(tr, &m->bb, tr->row_bb, i, j, false);
    if (src && m->bb.bond) {
        const int32_t bond = m->bb.bond[src > 0 ? src - 1 : -src - 1];
        if (bond) tr->seen[bond - 1] = 1;
    }
    transfer_push(tr, i, j, src);
}

/* The grid's candidate pairs in cell order; with count, only counts them
 * (a build counts first, so the store is sized once, without growing). */
static void build_ball_pairs(sx_model *m, transfer *tr, int64_t *count)
{
    const sx_grid *g = &m->grid;
    const sx_balls *b = &m->balls;
    int64_t off[13][3];
    const int nst = half_stencil(off);
    for (int64_t cz = 0; cz < g->nc[2]; cz++)
        for (int64_t cy = 0; cy < g->nc[1]; cy++)
            for (int64_t cx = 0; cx < g->nc[0]; cx++) {
                const int64_t cell = cx + g->nc[0] * (cy + g->nc[1] * cz);
                for (int32_t i = g->start[cell]; i < g->start[cell + 1]; i++) {
                    const double *xi = b->x + (int64_t)i * D;
                    const double ri = b->rad[i] + m->skin;
                    /* own cell: later balls only */
                    for (int32_t j = i + 1; j < g->start[cell + 1]; j++) {
                        double dx[D];
                        for (int k = 0; k < D; k++) dx[k] = b->x[(int64_t)j * D + k] - xi[k];
                        const double reach = ri + b->rad[j];
                        if (dot(dx, dx) < reach * reach) candidate(m, tr, i, j, count);
                    }
                    for (int s = 0; s < nst; s++) {
                        const int64_t nx = cx + off[s][0], ny = cy + off[s][1], nz = cz + off[s][2];
                        if (nx < 0 || nx >= g->nc[0] || ny < 0 || ny >= g->nc[1] || nz >= g->nc[2]) continue;
                        const int64_t nc = nx + g->nc[0] * (ny + g->nc[1] * nz);
                        for (int32_t j = g->start[nc]; j < g->start[nc + 1]; j++) {
                            double dx[D];
                            for (int k = 0; k < D; k++) dx[k] = b->x[(int64_t)j * D + k] - xi[k];
                            const double reach = ri + b->rad[j];
                            if (dot(dx, dx) < reach * reach) candidate(m, tr, i, j, count);
                        }
                    }
                }
            }
}

/* Ball-wall candidates, ball-major so the contact loop walks balls in
 * order; with count, only counts them (as build_ball_pairs). */
static void build_wall_pairs(sx_model *m, transfer *tr, int64_t *count)
{
    const sx_balls *b = &m->balls;
    for (int64_t i = 0; i < b->n; i++)
        for (int64_t w = 0; w < m->nwall; w++) {
            double n[D];
            const double dist = wall_distance(&m->walls[w], b->x + i * D, n);
            if (dist >= b->rad[i] + m->skin) continue;
            if (count) (*count)++;
            else transfer_push(tr, (int32_t)i, (int32_t)w, old_pair(tr, &m->bw, tr->row_bw, i, w, true));
        }
}

/* The pairs of one store, counted, then listed (and the bonded pairs kept),
 * then carried over into the store. */
static bool build_store(sx_model *m, transfer *tr, bool walls)
{
    int64_t count = 0;
    if (walls) build_wall_pairs(m, tr, &count);
    else build_ball_pairs(m, tr, &count);
    if (!transfer_list(m, tr, count, true)) return false;
    if (walls) build_wall_pairs(m, tr, NULL);
    else build_ball_pairs(m, tr, NULL);
    return (walls || keep_bonded_pairs(m, tr)) && transfer_store(m, walls ? &m->bw : &m->bb, tr);
}

static bool plan_chunks(sx_model *m);

static bool KERNEL(build)(sx_model *m)
{
    if (m->balls.n == 0) { /* nothing to pair; a grid would have no extent */
        m->bb.n = m->bw.n = 0;
        m->nchunk = m->nblock = 0;
        m->builds++;
        m->build_needed = false;
        m->dt_stale = true;
        return true;
    }
    /* the automatic skin: a fifth of the mean radius */
    if (m->skin_user > 0) {
        m->skin = m->skin_user;
    } else {
        double sum = 0;
        for (int64_t i = 0; i < m->balls.n; i++) sum += m->balls.rad[i];
        m->skin = 0.2 * sum / (double)m->balls.n;
    }
    /* each pair store made from its counted pairs, so it holds no more than
     * them and never grows while it is filled */
    transfer tr;
    bool ok = transfer_begin(m, &tr) && grid_setup(m) && sort_balls(m, &tr) && build_store(m, &tr, false) &&
              build_store(m, &tr, true);
    transfer_end(m, &tr);
    if (!ok || !plan_chunks(m)) return false;
    memcpy(m->balls.x_build, m->balls.x, (size_t)(m->balls.n * D) * sizeof(double));
    for (int64_t w = 0; w < m->nwall; w++) m->walls[w].moved = 0;
    m->builds++;
    m->build_needed = false;
    m->dt_stale = true; /* new contacts: a new automatic timestep, wherever the build happens */
    return true;
}

/* ------------------------------------------------------- contact forces */

/* The rotation carried by a contact from one step to the next: into the new
 * contact plane (4-13/4-14, c = n_old x n) and about the normal by the mean
 * spin of the two entities (4-8/4-9/4-15). Applied to the shear force and to
 * the parallel bond's shear force and bending moment. */
typedef struct carry {
    double c[D == 3 ? 3 : 1];
    double wdt[D == 3 ? 3 : 1];
} carry;

static inline void carry_make(carry *r, const double *nold, const double *n, const double *wa, const double *wb,
                              double dt)
{
#if D == 3
    r->c[0] = nold[1] * n[2] - nold[2] * n[1];
    r->c[1] = nold[2] * n[0] - nold[0] * n[2];
    r->c[2] = nold[0] * n[1] - nold[1] * n[0];
    /* 4-9: the mean spin projected on the normal (a wall does not spin) */
    double ws[3];
    for (int k = 0; k < 3; k++) ws[k] = wa ? wa[k] + wb[k] : wb[k];
    const double wbar = 0.5 * dot(ws, n);
    for (int k = 0; k < 3; k++) r->wdt[k] = wbar * n[k] * dt;
#else
    /* in 2D c is along z, and the spins are normal to n, so 4-15 is the identity */
    (void)wa, (void)wb, (void)dt;
    r->c[0] = nold[0] * n[1] - nold[1] * n[0];
    r->wdt[0] = 0;
#endif
}

static inline void carry_apply(const carry *r, double *v)
{
#if D == 3
    double t[3];
    spin_cross(r->c, v, t); /* 4-14: F + c x F */
    for (int k = 0; k < 3; k++) v[k] += t[k];
    spin_cross(r->wdt, v, t); /* 4-15: F + (w dt) x F */
    for (int k = 0; k < 3; k++) v[k] += t[k];
#else
    const double v0 = v[0];
    v[0] -= r->c[0] * v[1];
    v[1] += r->c[0] * v0;
#endif
}

/* Normal and shear stiffness of a contact by its law (laws/registry.h).
 * rbar is 4-27's 2RARB/(RA+RB) (ball-wall: R, 4-28). Returns the normal force. */
static inline double stiffness(const sx_pair_law *l, double ra, double rb, double rbar, double un, double *kn,
                               double *ks)
{
    return sx__law_force(l, D, ra, rb, rbar, un, kn, ks);
}

/* Strain energy of a contact spring: its law's factor times Fn Un (linear
 * 1/2, Hertz 2/5), plus the shear spring's 1/2 |Fs|^2 / ks. */
static inline double contact_strain(const sx_pair_law *l, double fn, double un, const double *fs, double ks)
{
    const double normal = sx__law(l->law)->strain * fn * un;
    return normal + (ks > 0 ? 0.5 * dot(fs, fs) / ks : 0);
}

/* Section of a parallel bond: area, moment of inertia, polar moment (4-35;
 * 2D: a beam of unit thickness, A = 2R, I = 2/3 R^3, no twist). */
static inline void pb_section(double r, double *area, double *inertia, double *polar)
{
#if D == 3
    *area = SX_PI * r * r;
    *inertia = 0.25 * SX_PI * r * r * r * r;
    *polar = 0.5 * SX_PI * r * r * r * r;
#else
    *area = 2 * r;
    *inertia = 2.0 / 3.0 * r * r * r;
    *polar = 0;
#endif
}

static double pb_strain(const sx_bonds *b, int64_t s)
{
    double area, inertia, polar;
    pb_section(b->rbar[s], &area, &inertia, &polar);
    const double *fs = b->fs + s * D, *ms = b->ms + s * RD;
    double e = 0.5 * b->fn[s] * b->fn[s] / (b->kn[s] * area) + 0.5 * dot(fs, fs) / (b->ks[s] * area);
    double m2 = 0;
    for (int k = 0; k < RD; k++) m2 += ms[k] * ms[k];
    e += 0.5 * m2 / (b->kn[s] * inertia);
    if (D == 3) e += 0.5 * b->mn[s] * b->mn[s] / (b->ks[s] * polar);
    return e;
}

static double KERNEL(critical_dt)(sx_model *m);

/* 4-16 ... 4-20: the velocity v_{n-1/2} moved the entities from x_{n-1} to
 * x_n during the previous step, so displacement increments use its length. */
static inline double motion_dt(const sx_model *m) { return m->dt_prev > 0 ? m->dt_prev : m->dt; }

static sx_status overlap_error(sx_model *m, const char *what, int64_t ida, int64_t idb, double un, double r)
{
    return sx__fail(m, SX_EUNSTABLE,
                    "unstable at step %lld: %s %lld and %lld overlap by %g m, more than the radius %g m; "
                    "the timestep %g s is too large for the contact stiffness (critical estimate %g s): "
                    "lower the timestep or use the automatic one",
                    (long long)m->step, what, (long long)ida, (long long)idb, un, r, m->dt,
                    KERNEL(critical_dt)(m));
}

static void log_crack(sx_model *m, sx_chunk *o, const double *xc, sx_crack_mode mode, sx_bond_kind kind, int64_t i,
                      int64_t j, double fn, double fs, double mn, double ms)
{
    sx_crack c;
    memset(&c, 0, sizeof c);
    c.time = m->time;
    c.step = m->step;
    for (int k = 0; k < D; k++) c.pos[k] = xc[k];
    c.mode = mode;
    c.kind = kind;
    c.a = m->balls.id[i];
    c.b = m->balls.id[j];
    c.fn = fn, c.fs = fs, c.mn = mn, c.ms = ms;
    /* kept with the chunk, merged into the model's log in chunk order */
    if (o->ncracks == o->capcracks) {
        const int64_t cap = o->capcracks ? 2 * o->capcracks : 16;
        sx_crack *q = realloc(o->cracks, (size_t)cap * sizeof *q);
        if (!q) return; /* out of memory: the event is dropped, the bond still breaks */
        o->cracks = q;
        o->capcracks = cap;
    }
    o->cracks[o->ncracks++] = c;
}

/* The parallel bond of pair (i, j), 4-32 ... 4-39: carried with the contact,
 * incremented from the relative motion, checked against its strengths.
 * Adds its force to F (on j) and its moment to mb (on j). Returns false
 * when it broke. */
static bool parallel_bond(sx_model *m, sx_chunk *o, int32_t s, const carry *rot, const double *n, double vn, const double *vs,
                          const double *dtheta, const double *xc, int64_t i, int64_t j, double *F, double *mb)
{
    sx_bonds *b = &m->bonds;
    const double dt = motion_dt(m), rbar = b->rbar[s];
    double area, inertia, polar;
    pb_section(rbar, &area, &inertia, &polar);
    double *fs = b->fs + s * D, *ms = b->ms + s * RD;
    carry_apply(rot, fs);
#if D == 3
    carry_apply(rot, ms);
#endif
    b->fn[s] += b->kn[s] * area * (-vn * dt); /* 4-33, compression positive */
    for (int k = 0; k < D; k++) fs[k] -= b->ks[s] * area * vs[k] * dt; /* 4-33 with dUs (seed typo corrected) */
#if D == 3
    const double twist = dot(dtheta, n);
    b->mn[s] -= b->ks[s] * polar * twist; /* 4-34 */
    for (int k = 0; k < 3; k++) ms[k] -= b->kn[s] * inertia * (dtheta[k] - twist * n[k]);
#else
    (void)polar;
    ms[0] -= b->kn[s] * inertia * dtheta[0];
#endif
    double ms2 = 0;
    for (int k = 0; k < RD; k++) ms2 += ms[k] * ms[k];
    const double msn = sqrt(ms2), fsn = sqrt(dot(fs, fs)), mnn = fabs(b->mn[s]);
    /* 4-38 as corrected: magnitudes, the twist only in 3D */
    const double sigma = -b->fn[s] / area + msn * rbar / inertia;
    const double tau = fsn / area + (D == 3 ? mnn * rbar / polar : 0);
    if (sigma >= b->sigma_c[s] || tau >= b->tau_c[s]) {
        const bool tension = sigma / b->sigma_c[s] >= tau / b->tau_c[s];
        log_crack(m, o, xc, tension ? SX_CRACK_TENSION : SX_CRACK_SHEAR, SX_BOND_PARALLEL, i, j, b->fn[s], fsn, mnn,
                  msn);
        if (m->track_energy) o->released += pb_strain(b, s);
        return false;
    }
    for (int k = 0; k < D; k++) F[k] += b->fn[s] * n[k] + fs[k]; /* 4-32 */
#if D == 3
    for (int k = 0; k < 3; k++) mb[k] += b->mn[s] * n[k] + ms[k];
#else
    mb[0] += ms[0];
#endif
    return true;
}

/* A chunk's results start empty; the balls it clears start from their
 * applied loads (or nothing). */
static void chunk_start(sx_model *m, sx_chunk *o)
{
    sx_balls *B = &m->balls;
    const size_t nf = (size_t)((o->clear_hi - o->clear_lo) * D), nt = (size_t)((o->clear_hi - o->clear_lo) * RD);
    if (B->fapp) {
        memcpy(B->f + o->clear_lo * D, B->fapp + o->clear_lo * D, nf * sizeof(double));
        memcpy(B->t + o->clear_lo * RD, B->tapp + o->clear_lo * RD, nt * sizeof(double));
    } else {
        memset(B->f + o->clear_lo * D, 0, nf * sizeof(double));
        memset(B->t + o->clear_lo * RD, 0, nt * sizeof(double));
    }
    o->slip = o->viscous = o->released = 0;
    o->lost_bonds = 0;
    o->ncracks = 0;
    o->st = SX_OK;
}

/* Ball-ball contacts of one chunk, every model: 4-1 ... 4-21 with the
 * contact models of 4.3.3 - 4.3.5. The total force F acts on b and -F on
 * a; energies, cracks and errors go to the chunk. */
static void ball_chunk_pass(sx_model *m, sx_chunk *o)
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    const double *restrict x = B->x, *restrict v = B->v, *restrict w = B->w, *restrict rad = B->rad;
    const double *restrict im = B->inv_mass;
    const uint16_t *restrict mat = B->mat;
    const int32_t *restrict pa = p->a, *restrict pb = p->b;
    const int32_t *restrict bond = p->bond;
    double *restrict fs_all = p->fs, *restrict geo_all = p->geo, *restrict fn_all = p->fn;
    uint8_t *restrict touching = p->touching;
    double *restrict f = B->f, *restrict t = B->t;
    const sx_pair_law *laws = m->law;
    chunk_start(m, o);
    const double dt = motion_dt(m);
    const int nlaw = m->law_n;
    const bool track = m->track_energy;
    for (int64_t c = o->first; c < o->last; c++) {
        const int64_t i = pa[c], j = pb[c];
        const int32_t slot = bond ? bond[c] - 1 : -1;
        double dx[D];
        for (int k = 0; k < D; k++) dx[k] = x[j * D + k] - x[i * D + k];
        const double d2 = dot(dx, dx), ri = rad[i], rj = rad[j], rsum = ri + rj;
        const sx_pair_law *law = &laws[mat[i] * nlaw + mat[j]];
        double *restrict fs = fs_all + c * D, *restrict rel = geo_all + c * D;
        if (d2 >= rsum * rsum && slot < 0) {
            if (track && touching[c]) { /* the shear spring's energy is released as the contact opens */
                double kn, ks;
                stiffness(law, ri, rj, 2 * ri * rj / rsum, 0, &kn, &ks);
                if (ks > 0) o->slip += 0.5 * dot(fs, fs) / ks;
            }
            touching[c] = 0;
            fn_all[c] = 0; /* its last evaluation: no force */
            continue;
        }
        /* 4-1 ... 4-4 */
        const double d = sqrt(d2), inv_d = 1.0 / d;
        double n[D];
        for (int k = 0; k < D; k++) n[k] = dx[k] * inv_d;
        const double un = rsum - d;
        const double rmin = ri < rj ? ri : rj;
        if (un > rmin) {
            o->st = SX_EUNSTABLE;
            o->err_a = B->id[i], o->err_b = B->id[j], o->err_un = un, o->err_r = rmin;
            return;
        }
        const double la = ri - 0.5 * un, lb = rj - 0.5 * un;
        /* 4-16 with the arms la n from a and -lb n from b: the contact-point
         * velocity of b relative to a is vb - va - (la wa + lb wb) x n */
        const double *wi = w + i * RD, *wj = w + j * RD;
        double ws[RD], wn[D], vc[D];
        for (int k = 0; k < RD; k++) ws[k] = la * wi[k] + lb * wj[k];
        spin_cross(ws, n, wn);
        for (int k = 0; k < D; k++) vc[k] = (v[j * D + k] - v[i * D + k]) - wn[k];
        const double vn = dot(vc, n);
        double vs[D];
        for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k]; /* 4-17 */

        /* the previous normal, from the last evaluation's relative position as n
         * was computed from dx (the same bits); none for a new contact */
        double nold[D];
        if (touching[c]) {
            const double inv_r = 1.0 / sqrt(dot(rel, rel));
            for (int k = 0; k < D; k++) nold[k] = rel[k] * inv_r;
        } else {
            for (int k = 0; k < D; k++) fs[k] = 0, nold[k] = n[k];
        }
        carry rot;
        carry_make(&rot, nold, n, wi, wj, dt);
        unsigned bonds = slot >= 0 ? m->bonds.kind[slot] : 0;
        const unsigned bonds_before = bonds;
        double xc[D]; /* the contact point (4-4), for the crack log */
        if (slot >= 0)
            for (int k = 0; k < D; k++) xc[k] = x[i * D + k] + la * n[k];

        double kn, ks, fn = 0, F[D], mb[RD];
        bool bond_moment = false;
        const bool active = un > 0 || (bonds & SX_BOND_CONTACT); /* a contact bond carries tension */
        bool slip = false;
        if (active) {
            fn = stiffness(law, ri, rj, 2 * ri * rj / rsum, un, &kn, &ks);
            carry_apply(&rot, fs);
            double f0[D]; /* the shear force before this step's increment, for the slip energy */
            for (int k = 0; k < D; k++) f0[k] = fs[k];
            const double ksdt = ks * dt;
            for (int k = 0; k < D; k++) fs[k] -= ksdt * vs[k]; /* 4-18 ... 4-20 */
            if (bonds & SX_BOND_CONTACT) {
                const double fsn = sqrt(dot(fs, fs));
                if (-fn >= m->bonds.cb_n[slot]) { /* tension failure: both components vanish */
                    log_crack(m, o, xc, SX_CRACK_TENSION, SX_BOND_CONTACT, i, j, fn, fsn, 0, 0);
                    if (track) o->released += 0.5 * fn * un + (ks > 0 ? 0.5 * fsn * fsn / ks : 0);
                    bonds &= ~(unsigned)SX_BOND_CONTACT;
                    fn = 0;
                    for (int k = 0; k < D; k++) fs[k] = 0;
                } else if (fsn >= m->bonds.cb_s[slot]) { /* shear failure: slip takes over */
                    log_crack(m, o, xc, SX_CRACK_SHEAR, SX_BOND_CONTACT, i, j, fn, fsn, 0, 0);
                    bonds &= ~(unsigned)SX_BOND_CONTACT;
                }
            }
            if (!(bonds & SX_BOND_CONTACT)) {
                if (un <= 0) { /* unbonded and open: no contact force */
                    /* a contact bond that failed in shear while in tension releases both springs */
                    if (track) o->released += 0.5 * fn * un + (ks > 0 ? 0.5 * dot(fs, fs) / ks : 0);
                    fn = 0;
                    for (int k = 0; k < D; k++) fs[k] = 0;
                }
                /* 4-30/4-31: Coulomb slip with the smaller friction */
                const double fmax = law->mu * (fn > 0 ? fn : 0);
                const double f2 = dot(fs, fs);
                if (f2 > fmax * fmax) {
                    const double sc = fmax / sqrt(f2);
                    /* slip work: the mean of the shear force before and after the step along the
                     * slip displacement (trial - final force) / ks */
                    if (track && ks > 0) {
                        double e = 0;
                        for (int k = 0; k < D; k++) e += (f0[k] + sc * fs[k]) * (1 - sc) * fs[k];
                        o->slip += 0.5 * e / ks;
                    }
                    for (int k = 0; k < D; k++) fs[k] *= sc;
                    slip = true;
                }
            }
            double fd = fn, dsh[D];
            bool shear_dashpot = false;
            if ((law->beta_n > 0 || law->beta_s > 0) && un > 0) {
                /* viscous dashpots at the critical-damping ratios on the reduced mass
                 * m* = 1 / (1/ma + 1/mb): c = 2 beta sqrt(m* k), a per-law factor when k is */
                const double sum_im = im[i] + im[j];
                const double cn = !law->plain ? 2 * law->beta_n * sqrt(kn / sum_im)
                                                                : sqrt(law->dash_n / sum_im);
                const double fdn = -cn * vn;
                fd += fdn;
                double work = fdn * vn;
                if (!slip && law->beta_s > 0) {
                    const double cs = 2 * law->beta_s * sqrt(ks / sum_im);
                    for (int k = 0; k < D; k++) dsh[k] = -cs * vs[k];
                    work += dot(dsh, vs);
                    shear_dashpot = true;
                }
                if (track) o->viscous -= work * dt;
            }
            for (int k = 0; k < D; k++) F[k] = fd * n[k] + fs[k]; /* 4-5 */
            if (shear_dashpot)
                for (int k = 0; k < D; k++) F[k] += dsh[k];
            fn_all[c] = fd;
        } else {
            if (track && touching[c]) { /* a parallel-bonded pair's contact opened: its shear spring is released */
                double kn0, ks0;
                stiffness(law, ri, rj, 2 * ri * rj / rsum, 0, &kn0, &ks0);
                if (ks0 > 0) o->slip += 0.5 * dot(fs, fs) / ks0;
            }
            for (int k = 0; k < D; k++) F[k] = fs[k] = 0;
            fn_all[c] = 0;
        }
        if (bonds & SX_BOND_PARALLEL) {
            double dtheta[RD];
            for (int k = 0; k < RD; k++) dtheta[k] = (wj[k] - wi[k]) * dt;
            for (int k = 0; k < RD; k++) mb[k] = 0;
            if (parallel_bond(m, o, slot, &rot, n, vn, vs, dtheta, xc, i, j, F, mb)) bond_moment = true;
            else bonds &= ~(unsigned)SX_BOND_PARALLEL;
        }
        if (bonds != bonds_before) { /* only this pair touches its bond slot */
            m->bonds.kind[slot] = (uint8_t)bonds;
            if (!bonds) {
                p->bond[c] = 0;
                o->lost_bonds++;
            }
        }
        for (int k = 0; k < D; k++) rel[k] = dx[k];
        touching[c] = active || bonds;
        /* 4-21 and 4-39: both arms lie along n, so both moments are multiples of n x F */
        double nf[RD];
        moment_of(n, F, nf);
        double *fi = f + i * D, *ti = t + i * RD, *fj = f + j * D, *tj = t + j * RD;
        for (int k = 0; k < D; k++) {
            fi[k] -= F[k];
            fj[k] += F[k];
        }
        for (int k = 0; k < RD; k++) {
            double ma = la * nf[k], mj = -lb * nf[k];
            if (bond_moment) ma += mb[k], mj += mb[k];
            ti[k] -= ma;
            tj[k] += mj;
        }
    }
}

/* The common case (linear laws without a shear dashpot, no bonds, no
 * energy tracking) of ball_chunk_pass, four pairs at a time: each pair's
 * inputs are loaded straight into one lane of vector registers, every
 * formula runs on the four lanes at once (branches become selects: a pair
 * out of contact or not slipping takes the same lanes, and multiplying by
 * a scale of exactly 1 changes nothing), and the results are scattered
 * in pair order. Each lane does the scalar pass's arithmetic in its
 * order, so both give the same bits. */
enum { LANES = 4 };

/* Four doubles and four lane masks (-1 or 0), GCC's vector extensions:
 * an AVX register in the avx2 clone below, two SSE2 halves in the
 * baseline one; each operation is the IEEE operation of each lane. */
typedef double vd __attribute__((vector_size(LANES * sizeof(double))));
typedef int64_t vm __attribute__((vector_size(LANES * sizeof(int64_t))));
typedef uint8_t v4u8 __attribute__((vector_size(LANES))); /* four pairs' touching flags */

/* (macros, not functions: a vector argument would change the baseline ABI) */
#define VSEL(msk, a, b) ((vd)(((vm)(a) & (msk)) | ((vm)(b) & ~(msk))))
#define VSQRT(a)                                                        \
    __extension__({                                                     \
        const vd a_ = (a);                                              \
        vd r_;                                                          \
        for (int q_ = 0; q_ < LANES; q_++) r_[q_] = sqrt(a_[q_]);       \
        r_;                                                             \
    })
#define VANY(msk) (((msk)[0] | (msk)[1] | (msk)[2] | (msk)[3]) != 0)
#define VZERO ((vd){0, 0, 0, 0})

/* component k of each lane's element idx[q] of an array of `per` components */
#define LANES_OF(arr, idx, per, k)                                                                          \
    ((vd){(arr)[(idx)[0] * (per) + (k)], (arr)[(idx)[1] * (per) + (k)], (arr)[(idx)[2] * (per) + (k)],   \
          (arr)[(idx)[3] * (per) + (k)]})

/* Four consecutive pairs' D-vectors (a pair's components adjacent in
 * memory) to and from one vector per component, by shuffles. */
static inline void load_lanes(const double *p, vd *out)
{
#if D == 3
    vd m0, m1, m2;
    memcpy(&m0, p, sizeof m0), memcpy(&m1, p + 4, sizeof m1), memcpy(&m2, p + 8, sizeof m2);
    out[0] = __builtin_shuffle(__builtin_shuffle(m0, m1, (vm){0, 3, 6, 0}), m2, (vm){0, 1, 2, 5});
    out[1] = __builtin_shuffle(__builtin_shuffle(m0, m1, (vm){1, 4, 7, 0}), m2, (vm){0, 1, 2, 6});
    out[2] = __builtin_shuffle(__builtin_shuffle(m0, m1, (vm){2, 5, 0, 0}), m2, (vm){0, 1, 4, 7});
#else
    vd m0, m1;
    memcpy(&m0, p, sizeof m0), memcpy(&m1, p + 4, sizeof m1);
    out[0] = __builtin_shuffle(m0, m1, (vm){0, 2, 4, 6});
    out[1] = __builtin_shuffle(m0, m1, (vm){1, 3, 5, 7});
#endif
}

static inline void store_lanes(double *p, const vd *in)
{
#if D == 3
    const vd o0 = __builtin_shuffle(__builtin_shuffle(in[0], in[1], (vm){0, 4, 1, 0}), in[2], (vm){0, 1, 4, 2});
    const vd o1 = __builtin_shuffle(__builtin_shuffle(in[1], in[2], (vm){1, 5, 2, 0}), in[0], (vm){0, 1, 6, 2});
    const vd o2 = __builtin_shuffle(__builtin_shuffle(in[0], in[1], (vm){3, 7, 0, 0}), in[2], (vm){6, 0, 1, 7});
    memcpy(p, &o0, sizeof o0), memcpy(p + 4, &o1, sizeof o1), memcpy(p + 8, &o2, sizeof o2);
#else
    const vd o0 = __builtin_shuffle(in[0], in[1], (vm){0, 4, 1, 5}), o1 = __builtin_shuffle(in[0], in[1], (vm){2, 6, 3, 7});
    memcpy(p, &o0, sizeof o0), memcpy(p + 4, &o1, sizeof o1);
#endif
}

/* The shear force g of four lanes, as the scalar passes make it: the
 * stored one where the pair had a contact (had) and none otherwise,
 * rotated (4-14, as carry_make and carry_apply) from the previous normal
 * (prev; n for a new contact) into n, then in 3D (4-15) about n by half
 * the bodies' summed spin about it (spin_sum; a wall does not spin, so
 * there its ball's spin alone); the increment of the shear velocity vs
 * (4-18 ... 4-20); the Coulomb limit fmax (4-30/4-31). (Arrays and masks
 * by pointer: a vector argument would change the baseline ABI.) */
static inline __attribute__((always_inline)) void shear_lanes(vd *g, const vd *fs_old, const vd *prev, const vm *had,
                                                              const vd *n, const vd *spin_sum, const vd *vs,
                                                              const vd *ks, const vd *fmax, double dt)
{
    vd no[D];
    for (int k = 0; k < D; k++) {
        g[k] = VSEL(*had, fs_old[k], VZERO);
        no[k] = VSEL(*had, prev[k], n[k]);
    }
#if D == 3
    const vd c0v = no[1] * n[2] - no[2] * n[1], c1v = no[2] * n[0] - no[0] * n[2], c2v = no[0] * n[1] - no[1] * n[0];
    vd t0 = c1v * g[2] - c2v * g[1], t1 = c2v * g[0] - c0v * g[2], t2 = c0v * g[1] - c1v * g[0];
    g[0] += t0, g[1] += t1, g[2] += t2;
    const vd wbar = 0.5 * (((VZERO + spin_sum[0] * n[0]) + spin_sum[1] * n[1]) + spin_sum[2] * n[2]);
    const vd r0 = wbar * n[0] * dt, r1 = wbar * n[1] * dt, r2 = wbar * n[2] * dt;
    t0 = r1 * g[2] - r2 * g[1], t1 = r2 * g[0] - r0 * g[2], t2 = r0 * g[1] - r1 * g[0];
    g[0] += t0, g[1] += t1, g[2] += t2;
#else
    (void)spin_sum;
    const vd cz = no[0] * n[1] - no[1] * n[0], g0 = g[0];
    g[0] -= cz * g[1];
    g[1] += cz * g0;
#endif
    const vd ksdt = *ks * dt;
    for (int k = 0; k < D; k++) g[k] -= ksdt * vs[k];
    vd f2 = VZERO;
    for (int k = 0; k < D; k++) f2 += g[k] * g[k];
    const vm slips = f2 > *fmax * *fmax;
    if (VANY(slips)) {
        const vd sc = VSEL(slips, *fmax / VSQRT(f2), VZERO + 1.0);
        for (int k = 0; k < D; k++) g[k] *= sc;
    }
}

/* The batched pass is compiled three times where the compiler can pick at
 * run time (GCC's function multi-versioning on x86-64 GNU/Linux): for
 * x86-64-v4 (AVX-512: the same four lanes, in twice as many registers, so
 * fewer spills), with AVX2, four lanes per instruction, and for the
 * baseline ISA. None fuses (-ffp-contract=off) and all round every
 * operation alike, so they give the same bits. AddressSanitizer builds keep
 * the baseline alone (an ifunc resolver runs before the sanitizer is set
 * up). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
#define SX_VECTOR_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define SX_VECTOR_CLONES
#endif

SX_VECTOR_CLONES static void ball_chunk_batched(sx_model *m, sx_chunk *o)
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    const double *restrict x = B->x, *restrict v = B->v, *restrict w = B->w, *restrict rad = B->rad;
    const double *restrict im = B->inv_mass;
    const uint16_t *restrict mat = B->mat;
    const int32_t *restrict pa = p->a, *restrict pb = p->b;
    double *restrict fs_all = p->fs, *restrict geo_all = p->geo, *restrict fn_all = p->fn;
    uint8_t *restrict touching = p->touching;
    double *restrict f = B->f, *restrict t = B->t;
    const sx_pair_law *laws = m->law;
    const int nlaw = m->law_n;
    chunk_start(m, o);
    const double dt = motion_dt(m);
    /* the law's parameters per lane; with one material, the same in every lane */
    vd kn = VZERO + laws->kn, ks = VZERO + laws->ks, mu = VZERO + laws->mu, dash = VZERO + laws->dash_n,
       bn = VZERO + laws->beta_n;
    /* the dashpot's sqrt(dash / (1/ma + 1/mb)) of the last lanes that needed one:
     * balls of one size and material share it */
    double memo_dash = NAN, memo_sim = NAN, memo_cn = 0;

    for (int64_t c0 = o->first; c0 < o->last; c0 += LANES) {
        const int nb = o->last - c0 < LANES ? (int)(o->last - c0) : LANES;
        int64_t cc[LANES], i[LANES], j[LANES]; /* lanes past nb repeat the first pair */
        for (int q = 0; q < LANES; q++) {
            cc[q] = c0 + (q < nb ? q : 0);
            i[q] = pa[cc[q]], j[q] = pb[cc[q]];
        }
        if (nlaw > 1)
            for (int q = 0; q < LANES; q++) {
                const sx_pair_law *law = &laws[mat[i[q]] * nlaw + mat[j[q]]];
                kn[q] = law->kn, ks[q] = law->ks, mu[q] = law->mu, dash[q] = law->dash_n, bn[q] = law->beta_n;
            }
        /* the history as stored, four consecutive pairs by shuffles (a short
         * batch copied to four pairs first) */
        const bool full = nb == LANES;
        double tail[2 * LANES * D];
        uint8_t tail_touching[LANES];
        const double *hfs = fs_all + c0 * D, *hrel = geo_all + c0 * D;
        const uint8_t *htouching = touching + c0;
        if (!full) {
            for (int q = 0; q < LANES; q++) {
                memcpy(tail + q * D, fs_all + cc[q] * D, D * sizeof(double));
                memcpy(tail + (LANES + q) * D, geo_all + cc[q] * D, D * sizeof(double));
                tail_touching[q] = touching[cc[q]];
            }
            hfs = tail, hrel = tail + LANES * D, htouching = tail_touching;
        }
        vd fs_old[D], rel_old[D];
        load_lanes(hfs, fs_old);
        load_lanes(hrel, rel_old);
        v4u8 touched;
        memcpy(&touched, htouching, sizeof touched);
        const vm had = __builtin_convertvector(touched, vm) != 0;

        /* the previous normal from the relative position as in ball_chunk_pass
         * (first: its square root and division overlap the loads below) */
        vd rr = VZERO;
        for (int k = 0; k < D; k++) rr += rel_old[k] * rel_old[k];
        const vd inv_r = 1.0 / VSQRT(rr);

        vd dx[D], dv[D];
        for (int k = 0; k < D; k++) {
            dx[k] = LANES_OF(x, j, D, k) - LANES_OF(x, i, D, k);
            dv[k] = LANES_OF(v, j, D, k) - LANES_OF(v, i, D, k);
        }
        const vd ri = LANES_OF(rad, i, 1, 0), rj = LANES_OF(rad, j, 1, 0);

        /* 4-1 ... 4-4 */
        /* sums from zero, as dot() (the sign of a zero sum) */
        vd d2 = VZERO;
        for (int k = 0; k < D; k++) d2 += dx[k] * dx[k];
        const vd d = VSQRT(d2), inv_d = 1.0 / d;
        vd n[D];
        for (int k = 0; k < D; k++) n[k] = dx[k] * inv_d;
        const vd rsum = ri + rj, u = rsum - d;
        const vd la = ri - 0.5 * u, lb = rj - 0.5 * u;
        /* 4-16, 4-17 as in ball_chunk_pass */
        vd ws[RD], vc[D];
#if D == 3
        vd wsum[3]; /* for 4-15 */
#endif
        for (int k = 0; k < RD; k++) {
            const vd wa = LANES_OF(w, i, RD, k), wb = LANES_OF(w, j, RD, k);
            ws[k] = la * wa + lb * wb;
#if D == 3
            wsum[k] = wa + wb;
#endif
        }
#if D == 3
        vc[0] = dv[0] - (ws[1] * n[2] - ws[2] * n[1]);
        vc[1] = dv[1] - (ws[2] * n[0] - ws[0] * n[2]);
        vc[2] = dv[2] - (ws[0] * n[1] - ws[1] * n[0]);
#else
        vc[0] = dv[0] - -ws[0] * n[1];
        vc[1] = dv[1] - ws[0] * n[0];
#endif
        vd vn = VZERO;
        for (int k = 0; k < D; k++) vn += vc[k] * n[k];
        vd vs[D];
        for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k];
        const vd fn = kn * u; /* 4-6 */
        const vd fmax = mu * VSEL(fn > VZERO, fn, VZERO);
        /* the shear force (none for a new contact) */
        vd g[D], prev[D];
        for (int k = 0; k < D; k++) prev[k] = rel_old[k] * inv_r;
#if D == 3
        shear_lanes(g, fs_old, prev, &had, n, wsum, vs, &ks, &fmax, dt);
#else
        shear_lanes(g, fs_old, prev, &had, n, NULL, vs, &ks, &fmax, dt);
#endif
        const vm active = u > VZERO;
        const vd sim = LANES_OF(im, i, 1, 0) + LANES_OF(im, j, 1, 0);
        vd cn;
        const vm other = (sim != memo_sim) | (dash != memo_dash);
        if (!VANY(other)) {
            cn = VZERO + memo_cn;
        } else {
            cn = VSQRT(dash / sim);
            memo_sim = sim[0], memo_dash = dash[0], memo_cn = cn[0];
        }
        const vd fd = VSEL(active & (bn > VZERO), fn + -cn * vn, fn);
        vd F[D];
        for (int k = 0; k < D; k++) {
            F[k] = VSEL(active, fd * n[k] + g[k], VZERO); /* 4-5 */
            g[k] = VSEL(active, g[k], VZERO);
        }
        /* 4-21: both arms lie along n */
        vd nf[RD];
#if D == 3
        nf[0] = n[1] * F[2] - n[2] * F[1];
        nf[1] = n[2] * F[0] - n[0] * F[2];
        nf[2] = n[0] * F[1] - n[1] * F[0];
#else
        nf[0] = n[0] * F[1] - n[1] * F[0];
#endif
        vd ma[RD], mj[RD];
        for (int k = 0; k < RD; k++) ma[k] = la * nf[k], mj[k] = -lb * nf[k];
        const vd fdo = VSEL(active, fd, VZERO);
        const vm live = d2 < rsum * rsum;
        const vm bad = live & (u > VSEL(ri < rj, ri, rj));
        if (VANY(bad))
            for (int q = 0; q < nb; q++)
                if (bad[q]) {
                    o->st = SX_EUNSTABLE;
                    o->err_a = B->id[i[q]], o->err_b = B->id[j[q]], o->err_un = u[q];
                    o->err_r = ri[q] < rj[q] ? ri[q] : rj[q];
                    return;
                }
        /* a pair out of reach this step keeps its history, untouched, and has no force */
        if (full) {
            vd keep[D];
            for (int k = 0; k < D; k++) keep[k] = VSEL(live, g[k], fs_old[k]);
            store_lanes(fs_all + c0 * D, keep);
            for (int k = 0; k < D; k++) keep[k] = VSEL(live, dx[k], rel_old[k]);
            store_lanes(geo_all + c0 * D, keep);
            memcpy(fn_all + c0, &fdo, sizeof fdo); /* 0 out of reach, as in ball_chunk_pass */
            for (int q = 0; q < LANES; q++) touching[c0 + q] = (live[q] & active[q]) != 0;
        } else {
            for (int q = 0; q < nb; q++) {
                const int64_t c = cc[q];
                touching[c] = (live[q] & active[q]) != 0;
                fn_all[c] = fdo[q];
                if (!live[q]) continue;
                for (int k = 0; k < D; k++) fs_all[c * D + k] = g[k][q], geo_all[c * D + k] = dx[k][q];
            }
        }
        for (int q = 0; q < nb; q++) {
            if (!live[q]) continue;
            double *fi = f + i[q] * D, *ti = t + i[q] * RD, *fj = f + j[q] * D, *tj = t + j[q] * RD;
            for (int k = 0; k < D; k++) {
                fi[k] -= F[k][q];
                fj[k] += F[k][q];
            }
            for (int k = 0; k < RD; k++) {
                ti[k] -= ma[k][q];
                tj[k] += mj[k][q];
            }
        }
    }
}

static void ball_chunk(sx_model *m, sx_chunk *o)
{
    if (m->law_plain && !m->bb.bond && !m->track_energy) ball_chunk_batched(m, o);
    else ball_chunk_pass(m, o);
}

/* Chunks of the ball-ball pass and blocks of the per-ball passes, planned
 * after each build (and on a restore) from the stores alone. A power of
 * two of chunks (so that each phase splits evenly over 2, 4, ... threads)
 * of at least CHUNK_PAIRS pairs, at most MAX_CHUNKS; MAX_CHUNKS / 2 bounds
 * the useful thread count of that pass, MOTION_BLOCKS that of the per-ball
 * passes. */
enum { CHUNK_PAIRS = 1024, MAX_CHUNKS = 16, MOTION_BLOCKS = SX_MOTION_BLOCKS, MOTION_MIN = 256 };

/* First index c of sorted a[0..n) with a[c] >= key. */
static int64_t lower_bound(const int32_t *a, int64_t n, int64_t key)
{
    int64_t lo = 0, hi = n;
    while (lo < hi) {
        const int64_t mid = lo + (hi - lo) / 2;
        if (a[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

static bool plan_chunks(sx_model *m)
{
    /* ownership needs the pairs grouped by a: bonded pairs appended by a
     * build, or a store patched by a removal, are put in order (stably, so
     * each ball's contacts keep their order) */
    if (!sx__pairs_sort(m, &m->bb) || !sx__pairs_sort(m, &m->bw)) return false;
    const sx_pairs *p = &m->bb;
    const int64_t n = m->balls.n;
    int64_t k = 1;
    while (2 * k <= MAX_CHUNKS && 2 * k * CHUNK_PAIRS <= p->n) k *= 2;
    if (k > m->cap_chunk) {
        sx_chunk *q = sx_alloc_resize(&m->alloc, m->chunks, (size_t)m->cap_chunk, (size_t)k, sizeof *q);
        if (!q) return false;
        m->chunks = q;
        m->cap_chunk = k;
    }
    m->nchunk = k;
    /* chunk c starts at the ball of pair p->n c / k, and at least where the
     * chunk two before it reaches (its largest b), so that a chunk's b's
     * fall in its own range or the next one's */
    int64_t lo[MAX_CHUNKS + 1];
    for (int64_t c = 0; c < k; c++) {
        const int64_t q = p->n * c / k;
        lo[c] = c == 0 ? 0 : q < p->n ? p->a[q] : n;
    }
    lo[k] = n;
    for (int64_t c = 0; c < k; c++) {
        if (c > 0 && lo[c] < lo[c - 1]) lo[c] = lo[c - 1];
        sx_chunk *o = &m->chunks[c];
        o->own_lo = lo[c];
        o->first = lower_bound(p->a, p->n, lo[c]);
        if (c >= 2) { /* chunk c - 2 is complete once chunk c - 1 starts */
            const sx_chunk *e = &m->chunks[c - 2];
            int64_t reach = lo[c - 1];
            for (int64_t q = e->first; q < m->chunks[c - 1].first; q++)
                if (p->b[q] + 1 > reach) reach = p->b[q] + 1;
            if (reach > lo[c]) {
                lo[c] = reach;
                o->own_lo = reach;
                o->first = lower_bound(p->a, p->n, reach);
            }
        }
    }
    for (int64_t c = 0; c < k; c++) {
        sx_chunk *o = &m->chunks[c];
        o->own_hi = c + 1 < k ? m->chunks[c + 1].own_lo : n;
        o->last = c + 1 < k ? m->chunks[c + 1].first : p->n;
        /* the first phase clears the forces of every ball before either phase adds to them */
        o->clear_lo = c % 2 == 0 ? o->own_lo : 0;
        o->clear_hi = c % 2 == 0 ? (c + 2 < k ? m->chunks[c + 2].own_lo : n) : 0;
        for (int64_t q = o->first; q < o->last; q++) /* what the two phases rely on */
            assert(p->a[q] >= o->own_lo && p->a[q] < o->own_hi && (c + 2 >= k || p->b[q] < m->chunks[c + 2].own_lo));
    }
    /* blocks of at least MOTION_MIN balls, at most MOTION_BLOCKS of them */
    if (!m->blocks) {
        m->blocks = sx_alloc_resize(&m->alloc, NULL, 0, MOTION_BLOCKS, sizeof *m->blocks);
        if (!m->blocks) return false;
    }
    int64_t nb = (n + MOTION_MIN - 1) / MOTION_MIN;
    if (nb > MOTION_BLOCKS) nb = MOTION_BLOCKS;
    const int64_t size = nb ? (n + nb - 1) / nb : 0;
    m->nblock = nb;
    for (int64_t b = 0; b < nb; b++) {
        sx_block *o = &m->blocks[b];
        o->b0 = b * size;
        o->b1 = (b + 1) * size < n ? (b + 1) * size : n;
        o->w0 = lower_bound(m->bw.a, m->bw.n, o->b0);
        o->w1 = lower_bound(m->bw.a, m->bw.n, o->b1);
    }
    return true;
}

/* Runs the even chunks, then the odd ones (each phase in parallel), then
 * merges energies, cracks and errors in chunk order. */
static sx_status KERNEL(contacts)(sx_model *m)
{
    const int64_t nchunk = m->nchunk;
#pragma omp parallel num_threads(m->threads) if (nchunk > 2)
    for (int64_t phase = 0; phase < 2; phase++) {
#pragma omp for schedule(static)
        for (int64_t c = phase; c < nchunk; c += 2) ball_chunk(m, &m->chunks[c]);
    }
    for (int64_t c = 0; c < nchunk; c++) {
        sx_chunk *o = &m->chunks[c];
        if (o->st) return overlap_error(m, "balls", o->err_a, o->err_b, o->err_un, o->err_r);
        m->acc.slip += o->slip;
        m->acc.viscous += o->viscous;
        m->acc.bond_released += o->released;
        m->bonds.intact -= o->lost_bonds;
        for (int64_t e = 0; e < o->ncracks; e++) sx__crack_log(m, &o->cracks[e]);
    }
    return SX_OK;
}

/* The wall pass of one block: the block's ball-wall contacts, after the
 * ball-ball pass. The wall is entity A (phi1 of 4-10), the ball B; n
 * points from the wall to the ball. Wall resultants go to the block's
 * partial sums acc (one per wall). */

/* The dashpot factor of the last contact that needed one (balls of one
 * size and material share it). */
typedef struct dash_memo {
    double dash, im, cn;
} dash_memo;

/* One ball-wall contact c, every law and wall kind; false on an overlap error. */
static inline __attribute__((always_inline)) bool wall_contact(sx_model *m, sx_block *o, sx_wall_acc *acc, int64_t c, dash_memo *memo)
{
    sx_balls *B = &m->balls;
    double *restrict f = B->f, *restrict t = B->t;
    sx_pairs *p = &m->bw;
    const double dt = motion_dt(m);
    const bool track = m->track_energy;
    const int64_t i = p->a[c];
    const sx_wall *wl = &m->walls[p->b[c]];
    sx_wall_acc *wa = &acc[p->b[c]];
    const double *xi = B->x + i * D, r = B->rad[i];
    double *fs = p->fs + c * D;
    double n[D];
    const double dist = wall_distance(wl, xi, n);
    const sx_pair_law *law = &m->wlaw[B->mat[i] * m->nwall + p->b[c]];
    if (dist >= r) {
        if (p->touching[c] && track) { /* a Hertz spring holds nothing at zero overlap: ks = 0 */
            double kn, ks;
            stiffness(law, r, 0, r, 0, &kn, &ks);
            if (ks > 0) o->slip += 0.5 * dot(fs, fs) / ks;
        }
        p->touching[c] = 0;
        return true;
    }
    const double un = r - dist; /* 4-3 */
    if (un > r) {
        o->st = SX_EUNSTABLE;
        o->err_ball = B->id[i], o->err_wall = wl->id, o->err_un = un, o->err_r = r;
        return false;
    }
    const double lb = r - 0.5 * un;
    double xc[D];
    for (int k = 0; k < D; k++) xc[k] = xi[k] - lb * n[k]; /* 4-4 */
    /* the contact point's velocity: the ball's, with its arm -lb n, less the
     * wall's surface velocity (its translation, and a cylinder's radial
     * motion along -n) */
    double wn[D], vc[D];
    spin_cross(B->w + i * RD, n, wn);
    for (int k = 0; k < D; k++)
        vc[k] = (B->v[i * D + k] - lb * wn[k]) - (wl->def.vel[k] - wl->def.radial_vel * n[k]);
    const double vn = dot(vc, n);
    double vs[D];
    for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k];

    double kn, ks;
    const double fn = stiffness(law, r, 0, r, un, &kn, &ks);
    if (!p->touching[c])
        for (int k = 0; k < D; k++) fs[k] = 0, p->geo[c * D + k] = n[k];
    carry rot;
    carry_make(&rot, p->geo + c * D, n, NULL, B->w + i * RD, dt);
    carry_apply(&rot, fs);
    double f0[D];
    for (int k = 0; k < D; k++) f0[k] = fs[k];
    const double ksdt = ks * dt;
    for (int k = 0; k < D; k++) fs[k] -= ksdt * vs[k];
    const double fmax = law->mu * fn, f2 = dot(fs, fs);
    bool slip = false;
    if (f2 > fmax * fmax) {
        const double sc = fmax / sqrt(f2);
        if (track && ks > 0) { /* as for ball-ball contacts */
            double e = 0;
            for (int k = 0; k < D; k++) e += (f0[k] + sc * fs[k]) * (1 - sc) * fs[k];
            o->slip += 0.5 * e / ks;
        }
        for (int k = 0; k < D; k++) fs[k] *= sc;
        slip = true;
    }
    for (int k = 0; k < D; k++) p->geo[c * D + k] = n[k];
    p->touching[c] = 1;

    double fd = fn, dsh[D], F[D];
    bool shear_dashpot = false;
    if (law->beta_n > 0 || law->beta_s > 0) {
        /* the ball's full mass: c = 2 beta sqrt(m k); balls of one size and material share it */
        double cn;
        if (!law->plain) {
            cn = 2 * law->beta_n * sqrt(kn / B->inv_mass[i]);
        } else if (law->dash_n == memo->dash && B->inv_mass[i] == memo->im) {
            cn = memo->cn;
        } else {
            cn = sqrt(law->dash_n / B->inv_mass[i]);
            memo->dash = law->dash_n, memo->im = B->inv_mass[i], memo->cn = cn;
        }
        const double fdn = -cn * vn;
        fd += fdn;
        double work = fdn * vn;
        if (!slip && law->beta_s > 0) {
            const double cs = 2 * law->beta_s * sqrt(ks / B->inv_mass[i]);
            for (int k = 0; k < D; k++) dsh[k] = -cs * vs[k];
            work += dot(dsh, vs);
            shear_dashpot = true;
        }
        if (track) o->viscous -= work * dt;
    }
    for (int k = 0; k < D; k++) F[k] = fd * n[k] + fs[k];
    if (shear_dashpot)
        for (int k = 0; k < D; k++) F[k] += dsh[k];
    p->un[c] = un;
    p->fn[c] = fd;
    wa->load += fd;
    wa->kn_sum += kn;
    wa->contacts++;
    /* 4-21: the ball's arm is -lb n */
    double nf[RD], mw[RD], arm[D];
    moment_of(n, F, nf);
    for (int k = 0; k < D; k++) {
        f[i * D + k] += F[k];
        wa->force[k] -= F[k];
        arm[k] = xc[k] - wl->def.point[k];
    }
#if D == 3
    if (wl->def.kind == SX_WALL_RECT)
        for (int k = 0; k < D; k++) arm[k] -= 0.5 * (wl->def.edge1[k] + wl->def.edge2[k]);
#endif
    moment_of(arm, F, mw);
    for (int k = 0; k < RD; k++) {
        t[i * RD + k] -= lb * nf[k];
        wa->moment[k] -= mw[k];
    }
    return true;
}

/* Four ball-wall contacts [c0, c0 + 4) at once where each is plain (an
 * infinite wall, a linear law without a shear dashpot, no energy
 * tracking): wall_contact's arithmetic in vector lanes, as
 * ball_chunk_batched does it for ball-ball pairs, then the results in
 * contact order; the same bits. false on an overlap error. */
/* GCC 12 takes a vector built from four scalars straight into an array
 * element for a read of the element's old value (-Wmaybe-uninitialized);
 * every element here is written before it is read. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
static inline __attribute__((always_inline)) bool wall_lanes(sx_model *m, sx_block *o, sx_wall_acc *acc, int64_t c0, dash_memo *memo)
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bw;
    const double dt = motion_dt(m);
    int64_t i[LANES];
    const sx_wall *wl[LANES];
    const sx_pair_law *law[LANES];
    for (int q = 0; q < LANES; q++) {
        i[q] = p->a[c0 + q];
        wl[q] = &m->walls[p->b[c0 + q]];
        law[q] = &m->wlaw[B->mat[i[q]] * m->nwall + p->b[c0 + q]];
    }
#define WALL_LANES(field) ((vd){wl[0]->def.field, wl[1]->def.field, wl[2]->def.field, wl[3]->def.field})
#define LAW_LANES(field) ((vd){law[0]->field, law[1]->field, law[2]->field, law[3]->field})
    vd x[D], v[D], pt[D], n[D], vel[D];
    for (int k = 0; k < D; k++) {
        x[k] = LANES_OF(B->x, i, D, k);
        v[k] = LANES_OF(B->v, i, D, k);
        pt[k] = WALL_LANES(point[k]);
        n[k] = WALL_LANES(normal[k]);
        vel[k] = WALL_LANES(vel[k]);
    }
    const vd rvel = WALL_LANES(radial_vel);
    const vd rad = LANES_OF(B->rad, i, 1, 0), im = LANES_OF(B->inv_mass, i, 1, 0);
    const vd kn = LAW_LANES(kn), ks = LAW_LANES(ks), mu = LAW_LANES(mu), dash = LAW_LANES(dash_n),
             bn = LAW_LANES(beta_n);
#undef WALL_LANES
#undef LAW_LANES
    vd fs_old[D], no_old[D];
    load_lanes(p->fs + c0 * D, fs_old);
    load_lanes(p->geo + c0 * D, no_old);
    v4u8 touched;
    memcpy(&touched, p->touching + c0, sizeof touched);
    const vm had = __builtin_convertvector(touched, vm) != 0;

    /* the distance from an infinite wall (sums from zero, as dot()) */
    vd dist = VZERO;
    for (int k = 0; k < D; k++) dist += (x[k] - pt[k]) * n[k];
    const vm live = dist < rad;
    const vd un = rad - dist; /* 4-3 */
    const vm bad = live & (un > rad);
    if (VANY(bad))
        for (int q = 0; q < LANES; q++)
            if (bad[q]) {
                o->st = SX_EUNSTABLE;
                o->err_ball = B->id[i[q]], o->err_wall = wl[q]->id, o->err_un = un[q], o->err_r = rad[q];
                return false;
            }
    const vd lb = rad - 0.5 * un;
    vd xc[D], wn[D], vc[D];
    for (int k = 0; k < D; k++) xc[k] = x[k] - lb * n[k]; /* 4-4 */
#if D == 3
    vd w[3];
    for (int k = 0; k < 3; k++) w[k] = LANES_OF(B->w, i, 3, k);
    wn[0] = w[1] * n[2] - w[2] * n[1];
    wn[1] = w[2] * n[0] - w[0] * n[2];
    wn[2] = w[0] * n[1] - w[1] * n[0];
#else
    const vd w0 = LANES_OF(B->w, i, 1, 0);
    wn[0] = -w0 * n[1];
    wn[1] = w0 * n[0];
#endif
    for (int k = 0; k < D; k++) vc[k] = (v[k] - lb * wn[k]) - (vel[k] - rvel * n[k]);
    vd vn = VZERO;
    for (int k = 0; k < D; k++) vn += vc[k] * n[k];
    vd vs[D];
    for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k];
    const vd fn = kn * un, fmax = mu * fn; /* 4-6 */
    /* the shear force (the wall does not spin) */
    vd g[D];
#if D == 3
    shear_lanes(g, fs_old, no_old, &had, n, w, vs, &ks, &fmax, dt);
#else
    shear_lanes(g, fs_old, no_old, &had, n, NULL, vs, &ks, &fmax, dt);
#endif
    /* the ball's full mass: c = 2 beta sqrt(m k) */
    vd cn = VZERO + memo->cn;
    const vm other = (im != memo->im) | (dash != memo->dash);
    if (VANY(other)) {
        cn = VSQRT(dash / im);
        memo->dash = dash[0], memo->im = im[0], memo->cn = cn[0];
    }
    const vd fd = VSEL(bn > VZERO, fn + -cn * vn, fn);
    vd F[D], nf[RD], mw[RD], arm[D];
    for (int k = 0; k < D; k++) {
        F[k] = fd * n[k] + g[k];
        arm[k] = xc[k] - pt[k];
    }
    /* 4-21: the ball's arm is -lb n */
#if D == 3
    nf[0] = n[1] * F[2] - n[2] * F[1], nf[1] = n[2] * F[0] - n[0] * F[2], nf[2] = n[0] * F[1] - n[1] * F[0];
    mw[0] = arm[1] * F[2] - arm[2] * F[1], mw[1] = arm[2] * F[0] - arm[0] * F[2], mw[2] = arm[0] * F[1] - arm[1] * F[0];
#else
    nf[0] = n[0] * F[1] - n[1] * F[0];
    mw[0] = arm[0] * F[1] - arm[1] * F[0];
#endif
    double *restrict f = B->f, *restrict t = B->t;
    for (int q = 0; q < LANES; q++) {
        const int64_t c = c0 + q;
        if (!live[q]) {
            p->touching[c] = 0;
            continue;
        }
        sx_wall_acc *wa = &acc[p->b[c]];
        for (int k = 0; k < D; k++) p->fs[c * D + k] = g[k][q], p->geo[c * D + k] = n[k][q];
        p->touching[c] = 1;
        p->un[c] = un[q];
        p->fn[c] = fd[q];
        wa->load += fd[q];
        wa->kn_sum += kn[q];
        wa->contacts++;
        for (int k = 0; k < D; k++) {
            f[i[q] * D + k] += F[k][q];
            wa->force[k] -= F[k][q];
        }
        for (int k = 0; k < RD; k++) {
            t[i[q] * RD + k] -= lb[q] * nf[k][q];
            wa->moment[k] -= mw[k][q];
        }
    }
    return true;
}

#pragma GCC diagnostic pop

/* A contact wall_lanes takes. */
static inline bool plain_wall_contact(const sx_model *m, int64_t c)
{
    const sx_wall *wl = &m->walls[m->bw.b[c]];
    const sx_pair_law *law = &m->wlaw[m->balls.mat[m->bw.a[c]] * m->nwall + m->bw.b[c]];
    return (wl->def.kind == SX_WALL_PLANE || wl->def.kind == SX_WALL_LINE) && law->plain &&
           law->beta_s == 0;
}

SX_VECTOR_CLONES static void wall_block(sx_model *m, sx_block *o, sx_wall_acc *acc)
{
    if (m->nwall) memset(acc, 0, (size_t)m->nwall * sizeof *acc);
    o->slip = o->viscous = 0;
    o->st = SX_OK;
    dash_memo memo = {NAN, NAN, 0};
    for (int64_t c = o->w0; c < o->w1;) {
        bool lanes = !m->track_energy && c + LANES <= o->w1;
        for (int q = 0; q < LANES && lanes; q++) lanes = plain_wall_contact(m, c + q);
        if (lanes) {
            if (!wall_lanes(m, o, acc, c, &memo)) return;
            c += LANES;
        } else {
            if (!wall_contact(m, o, acc, c, &memo)) return;
            c++;
        }
    }
}

/* The wall pass over all blocks (in parallel), then the walls' resultants,
 * energies and errors summed in block order. */
static sx_status KERNEL(walls)(sx_model *m)
{
    const int64_t nw = m->nwall, nb = m->nblock;
    /* the laws of each material against each wall, for this step */
    if (m->nmat * nw > m->cap_wlaw) {
        sx_pair_law *q = sx_alloc_resize(&m->alloc, m->wlaw, (size_t)m->cap_wlaw, (size_t)(m->nmat * nw), sizeof *q);
        if (!q) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
        m->wlaw = q;
        m->cap_wlaw = m->nmat * nw;
    }
    for (int a = 0; a < m->nmat; a++)
        for (int64_t w = 0; w < nw; w++) m->wlaw[a * nw + w] = sx__wall_law(m, a, &m->walls[w]);
    if (nb * nw > m->cap_wall_acc) {
        sx_wall_acc *q = sx_alloc_resize(&m->alloc, m->wall_acc, (size_t)m->cap_wall_acc, (size_t)(nb * nw), sizeof *q);
        if (!q) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
        m->wall_acc = q;
        m->cap_wall_acc = nb * nw;
    }
#pragma omp parallel for schedule(static) num_threads(m->threads) if (nb > 1)
    for (int64_t b = 0; b < nb; b++) wall_block(m, &m->blocks[b], nw ? m->wall_acc + b * nw : NULL);
    for (int64_t w = 0; w < nw; w++) {
        sx_wall *wl = &m->walls[w];
        memset(wl->force, 0, sizeof wl->force);
        memset(wl->moment, 0, sizeof wl->moment);
        wl->load = wl->kn_sum = 0;
        wl->contacts = 0;
    }
    for (int64_t b = 0; b < nb; b++) {
        const sx_block *o = &m->blocks[b];
        if (o->st) return overlap_error(m, "ball and wall", o->err_ball, o->err_wall, o->err_un, o->err_r);
        m->acc.slip += o->slip;
        m->acc.viscous += o->viscous;
        for (int64_t w = 0; w < nw; w++) {
            const sx_wall_acc *a = &m->wall_acc[b * nw + w];
            sx_wall *wl = &m->walls[w];
            for (int k = 0; k < 3; k++) wl->force[k] += a->force[k], wl->moment[k] += a->moment[k];
            wl->load += a->load;
            wl->kn_sum += a->kn_sum;
            wl->contacts += a->contacts;
        }
    }
    if (m->track_energy) /* boundary work of the moving walls over this step */
        for (int64_t w = 0; w < nw; w++)
            m->acc.boundary_work -= (dot(m->walls[w].force, m->walls[w].def.vel) + m->walls[w].def.radial_vel * m->walls[w].load) * m->dt;
    return SX_OK;
}

/* --------------------------------------------------------- law of motion */


/* After a block's law of motion: when its check sum is not finite, the
 * first ball whose position, velocity or spin is not (-1: none, the sum
 * overflowed). */
static void blame_non_finite(const sx_model *m, sx_block *o, double check)
{
    const sx_balls *B = &m->balls;
    o->bad = -1;
    if (isfinite(check)) return;
    for (int64_t i = o->b0; i < o->b1 && o->bad < 0; i++) {
        bool ok = true;
        for (int k = 0; k < D; k++) ok &= isfinite(B->x[i * D + k]) && isfinite(B->v[i * D + k]);
        for (int k = 0; k < RD; k++) ok &= isfinite(B->w[i * RD + k]);
        if (!ok) o->bad = i;
    }
}

/* 4-46 ... 4-48: central differences, velocities at half steps, for the
 * balls of one block; partial sums go to the block. With energy tracking,
 * the damping's and applied loads' work use the mean of the old and new
 * velocities. A free, undamped component takes v += (F/m + g) dt, the
 * same lines in both instances: `plain` (a constant at each call site)
 * compiles a block without fixities, damping or tracking alone. */
static inline __attribute__((always_inline)) void motion_pass(sx_model *m, sx_block *o, const bool plain)
{
    sx_balls *B = &m->balls;
    const double dt = m->dt;
    /* the kick spans the time between the half-step velocities, t_{n+1/2} - t_{n-1/2} */
    const double dtv = m->dt_prev > 0 ? 0.5 * (m->dt_prev + m->dt) : m->dt;
    const double g[D] = {m->gravity[0], m->gravity[1]
#if D == 3
                         , m->gravity[2]
#endif
    };
    const bool track = !plain && m->track_energy;
    double *restrict xa = B->x, *restrict va = B->v, *restrict wa = B->w;
    const double *restrict fa = B->f, *restrict ta = B->t, *restrict xb = B->x_build;
    const double *restrict ima = B->inv_mass, *restrict iia = B->inv_inertia;
    const uint8_t *restrict fixa = B->fix;
    const int32_t *cl = B->clump;
    double worst = 0, damp_work = 0, load_work = 0;
    /* the displacements' squares (a non-finite velocity makes its position
     * so) and 0 x every spin: not finite once some value is not (or once
     * the squares overflow; the search below tells) */
    double check = 0;
    for (int64_t i = o->b0; i < o->b1; i++) {
        if (cl && cl[i]) continue; /* clumps: a pebble moves with its clump (clumps.c) */
        const unsigned fix = plain ? 0 : fixa[i];
        const double a = plain ? 0 : sx__ball_damping(m, i), im = ima[i], ii = iia[i];
        double *v = va + i * D, *x = xa + i * D;
        const double *f = fa + i * D;
        double disp2 = 0;
        for (int k = 0; k < D; k++) {
            if (!(fix & (SX_FIX_VX << k))) {
                const double vold = v[k];
                if (a == 0) {
                    v[k] += (f[k] * im + g[k]) * dtv; /* 4-46 with 4-40 */
                } else {
                    const double force = f[k] + g[k] / im; /* 4-40: the unbalanced force includes the weight */
                    const double fd = sx__damped(force, v[k], a);
                    v[k] += fd * im * dtv; /* 4-46 */
                    if (track) damp_work += (fd - force) * 0.5 * (vold + v[k]) * dt;
                }
                if (track && B->fapp) load_work += B->fapp[i * D + k] * 0.5 * (vold + v[k]) * dt;
            }
            x[k] += v[k] * dt; /* 4-48 */
            const double u = x[k] - xb[i * D + k];
            disp2 += u * u;
        }
        check += disp2;
        double *w = wa + i * RD;
        const double *t = ta + i * RD;
        for (int k = 0; k < RD; k++) {
            if (!(fix & (SX_FIX_WX << k))) {
                const double wold = w[k];
                if (a == 0) {
                    w[k] += t[k] * ii * dtv; /* 4-47 */
                } else {
                    const double md = sx__damped(t[k], w[k], a);
                    w[k] += md * ii * dtv;
                    if (track) damp_work += (md - t[k]) * 0.5 * (wold + w[k]) * dt;
                }
                if (track && B->tapp) load_work += B->tapp[i * RD + k] * 0.5 * (wold + w[k]) * dt;
            }
            check += 0 * w[k];
        }
        worst = disp2 > worst ? disp2 : worst;
    }
    o->worst = worst;
    o->damp_work = damp_work;
    o->load_work = load_work;
    blame_non_finite(m, o, check);
}

/* A plain block (no fixities, damping, tracking or pebbles) four balls at
 * a time: motion_pass's arithmetic in vector lanes (four balls' components
 * are adjacent in memory, moved by shuffles), the largest displacement per
 * lane and then over the lanes (a maximum, in any order the same), the
 * last balls one by one. */
static inline __attribute__((always_inline)) void motion_lanes(sx_model *m, sx_block *o)
{
    sx_balls *B = &m->balls;
    const double dt = m->dt;
    const double dtv = m->dt_prev > 0 ? 0.5 * (m->dt_prev + m->dt) : m->dt; /* as in motion_pass */
    double *restrict xa = B->x, *restrict va = B->v, *restrict wa = B->w;
    const double *restrict fa = B->f, *restrict ta = B->t, *restrict xb = B->x_build;
    const double *restrict ima = B->inv_mass, *restrict iia = B->inv_inertia;
    vd worst = VZERO, check = VZERO;
    int64_t i = o->b0;
    for (; i + LANES <= o->b1; i += LANES) {
        vd x[D], v[D], f[D], x0[D], im, ii;
        load_lanes(xa + i * D, x);
        load_lanes(va + i * D, v);
        load_lanes(fa + i * D, f);
        load_lanes(xb + i * D, x0);
        memcpy(&im, ima + i, sizeof im);
        memcpy(&ii, iia + i, sizeof ii);
        vd disp2 = VZERO;
        for (int k = 0; k < D; k++) {
            v[k] += (f[k] * im + m->gravity[k]) * dtv; /* 4-46 with 4-40 */
            x[k] += v[k] * dt;                         /* 4-48 */
            const vd u = x[k] - x0[k];
            disp2 += u * u;
        }
        store_lanes(xa + i * D, x);
        store_lanes(va + i * D, v);
        check += disp2;
        worst = VSEL(disp2 > worst, disp2, worst);
#if D == 3
        vd w[3], t[3];
        load_lanes(wa + i * 3, w);
        load_lanes(ta + i * 3, t);
        for (int k = 0; k < 3; k++) {
            w[k] += t[k] * ii * dtv; /* 4-47 */
            check += 0 * w[k];
        }
        store_lanes(wa + i * 3, w);
#else
        vd w, t;
        memcpy(&w, wa + i, sizeof w);
        memcpy(&t, ta + i, sizeof t);
        w += t * ii * dtv; /* 4-47 */
        check += 0 * w;
        memcpy(wa + i, &w, sizeof w);
#endif
    }
    double most = 0, sum = check[0] + check[1] + check[2] + check[3];
    for (int q = 0; q < LANES; q++) most = worst[q] > most ? worst[q] : most;
    for (; i < o->b1; i++) {
        const double im = ima[i], ii = iia[i];
        double disp2 = 0;
        for (int k = 0; k < D; k++) {
            va[i * D + k] += (fa[i * D + k] * im + m->gravity[k]) * dtv;
            xa[i * D + k] += va[i * D + k] * dt;
            const double u = xa[i * D + k] - xb[i * D + k];
            disp2 += u * u;
        }
        sum += disp2;
        for (int k = 0; k < RD; k++) {
            wa[i * RD + k] += ta[i * RD + k] * ii * dtv;
            sum += 0 * wa[i * RD + k];
        }
        most = disp2 > most ? disp2 : most;
    }
    o->worst = most;
    o->damp_work = o->load_work = 0;
    blame_non_finite(m, o, sum);
}

SX_VECTOR_CLONES static void integrate_block(sx_model *m, sx_block *o)
{
    const sx_balls *B = &m->balls;
    /* undamped: no ball has its own damping and no material has any (no per-ball test needed) */
    bool plain = !m->track_energy, undamped = !B->alpha;
    for (int k = 0; k < m->nmat && undamped; k++) undamped = m->mats[k].def.damping == 0;
    for (int64_t i = o->b0; i < o->b1 && plain; i++) plain = !B->fix[i] && (undamped || sx__ball_damping(m, i) == 0);
    if (plain && !B->clump) motion_lanes(m, o);
    else if (plain) motion_pass(m, o, true);
    else motion_pass(m, o, false);
}

/* The law of motion in fixed blocks of balls whose partial sums are added
 * in block order (the same bits for any thread count). Returns the largest
 * displacement since the last build in *max_disp. */
static sx_status KERNEL(integrate)(sx_model *m, double *max_disp)
{
    const int64_t nb = m->nblock;
#pragma omp parallel for schedule(static) num_threads(m->threads) if (nb > 1)
    for (int64_t b = 0; b < nb; b++) integrate_block(m, &m->blocks[b]);
    double worst = 0;
    for (int64_t b = 0; b < nb; b++) {
        const sx_block *o = &m->blocks[b];
        if (o->bad >= 0)
            return sx__fail(m, SX_EUNSTABLE,
                            "unstable at step %lld: ball %lld has a non-finite position, velocity or spin; "
                            "the timestep %g s is likely too large (critical estimate %g s)",
                            (long long)m->step, (long long)m->balls.id[o->bad], m->dt, KERNEL(critical_dt)(m));
        if (o->worst > worst) worst = o->worst;
        if (m->track_energy) {
            m->acc.local_damping -= o->damp_work;
            m->acc.boundary_work += o->load_work;
        }
    }
    *max_disp = sqrt(worst);
    return SX_OK;
}

/* -------------------------------------------------------------- timestep */

/* Hertz has no stiffness at zero overlap: a free Hertz ball is rated at the
 * tangent stiffness of this overlap, a fraction of its radius. */
#define HERTZ_REFERENCE_OVERLAP 0.01

/* PFC-style estimate: for each ball sqrt(m / k_tran) with k_tran the sum of
 * its contacts' (tangent) normal and shear stiffnesses, bonds included, and
 * sqrt(I / k_rot) with k_rot = sum ks l^2 plus the bonds' rotational
 * stiffness. A ball is never rated below its own stiffness (as if touching
 * one entity like itself), so the first impact is already resolved and the
 * timestep does not jump as contacts form. */
static double KERNEL(critical_dt)(sx_model *m)
{
    sx_balls *B = &m->balls;
    const int64_t n = B->n;
    if (n == 0) return INFINITY;
    double *kt = sx__scratch(m, 4 * n);
    if (!kt) return INFINITY;
    double *kr = kt + n, *ct = kt + 2 * n, *cr = kt + 3 * n; /* stiffness and dashpot sums */
    memset(kt, 0, (size_t)(4 * n) * sizeof(double));
    const sx_pairs *p = &m->bb;
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t i = p->a[c], j = p->b[c];
        const int32_t slot = p->bond ? p->bond[c] - 1 : -1;
        double dx[D];
        for (int k = 0; k < D; k++) dx[k] = B->x[j * D + k] - B->x[i * D + k];
        const double rsum = B->rad[i] + B->rad[j], d = sqrt(dot(dx, dx)), un = rsum - d;
        const sx_pair_law *law = &m->law[B->mat[i] * m->law_n + B->mat[j]];
        double ktr = 0, krot_i = 0, krot_j = 0;
        if (un > 0 || (slot >= 0 && (m->bonds.kind[slot] & SX_BOND_CONTACT))) {
            double kn, ks;
            stiffness(law, B->rad[i], B->rad[j], 2 * B->rad[i] * B->rad[j] / rsum, un, &kn, &ks);
            if (un > 0 && (law->beta_n > 0 || law->beta_s > 0)) { /* the dashpots of ball_contacts */
                const double mstar = 1.0 / (B->inv_mass[i] + B->inv_mass[j]);
                const double cn = 2 * law->beta_n * sqrt(mstar * kn), cs = 2 * law->beta_s * sqrt(mstar * ks);
                ct[i] += cn + cs, ct[j] += cn + cs;
                cr[i] += cs * B->rad[i] * B->rad[i], cr[j] += cs * B->rad[j] * B->rad[j];
            }
            kn *= sx__law(law->law)->tangent; /* 4-29 */
            ktr = kn + ks;
            krot_i = ks * B->rad[i] * B->rad[i];
            krot_j = ks * B->rad[j] * B->rad[j];
        }
        if (slot >= 0 && (m->bonds.kind[slot] & SX_BOND_PARALLEL)) {
            const sx_bonds *b = &m->bonds;
            double area, inertia, polar;
            pb_section(b->rbar[slot], &area, &inertia, &polar);
            ktr += (b->kn[slot] + b->ks[slot]) * area;
            const double krb = b->kn[slot] * inertia + b->ks[slot] * polar;
            krot_i += krb + b->ks[slot] * area * B->rad[i] * B->rad[i];
            krot_j += krb + b->ks[slot] * area * B->rad[j] * B->rad[j];
        }
        kt[i] += ktr;
        kt[j] += ktr;
        kr[i] += krot_i;
        kr[j] += krot_j;
    }
    p = &m->bw;
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t i = p->a[c];
        double nrm[D];
        const double un = B->rad[i] - wall_distance(&m->walls[p->b[c]], B->x + i * D, nrm);
        if (un <= 0) continue;
        const sx_pair_law law = sx__wall_law(m, B->mat[i], &m->walls[p->b[c]]);
        double kn, ks;
        stiffness(&law, B->rad[i], 0, B->rad[i], un, &kn, &ks);
        if (law.beta_n > 0 || law.beta_s > 0) {
            const double mass = 1.0 / B->inv_mass[i];
            const double cs = 2 * law.beta_s * sqrt(mass * ks);
            ct[i] += 2 * law.beta_n * sqrt(mass * kn) + cs;
            cr[i] += cs * B->rad[i] * B->rad[i];
        }
        kn *= sx__law(law.law)->tangent;
        kt[i] += kn + ks;
        kr[i] += ks * B->rad[i] * B->rad[i];
    }
    double best = INFINITY;
    for (int64_t i = 0; i < n; i++) {
        /* the ball's own rating: a contact with an entity of its own stiffness */
        const sx_pair_law *self = &m->law[B->mat[i] * m->law_n + B->mat[i]];
        const double r = B->rad[i];
        double kn, ks;
        stiffness(self, r, r, r, HERTZ_REFERENCE_OVERLAP * r, &kn, &ks);
        const sx_law *own = sx__law(self->law);
        kn *= own->tangent;
        if (own->series) kn *= 2, ks *= 2; /* undo the series combination with itself */
        const double ktr = kt[i] > kn + ks ? kt[i] : kn + ks;
        const double krot = kr[i] > ks * r * r ? kr[i] : ks * r * r;
        if (B->clump && B->clump[i]) { /* clumps: the body is rated from its pebbles' sums (clumps.c) */
            kt[i] = ktr, kr[i] = krot;
            continue;
        }
        /* Contact dashpots lower the stable timestep of the central differences: for
         * m x'' + c x' + k x = 0 with x' taken at the half step, stability needs
         * (w dt)^2 + 4 z (w dt) < 4, i.e. dt < (2/w)(sqrt(1 + z^2) - z), z = c / (2 sqrt(k m));
         * local damping scales a decelerating force by up to (1 + alpha), so z is scaled too. */
        const double amp = 1 + sx__ball_damping(m, i);
        const double zt = amp * ct[i] / (2 * sqrt(ktr / B->inv_mass[i]));
        const double dtt = sqrt(1.0 / (B->inv_mass[i] * ktr)) * (sqrt(1 + zt * zt) - zt);
        if (dtt < best) best = dtt;
        if (krot > 0) {
            const double zr = amp * cr[i] / (2 * sqrt(krot / B->inv_inertia[i]));
            const double dtr = sqrt(1.0 / (B->inv_inertia[i] * krot)) * (sqrt(1 + zr * zr) - zr);
            if (dtr < best) best = dtr;
        }
    }
    if (m->clumps) best = fmin(best, sx__clumps_critical_dt(m, kt, kr, ct, cr)); /* reads the sums above */
    sx__scratch_release(m);
    return best;
}

/* -------------------------------------------------- energies and queries */

/* Geometry of a stored ball-ball pair: overlap and unit normal. */
static double pair_geometry(const sx_model *m, int64_t i, int64_t j, double *n)
{
    const sx_balls *B = &m->balls;
    for (int k = 0; k < D; k++) n[k] = B->x[j * D + k] - B->x[i * D + k];
    const double d = sqrt(dot(n, n));
    for (int k = 0; k < D; k++) n[k] = d > 0 ? n[k] / d : 0;
    return B->rad[i] + B->rad[j] - d;
}

/* Normal force and stiffnesses of a stored ball-ball pair from its geometry. */
static double pair_force(const sx_model *m, int64_t c, double un, double *kn, double *ks)
{
    const sx_balls *B = &m->balls;
    const int64_t i = m->bb.a[c], j = m->bb.b[c];
    const sx_pair_law *law = &m->law[B->mat[i] * m->law_n + B->mat[j]];
    const int32_t slot = m->bb.bond ? m->bb.bond[c] - 1 : -1;
    const bool active = un > 0 || (slot >= 0 && (m->bonds.kind[slot] & SX_BOND_CONTACT));
    const double rsum = B->rad[i] + B->rad[j];
    const double fn = stiffness(law, B->rad[i], B->rad[j], 2 * B->rad[i] * B->rad[j] / rsum, un, kn, ks);
    return active ? fn : 0;
}

static void KERNEL(energy)(const sx_model *m, sx_energy *e)
{
    const sx_balls *B = &m->balls;
    *e = m->acc;
    e->kinetic = e->gravitational = e->strain = e->bond_strain = 0;
    for (int64_t i = 0; i < B->n; i++) {
        if (B->clump && B->clump[i]) continue; /* clumps: a body's energy is counted once, below */
        const double *v = B->v + i * D, *w = B->w + i * RD;
        double ww = 0;
        for (int k = 0; k < RD; k++) ww += w[k] * w[k];
        e->kinetic += 0.5 * dot(v, v) / B->inv_mass[i] + 0.5 * ww / B->inv_inertia[i];
        e->gravitational -= dot(m->gravity, B->x + i * D) / B->inv_mass[i];
    }
    if (m->clumps) sx__clumps_energy(m, e);
    /* every overlap stores normal strain, even one no step has seen yet;
     * the shear spring only once the contact has history */
    const double zero[D] = {0};
    for (int64_t c = 0; c < m->bb.n; c++) {
        double n[D], kn, ks;
        const int64_t i = m->bb.a[c], j = m->bb.b[c];
        const double un = pair_geometry(m, i, j, n);
        const double fn = pair_force(m, c, un, &kn, &ks);
        e->strain += contact_strain(&m->law[B->mat[i] * m->law_n + B->mat[j]], fn, un, m->bb.touching[c] ? m->bb.fs + c * D : zero, ks);
        const int32_t slot = m->bb.bond ? m->bb.bond[c] - 1 : -1;
        if (slot >= 0 && (m->bonds.kind[slot] & SX_BOND_PARALLEL)) e->bond_strain += pb_strain(&m->bonds, slot);
    }
    for (int64_t c = 0; c < m->bw.n; c++) {
        double n[D], kn, ks;
        const int64_t i = m->bw.a[c];
        const sx_wall *wl = &m->walls[m->bw.b[c]];
        const double un = B->rad[i] - wall_distance(wl, B->x + i * D, n);
        const sx_pair_law law = sx__wall_law(m, B->mat[i], wl);
        const double fn = un > 0 ? stiffness(&law, B->rad[i], 0, B->rad[i], un, &kn, &ks) : 0;
        if (un > 0) e->strain += contact_strain(&law, fn, un, m->bw.touching[c] ? m->bw.fs + c * D : zero, ks);
    }
}

/* Contacts are reported as the last force evaluation left them (the forces
 * the balls felt): normal, overlap (a ball-ball one from the evaluation's
 * centre distance and the current radii), normal force (with its dashpot),
 * the elastic shear force and the bonds; the point is placed from ball a's
 * current centre. */
static bool report(const sx_model *m, const sx_pairs *p, int64_t c, bool is_wall,
                   bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    const sx_balls *B = &m->balls;
    const int64_t i = p->a[c];
    double n[D], un;
    if (is_wall) {
        for (int k = 0; k < D; k++) n[k] = p->geo[c * D + k];
        un = p->un[c];
    } else { /* the normal and overlap of the relative position, as the step computed them */
        const double *rel = p->geo + c * D, d = sqrt(dot(rel, rel)), inv_d = 1.0 / d;
        for (int k = 0; k < D; k++) n[k] = rel[k] * inv_d;
        un = B->rad[i] + B->rad[p->b[c]] - d;
    }
    sx_contact_info ci;
    memset(&ci, 0, sizeof ci);
    const sx_pair_law law = is_wall ? sx__wall_law(m, B->mat[i], &m->walls[p->b[c]])
                                    : m->law[B->mat[i] * m->law_n + B->mat[p->b[c]]];
    const double rj = is_wall ? B->rad[i] : B->rad[p->b[c]];
    stiffness(&law, B->rad[i], rj, is_wall ? B->rad[i] : 2 * B->rad[i] * rj / (B->rad[i] + rj), un, &ci.kn, &ci.ks);
    /* ball-wall normals point from the wall to the ball, so the point lies behind the centre */
    const double arm = is_wall ? -(B->rad[i] - 0.5 * un) : B->rad[i] - 0.5 * un;
    for (int k = 0; k < D; k++) {
        ci.normal[k] = n[k];
        ci.point[k] = B->x[i * D + k] + arm * n[k];
        ci.shear[k] = p->fs[c * D + k];
    }
    ci.overlap = un;
    ci.fn = p->fn[c];
    ci.a = B->id[i];
    ci.b = is_wall ? m->walls[p->b[c]].id : B->id[p->b[c]];
    ci.is_wall = is_wall;
    const int32_t slot = !is_wall && p->bond ? p->bond[c] - 1 : -1;
    if (slot >= 0) {
        const sx_bonds *b = &m->bonds;
        ci.bond = b->kind[slot];
        if (b->kind[slot] & SX_BOND_PARALLEL) {
            ci.pb_fn = b->fn[slot];
            ci.pb_radius = b->rbar[slot];
            for (int k = 0; k < D; k++) ci.pb_fs[k] = b->fs[slot * D + k];
#if D == 3
            for (int k = 0; k < 3; k++) ci.pb_moment[k] = b->mn[slot] * n[k] + b->ms[slot * 3 + k];
#else
            ci.pb_moment[0] = b->ms[slot];
#endif
        }
    }
    return fn(&ci, ud);
}

static bool KERNEL(each_contact)(const sx_model *m, bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    for (int64_t c = 0; c < m->bb.n; c++)
        if (m->bb.touching[c] && !report(m, &m->bb, c, false, fn, ud)) return false;
    for (int64_t c = 0; c < m->bw.n; c++)
        if (m->bw.touching[c] && !report(m, &m->bw, c, true, fn, ud)) return false;
    return true;
}

static int64_t KERNEL(count_contacts)(const sx_model *m)
{
    int64_t n = 0;
    for (int64_t c = 0; c < m->bb.n; c++) n += m->bb.touching[c];
    for (int64_t c = 0; c < m->bw.n; c++) n += m->bw.touching[c];
    return n;
}

const sx_kernels KERNEL(sx_kernels) = {
    .build = KERNEL(build),
    .contacts = KERNEL(contacts),
    .walls = KERNEL(walls),
    .integrate = KERNEL(integrate),
    .critical_dt = KERNEL(critical_dt),
    .energy = KERNEL(energy),
    .each_contact = KERNEL(each_contact),
    .count_contacts = KERNEL(count_contacts),
    .plan = plan_chunks,
};
