/* Where m:generate's bodies go.
 *
 * Overlap checks go through a uniform cell grid of the region, so
 * placement is O(N). A centre is sampled uniformly over where a body fits
 * in the region (a polygon: its bounding box, then the containment test).
 * The placements: random (balls, largest first, and clumps, each pebble in
 * the region and clear of every ball), distribute's centres pushed apart,
 * and the sites of a lattice. */
#include <math.h>
#include <string.h>

#include "generate.h"

/* ---------------------------------------------------------------- grid */

/* A uniform cell grid over the balls at x[i*3], r[i]; cell size h >= the
 * largest sum of two radii, so that a ball's neighbours are in the 3^dim
 * cells around its own. */
typedef struct grid {
    int dim;
    double lo[3], h;
    int64_t n[3], ncell;
    int64_t *head, *next;  // per cell, per ball; -1 ends a list
    double *x, *r;         // 3 per ball, 1 per ball
    int64_t count, cap;
} grid;

static int64_t cell_coord(const grid *gr, int k, double v)
{
    double c = floor((v - gr->lo[k]) / gr->h);
    if (!(c >= 0)) c = 0;  // also NaN
    if (c > (double)(gr->n[k] - 1)) c = (double)(gr->n[k] - 1);
    return (int64_t)c;
}

static int64_t cell_of(const grid *gr, const double *x)
{
    int64_t c = 0;
    for (int k = gr->dim - 1; k >= 0; k--) c = c * gr->n[k] + cell_coord(gr, k, x[k]);
    return c;
}

/* Pushes the grid's storage (two userdata) over the box [lo, hi] for cap balls. */
static void grid_init(lua_State *L, grid *gr, int dim, const double *lo, const double *hi, double h, int64_t cap)
{
    memset(gr, 0, sizeof *gr);
    gr->dim = dim;
    gr->cap = cap;
    const double target = fmax(1024.0, 2.0 * (double)cap);
    /* no ball to size the cells by (h = 0: nothing placed yet), or radii
     * that overflow: cells of a target's share of the box, never a size
     * the loop below cannot grow from */
    double extent = 0;
    for (int k = 0; k < dim; k++) extent = fmax(extent, hi[k] - lo[k]);
    if (!(h > 0) || !isfinite(h)) h = isfinite(extent) && extent > 0 ? extent / target * 4 : 1;
    for (;;) {
        double cells = 1;
        for (int k = 0; k < dim; k++) cells *= floor((hi[k] - lo[k]) / h) + 3;
        if (cells <= target) break;
        h *= pow(cells / target, 1.0 / dim) * 1.01;
    }
    gr->h = h;
    gr->ncell = 1;
    for (int k = 0; k < dim; k++) {
        gr->lo[k] = lo[k] - h;
        gr->n[k] = (int64_t)floor((hi[k] - lo[k]) / h) + 3;
        gr->ncell *= gr->n[k];
    }
    gr->head = lua_newuserdatauv(L, (size_t)gr->ncell * sizeof *gr->head, 0);
    for (int64_t c = 0; c < gr->ncell; c++) gr->head[c] = -1;
    char *mem = lua_newuserdatauv(L, (size_t)(cap > 0 ? cap : 1) * (sizeof(int64_t) + 4 * sizeof(double)), 0);
    gr->next = (int64_t *)mem;
    gr->x = (double *)(mem + (size_t)(cap > 0 ? cap : 1) * sizeof(int64_t));
    gr->r = gr->x + 3 * (cap > 0 ? cap : 1);
}

static void grid_add(grid *gr, const double *x, double r)
{
    const int64_t i = gr->count++;
    for (int k = 0; k < 3; k++) gr->x[3 * i + k] = k < gr->dim ? x[k] : 0;
    gr->r[i] = r;
    const int64_t c = cell_of(gr, x);
    gr->next[i] = gr->head[c];
    gr->head[c] = i;
}

/* Whether a ball at p of radius r reaches within `reach` of the region's
 * box: the model's balls that new ones may meet. */
static bool near_region(const sx_lua_region *reg, int dim, const double *p, double r, double reach)
{
    bool in = true;
    for (int k = 0; k < dim; k++) in &= p[k] > reg->lo[k] - r - reach && p[k] < reg->hi[k] + r + reach;
    return in;
}

