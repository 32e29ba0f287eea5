/* The step's kernels, compiled once per dimension (SEIXO_DIM = 2 or 3) so
 * that every vector loop has a constant trip count and a 2D scene never
 * touches a third component. The dimension-independent layer (model.c)
 * calls them through sx_kernels_2d / sx_kernels_3d.
 *
 * Broad phase: a uniform grid of cells at least one diameter plus the skin
 * wide; balls are sorted by cell at every build (cache locality and a
 * deterministic pair order); a forward half stencil gives each pair once
 * with a < b. History (shear force and previous normal) is carried across
 * builds through a hash keyed by the pair of stable ids.
 */
#include "model_internal.h"

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

/* A pair's history as saved across a build: shear force (D), previous
 * normal (D), overlap and normal force of the last evaluation. */
#define REC (2 * D + 2)

typedef struct history {
    uint64_t *key;   /* 0 = empty slot */
    int64_t *src;    /* record index of each slot */
    int64_t cap;
    double *rec;     /* REC doubles per saved pair */
    int64_t n;
} history;

static inline uint64_t hash_key(uint64_t k)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return k;
}

static inline uint64_t bb_key(int64_t ida, int64_t idb)
{
    return ida < idb ? ((uint64_t)ida << 32) | (uint64_t)idb : ((uint64_t)idb << 32) | (uint64_t)ida;
}

static inline uint64_t bw_key(int64_t id, int64_t wall)
{
    return (1ULL << 63) | ((uint64_t)id << 32) | (uint64_t)wall;
}

/* Saves pair c of p; sgn re-expresses the vectors for the key's orientation. */
static void history_put(history *h, uint64_t key, const sx_pairs *p, int64_t c, double sgn)
{
    int64_t s = (int64_t)(hash_key(key) & (uint64_t)(h->cap - 1));
    while (h->key[s]) s = (s + 1) & (h->cap - 1);
    h->key[s] = key;
    h->src[s] = h->n;
    double *r = h->rec + h->n * REC;
    for (int k = 0; k < D; k++) {
        r[k] = sgn * p->fs[c * D + k];
        r[D + k] = sgn * p->nold[c * D + k];
    }
    r[2 * D] = p->un[c];
    r[2 * D + 1] = p->fn[c];
    h->n++;
}

static int64_t history_get(const history *h, uint64_t key)
{
    if (!h->cap) return -1;
    int64_t s = (int64_t)(hash_key(key) & (uint64_t)(h->cap - 1));
    while (h->key[s]) {
        if (h->key[s] == key) return h->src[s];
        s = (s + 1) & (h->cap - 1);
    }
    return -1;
}

/* Saves every touching pair's history keyed by stable ids (ball-ball
 * vectors relative to lower id -> higher id). */
static bool history_save(sx_model *m, history *h)
{
    memset(h, 0, sizeof *h);
    int64_t live = 0;
    for (int64_t c = 0; c < m->bb.n; c++) live += m->bb.touching[c];
    for (int64_t c = 0; c < m->bw.n; c++) live += m->bw.touching[c];
    if (!live) return true;
    h->cap = 16;
    while (h->cap < 2 * live) h->cap *= 2;
    h->key = calloc((size_t)h->cap, sizeof *h->key);
    h->src = malloc((size_t)h->cap * sizeof *h->src);
    h->rec = malloc((size_t)(live * REC) * sizeof(double));
    if (!h->key || !h->src || !h->rec) return false;
    const int32_t *id = m->balls.id;
    for (int64_t c = 0; c < m->bb.n; c++) {
        if (!m->bb.touching[c]) continue;
        const int64_t ia = id[m->bb.a[c]], ib = id[m->bb.b[c]];
        history_put(h, bb_key(ia, ib), &m->bb, c, ia < ib ? 1.0 : -1.0);
    }
    for (int64_t c = 0; c < m->bw.n; c++)
        if (m->bw.touching[c]) history_put(h, bw_key(id[m->bw.a[c]], m->bw.b[c]), &m->bw, c, 1.0);
    return true;
}

