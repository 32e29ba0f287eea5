/* Triangle-mesh walls: welding, checks and repair of the triangles, the
 * mesh's pose (a point and an orientation) and its facet grid.
 *
 * A mesh is kept in its own frame (vertices relative to the wall's point
 * at creation) and placed by the point and a unit quaternion, so its
 * shape never drifts however long it turns, and a restart needs only the
 * frame's vertices and the pose. The grid over the facets is built once in
 * that frame; the broad phase takes a ball into the frame to look it up.
 * The contacts themselves are in kernels/mesh_contacts.c. */
#include "state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void sx__mesh_free(sx_model *m, sx_mesh *mesh)
{
    if (!mesh) return;
    const size_t nv = (size_t)mesh->nv, nt = (size_t)mesh->nt;
    sx_alloc_free(&m->alloc, mesh->body, 3 * nv, sizeof(double));
    sx_alloc_free(&m->alloc, mesh->x, 3 * nv, sizeof(double));
    sx_alloc_free(&m->alloc, mesh->tri, 3 * nt, sizeof(int32_t));
    sx_alloc_free(&m->alloc, mesh->nrm, 3 * nt, sizeof(double));
    sx_alloc_free(&m->alloc, mesh->stamp, nt, sizeof(uint32_t));
    sx_alloc_free(&m->alloc, mesh->start,
                  mesh->start ? (size_t)(mesh->nc[0] * mesh->nc[1] * mesh->nc[2] + 1) : 0, sizeof(int32_t));
    sx_alloc_free(&m->alloc, mesh->items, (size_t)mesh->nitems, sizeof(int32_t));
    sx_alloc_free(&m->alloc, mesh, 1, sizeof *mesh);
}

/* The rotation matrix of unit quaternion q (w, x, y, z), row-major. */
static void quat_matrix(const double *q, double *r)
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    r[0] = 1 - 2 * (y * y + z * z), r[1] = 2 * (x * y - w * z), r[2] = 2 * (x * z + w * y);
    r[3] = 2 * (x * y + w * z), r[4] = 1 - 2 * (x * x + z * z), r[5] = 2 * (y * z - w * x);
    r[6] = 2 * (x * z - w * y), r[7] = 2 * (y * z + w * x), r[8] = 1 - 2 * (x * x + y * y);
}

void sx__mesh_pose(const sx_wall *w)
{
    sx_mesh *s = w->mesh;
    const double *p = w->def.point, *r = s->rot;
    for (int64_t v = 0; v < s->nv; v++) {
        const double *b = s->body + 3 * v;
        for (int k = 0; k < 3; k++) s->x[3 * v + k] = p[k] + dot3(r + 3 * k, b);
    }
    for (int64_t t = 0; t < s->nt; t++) {
        const double *a = s->x + 3 * s->tri[3 * t], *b = s->x + 3 * s->tri[3 * t + 1], *c = s->x + 3 * s->tri[3 * t + 2];
        double e1[3], e2[3], n[3];
        for (int k = 0; k < 3; k++) e1[k] = b[k] - a[k], e2[k] = c[k] - a[k];
        cross3(e1, e2, n);
        const double len = sqrt(dot3(n, n));
        for (int k = 0; k < 3; k++) s->nrm[3 * t + k] = n[k] / len;
    }
}

double sx__mesh_turn(sx_wall *w, double dt)
{
    sx_mesh *s = w->mesh;
    const double *o = w->def.spin;
    const double rate = sqrt(dot3(o, o)), angle = rate * dt;
    if (angle == 0) return 0;
    /* q <- dq q, dq the turn by angle about the spin's axis, then renormalised */
    const double h = 0.5 * angle, sh = sin(h) / rate;
    const double d[4] = {cos(h), o[0] * sh, o[1] * sh, o[2] * sh}, *q = s->q;
    double n[4] = {d[0] * q[0] - d[1] * q[1] - d[2] * q[2] - d[3] * q[3],
                   d[0] * q[1] + d[1] * q[0] + d[2] * q[3] - d[3] * q[2],
                   d[0] * q[2] - d[1] * q[3] + d[2] * q[0] + d[3] * q[1],
                   d[0] * q[3] + d[1] * q[2] - d[2] * q[1] + d[3] * q[0]};
    const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] + n[3] * n[3]);
    for (int k = 0; k < 4; k++) s->q[k] = n[k] / len;
    quat_matrix(s->q, s->rot);
    return angle * s->reach; /* a chord is no longer than its arc */
}