/* A grid (a Lua userdata on the stack) over the region holding the model's
 * balls near it, within `reach` of its box, so new balls are also checked
 * against them; cells fit a new ball of radius rnew against the largest
 * of those, and room is made for `more` new entries. */
static grid *grid_of_model(lua_State *L, const sx_model *m, const sx_lua_region *reg, double reach, double rnew,
                           int64_t more)
{
    const int dim = sx_model_dim(m);
    const int64_t nb = sx_ball_count(m);
    double rold = 0;
    int64_t near = 0;
    grid *gr = NULL;
    for (int pass = 0; pass < 2; pass++) { /* count, then fill */
        for (int64_t i = 0; i < nb; i++) {
            const int64_t id = sx_ball_id_at(m, i);
            double p[3], rb;
            sx_ball_get_vec(m, id, SX_BALL_POS, p);
            sx_ball_get(m, id, SX_BALL_RADIUS, &rb);
            if (!near_region(reg, dim, p, rb, reach)) continue;
            if (gr) {
                grid_add(gr, p, rb);
            } else {
                near++;
                if (rb > rold) rold = rb;
            }
        }
        if (!gr) {
            gr = lua_newuserdatauv(L, sizeof *gr, 0);
            grid_init(L, gr, dim, reg->lo, reg->hi, rnew + fmax(rnew, rold), near + more);
        }
    }
    return gr;
}

/* Calls fn(i, ud) for every ball in the cells around x; stops when fn returns true. */
static bool grid_near(const grid *gr, const double *x, bool (*fn)(const grid *, int64_t, void *), void *ud)
{
    int64_t c0[3] = {0, 0, 0}, lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int k = 0; k < gr->dim; k++) {
        c0[k] = cell_coord(gr, k, x[k]);
        lo[k] = c0[k] > 0 ? c0[k] - 1 : 0;
        hi[k] = c0[k] < gr->n[k] - 1 ? c0[k] + 1 : gr->n[k] - 1;
    }
    for (int64_t cz = lo[2]; cz <= hi[2]; cz++)
        for (int64_t cy = lo[1]; cy <= hi[1]; cy++)
            for (int64_t cx = lo[0]; cx <= hi[0]; cx++) {
                const int64_t c = gr->dim == 3 ? (cz * gr->n[1] + cy) * gr->n[0] + cx : cy * gr->n[0] + cx;
                for (int64_t i = gr->head[c]; i >= 0; i = gr->next[i])
                    if (fn(gr, i, ud)) return true;
            }
    return false;
}

typedef struct probe {
    const double *x;
    double r;
} probe;

static bool overlaps_one(const grid *gr, int64_t i, void *ud)
{
    const probe *p = ud;
    double d2 = 0;
    for (int k = 0; k < gr->dim; k++) {
        const double d = gr->x[3 * i + k] - p->x[k];
        d2 += d * d;
    }
    const double s = gr->r[i] + p->r;
    return d2 < s * s;
}

/* --------------------------------------------------------------- sampling */

/* An orthonormal pair perpendicular to the unit vector a. */
static void perpendicular(const double *a, double *e1, double *e2)
{
    const double t[3] = {fabs(a[0]) < 0.9 ? 1 : 0, fabs(a[0]) < 0.9 ? 0 : 1, 0};
    e1[0] = a[1] * t[2] - a[2] * t[1];
    e1[1] = a[2] * t[0] - a[0] * t[2];
    e1[2] = a[0] * t[1] - a[1] * t[0];
    const double l = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int k = 0; k < 3; k++) e1[k] /= l;
    e2[0] = a[1] * e1[2] - a[2] * e1[1];
    e2[1] = a[2] * e1[0] - a[0] * e1[2];
    e2[2] = a[0] * e1[1] - a[1] * e1[0];
}

/* A point uniform in the disk/ball of unit radius (rejection from the square/cube). */
static void unit_ball(rng *r, int dim, double *p)
{
    for (;;) {
        double s = 0;
        for (int k = 0; k < dim; k++) {
            p[k] = 2 * sx_lua_rng_uniform(r) - 1;
            s += p[k] * p[k];
        }
        if (s <= 1) return;
    }
}

/* Whether a ball of radius rad can fit at all, by the region's own measure. */
static bool fits(const sx_lua_region *g, double rad)
{
    switch (g->kind) {
    case SX_REGION_BOX:
        for (int k = 0; k < g->dim; k++)
            if (g->hi[k] - g->lo[k] < 2 * rad) return false;
        return true;
    case SX_REGION_SPHERE:
    case SX_REGION_DISK: return rad <= g->r;
    case SX_REGION_CYLINDER: return rad <= g->r && 2 * rad <= g->len;
    default: return true;  // a polygon: the tries decide
    }
}