static void history_free(history *h)
{
    free(h->key);
    free(h->src);
    free(h->rec);
}

/* Appends candidate pair (a, b) and restores its history if it had one;
 * sgn is -1 when a has the higher id. */
static bool pair_push(sx_model *m, sx_pairs *p, int32_t a, int32_t b, const history *h, uint64_t key, double sgn)
{
    if (p->n == p->cap && sx__pairs_reserve(m, p, p->n + 1)) return false;
    const int64_t c = p->n++;
    p->a[c] = a;
    p->b[c] = b;
    const int64_t s = history_get(h, key);
    const double *r = s >= 0 ? h->rec + s * REC : NULL;
    for (int k = 0; k < D; k++) {
        p->fs[c * D + k] = r ? sgn * r[k] : 0;
        p->nold[c * D + k] = r ? sgn * r[D + k] : 0;
    }
    p->un[c] = r ? r[2 * D] : 0;
    p->fn[c] = r ? r[2 * D + 1] : 0;
    p->touching[c] = r != NULL;
    return true;
}

/* Distance from ball centre x to wall w: fills the unit normal from the wall
 * to the ball and returns the (signed, for planes) distance. */
static double wall_distance(const sx_wall *w, const double *x, double *n)
{
    const sx_wall_def *d = &w->def;
    double r[D];
    for (int k = 0; k < D; k++) r[k] = x[k] - d->point[k];
    if (d->kind == SX_WALL_PLANE || d->kind == SX_WALL_LINE) {
        for (int k = 0; k < D; k++) n[k] = d->normal[k];
        return dot(r, d->normal);
    }
    double q[D];
#if D == 3
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
    double cell = 2 * rmax + m->skin;
    const double limit = 2.0 * (double)b->n + 64;
    for (;;) {
        double cells = 1;
        for (int k = 0; k < D; k++) cells *= floor((hi[k] - lo[k]) / cell) + 1;
        if (cells <= limit) break;
        cell *= 1.5;
    }
    g->cell = cell;
    g->ncells = 1;
    for (int k = 0; k < 3; k++) {
        g->lo[k] = k < D ? lo[k] : 0;
        g->nc[k] = k < D ? (int64_t)floor((hi[k] - lo[k]) / cell) + 1 : 1;
        g->ncells *= g->nc[k];
    }
    if (g->ncells + 1 > g->cap_cells) {
        int32_t *q = sx_alloc_resize(&m->alloc, g->start, (size_t)g->cap_cells, (size_t)(g->ncells + 1), sizeof *q);
        if (!q) return false;
        g->start = q;
        g->cap_cells = g->ncells + 1;
    }
    if (b->n > g->cap_balls) {
        int32_t *q = sx_alloc_resize(&m->alloc, g->cell_of, (size_t)g->cap_balls, (size_t)b->cap, sizeof *q);
        if (!q) return false;
        g->cell_of = q;
        g->cap_balls = b->cap;
    }
    return true;
}

static inline void cell_coords(const sx_grid *g, const double *x, int64_t *c)
{
    for (int k = 0; k < D; k++) {
        int64_t v = (int64_t)((x[k] - g->lo[k]) / g->cell);
        c[k] = v < 0 ? 0 : v >= g->nc[k] ? g->nc[k] - 1 : v;
    }
}