/* ------------------------------------------------------------- the grid */

/* The box of facet t in the mesh's frame. */
static void facet_box(const sx_mesh *s, int64_t t, double *lo, double *hi)
{
    for (int k = 0; k < 3; k++) lo[k] = hi[k] = s->body[3 * s->tri[3 * t] + k];
    for (int j = 1; j < 3; j++)
        for (int k = 0; k < 3; k++) {
            const double v = s->body[3 * s->tri[3 * t + j] + k];
            if (v < lo[k]) lo[k] = v;
            if (v > hi[k]) hi[k] = v;
        }
}

static int64_t clamp_cell(const sx_mesh *s, double x, int k)
{
    const double q = floor((x - s->lo[k]) / s->cell);
    return q < 0 ? 0 : q >= (double)s->nc[k] ? s->nc[k] - 1 : (int64_t)q;
}

/* Cells about the mean facet size, widened until there are at most ~4 per
 * facet; each facet is listed in every cell its box meets. */
static bool build_grid(sx_model *m, sx_mesh *s)
{
    double lo[3], hi[3], size = 0;
    for (int k = 0; k < 3; k++) lo[k] = hi[k] = s->body[k];
    for (int64_t t = 0; t < s->nt; t++) {
        double a[3], b[3];
        facet_box(s, t, a, b);
        double big = 0;
        for (int k = 0; k < 3; k++) {
            if (a[k] < lo[k]) lo[k] = a[k];
            if (b[k] > hi[k]) hi[k] = b[k];
            if (b[k] - a[k] > big) big = b[k] - a[k];
        }
        size += big;
    }
    double cell = size / (double)s->nt;
    for (int k = 0; k < 3; k++)
        if ((hi[k] - lo[k]) * 1e-6 > cell) cell = (hi[k] - lo[k]) * 1e-6; /* a flat mesh still has a width */
    const double limit = 4.0 * (double)s->nt + 64;
    for (;;) {
        double cells = 1;
        for (int k = 0; k < 3; k++) cells *= floor((hi[k] - lo[k]) / cell) + 1;
        if (cells <= limit) break;
        cell *= 1.5;
    }
    s->cell = cell;
    int64_t ncells = 1;
    for (int k = 0; k < 3; k++) {
        s->lo[k] = lo[k];
        s->nc[k] = (int64_t)floor((hi[k] - lo[k]) / cell) + 1;
        ncells *= s->nc[k];
    }
    s->start = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)ncells + 1, sizeof *s->start);
    if (!s->start) return false;
    /* counted, then listed */
    for (int pass = 0; pass < 2; pass++) {
        for (int64_t t = 0; t < s->nt; t++) {
            double a[3], b[3];
            facet_box(s, t, a, b);
            int64_t c0[3], c1[3];
            for (int k = 0; k < 3; k++) c0[k] = clamp_cell(s, a[k], k), c1[k] = clamp_cell(s, b[k], k);
            for (int64_t z = c0[2]; z <= c1[2]; z++)
                for (int64_t y = c0[1]; y <= c1[1]; y++)
                    for (int64_t x = c0[0]; x <= c1[0]; x++) {
                        const int64_t c = x + s->nc[0] * (y + s->nc[1] * z);
                        if (pass == 0) s->start[c + 1]++;
                        else s->items[s->start[c]++] = (int32_t)t;
                    }
        }
        if (pass == 0) {
            for (int64_t c = 0; c < ncells; c++) s->start[c + 1] += s->start[c];
            s->nitems = s->start[ncells];
            s->items = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)s->nitems, sizeof *s->items);
            if (!s->items) return false;
        } else { /* start[c] now holds the end of cell c */
            for (int64_t c = ncells; c > 0; c--) s->start[c] = s->start[c - 1];
            s->start[0] = 0;
        }
    }
    return true;
}

