/* Stage: the broad phase (entry point KERNEL(build)). Part of the
 * per-dimension unit kernels.c, which includes it; not compiled alone. */

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
    int32_t *f;               /* the listed ball-wall pairs' facets (mesh walls; NULL without meshes) */
    int64_t n, cap;
    uint8_t *seen;            /* per bond slot: found again by the grid */
    /* periodic space: the cell vectors each old ball was wrapped by (3 per
     * ball), and the old ghosts (slots gbase + g: owner, image) */
    int32_t *wrap;
    int64_t nwrap;
    int64_t gbase, gcap;
    int32_t *gowner;
    int8_t *gimage;
    bool facets;              /* the store being listed carries facets */
    int32_t *near;            /* one ball's candidate facets of one mesh (room for the largest mesh) */
    /* a Ctrl-C stops the ball-ball listing (poll: not in periodic space,
     * where the balls were wrapped too and cannot be put back) */
    bool poll, stopped;
    bool replaced;            /* the old ball-ball store was given up for the new one */
} transfer;

/* One part of a listing: the pairs of the balls `balls` (their first
 * ball's), only counted in at (list false), or put into the list from
 * entry at on. A build counts first, so each store is sized once. */
typedef struct cursor {
    sx_span balls;
    int64_t at;
    bool list, stopped;
} cursor;

/* periodic space (kernels/ghosts.c) */
static bool wrap_balls(sx_model *m, int32_t *wrap);
static bool make_ghosts(sx_model *m);
static void build_ghost_pairs(sx_model *m, transfer *tr, cursor *to);
static bool bonded_ends(sx_model *m, int32_t a, int32_t b, int32_t *ra, int32_t *rb);

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
    sx_cell *cell = m->cell;
    if (cell) { /* the wrap of every ball, history or not */
        tr->wrap = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(m->balls.n * 3), sizeof *tr->wrap);
        if (!tr->wrap) return false;
        tr->nwrap = m->balls.n;
    }
    for (int64_t c = 0; c < m->bb.n && !tr->history; c++) tr->history = m->bb.touching[c];
    for (int64_t c = 0; c < m->bw.n && !tr->history; c++) tr->history = m->bw.touching[c];
    if (!tr->history) return true;
    if (cell) { /* the old ghosts name the old pairs' far ends; make_ghosts starts a new table */
        tr->gbase = cell->base, tr->gcap = cell->cap, tr->gowner = cell->owner, tr->gimage = cell->image;
        cell->owner = NULL, cell->image = NULL, cell->cap = cell->n = 0;
    }
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
    sx_alloc_free(&m->alloc, tr->wrap, tr->wrap ? (size_t)(tr->nwrap * 3) : 0, sizeof *tr->wrap);
    sx_alloc_free(&m->alloc, tr->gowner, (size_t)tr->gcap, sizeof *tr->gowner);
    sx_alloc_free(&m->alloc, tr->gimage, (size_t)tr->gcap * 3, sizeof *tr->gimage);
    sx_alloc_free(&m->alloc, tr->f, (size_t)tr->cap, sizeof *tr->f);
    free(tr->near);
}