/* Sorts balls by cell (counting sort, stable) and fills g->start. */
static bool sort_balls(sx_model *m)
{
    sx_grid *g = &m->grid;
    sx_balls *b = &m->balls;
    const int64_t n = b->n;
    int32_t *order = malloc((size_t)(n > 0 ? n : 1) * sizeof *order);
    double *scratch = sx__scratch(m, n * D);
    if (!order || !scratch) {
        free(order);
        return false;
    }
    memset(g->start, 0, (size_t)(g->ncells + 1) * sizeof *g->start);
    for (int64_t i = 0; i < n; i++) {
        int64_t c[3] = {0, 0, 0};
        cell_coords(g, b->x + i * D, c);
        const int64_t cell = c[0] + g->nc[0] * (c[1] + g->nc[1] * c[2]);
        g->cell_of[i] = (int32_t)cell;
        g->start[cell + 1]++;
    }
    for (int64_t c = 0; c < g->ncells; c++) g->start[c + 1] += g->start[c];
    for (int64_t i = 0; i < n; i++) order[g->start[g->cell_of[i]]++] = (int32_t)i;
    /* start[c] now holds the end of cell c: shift back to starts */
    for (int64_t c = g->ncells; c > 0; c--) g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    sx__balls_permute(m, order, scratch);
    free(order);
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

static bool build_ball_pairs(sx_model *m, const history *h)
{
    const sx_grid *g = &m->grid;
    const sx_balls *b = &m->balls;
    const int32_t *id = b->id;
    sx_pairs *p = &m->bb;
    int64_t off[13][3];
    const int nst = half_stencil(off);
    p->n = 0;
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
                        if (dot(dx, dx) < reach * reach &&
                            !pair_push(m, p, i, j, h, bb_key(id[i], id[j]), id[i] < id[j] ? 1.0 : -1.0))
                            return false;
                    }
                    for (int s = 0; s < nst; s++) {
                        const int64_t nx = cx + off[s][0], ny = cy + off[s][1], nz = cz + off[s][2];
                        if (nx < 0 || nx >= g->nc[0] || ny < 0 || ny >= g->nc[1] || nz >= g->nc[2]) continue;
                        const int64_t nc = nx + g->nc[0] * (ny + g->nc[1] * nz);
                        for (int32_t j = g->start[nc]; j < g->start[nc + 1]; j++) {
                            double dx[D];
                            for (int k = 0; k < D; k++) dx[k] = b->x[(int64_t)j * D + k] - xi[k];
                            const double reach = ri + b->rad[j];
                            if (dot(dx, dx) < reach * reach &&
                                !pair_push(m, p, i, j, h, bb_key(id[i], id[j]), id[i] < id[j] ? 1.0 : -1.0))
                                return false;
                        }
                    }
                }
            }
    return true;
}

/* Ball-wall candidates, ball-major so the contact loop walks balls in order. */
static bool build_wall_pairs(sx_model *m, const history *h)
{
    const sx_balls *b = &m->balls;
    sx_pairs *p = &m->bw;
    p->n = 0;
    for (int64_t i = 0; i < b->n; i++)
        for (int64_t w = 0; w < m->nwall; w++) {
            double n[D];
            const double dist = wall_distance(&m->walls[w], b->x + i * D, n);
            if (dist < b->rad[i] + m->skin && !pair_push(m, p, (int32_t)i, (int32_t)w, h, bw_key(b->id[i], w), 1.0))
                return false;
        }
    return true;
}