void sx__mesh_query(sx_mesh *s, const double xb[3], double h, void (*fn)(int32_t facet, void *ud), void *ud)
{
    int64_t c0[3], c1[3];
    for (int k = 0; k < 3; k++) {
        if (xb[k] + h < s->lo[k] || xb[k] - h > s->lo[k] + s->cell * (double)s->nc[k]) return;
        c0[k] = clamp_cell(s, xb[k] - h, k), c1[k] = clamp_cell(s, xb[k] + h, k);
    }
    if (++s->query == 0) { /* the stamps wrapped: start them afresh */
        memset(s->stamp, 0, (size_t)s->nt * sizeof *s->stamp);
        s->query = 1;
    }
    for (int64_t z = c0[2]; z <= c1[2]; z++)
        for (int64_t y = c0[1]; y <= c1[1]; y++)
            for (int64_t x = c0[0]; x <= c1[0]; x++) {
                const int64_t c = x + s->nc[0] * (y + s->nc[1] * z);
                for (int32_t e = s->start[c]; e < s->start[c + 1]; e++) {
                    const int32_t t = s->items[e];
                    if (s->stamp[t] == s->query) continue;
                    s->stamp[t] = s->query;
                    fn(t, ud);
                }
            }
}

bool sx__mesh_derive(sx_model *m, sx_mesh *s)
{
    s->x = sx_alloc_resize(&m->alloc, NULL, 0, 3 * (size_t)s->nv, sizeof(double));
    s->nrm = sx_alloc_resize(&m->alloc, NULL, 0, 3 * (size_t)s->nt, sizeof(double));
    s->stamp = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)s->nt, sizeof(uint32_t));
    if (!s->x || !s->nrm || !s->stamp) return false;
    s->reach = 0;
    for (int64_t v = 0; v < s->nv; v++) {
        const double r = sqrt(dot3(s->body + 3 * v, s->body + 3 * v));
        if (r > s->reach) s->reach = r;
    }
    quat_matrix(s->q, s->rot);
    return build_grid(m, s);
}

/* ---------------------------------------------------------- the triangles */

/* Corners closer than this fraction of the mesh's largest extent, in every
 * coordinate, are one vertex: a mesh built by trigonometry closes within
 * rounding (sin 2 pi is -2.4e-16, not 0), and a seam left open would give
 * a ball two contacts on it, one for each side's edge. */
#define WELD_TOLERANCE 1e-9

/* An input vertex by the cell of side tol it lies in. */
typedef struct keyed {
    int64_t cell[3];
    int64_t i;
} keyed;

static int by_cell(const void *pa, const void *pb)
{
    const keyed *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->cell[k] != b->cell[k]) return a->cell[k] < b->cell[k] ? -1 : 1;
    return a->i < b->i ? -1 : a->i > b->i;
}