/* Room for cap listed pairs (the list emptied when fresh). */
static bool transfer_list(sx_model *m, transfer *tr, int64_t cap, bool fresh)
{
    if (fresh) tr->n = 0;
    if (cap < 16) cap = 16; /* never an empty allocation */
    if (cap > INT32_MAX) return false;
    if (cap == tr->cap) return true;
    int32_t **q[4] = {&tr->a, &tr->b, &tr->f, &tr->src};
    for (int k = 0; k < 4; k++) {
        if ((k == 2 && !tr->facets) || (k == 3 && !tr->history)) continue;
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
 * ball-wall pair (wall) under its ball, a mesh's by its facet too. */
static int32_t old_pair(const transfer *tr, const sx_pairs *p, const int32_t *row, int64_t a, int64_t b, bool wall,
                        int32_t facet)
{
    if (!tr->history) return 0;
    const int64_t oa = tr->order[a], ob = wall ? b : tr->order[b];
    const int64_t lo = wall || oa < ob ? oa : ob, hi = wall || oa < ob ? ob : oa;
    for (int32_t c = row[lo]; c < row[lo + 1]; c++)
        if (p->b[c] == hi && (!p->facet || p->facet[c] == facet))
            return p->touching[c] ? (oa == lo ? c + 1 : -(c + 1)) : 0;
    return 0;
}

/* An end of an old ball-ball pair: its ball (old index) and, for a ghost,
 * the image it was seen through. */
static int64_t old_end(const transfer *tr, int64_t b, int32_t *img)
{
    img[0] = img[1] = img[2] = 0;
    if (!tr->gowner || b < tr->gbase) return b;
    for (int k = 0; k < 3; k++) img[k] = tr->gimage[(b - tr->gbase) * 3 + k];
    return tr->gowner[b - tr->gbase];
}

/* Old pair of new ball-ball pair (a, b) (see old_pair). Periodic space: b
 * may be a ghost, and either end may have been wrapped since; the pair is
 * the same contact when the image of b seen from a, counted in cell
 * vectors from the balls' old places (s - wrap_b + wrap_a), matches, kept
 * under a, or the reverse under b. */
static int32_t old_ball_pair(const sx_model *m, const transfer *tr, int64_t a, int64_t b)
{
    if (!m->cell || !tr->history) return old_pair(tr, &m->bb, tr->row_bb, a, b, false, 0);
    const sx_cell *c = m->cell;
    int32_t s[3] = {0, 0, 0};
    int64_t ob = b;
    if (b >= c->base) {
        for (int k = 0; k < 3; k++) s[k] = c->image[(b - c->base) * 3 + k];
        ob = c->owner[b - c->base];
    }
    const int64_t oa = tr->order[a];
    ob = tr->order[ob];
    for (int k = 0; k < 3; k++) s[k] += tr->wrap[oa * 3 + k] - tr->wrap[ob * 3 + k];
    for (int side = 0; side < 2; side++) {
        const int64_t lo = side ? ob : oa, hi = side ? oa : ob;
        for (int32_t q = tr->row_bb[lo]; q < tr->row_bb[lo + 1]; q++) {
            int32_t img[3];
            if (old_end(tr, m->bb.b[q], img) != hi) continue;
            bool same = true;
            for (int k = 0; k < 3; k++) same &= img[k] == (side ? -s[k] : s[k]);
            if (same) return m->bb.touching[q] ? (side ? -(q + 1) : q + 1) : 0;
        }
    }
    return 0;
}

static void put_pair(transfer *tr, int64_t at, int32_t a, int32_t b, int32_t facet, int32_t src)
{
    tr->a[at] = a, tr->b[at] = b;
    if (tr->f) tr->f[at] = facet;
    if (tr->src) tr->src[at] = src;
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
    if (tr->f) { /* the facets too are ends */
        sx_alloc_free(&m->alloc, p->facet, (size_t)old, sizeof *p->facet);
        p->facet = tr->f;
        tr->f = NULL;
    }
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
    /* decomposed: each new pair's old one, for the history the ranks move after the plan */
    if (!sx__dd_keep_sources(m, p == &m->bw, tr->src, tr->n)) return false;
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
        if (m->cell) { /* through the boundary, maybe */
            if (!bonded_ends(m, a, b, &a, &b)) return false;
        } else if (a > b) {
            const int32_t t = a;
            a = b, b = t;
        }
        put_pair(tr, tr->n++, a, b, 0, old_ball_pair(m, tr, a, b));
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

/* The cell order's axes (sx_grid): the last axis is the slowest unless
 * another has at least twice its cells, which then is (the one with most
 * cells; the others keep their order). A decomposed run's slabs are cut
 * across the slowest axis, so a flat bed is cut across its length, not
 * its depth (the ghosts: one layer of cells each side of a slab). */
static void grid_axes(const int64_t *nc, int *axis)
{
    int slow = D - 1;
    for (int k = 0; k < D - 1; k++)
        if (nc[k] >= 2 * nc[D - 1] && nc[k] > nc[slow]) slow = k;
    int n = 0;
    for (int k = 0; k < D; k++)
        if (k != slow) axis[n++] = k;
    axis[n++] = slow;
    for (; n < 3; n++) axis[n] = n;
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
    int64_t nc[D];
    for (int k = 0; k < D; k++) nc[k] = (int64_t)floor(extent[k] / cell) + 1;
    grid_axes(nc, g->axis);
    for (int k = 0; k < 3; k++) {
        g->lo[k] = k < D ? lo[g->axis[k]] : 0;
        g->nc[k] = k < D ? nc[g->axis[k]] : 1;
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
        const double q = (x[g->axis[k]] - g->lo[k]) / g->cell; /* NaN when both are infinite: cell 0 */
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
    tr->order = order; /* the transfer's, and the way back (unsort_balls) */
    return true;
}

/* A build that stopped before the old ball-ball store was given up (a
 * Ctrl-C, out of memory): the balls go back to their order before the
 * sort, so that the old stores' ends name them again and the model is as
 * it was. The listing's memory goes first, to make room for the scratch. */
static bool unsort_balls(sx_model *m, transfer *tr)
{
    sx_alloc_free(&m->alloc, tr->a, (size_t)tr->cap, sizeof *tr->a);
    sx_alloc_free(&m->alloc, tr->b, (size_t)tr->cap, sizeof *tr->b);
    sx_alloc_free(&m->alloc, tr->src, (size_t)tr->cap, sizeof *tr->src);
    sx_alloc_free(&m->alloc, tr->f, (size_t)tr->cap, sizeof *tr->f);
    tr->a = tr->b = tr->src = tr->f = NULL;
    tr->n = tr->cap = 0;
    const int64_t n = m->balls.n;
    /* the permutation's gathers use n x D doubles; the inverse order follows them */
    double *scratch = sx__scratch(m, n * D + (n + 1) / 2);
    if (!scratch) return false;
    int32_t *inverse = (int32_t *)(scratch + n * D);
    for (int64_t i = 0; i < n; i++) inverse[tr->order[i]] = (int32_t)i;
    sx__balls_permute(m, inverse, scratch);
    sx__scratch_release(m);
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

/* A candidate pair (i, j), i < j, counted or listed with its old pair. */
static inline void candidate(sx_model *m, transfer *tr, int32_t i, int32_t j, cursor *c)
{
    const int32_t *cl = m->balls.clump; /* clumps: pebbles of one clump never pair (NULL without clumps) */
    if (cl && cl[i] && cl[i] == cl[j]) return;
    if (c->list) put_pair(tr, c->at, i, j, 0, old_ball_pair(m, tr, i, j));
    c->at++;
}

/* The bonds whose pairs the grid listed again (keep_bonded_pairs lists the
 * others): marked once the parts are joined, since a rank lists only its
 * part, and threads marking as they list would write one array. */
static void mark_found_bonds(sx_model *m, transfer *tr)
{
    if (!tr->src || !m->bb.bond) return;
    for (int64_t c = 0; c < tr->n; c++) {
        const int32_t s = tr->src[c], bond = s ? m->bb.bond[s > 0 ? s - 1 : -s - 1] : 0;
        if (bond) tr->seen[bond - 1] = 1;
    }
}

/* The grid's candidate pairs of c's balls in cell order. The balls are
 * sorted by cell, so a part is a run of cells, and its pairs a run of the
 * whole list. */
static void build_ball_pairs(sx_model *m, transfer *tr, cursor *c)
{
    const sx_span part = c->balls;
    const sx_grid *g = &m->grid;
    const sx_balls *b = &m->balls;
    int64_t off[13][3];
    const int nst = half_stencil(off);
    int64_t cell = 0, top = g->ncells; /* the first cell ending after the part's first ball */
    while (cell < top) {
        const int64_t mid = cell + (top - cell) / 2;
        if (g->start[mid + 1] <= part.lo) cell = mid + 1;
        else top = mid;
    }
    for (; cell < g->ncells && g->start[cell] < part.hi; cell++) {
        const int64_t cx = cell % g->nc[0], cy = cell / g->nc[0] % g->nc[1], cz = cell / (g->nc[0] * g->nc[1]);
        const int32_t i0 = g->start[cell] > part.lo ? g->start[cell] : (int32_t)part.lo;
        const int32_t i1 = g->start[cell + 1] < part.hi ? g->start[cell + 1] : (int32_t)part.hi;
        for (int32_t i = i0; i < i1; i++) {
            /* a wide skin can make this the longest loop of seixo */
            if (tr->poll && i % 64 == 0 && sx__interrupted(m)) {
                c->stopped = true;
                return;
            }
            const double *xi = b->x + (int64_t)i * D;
            const double ri = b->rad[i] + m->skin;
            /* own cell: later balls only */
            for (int32_t j = i + 1; j < g->start[cell + 1]; j++) {
                double dx[D];
                for (int k = 0; k < D; k++) dx[k] = b->x[(int64_t)j * D + k] - xi[k];
                const double reach = ri + b->rad[j];
                if (dot(dx, dx) < reach * reach) candidate(m, tr, i, j, c);
            }
            for (int s = 0; s < nst; s++) {
                const int64_t nx = cx + off[s][0], ny = cy + off[s][1], nz = cz + off[s][2];
                if (nx < 0 || nx >= g->nc[0] || ny < 0 || ny >= g->nc[1] || nz >= g->nc[2]) continue;
                const int64_t nc = nx + g->nc[0] * (ny + g->nc[1] * nz);
                for (int32_t j = g->start[nc]; j < g->start[nc + 1]; j++) {
                    double dx[D];
                    for (int k = 0; k < D; k++) dx[k] = b->x[(int64_t)j * D + k] - xi[k];
                    const double reach = ri + b->rad[j];
                    if (dot(dx, dx) < reach * reach) candidate(m, tr, i, j, c);
                }
            }
        }
    }
}

#if D == 3
typedef struct near_list {
    int32_t *near;
    int64_t n;
} near_list;

static void near_push(int32_t t, void *ud)
{
    near_list *l = ud;
    l->near[l->n++] = t;
}

static int by_index(const void *a, const void *b)
{
    const int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return x < y ? -1 : x > y;
}

/* Ball i's facets of mesh wall w closer than its radius plus the skin, in
 * facet order, found through the mesh's grid (the ball taken into the
 * mesh's frame), counted or listed. */
static void list_mesh_pairs(sx_model *m, transfer *tr, int64_t i, int64_t w, cursor *c)
{
    const sx_wall *wl = &m->walls[w];
    sx_mesh *s = wl->mesh;
    const double *x = m->balls.x + i * D, reach = m->balls.rad[i] + m->skin;
    double r[3], xb[3];
    for (int k = 0; k < 3; k++) r[k] = x[k] - wl->def.point[k];
    for (int k = 0; k < 3; k++) xb[k] = s->rot[k] * r[0] + s->rot[3 + k] * r[1] + s->rot[6 + k] * r[2];
    near_list l = {tr->near, 0};
    sx__mesh_query(s, xb, reach, near_push, &l);
    qsort(l.near, (size_t)l.n, sizeof *l.near, by_index);
    for (int64_t e = 0; e < l.n; e++) {
        facet_hit h;
        facet_closest(s, l.near[e], x, &h);
        if (!(h.dist < reach)) continue;
        if (c->list) put_pair(tr, c->at, (int32_t)i, (int32_t)w, l.near[e], old_pair(tr, &m->bw, tr->row_bw, i, w, true, l.near[e]));
        c->at++;
    }
}
#endif

/* Ball-wall candidates of c's balls, ball-major so the contact loop walks
 * balls in order. */
static void build_wall_pairs(sx_model *m, transfer *tr, cursor *c)
{
    const sx_balls *b = &m->balls;
    for (int64_t i = c->balls.lo; i < c->balls.hi; i++)
        for (int64_t w = 0; w < m->nwall; w++) {
#if D == 3
            if (m->walls[w].mesh) {
                list_mesh_pairs(m, tr, i, w, c);
                continue;
            }
#endif
            double n[D];
            const double dist = wall_distance(&m->walls[w], b->x + i * D, n);
            if (dist >= b->rad[i] + m->skin) continue;
            if (c->list) put_pair(tr, c->at, (int32_t)i, (int32_t)w, 0, old_pair(tr, &m->bw, tr->row_bw, i, w, true, 0));
            c->at++;
        }
}

/* The parts' pairs, each part on a thread of its own, its cursor a copy
 * of its own while it lists (cursors side by side share a cache line). */
static void list_parts(sx_model *m, transfer *tr, bool walls, cursor *c, int parts)
{
#pragma omp parallel for num_threads(parts) schedule(static, 1) if (parts > 1)
    for (int k = 0; k < parts; k++) {
        cursor mine = c[k];
        if (walls) build_wall_pairs(m, tr, &mine);
        else build_ball_pairs(m, tr, &mine);
        c[k] = mine;
    }
    for (int k = 0; k < parts; k++) tr->stopped |= c[k].stopped;
}

/* Every rank's part of the listed pairs on every rank. */
static bool join_parts(sx_model *m, transfer *tr, int64_t total)
{
    return sx__dd_join(m, tr->a, sizeof *tr->a, total) && sx__dd_join(m, tr->b, sizeof *tr->b, total) &&
           (!tr->f || sx__dd_join(m, tr->f, sizeof *tr->f, total)) &&
           (!tr->src || sx__dd_join(m, tr->src, sizeof *tr->src, total));
}

/* Balls per thread below which a listing is not worth a thread; at most
 * LIST_PARTS_MAX parts (their cursors on the stack: more threads than
 * that gain nothing on a listing this short). */
#define LIST_THREAD_BALLS 1024
#define LIST_PARTS_MAX 64

/* The pairs of one store, counted, then listed (and the bonded pairs kept),
 * then carried over into the store. The listing, the costly part of a
 * build, is made in parts whose lists are joined in order, the serial
 * list whatever the parts: the threads' (without meshes), and inside
 * a decomposed cycle the ranks' (each the pairs of its own balls, the
 * last plan's cut, balanced by work; periodic space's ghost pairs, listed
 * after them, by every rank). */
static bool build_store(sx_model *m, transfer *tr, bool walls)
{
    int64_t most = 0;
    tr->facets = walls && m->mesh_pairs;
    for (int64_t w = 0; walls && w < m->nwall; w++)
        if (m->walls[w].mesh && m->walls[w].mesh->nt > most) most = m->walls[w].mesh->nt;
    if (most && !(tr->near = malloc((size_t)most * sizeof *tr->near))) return false;
    const bool split = m->dd && m->dd->active;
    const sx_span part = split ? m->dd->own[m->dd->x.rank] : (sx_span){0, m->balls.n};
    const int64_t len = part.hi - part.lo;
    /* a mesh's query writes tr->near and the mesh's own stamps: one part */
    int64_t parts = most ? 1 : len / LIST_THREAD_BALLS;
    if (parts > m->threads) parts = m->threads;
    if (parts > LIST_PARTS_MAX) parts = LIST_PARTS_MAX;
    if (parts < 1) parts = 1;
    cursor c[LIST_PARTS_MAX];
    for (int64_t k = 0; k < parts; k++)
        c[k] = (cursor){.balls = {part.lo + len * k / parts, part.lo + len * (k + 1) / parts}};
    list_parts(m, tr, walls, c, (int)parts);
    int64_t count = 0;
    for (int64_t k = 0; k < parts; k++) count += c[k].at;
    sx_span mine = {0, count};
    int64_t total = count;
    if (split && !sx__dd_parts(m, count, &mine, &total)) return false;
    cursor ghosts = {.at = total};
    if (!walls && m->cell) build_ghost_pairs(m, tr, &ghosts);
    if (tr->stopped || !transfer_list(m, tr, ghosts.at, true)) return false;
    for (int64_t k = 0, at = mine.lo; k < parts; k++) {
        const int64_t n = c[k].at;
        c[k].at = at, c[k].list = true;
        at += n;
    }
    list_parts(m, tr, walls, c, (int)parts);
    if (split && !join_parts(m, tr, total)) return false;
    ghosts = (cursor){.at = total, .list = true};
    if (!walls && m->cell) build_ghost_pairs(m, tr, &ghosts);
    tr->n = ghosts.at;
    if (tr->stopped) return false;
    if (!walls) mark_found_bonds(m, tr);
    if (!walls && !keep_bonded_pairs(m, tr)) return false;
    if (!walls) tr->replaced = true;
    return transfer_store(m, walls ? &m->bw : &m->bb, tr);
}

static bool plan_chunks(sx_model *m);

static sx_status KERNEL(build)(sx_model *m)
{
    if (m->balls.n == 0) { /* nothing to pair; a grid would have no extent */
        m->bb.n = m->bw.n = 0;
        if (m->cell) m->cell->n = m->cell->base = 0;
        m->nchunk = m->nblock = 0;
        m->builds++;
        m->build_needed = false;
        m->dt_stale = true;
        return SX_OK;
    }
    const double skin = m->skin; /* the last build's, kept by a build that stops */
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
    bool ok = transfer_begin(m, &tr);
    tr.poll = !m->cell && !(m->dd && m->dd->active); /* the ranks' parts must all be listed */
    ok = ok && (!m->cell || wrap_balls(m, tr.wrap)); /* periodic space: balls into the cell, then their ghosts */
    ok = ok && grid_setup(m) && sort_balls(m, &tr) && (!m->cell || make_ghosts(m)) && build_store(m, &tr, false) &&
         build_store(m, &tr, true);
    bool undone = false;
    if (!ok && tr.order && !tr.replaced && !m->cell) {
        undone = unsort_balls(m, &tr);
        m->skin = skin;
        /* no memory to put the balls back: the old stores are dropped (the
         * history is lost), as when a store runs out of memory while filled */
        if (!undone) m->bb.n = m->bw.n = 0;
    } else if (!ok && tr.replaced) {
        m->bw.n = 0; /* its ends name the balls in their order before the sort */
    }
    transfer_end(m, &tr);
    if (tr.stopped && undone) return SX_EINTERRUPT;
    if (!ok || !plan_chunks(m)) return SX_ENOMEM;
    memcpy(m->balls.x_build, m->balls.x, (size_t)(m->balls.n * D) * sizeof(double));
    for (int64_t w = 0; w < m->nwall; w++) m->walls[w].moved = 0;
    m->builds++;
    m->build_needed = false;
    m->dt_stale = true; /* new contacts: a new automatic timestep, wherever the build happens */
    return SX_OK;
}