/* A centre for a ball of radius rad, uniform over where it fits in the region. */
static void sample(const sx_lua_region *g, rng *r, double rad, const double *e1, const double *e2, double *x)
{
    double p[3] = {0, 0, 0};
    switch (g->kind) {
    case SX_REGION_BOX:
    case SX_REGION_POLYGON:  // the bounding box; the caller checks containment
        for (int k = 0; k < g->dim; k++) x[k] = g->lo[k] + rad + (g->hi[k] - g->lo[k] - 2 * rad) * sx_lua_rng_uniform(r);
        return;
    case SX_REGION_SPHERE:
    case SX_REGION_DISK:
        unit_ball(r, g->dim, p);
        for (int k = 0; k < g->dim; k++) x[k] = g->c[k] + (g->r - rad) * p[k];
        return;
    case SX_REGION_CYLINDER: {
        const double t = rad + (g->len - 2 * rad) * sx_lua_rng_uniform(r);
        unit_ball(r, 2, p);
        for (int k = 0; k < 3; k++)
            x[k] = g->c[k] + t * g->axis[k] + (g->r - rad) * (p[0] * e1[k] + p[1] * e2[k]);
        return;
    }
    }
}

/* ------------------------------------------------------- random placement */

/* Places n balls of radii rad (sorted, largest first) without overlaps
 * among them and with the model's balls; writes centres to x (3 per ball).
 * Pushes the grid's storage. */
void sx_lua_place_random(lua_State *L, sx_lua_run *run, const sx_model *m, const gen *g, rng *r, const double *rad,
                         int64_t n, double *x)
{
    const sx_lua_region *reg = &g->region;
    if (n > 0 && !fits(reg, rad[0]))
        luaL_argerror(L, 2, lua_pushfstring(L, "a ball of radius %f m does not fit in the region", rad[0]));
    /* the model's balls near the region take part in the overlap checks */
    const double rnew = n > 0 ? rad[0] : 0;
    grid *gr = grid_of_model(L, m, reg, rnew, rnew, n);
    double e1[3] = {0, 0, 0}, e2[3] = {0, 0, 0};
    if (reg->kind == SX_REGION_CYLINDER) perpendicular(reg->axis, e1, e2);
    for (int64_t i = 0; i < n; i++) {
        if (i % 1024 == 0) sx_lua_run_poll(L, run); /* a Ctrl-C, in a run or not */
        double *xi = x + 3 * i;
        int64_t t = 0;
        for (; t < g->tries; t++) {
            if (t % 4096 == 4095) sx_lua_run_poll(L, run); /* a region that is full: many tries per ball */
            sample(reg, r, rad[i], e1, e2, xi);
            if (!sx_lua_region_contains(reg, xi, rad[i])) continue;
            probe p = {xi, rad[i]};
            if (!grid_near(gr, xi, overlaps_one, &p)) break;
        }
        if (t == g->tries)
            luaL_error(L, "m:generate: placed %I of %I balls; no room for one of radius %f m after %I tries: lower the "
                       "count or the radii, enlarge the region, or use method = 'distribute'",
                       (lua_Integer)i, (lua_Integer)n, rad[i], (lua_Integer)g->tries);
        grid_add(gr, xi, rad[i]);
    }
}

/* ------------------------------------------------------- distribute */

/* The worst overlap of one of the model's balls (x, r) with the new balls
 * of a grid: its ratio to the smaller radius, and which new ball. */
typedef struct clash {
    const double *x;
    double r, ratio, overlap, radius;
    int64_t i;
} clash;

static bool worst_clash(const grid *gr, int64_t i, void *ud)
{
    clash *c = ud;
    double d2 = 0;
    for (int k = 0; k < gr->dim; k++) d2 += (gr->x[3 * i + k] - c->x[k]) * (gr->x[3 * i + k] - c->x[k]);
    const double over = gr->r[i] + c->r - sqrt(d2), small = fmin(gr->r[i], c->r);
    if (over > 0 && small > 0 && over / small > c->ratio) c->ratio = over / small, c->overlap = over, c->radius = small, c->i = i;
    return false;
}