static bool KERNEL(build)(sx_model *m)
{
    if (m->balls.n == 0) { /* nothing to pair; a grid would have no extent */
        m->bb.n = m->bw.n = 0;
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
    history h;
    bool ok = history_save(m, &h) && grid_setup(m) && sort_balls(m) && build_ball_pairs(m, &h) &&
              build_wall_pairs(m, &h);
    history_free(&h);
    if (!ok) return false;
    memcpy(m->balls.x_build, m->balls.x, (size_t)(m->balls.n * D) * sizeof(double));
    for (int64_t w = 0; w < m->nwall; w++) m->walls[w].moved = 0;
    m->builds++;
    m->build_needed = false;
    m->dt_stale = true; /* new contacts: a new automatic timestep, wherever the build happens */
    return true;
}

/* ------------------------------------------------------- contact forces */

/* The incremental shear force of one contact, 4-7 ... 4-20, and the slip
 * limit 4-30/4-31. n is the current normal (from a to b), vc the velocity of
 * b's contact point relative to a's, wbar_n the mean spin of the two
 * entities projected on n (4-9). Returns true when the contact slips. */
static inline bool shear_update(double *fs, const double *nold, const double *n, const double *wn, double dt,
                                const double *vs, double ks, double fmax)
{
    /* 4-13/4-14: rotate the old shear force into the new contact plane, F += (n_old x n) x F */
#if D == 3
    double c[3];
    c[0] = nold[1] * n[2] - nold[2] * n[1];
    c[1] = nold[2] * n[0] - nold[0] * n[2];
    c[2] = nold[0] * n[1] - nold[1] * n[0];
    double r[3];
    spin_cross(c, fs, r);
    for (int k = 0; k < 3; k++) fs[k] += r[k];
    /* 4-8/4-15: rotate about the normal by the mean spin, F += (w_bar dt) x F */
    const double wdt[3] = {wn[0] * dt, wn[1] * dt, wn[2] * dt};
    spin_cross(wdt, fs, r);
    for (int k = 0; k < 3; k++) fs[k] += r[k];
#else
    /* in 2D c is along z and the spins are normal to n, so 4-15 is the identity */
    (void)wn;
    (void)dt;
    const double c = nold[0] * n[1] - nold[1] * n[0];
    const double f0 = fs[0];
    fs[0] -= c * fs[1];
    fs[1] += c * f0;
#endif
    /* 4-18/4-19/4-20: increment from the shear velocity */
    for (int k = 0; k < D; k++) fs[k] -= ks * vs[k] * dt;
    /* 4-30/4-31: Coulomb slip */
    const double f2 = dot(fs, fs);
    if (f2 > fmax * fmax) {
        const double s = fmax / sqrt(f2);
        for (int k = 0; k < D; k++) fs[k] *= s;
        return true;
    }
    return false;
}

static double KERNEL(critical_dt)(sx_model *m);

static sx_status overlap_error(sx_model *m, const char *what, int64_t ida, int64_t idb, double un, double r)
{
    return sx__fail(m, SX_EUNSTABLE,
                    "unstable at step %lld: %s %lld and %lld overlap by %g m, more than the radius %g m; "
                    "the timestep %g s is too large for the contact stiffness (critical estimate %g s): "
                    "lower the timestep or use the automatic one",
                    (long long)m->step, what, (long long)ida, (long long)idb, un, r, m->dt,
                    KERNEL(critical_dt)(m));
}

/* Ball-ball contacts: 4-1 ... 4-21 with the linear law 4-22/4-23 and the
 * contact dashpots. The total force F acts on b and -F on a. */
static sx_status ball_contacts(sx_model *m)
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    const double *x = B->x, *v = B->v, *w = B->w, *rad = B->rad, *im = B->inv_mass;
    double *f = B->f, *t = B->t;
    /* 4-16 ... 4-20: v_{n-1/2} moved the balls from x_{n-1} to x_n during the previous step */
    const double dt = m->dt_prev > 0 ? m->dt_prev : m->dt;
    const int nlaw = m->law_n;
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t i = p->a[c], j = p->b[c];
        double n[D];
        for (int k = 0; k < D; k++) n[k] = x[j * D + k] - x[i * D + k];
        const double d2 = dot(n, n), rsum = rad[i] + rad[j];
        if (d2 >= rsum * rsum) {
            p->touching[c] = 0;
            continue;
        }
        /* 4-1 ... 4-4 */
        const double d = sqrt(d2);
        for (int k = 0; k < D; k++) n[k] /= d;
        const double un = rsum - d;
        const double rmin = rad[i] < rad[j] ? rad[i] : rad[j];
        if (un > rmin) return overlap_error(m, "balls", B->id[i], B->id[j], un, rmin);
        const double la = rad[i] - 0.5 * un, lb = rad[j] - 0.5 * un;
        double ra[D], rb[D];
        for (int k = 0; k < D; k++) {
            ra[k] = la * n[k];
            rb[k] = -lb * n[k];
        }
        /* 4-16: contact-point velocity of b relative to a */
        double va[D], vb[D], vc[D];
        spin_cross(w + i * RD, ra, va);
        spin_cross(w + j * RD, rb, vb);
        for (int k = 0; k < D; k++) vc[k] = (v[j * D + k] + vb[k]) - (v[i * D + k] + va[k]);
        const double vn = dot(vc, n);
        double vs[D];
        for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k]; /* 4-17 */

        const sx_pair_law *law = &m->law[B->mat[i] * nlaw + B->mat[j]];
        const double fn = law->kn * un; /* 4-6 */
        double *fs = p->fs + c * D;
        double wn[D];