/* The first entry of k (n, sorted by by_cell) in cell c, or n. */
static int64_t first_in_cell(const keyed *k, int64_t n, const int64_t *c)
{
    int64_t lo = 0, hi = n;
    while (lo < hi) {
        const int64_t mid = lo + (hi - lo) / 2;
        const keyed probe = {{c[0], c[1], c[2]}, -1};
        if (by_cell(&k[mid], &probe) < 0) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* The smallest input index of v's group (path halving). */
static int64_t group_of(int64_t *up, int64_t v)
{
    while (up[v] != v) v = up[v] = up[up[v]];
    return v;
}

/* map[v]: the welded index of input vertex v, welded vertices numbered in
 * order of first appearance: corners within WELD_TOLERANCE of the extent
 * of each other (a chain of them too) are one; returns their count, -1 out
 * of memory. Each cell's own and the next 13 of its 26 neighbours are
 * searched, so each close pair is met once. */
static int64_t weld(const double *x, int64_t nv, int64_t *map)
{
    keyed *k = malloc((size_t)nv * sizeof *k);
    int64_t *up = malloc((size_t)nv * sizeof *up);
    if (!k || !up) {
        free(k);
        free(up);
        return -1;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, extent = 0;
    for (int64_t v = 0; v < nv; v++)
        for (int q = 0; q < 3; q++) lo[q] = fmin(lo[q], x[3 * v + q]);
    for (int64_t v = 0; v < nv; v++)
        for (int q = 0; q < 3; q++) extent = fmax(extent, x[3 * v + q] - lo[q]);
    const double tol = WELD_TOLERANCE * extent;
    for (int64_t v = 0; v < nv; v++) {
        for (int q = 0; q < 3; q++) k[v].cell[q] = tol > 0 ? (int64_t)floor((x[3 * v + q] - lo[q]) / tol) : 0;
        k[v].i = v, up[v] = v;
    }
    qsort(k, (size_t)nv, sizeof *k, by_cell);
    for (int64_t j = 0; j < nv; j++) {
        const double *p = x + 3 * k[j].i;
        for (int d = 13; d < 27; d++) { /* offsets (0,0,0) and after, in the sort's order */
            const int64_t c[3] = {k[j].cell[0] + d / 9 - 1, k[j].cell[1] + d / 3 % 3 - 1, k[j].cell[2] + d % 3 - 1};
            for (int64_t e = d == 13 ? j + 1 : first_in_cell(k, nv, c); e < nv; e++) {
                if (k[e].cell[0] != c[0] || k[e].cell[1] != c[1] || k[e].cell[2] != c[2]) break;
                const double *r = x + 3 * k[e].i;
                if (!(fabs(p[0] - r[0]) <= tol && fabs(p[1] - r[1]) <= tol && fabs(p[2] - r[2]) <= tol)) continue;
                const int64_t a = group_of(up, k[j].i), b = group_of(up, k[e].i);
                if (a < b) up[b] = a;
                else up[a] = b;
            }
        }
    }
    int64_t n = 0;
    for (int64_t v = 0; v < nv; v++) {
        const int64_t g = group_of(up, v);
        map[v] = g == v ? n++ : map[g];
    }
    free(k);
    free(up);
    return n;
}

typedef struct edge {
    int32_t lo, hi;
    int64_t t;   /* its triangle */
    bool up;     /* the triangle goes lo -> hi */
} edge;

static int by_ends(const void *pa, const void *pb)
{
    const edge *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->t < b->t ? -1 : a->t > b->t;
}

/* Winds every triangle as its neighbours across the edges two triangles
 * share: a walk over each connected piece, then the smaller set of each
 * piece turned round. flip[t] is set for the triangles turned; returns
 * their count, -1 out of memory. */
static int64_t orient(int32_t *tri, int64_t nt, uint8_t *flip)
{
    edge *e = malloc((size_t)(3 * nt) * sizeof *e);
    int64_t *stack = malloc((size_t)nt * sizeof *stack), *piece = malloc((size_t)nt * sizeof *piece);
    int64_t *at = malloc((size_t)(3 * nt) * sizeof *at); /* where each triangle's edges are in e */
    int64_t flipped = -1;
    if (!e || !stack || !piece || !at) goto out;
    for (int64_t t = 0; t < nt; t++)
        for (int j = 0; j < 3; j++) {
            const int32_t a = tri[3 * t + j], b = tri[3 * t + (j + 1) % 3];
            e[3 * t + j] = (edge){a < b ? a : b, a < b ? b : a, t, a < b};
        }
    qsort(e, (size_t)(3 * nt), sizeof *e, by_ends);
    int64_t *fill = calloc((size_t)nt, sizeof *fill);
    if (!fill) goto out;
    for (int64_t q = 0; q < 3 * nt; q++) at[3 * e[q].t + fill[e[q].t]++] = q;
    free(fill);
    for (int64_t t = 0; t < nt; t++) flip[t] = 0, piece[t] = -1;
    flipped = 0;
    for (int64_t seed = 0; seed < nt; seed++) {
        if (piece[seed] >= 0) continue;
        int64_t top = 0, members = 0, turned = 0;
        stack[top++] = seed;
        piece[seed] = seed;
        while (top) {
            const int64_t t = stack[--top];
            members++;
            turned += flip[t];
            for (int j = 0; j < 3; j++) {
                const int64_t q = at[3 * t + j];
                /* the run of e sharing q's ends: a manifold edge has two */
                int64_t r0 = q, r1 = q + 1;
                while (r0 > 0 && e[r0 - 1].lo == e[q].lo && e[r0 - 1].hi == e[q].hi) r0--;
                while (r1 < 3 * nt && e[r1].lo == e[q].lo && e[r1].hi == e[q].hi) r1++;
                if (r1 - r0 != 2) continue;
                const int64_t r = r0 == q ? r0 + 1 : r0;
                const int64_t u = e[r].t;
                if (piece[u] >= 0) continue;
                /* neighbours agree when they run the shared edge opposite ways */
                flip[u] = (e[q].up != (flip[t] != 0)) == e[r].up;
                piece[u] = seed;
                stack[top++] = u;
            }
        }
        const bool invert = 2 * turned > members; /* turn the fewer */
        for (int64_t t = seed; t < nt; t++)
            if (piece[t] == seed) {
                if (invert) flip[t] = !flip[t];
                flipped += flip[t];
            }
    }
    for (int64_t t = 0; t < nt; t++)
        if (flip[t]) {
            const int32_t s = tri[3 * t + 1];
            tri[3 * t + 1] = tri[3 * t + 2], tri[3 * t + 2] = s;
        }
out:
    free(e);
    free(stack);
    free(piece);
    free(at);
    return flipped;
}

/* Twice the area of triangle (a, b, c) against the square of its longest
 * edge: zero for a repeated vertex or a needle. */
static bool degenerate(const double *a, const double *b, const double *c)
{
    double e1[3], e2[3], e3[3], n[3];
    for (int k = 0; k < 3; k++) e1[k] = b[k] - a[k], e2[k] = c[k] - a[k], e3[k] = c[k] - b[k];
    cross3(e1, e2, n);
    double big = dot3(e1, e1);
    if (dot3(e2, e2) > big) big = dot3(e2, e2);
    if (dot3(e3, e3) > big) big = dot3(e3, e3);
    return !(sqrt(dot3(n, n)) > 1e-12 * big);
}

sx_status sx__pairs_expand_facets(sx_model *m)
{
    sx_pairs *p = &m->bw;
    if (m->mesh_pairs) return SX_OK;
    if (p->cap > 0) {
        p->facet = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)p->cap, sizeof *p->facet);
        if (!p->facet) return SX_ENOMEM;
    }
    m->mesh_pairs = true;
    return SX_OK;
}

/* The welded, checked (and, asked to, repaired) triangles of def into s;
 * the vertices in s->body still in world coordinates. */
sx_mesh *sx__mesh_alloc(sx_model *m, int64_t nv, int64_t nt)
{
    sx_mesh *s = sx_alloc_resize(&m->alloc, NULL, 0, 1, sizeof *s);
    if (!s) return NULL;
    s->nv = nv, s->nt = nt;
    s->body = sx_alloc_resize(&m->alloc, NULL, 0, 3 * (size_t)nv, sizeof(double));
    s->tri = sx_alloc_resize(&m->alloc, NULL, 0, 3 * (size_t)nt, sizeof(int32_t));
    if (!s->body || !s->tri) {
        sx__mesh_free(m, s);
        return NULL;
    }
    return s;
}

static sx_status shape(sx_model *m, const sx_mesh_def *def, sx_mesh *s, sx_mesh_report *rep)
{
    int64_t *map = malloc((size_t)def->nv * sizeof *map);
    uint8_t *flip = malloc((size_t)def->nt);
    int64_t *input = malloc((size_t)def->nt * sizeof *input); /* each kept triangle's input index */
    sx_status st = SX_ENOMEM;
    const char *why = "wall_add_mesh: out of memory";
    if (!map || !flip || !input) goto out;
    s->nv = weld(def->vertices, def->nv, map);
    if (s->nv < 0) goto out;
    rep->welded = def->nv - s->nv;
    s->body = sx_alloc_resize(&m->alloc, NULL, 0, 3 * (size_t)s->nv, sizeof(double));
    s->tri = sx_alloc_resize(&m->alloc, NULL, 0, 3 * (size_t)def->nt, sizeof(int32_t));
    if (!s->body || !s->tri) goto out;
    /* a welded vertex is where its first corner is */
    for (int64_t v = def->nv - 1; v >= 0; v--) memcpy(s->body + 3 * map[v], def->vertices + 3 * v, 3 * sizeof(double));
    st = SX_EINVAL;
    for (int64_t t = 0; t < def->nt; t++) {
        const int32_t *in = def->triangles + 3 * t;
        int32_t w[3];
        for (int j = 0; j < 3; j++) w[j] = (int32_t)map[in[j]];
        if (!degenerate(s->body + 3 * w[0], s->body + 3 * w[1], s->body + 3 * w[2])) {
            memcpy(s->tri + 3 * s->nt, w, sizeof w);
            input[s->nt++] = t;
            continue;
        }
        if (!def->repair) {
            sx__fail(m, SX_EINVAL,
                     "wall_add_mesh: triangle %lld (vertices %d, %d, %d) is degenerate: %s; "
                     "remove it or ask for repair",
                     (long long)t + 1, in[0] + 1, in[1] + 1, in[2] + 1,
                     w[0] == w[1] || w[1] == w[2] || w[0] == w[2] ? "two of its corners coincide" : "it has no area");
            goto out_failed;
        }
        if (rep->dropped++ == 0) rep->first_dropped = t;
    }
    if (s->nt == 0) {
        sx__fail(m, SX_EINVAL, "wall_add_mesh: no triangle with an area is left of %lld", (long long)def->nt);
        goto out_failed;
    }
    st = SX_ENOMEM;
    rep->flipped = orient(s->tri, s->nt, flip);
    if (rep->flipped < 0) goto out;
    for (int64_t t = 0; t < s->nt && rep->first_flipped < 0; t++)
        if (flip[t]) rep->first_flipped = input[t];
    st = SX_OK;
out:
    if (st) sx__fail(m, st, "%s", why);
out_failed:
    if (s->nv < 0) s->nv = 0;
    if (s->tri && s->nt < def->nt) { /* the kept triangles only (none on a failure) */
        int32_t *q = sx_alloc_resize(&m->alloc, s->tri, 3 * (size_t)def->nt, 3 * (size_t)s->nt, sizeof *q);
        if (q || s->nt == 0) s->tri = q;
        else s->nt = def->nt; /* kept at its size, which sx__mesh_free then frees */
    }
    free(map);
    free(flip);
    free(input);
    return st;
}

/* A mesh restored from a file written before meshes were welded (a
 * trigonometric seam left open) is welded as sx_wall_add_mesh would have:
 * its body frame is the frame it was welded in. A mesh already welded is
 * left to the bit; one whose welding would make a triangle degenerate is
 * kept as saved (dropping a facet would renumber the contacts' facets).
 * False: out of memory. */
bool sx__mesh_weld_restored(sx_model *m, sx_mesh *s)
{
    int64_t *map = malloc((size_t)s->nv * sizeof *map);
    if (!map) return false;
    const int64_t n = weld(s->body, s->nv, map);
    bool ok = n >= 0;
    if (n > 0 && n < s->nv) {
        double *x = sx_alloc_resize(&m->alloc, NULL, 0, 3 * (size_t)n, sizeof *x);
        ok = x != NULL;
        bool kept = ok;
        if (ok)
            for (int64_t v = s->nv - 1; v >= 0; v--) memcpy(x + 3 * map[v], s->body + 3 * v, 3 * sizeof(double));
        for (int64_t t = 0; t < s->nt && kept; t++) {
            const int32_t *c = s->tri + 3 * t;
            kept = !degenerate(x + 3 * map[c[0]], x + 3 * map[c[1]], x + 3 * map[c[2]]);
        }
        if (kept) {
            sx_alloc_free(&m->alloc, s->body, 3 * (size_t)s->nv, sizeof(double));
            s->body = x;
            for (int64_t k = 0; k < 3 * s->nt; k++) s->tri[k] = (int32_t)map[s->tri[k]];
            s->nv = n;
        } else {
            sx_alloc_free(&m->alloc, x, 3 * (size_t)n, sizeof(double));
        }
    }
    free(map);
    return ok;
}

sx_status sx_wall_add_mesh(sx_model *m, const sx_wall_def *def, const sx_mesh_def *mesh, int64_t *id,
                           sx_mesh_report *report)
{
    sx_mesh_report rep = {0, 0, 0, -1, -1};
    if (m->dim != 3) return sx__fail(m, SX_EINVAL, "wall_add_mesh: a mesh is a 3D wall (the model is %dD)", m->dim);
    if (m->locked) return sx__fail(m, SX_ELOCKED, "wall_add_mesh: the model is stepping");
    if (!mesh->vertices || !mesh->triangles || mesh->nv < 3 || mesh->nt < 1 || mesh->nv > INT32_MAX ||
        mesh->nt > INT32_MAX / 3)
        return sx__fail(m, SX_EINVAL, "wall_add_mesh: a mesh needs at least 3 vertices and 1 triangle (got %lld and %lld)",
                        (long long)mesh->nv, (long long)mesh->nt);
    for (int64_t v = 0; v < 3 * mesh->nv; v++)
        if (!isfinite(mesh->vertices[v]))
            return sx__fail(m, SX_EINVAL, "wall_add_mesh: vertex %lld is not finite", (long long)(v / 3 + 1));
    for (int64_t t = 0; t < 3 * mesh->nt; t++)
        if (mesh->triangles[t] < 0 || mesh->triangles[t] >= mesh->nv)
            return sx__fail(m, SX_EINVAL, "wall_add_mesh: triangle %lld names vertex %lld; there are %lld",
                            (long long)(t / 3 + 1), (long long)mesh->triangles[t] + 1, (long long)mesh->nv);
    sx_wall_def d = *def;
    d.kind = SX_WALL_MESH;
    for (int k = 0; k < 3; k++)
        if (!isfinite(d.spin[k])) return sx__fail(m, SX_EINVAL, "wall_add_mesh: the spin must be finite");
    if (sx__pairs_expand_facets(m)) return sx__fail(m, SX_ENOMEM, "wall_add_mesh: out of memory");
    sx_mesh *s = sx_alloc_resize(&m->alloc, NULL, 0, 1, sizeof *s);
    if (!s) return sx__fail(m, SX_ENOMEM, "wall_add_mesh: out of memory");
    sx_status st = shape(m, mesh, s, &rep);
    if (!st) {
        for (int64_t v = 0; v < s->nv; v++)
            for (int k = 0; k < 3; k++) s->body[3 * v + k] -= d.point[k];
        s->q[0] = 1;
        if (!sx__mesh_derive(m, s)) st = sx__fail(m, SX_ENOMEM, "wall_add_mesh: out of memory");
    }
    int64_t wid = 0;
    if (!st) st = sx__wall_add(m, &d, s, &wid);
    if (st) {
        sx__mesh_free(m, s);
        return st;
    }
    sx__mesh_pose(&m->walls[m->nwall - 1]);
    if (id) *id = wid;
    if (report) *report = rep;
    return SX_OK;
}

/* The mesh wall of id, or NULL with *st and the message set. */
static sx_wall *mesh_wall(const sx_model *m, int64_t id, const char *fn, sx_status *st)
{
    const int64_t i = sx__wall_index(m, id);
    if (i < 0 || !m->walls[i].mesh) {
        *st = sx__fail((sx_model *)m, i < 0 ? SX_ENOTFOUND : SX_EINVAL, "%s: %s %lld", fn,
                       i < 0 ? "no wall with id" : "not a mesh: wall", (long long)id);
        return NULL;
    }
    return &m->walls[i];
}

sx_status sx_wall_mesh_size(const sx_model *m, int64_t id, int64_t *nv, int64_t *nt)
{
    sx_status st;
    const sx_wall *w = mesh_wall(m, id, "wall_mesh_size", &st);
    if (!w) return st;
    if (nv) *nv = w->mesh->nv;
    if (nt) *nt = w->mesh->nt;
    return SX_OK;
}

sx_status sx_wall_mesh_get(const sx_model *m, int64_t id, double *vertices, int32_t *triangles)
{
    sx_status st;
    const sx_wall *w = mesh_wall(m, id, "wall_mesh_get", &st);
    if (!w) return st;
    if (vertices) memcpy(vertices, w->mesh->x, 3 * (size_t)w->mesh->nv * sizeof(double));
    if (triangles) memcpy(triangles, w->mesh->tri, 3 * (size_t)w->mesh->nt * sizeof(int32_t));
    return SX_OK;
}

double sx__mesh_spin_speed(const sx_mesh *s, const double *point, const double *spin)
{
    if (!(dot3(spin, spin) > 0)) return 0;
    double best = 0;
    for (int64_t v = 0; v < s->nv; v++) {
        double r[3], c[3];
        for (int k = 0; k < 3; k++) r[k] = s->x[3 * v + k] - point[k];
        cross3(spin, r, c);
        best = fmax(best, dot3(c, c));
    }
    return sqrt(best);
}

sx_status sx_wall_set_spin(sx_model *m, int64_t id, const double spin[3])
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    sx_status st;
    sx_wall *w = mesh_wall(m, id, "wall_set_spin", &st);
    if (!w) return st;
    for (int k = 0; k < 3; k++)
        if (!isfinite(spin[k])) return sx__fail(m, SX_EINVAL, "wall_set_spin: the spin must be finite");
    memcpy(w->def.spin, spin, sizeof w->def.spin);
    sx__wall_speed_changed(m, w);
    return SX_OK;
}