/* distribute pushes apart only the balls it makes: one of them over a ball
 * of the model (a region not clear of them) beyond seixo.model{overlap_limit}
 * is an error naming both, before any is added (a cycle would otherwise
 * fail on it, blaming the timestep). */
static void check_clear(lua_State *L, const sx_model *m, double limit, const gen *g, const double *x,
                        const double *rad, int64_t n)
{
    const int64_t nb = sx_ball_count(m);
    if (n == 0 || nb == 0) return;
    const int top = lua_gettop(L), dim = g->dim;
    double rnew = 0, rold = 0;
    for (int64_t i = 0; i < n; i++) rnew = fmax(rnew, rad[i]);
    for (int64_t j = 0; j < nb; j++) {
        double rb;
        sx_ball_get(m, sx_ball_id_at(m, j), SX_BALL_RADIUS, &rb);
        rold = fmax(rold, rb);
    }
    grid *gr = lua_newuserdatauv(L, sizeof *gr, 0);
    grid_init(L, gr, dim, g->region.lo, g->region.hi, rnew + rold, n);
    for (int64_t i = 0; i < n; i++) grid_add(gr, x + 3 * i, rad[i]);
    clash worst = {NULL, 0, 0, 0, 0, 0};
    int64_t worst_id = 0;
    for (int64_t j = 0; j < nb; j++) {
        const int64_t id = sx_ball_id_at(m, j);
        double p[3] = {0, 0, 0}, rb;
        sx_ball_get_vec(m, id, SX_BALL_POS, p);
        sx_ball_get(m, id, SX_BALL_RADIUS, &rb);
        if (!near_region(&g->region, dim, p, rb, rnew)) continue; /* the grid's cells clamp what lies beyond */
        clash c = worst;
        c.x = p, c.r = rb;
        grid_near(gr, p, worst_clash, &c);
        if (c.ratio > worst.ratio) worst = c, worst_id = id;
    }
    lua_settop(L, top);
    if (worst.ratio <= limit * (1 + 1e-9)) return;
    const double *q = x + 3 * worst.i;
    luaL_error(L, "m:generate: a ball it places (at %f, %f%s) would overlap ball %I by %f m, %d%% of the smaller radius "
                  "%f m (more than the %d%% of seixo.model{overlap_limit}): distribute moves only the balls it makes; "
                  "generate into a region clear of the model's balls, or remove them first",
               q[0], q[1], dim == 3 ? lua_pushfstring(L, ", %f", q[2]) : "", (lua_Integer)worst_id, worst.overlap,
               (int)lround(100 * worst.ratio), worst.radius, (int)lround(100 * limit));
}

/* Moves x back inside where a ball of radius rad fits; false if it cannot (then x is unchanged). */
static bool project(const sx_lua_region *g, double rad, double *x)
{
    if (sx_lua_region_contains(g, x, rad)) return true;
    switch (g->kind) {
    case SX_REGION_BOX:
        for (int k = 0; k < g->dim; k++) x[k] = fmin(fmax(x[k], g->lo[k] + rad), g->hi[k] - rad);
        return true;
    case SX_REGION_SPHERE:
    case SX_REGION_DISK: {
        double d2 = 0;
        for (int k = 0; k < g->dim; k++) d2 += (x[k] - g->c[k]) * (x[k] - g->c[k]);
        const double d = sqrt(d2), s = d > 0 ? (g->r - rad) / d : 0;
        for (int k = 0; k < g->dim; k++) x[k] = g->c[k] + (x[k] - g->c[k]) * s;
        return true;
    }
    case SX_REGION_CYLINDER: {
        double d[3], t = 0;
        for (int k = 0; k < 3; k++) {
            d[k] = x[k] - g->c[k];
            t += d[k] * g->axis[k];
        }
        double q[3], q2 = 0;
        for (int k = 0; k < 3; k++) {
            q[k] = d[k] - t * g->axis[k];
            q2 += q[k] * q[k];
        }
        const double tc = fmin(fmax(t, rad), g->len - rad), ql = sqrt(q2);
        const double s = ql > g->r - rad ? (g->r - rad) / ql : 1;
        for (int k = 0; k < 3; k++) x[k] = g->c[k] + tc * g->axis[k] + q[k] * s;
        return true;
    }
    default: return false;
    }
}

typedef struct push {
    int64_t self;
    double *dx;     // accumulated displacement, 3 per ball
    double worst;   // largest overlap / smaller radius seen
} push;