#if D == 3
        /* 4-9: mean spin of the two balls along the normal */
        const double wbar = 0.5 * (dot(w + i * RD, n) + dot(w + j * RD, n));
        for (int k = 0; k < D; k++) wn[k] = wbar * n[k];
#endif
        if (!p->touching[c]) {
            for (int k = 0; k < D; k++) fs[k] = 0;
            for (int k = 0; k < D; k++) p->nold[c * D + k] = n[k];
        }
        const bool slip = shear_update(fs, p->nold + c * D, n, wn, dt, vs, law->ks, law->mu * fn);
        for (int k = 0; k < D; k++) p->nold[c * D + k] = n[k];
        p->touching[c] = 1;

        double ftot_n = fn, F[D];
        double dsh[D] = {0};
        if (law->beta_n > 0 || law->beta_s > 0) {
            /* viscous dashpots at the critical-damping ratios, on the reduced mass */
            const double mstar = 1.0 / (im[i] + im[j]);
            ftot_n -= 2 * law->beta_n * sqrt(mstar * law->kn) * vn;
            if (!slip) {
                const double cs = 2 * law->beta_s * sqrt(mstar * law->ks);
                for (int k = 0; k < D; k++) dsh[k] = -cs * vs[k];
            }
        }
        for (int k = 0; k < D; k++) F[k] = ftot_n * n[k] + fs[k] + dsh[k]; /* 4-5 */
        p->un[c] = un;
        p->fn[c] = ftot_n;
        /* 4-21 */
        double ma[RD], mb[RD];
        moment_of(ra, F, ma);
        moment_of(rb, F, mb);
        for (int k = 0; k < D; k++) {
            f[i * D + k] -= F[k];
            f[j * D + k] += F[k];
        }
        for (int k = 0; k < RD; k++) {
            t[i * RD + k] -= ma[k];
            t[j * RD + k] += mb[k];
        }
    }
    return SX_OK;
}

/* Ball-wall contacts: the wall is entity A (phi1 of 4-10), the ball B;
 * n points from the wall to the ball. */
static sx_status wall_contacts(sx_model *m)
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bw;
    const double dt = m->dt_prev > 0 ? m->dt_prev : m->dt; /* as in ball_contacts */
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t i = p->a[c];
        sx_wall *wl = &m->walls[p->b[c]];
        const double *xi = B->x + i * D, r = B->rad[i];
        double n[D];
        const double dist = wall_distance(wl, xi, n);
        if (dist >= r) {
            p->touching[c] = 0;
            continue;
        }
        const double un = r - dist; /* 4-3 */
        if (un > r) return overlap_error(m, "ball and wall", B->id[i], wl->id, un, r);
        double rb[D], xc[D];
        for (int k = 0; k < D; k++) {
            rb[k] = -(r - 0.5 * un) * n[k];
            xc[k] = xi[k] + rb[k]; /* 4-4 */
        }
        double vb[D], vc[D];
        spin_cross(B->w + i * RD, rb, vb);
        for (int k = 0; k < D; k++) vc[k] = (B->v[i * D + k] + vb[k]) - wl->def.vel[k];
        const double vn = dot(vc, n);
        double vs[D];
        for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k];

        const sx_pair_law law = sx__wall_law(m, B->mat[i], wl);
        const double fn = law.kn * un;
        double *fs = p->fs + c * D;
        double wn[D];