static bool push_one(const grid *gr, int64_t j, void *ud)
{
    push *p = ud;
    const int64_t i = p->self;
    if (j <= i) return false;  // each pair once
    double n[3] = {0, 0, 0}, d2 = 0;
    for (int k = 0; k < gr->dim; k++) {
        n[k] = gr->x[3 * j + k] - gr->x[3 * i + k];
        d2 += n[k] * n[k];
    }
    /* radii inflated by 1 %: where there is room, the balls end apart */
    const double s = 1.01 * (gr->r[i] + gr->r[j]);
    if (d2 >= s * s) return false;
    double d = sqrt(d2);
    if (d == 0) {  // coincident centres: part them along x
        n[0] = 1;
        d = 1;
        d2 = 0;
    }
    const double over = s - sqrt(d2);
    const double rmin = fmin(gr->r[i], gr->r[j]);
    if (over / rmin > p->worst) p->worst = over / rmin;
    /* each moves by its share, the smaller ball the more */
    const double wi = 0.6 * over * gr->r[j] / s, wj = 0.6 * over * gr->r[i] / s;
    for (int k = 0; k < gr->dim; k++) {
        p->dx[3 * i + k] -= wi * n[k] / d;
        p->dx[3 * j + k] += wj * n[k] / d;
    }
    return false;
}

/* Pushes overlapping balls apart until no overlap exceeds `limit` of the
 * smaller radius (or the iterations run out); returns the worst ratio left. */
static double push_apart(lua_State *L, sx_lua_run *run, const gen *g, const double *rad, int64_t n, double *x,
                         double limit)
{
    double worst = INFINITY, best = INFINITY;
    double *dx = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * 3 * sizeof *dx, 0);
    const int top = lua_gettop(L);
    /* until the limit, or until 50 iterations bring no 1 % gain (a jammed packing) */
    for (int it = 0, stalled = 0; it < 5000 && worst > limit && stalled < 50; it++) {
        sx_lua_run_poll(L, run);
        grid gr;
        grid_init(L, &gr, g->dim, g->region.lo, g->region.hi, 2.02 * g->rmax, n);
        for (int64_t i = 0; i < n; i++) grid_add(&gr, x + 3 * i, rad[i]);
        memset(dx, 0, (size_t)n * 3 * sizeof *dx);
        push p = {0, dx, 0};
        for (int64_t i = 0; i < n; i++) {
            p.self = i;
            grid_near(&gr, x + 3 * i, push_one, &p);
        }
        worst = p.worst;
        if (worst < 0.99 * best) {
            best = worst;
            stalled = 0;
        } else {
            stalled++;
        }
        for (int64_t i = 0; i < n; i++) {
            double y[3];
            for (int k = 0; k < 3; k++) y[k] = x[3 * i + k] + dx[3 * i + k];
            if (project(&g->region, rad[i], y)) memcpy(x + 3 * i, y, sizeof y);
        }
        lua_settop(L, top);
    }
    return worst;
}

/* Centres at random where each ball fits, overlaps allowed, then pushed
 * apart. Refused when the overlaps stay above 0.9 of a radius (the
 * porosity is out of reach) or a new ball lies over one of the model's
 * beyond `limit` (check_clear). */
void sx_lua_place_distributed(lua_State *L, sx_lua_run *run, const gen *g, rng *r, const double *rad, int64_t n,
                              double *x, double limit)
{
    double e1[3] = {0, 0, 0}, e2[3] = {0, 0, 0};
    if (g->region.kind == SX_REGION_CYLINDER) perpendicular(g->region.axis, e1, e2);
    for (int64_t i = 0; i < n; i++) {
        if (!fits(&g->region, rad[i]))
            luaL_argerror(L, 2, lua_pushfstring(L, "a ball of radius %f m does not fit in the region", rad[i]));
        int64_t t = 0;
        do sample(&g->region, r, rad[i], e1, e2, x + 3 * i);
        while (!sx_lua_region_contains(&g->region, x + 3 * i, rad[i]) && ++t < g->tries);
        if (t == g->tries) luaL_error(L, "m:generate: the region leaves no room for a ball of radius %f m", rad[i]);
    }
    const double worst = push_apart(L, run, g, rad, n, x, 0.01);
    if (worst > 0.9)
        luaL_error(L, "m:generate: cannot reach porosity %f in this region: overlaps stay at %f of a radius; "
                      "raise the porosity", g->porosity, worst);
    check_clear(L, sx_lua_checkmodel(L, 1), limit, g, x, rad, n);
}