#if D == 3
        /* 4-9/4-10 with a wall that does not spin */
        const double wbar = 0.5 * dot(B->w + i * RD, n);
        for (int k = 0; k < D; k++) wn[k] = wbar * n[k];
#endif
        if (!p->touching[c])
            for (int k = 0; k < D; k++) fs[k] = 0, p->nold[c * D + k] = n[k];
        const bool slip = shear_update(fs, p->nold + c * D, n, wn, dt, vs, law.ks, law.mu * fn);
        for (int k = 0; k < D; k++) p->nold[c * D + k] = n[k];
        p->touching[c] = 1;

        double ftot_n = fn, dsh[D] = {0}, F[D];
        if (law.beta_n > 0 || law.beta_s > 0) {
            const double mass = 1.0 / B->inv_mass[i];
            ftot_n -= 2 * law.beta_n * sqrt(mass * law.kn) * vn;
            if (!slip) {
                const double cs = 2 * law.beta_s * sqrt(mass * law.ks);
                for (int k = 0; k < D; k++) dsh[k] = -cs * vs[k];
            }
        }
        for (int k = 0; k < D; k++) F[k] = ftot_n * n[k] + fs[k] + dsh[k];
        p->un[c] = un;
        p->fn[c] = ftot_n;
        double mb[RD], mw[RD], arm[D];
        moment_of(rb, F, mb);
        for (int k = 0; k < D; k++) {
            B->f[i * D + k] += F[k];
            wl->force[k] -= F[k];
            arm[k] = xc[k] - wl->def.point[k];
        }
#if D == 3
        if (wl->def.kind == SX_WALL_RECT)
            for (int k = 0; k < D; k++) arm[k] -= 0.5 * (wl->def.edge1[k] + wl->def.edge2[k]);
#endif
        moment_of(arm, F, mw);
        for (int k = 0; k < RD; k++) {
            B->t[i * RD + k] += mb[k];
            wl->moment[k] -= mw[k];
        }
    }
    return SX_OK;
}

static sx_status KERNEL(contacts)(sx_model *m)
{
    sx_balls *B = &m->balls;
    const size_t nf = (size_t)(B->n * D), nt = (size_t)(B->n * RD);
    if (B->fapp) {
        memcpy(B->f, B->fapp, nf * sizeof(double));
        memcpy(B->t, B->tapp, nt * sizeof(double));
    } else {
        memset(B->f, 0, nf * sizeof(double));
        memset(B->t, 0, nt * sizeof(double));
    }
    for (int64_t w = 0; w < m->nwall; w++) {
        memset(m->walls[w].force, 0, sizeof m->walls[w].force);
        memset(m->walls[w].moment, 0, sizeof m->walls[w].moment);
    }
    sx_status st = ball_contacts(m);
    if (st) return st;
    return wall_contacts(m);
}

/* --------------------------------------------------------- law of motion */

/* Local (non-viscous) damping: -alpha |F| sign(v), per component. */
static inline double damped(double force, double vel, double alpha)
{
    if (alpha == 0 || vel == 0) return force;
    return force - alpha * fabs(force) * (vel > 0 ? 1.0 : -1.0);
}

/* 4-46 ... 4-48: central differences, velocities at half steps. Returns the
 * largest displacement since the last build in *max_disp. */