/* -------------------------------------------------------------- lattice */

/* Lattice sites in the region: centres into a pushed array, returned; their number in *count. */
double *sx_lua_lattice_sites(lua_State *L, const gen *g, int64_t *count)
{
    const double r = g->rmin, *lo = g->region.lo, *hi = g->region.hi;
    const int dim = g->dim;
    /* the cell: its edge lengths and its basis (in edge units) */
    double a[3] = {2 * r, 2 * r, 2 * r};
    double basis[4][3] = {{0, 0, 0}};
    int nb = 1;
    switch (g->packing) {
    case P_HEX:
        a[1] = 2 * sqrt(3.0) * r;
        basis[1][0] = 0.5;
        basis[1][1] = 0.5;
        nb = 2;
        break;
    case P_FCC:
        for (int k = 0; k < 3; k++) a[k] = 2 * sqrt(2.0) * r;
        basis[1][0] = basis[1][1] = 0.5;
        basis[2][0] = basis[2][2] = 0.5;
        basis[3][1] = basis[3][2] = 0.5;
        nb = 4;
        break;
    default: break;
    }
    int64_t ncell[3] = {1, 1, 1};
    double sites = nb;
    for (int k = 0; k < dim; k++) {
        const double c = floor((hi[k] - lo[k] - 2 * r) / a[k]) + 2;
        if (!(c >= 1)) {
            *count = 0;
            return lua_newuserdatauv(L, sizeof(double), 0);
        }
        sites *= c;
        ncell[k] = (int64_t)fmin(c, 1e9);
    }
    const int64_t limit = g->has_count ? g->count : INT64_MAX;
    /* the sites of the bounding box, of which the region keeps some: the first `count` suffice */
    if (sites > (double)limit) sites = (double)limit;
    if (sites > MAX_GENERATE)
        luaL_argerror(L, 2, lua_pushfstring(L, "the lattice has too many sites (more than %d); use a larger radius "
                                            "or give a count", MAX_GENERATE));
    double *x = lua_newuserdatauv(L, (size_t)(sites > 1 ? sites : 1) * 3 * sizeof *x, 0);
    int64_t n = 0;
    const double shrink = r * (1 - 1e-9);  // touching the boundary counts as inside
    for (int64_t k2 = 0; k2 < ncell[2] && n < limit; k2++)
        for (int64_t k1 = 0; k1 < ncell[1] && n < limit; k1++)
            for (int64_t k0 = 0; k0 < ncell[0] && n < limit; k0++)
                for (int b = 0; b < nb && n < limit; b++) {
                    const int64_t kk[3] = {k0, k1, k2};
                    double p[3] = {0, 0, 0};
                    for (int k = 0; k < dim; k++) p[k] = lo[k] + r + (kk[k] + basis[b][k]) * a[k];
                    if (!sx_lua_region_contains(&g->region, p, shrink)) continue;
                    memcpy(x + 3 * n, p, sizeof p);
                    n++;
                }
    if (g->has_count && n < g->count)
        luaL_argerror(L, 2, lua_pushfstring(L, "only %I lattice sites fit in the region (count %I)", (lua_Integer)n,
                                            (lua_Integer)g->count));
    *count = n;
    return x;
}

/* --------------------------------------------------------------- clumps */

/* A uniformly random orientation: 3D Shoemake's quaternion from three
 * uniforms, 2D an angle about z. */
static void random_orientation(rng *r, int dim, double *q)
{
    if (dim == 2) {
        const double a = 2 * SX_LUA_PI * sx_lua_rng_uniform(r);
        q[0] = cos(0.5 * a), q[1] = q[2] = 0, q[3] = sin(0.5 * a);
        return;
    }
    const double u1 = sx_lua_rng_uniform(r), u2 = 2 * SX_LUA_PI * sx_lua_rng_uniform(r),
                 u3 = 2 * SX_LUA_PI * sx_lua_rng_uniform(r);
    const double a = sqrt(1 - u1), b = sqrt(u1);
    q[0] = a * sin(u2), q[1] = a * cos(u2), q[2] = b * sin(u3), q[3] = b * cos(u3);
}