static sx_status KERNEL(integrate)(sx_model *m, double *max_disp)
{
    sx_balls *B = &m->balls;
    const double dt = m->dt;
    /* the kick spans the time between the half-step velocities, t_{n+1/2} - t_{n-1/2} */
    const double dtv = m->dt_prev > 0 ? 0.5 * (m->dt_prev + m->dt) : m->dt;
    const double *g = m->gravity;
    double worst = 0;
    for (int64_t i = 0; i < B->n; i++) {
        const unsigned fix = B->fix[i];
        const double a = B->alpha[i], im = B->inv_mass[i], ii = B->inv_inertia[i];
        double *v = B->v + i * D, *x = B->x + i * D;
        const double *f = B->f + i * D;
        double disp2 = 0;
        for (int k = 0; k < D; k++) {
            if (!(fix & (SX_FIX_VX << k))) {
                const double force = f[k] + g[k] / im; /* 4-40: the unbalanced force includes the weight */
                v[k] += damped(force, v[k], a) * im * dtv; /* 4-46 */
            }
            x[k] += v[k] * dt; /* 4-48 */
            const double u = x[k] - B->x_build[i * D + k];
            disp2 += u * u;
        }
        double *w = B->w + i * RD;
        const double *t = B->t + i * RD;
        for (int k = 0; k < RD; k++)
            if (!(fix & (SX_FIX_WX << k))) w[k] += damped(t[k], w[k], a) * ii * dtv; /* 4-47 */
        bool ok = true;
        for (int k = 0; k < D; k++) ok &= isfinite(x[k]) && isfinite(v[k]);
        for (int k = 0; k < RD; k++) ok &= isfinite(w[k]);
        if (!ok)
            return sx__fail(m, SX_EUNSTABLE,
                            "unstable at step %lld: ball %lld has a non-finite position, velocity or spin; "
                            "the timestep %g s is likely too large (critical estimate %g s)",
                            (long long)m->step, (long long)B->id[i], m->dt, KERNEL(critical_dt)(m));
        if (disp2 > worst) worst = disp2;
    }
    *max_disp = sqrt(worst);
    return SX_OK;
}

/* -------------------------------------------------------------- timestep */

/* PFC-style estimate: for each ball sqrt(m / k_tran) with k_tran the sum of
 * its contacts' normal and shear stiffnesses, and sqrt(I / k_rot) with
 * k_rot = sum ks l^2 (l the lever arm). A ball without contacts is taken as
 * if touching one entity with its own stiffnesses, so the first impact is
 * already resolved. */
static double KERNEL(critical_dt)(sx_model *m)
{
    sx_balls *B = &m->balls;
    const int64_t n = B->n;
    if (n == 0) return INFINITY;
    double *kt = sx__scratch(m, 2 * n);
    if (!kt) return INFINITY;
    double *kr = kt + n;
    memset(kt, 0, (size_t)(2 * n) * sizeof(double));
    const sx_pairs *p = &m->bb;
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t i = p->a[c], j = p->b[c];
        double dx[D];
        for (int k = 0; k < D; k++) dx[k] = B->x[j * D + k] - B->x[i * D + k];
        const double rsum = B->rad[i] + B->rad[j];
        if (dot(dx, dx) >= rsum * rsum) continue;
        const sx_pair_law *law = &m->law[B->mat[i] * m->law_n + B->mat[j]];
        kt[i] += law->kn + law->ks;
        kt[j] += law->kn + law->ks;
        kr[i] += law->ks * B->rad[i] * B->rad[i];
        kr[j] += law->ks * B->rad[j] * B->rad[j];
    }
    p = &m->bw;
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t i = p->a[c];
        double nrm[D];
        if (wall_distance(&m->walls[p->b[c]], B->x + i * D, nrm) >= B->rad[i]) continue;
        const sx_pair_law law = sx__wall_law(m, B->mat[i], &m->walls[p->b[c]]);
        kt[i] += law.kn + law.ks;
        kr[i] += law.ks * B->rad[i] * B->rad[i];
    }
    double best = INFINITY;
    for (int64_t i = 0; i < n; i++) {
        double ktr = kt[i], krot = kr[i];
        if (ktr == 0) {
            const sx_material_def *md = &m->mats[B->mat[i]].def;
            ktr = md->kn + md->ks;
            krot = md->ks * B->rad[i] * B->rad[i];
        }
        const double dtt = sqrt(1.0 / (B->inv_mass[i] * ktr));
        if (dtt < best) best = dtt;
        if (krot > 0) {
            const double dtr = sqrt(1.0 / (B->inv_inertia[i] * krot));
            if (dtr < best) best = dtr;
        }
    }
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

static void KERNEL(energy)(const sx_model *m, sx_energy *e)
{
    const sx_balls *B = &m->balls;
    memset(e, 0, sizeof *e);
    for (int64_t i = 0; i < B->n; i++) {
        const double *v = B->v + i * D, *w = B->w + i * RD;
        double ww = 0;
        for (int k = 0; k < RD; k++) ww += w[k] * w[k];
        e->kinetic += 0.5 * dot(v, v) / B->inv_mass[i] + 0.5 * ww / B->inv_inertia[i];
        e->gravitational -= dot(m->gravity, B->x + i * D) / B->inv_mass[i];
    }
    /* every overlap stores normal strain, even one no step has seen yet;
     * the shear spring only once the contact has history */
    for (int64_t c = 0; c < m->bb.n; c++) {
        double n[D];
        const int64_t i = m->bb.a[c], j = m->bb.b[c];
        const double un = pair_geometry(m, i, j, n);
        const sx_pair_law *law = &m->law[B->mat[i] * m->law_n + B->mat[j]];
        const double *fs = m->bb.fs + c * D;
        if (un > 0) e->strain += 0.5 * law->kn * un * un;
        if (m->bb.touching[c] && law->ks > 0) e->strain += 0.5 * dot(fs, fs) / law->ks;
    }
    for (int64_t c = 0; c < m->bw.n; c++) {
        double n[D];
        const int64_t i = m->bw.a[c];
        const sx_wall *wl = &m->walls[m->bw.b[c]];
        const double un = B->rad[i] - wall_distance(wl, B->x + i * D, n);
        const sx_pair_law law = sx__wall_law(m, B->mat[i], wl);
        const double *fs = m->bw.fs + c * D;
        if (un > 0) e->strain += 0.5 * law.kn * un * un;
        if (m->bw.touching[c] && law.ks > 0) e->strain += 0.5 * dot(fs, fs) / law.ks;
    }
}

/* Contacts are reported as the last force evaluation left them (the forces
 * the balls felt): normal, overlap, normal force (with its dashpot) and the
 * elastic shear force; the point is placed from ball a's current centre. */
static bool report(const sx_model *m, const sx_pairs *p, int64_t c, bool is_wall,
                   bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    const sx_balls *B = &m->balls;
    const int64_t i = p->a[c];
    const double *n = p->nold + c * D, un = p->un[c];
    sx_contact_info ci;
    memset(&ci, 0, sizeof ci);
    const sx_pair_law law = is_wall ? sx__wall_law(m, B->mat[i], &m->walls[p->b[c]])
                                    : m->law[B->mat[i] * m->law_n + B->mat[p->b[c]]];
    /* ball-wall normals point from the wall to the ball, so the point lies behind the centre */
    const double arm = is_wall ? -(B->rad[i] - 0.5 * un) : B->rad[i] - 0.5 * un;
    for (int k = 0; k < D; k++) {
        ci.normal[k] = n[k];
        ci.point[k] = B->x[i * D + k] + arm * n[k];
        ci.shear[k] = p->fs[c * D + k];
    }
    ci.overlap = un;
    ci.fn = p->fn[c];
    ci.kn = law.kn;
    ci.ks = law.ks;
    ci.a = B->id[i];
    ci.b = is_wall ? m->walls[p->b[c]].id : B->id[p->b[c]];
    ci.is_wall = is_wall;
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
    .integrate = KERNEL(integrate),
    .critical_dt = KERNEL(critical_dt),
    .energy = KERNEL(energy),
    .each_contact = KERNEL(each_contact),
    .count_contacts = KERNEL(count_contacts),
};