/* v turned by the unit quaternion q (v + 2 w (u x v) + 2 u x (u x v)). */
static void rotate(const double *q, const double *v, double *out)
{
    const double *u = q + 1;
    const double t[3] = {2 * (u[1] * v[2] - u[2] * v[1]), 2 * (u[2] * v[0] - u[0] * v[2]), 2 * (u[0] * v[1] - u[1] * v[0])};
    out[0] = v[0] + q[0] * t[0] + (u[1] * t[2] - u[2] * t[1]);
    out[1] = v[1] + q[0] * t[1] + (u[2] * t[0] - u[0] * t[2]);
    out[2] = v[2] + q[0] * t[2] + (u[0] * t[1] - u[1] * t[0]);
}

/* Places n clumps of template g->tpl at scales s (sorted, largest first),
 * each at a random centroid and orientation where all its pebbles lie in
 * the region without overlapping one another's or the model's balls;
 * writes centroids to x (3 per clump) and orientations to q (4 per clump).
 * Pushes the grid's storage. */
void sx_lua_place_clumps(lua_State *L, const sx_model *m, const gen *g, rng *r, const double *s, int64_t n, double *x,
                         double *q)
{
    const sx_lua_region *reg = &g->region;
    const int dim = g->dim;
    sx_clump_props p;
    sx_lua_check(L, m, sx_clump_template_props(m, g->tpl, &p), "m:generate");
    const int64_t np = p.count;
    /* the pebbles about the centroid at scale 1, and the clump's bounding radius */
    double *peb = lua_newuserdatauv(L, (size_t)np * 4 * sizeof(double), 0);
    double bound = 0, rpeb = 0;
    for (int64_t k = 0; k < np; k++) {
        double c[3], rk;
        sx_lua_check(L, m, sx_clump_template_pebble(m, g->tpl, k, c, &rk), "m:generate");
        double d2 = 0;
        for (int j = 0; j < 3; j++) {
            peb[4 * k + j] = j < dim ? c[j] - p.centroid[j] : 0;
            d2 += peb[4 * k + j] * peb[4 * k + j];
        }
        peb[4 * k + 3] = rk;
        bound = fmax(bound, sqrt(d2) + rk);
        rpeb = fmax(rpeb, rk);
    }
    if (n > 0 && !fits(reg, s[0] * bound))
        luaL_argerror(L, 2, lua_pushfstring(L, "a clump of scale %f (bounding radius %f m) does not fit in the region", s[0],
                                            s[0] * bound));
    /* the model's balls near the region take part in the overlap checks, as in sx_lua_place_random */
    const double rnew = n > 0 ? s[0] * rpeb : 0, reach = n > 0 ? s[0] * bound : 0;
    grid *gr = grid_of_model(L, m, reg, reach, rnew, n * np);
    double e1[3] = {0, 0, 0}, e2[3] = {0, 0, 0};
    if (reg->kind == SX_REGION_CYLINDER) perpendicular(reg->axis, e1, e2);
    double *xp = lua_newuserdatauv(L, (size_t)np * 3 * sizeof(double), 0);
    for (int64_t i = 0; i < n; i++) {
        double *xi = x + 3 * i, *qi = q + 4 * i;
        int64_t t = 0;
        for (; t < g->tries; t++) {
            sample(reg, r, s[i] * bound, e1, e2, xi);
            random_orientation(r, dim, qi);
            bool ok = true;
            for (int64_t k = 0; k < np && ok; k++) {
                double b[3] = {s[i] * peb[4 * k], s[i] * peb[4 * k + 1], s[i] * peb[4 * k + 2]}, w[3];
                rotate(qi, b, w);
                for (int j = 0; j < 3; j++) xp[3 * k + j] = j < dim ? xi[j] + w[j] : 0;
                probe pr = {xp + 3 * k, s[i] * peb[4 * k + 3]};
                ok = sx_lua_region_contains(reg, pr.x, pr.r) && !grid_near(gr, pr.x, overlaps_one, &pr);
            }
            if (ok) break;
        }
        if (t == g->tries)
            luaL_error(L, "generate: placed %I of %I clumps; no room for one of scale %f after %I tries: lower the "
                       "count or the scale, or enlarge the region",
                       (lua_Integer)i, (lua_Integer)n, s[i], (lua_Integer)g->tries);
        for (int64_t k = 0; k < np; k++) grid_add(gr, xp + 3 * k, s[i] * peb[4 * k + 3]);
    }
}
