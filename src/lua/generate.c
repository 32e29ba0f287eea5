/* m:generate{...}: assemblies of balls in a region, reproducible from a seed.
 *
 * Methods:
 *   random      non-overlapping random placement (with the balls already
 *               there too), largest first; a clear error when a ball finds
 *               no room after `tries` attempts. `count` or `porosity`.
 *   distribute  PFC's ball distribute: radii up to the target porosity,
 *               centres placed at random with overlaps, then relaxed.
 *               Overlaps above a hundredth of the smaller radius are
 *               first pushed apart geometrically where there is room (the
 *               core's stability guard refuses overlaps beyond a radius),
 *               then the model cycles with the user's materials, gravity
 *               off and velocities zeroed every `calm` steps, until the
 *               mean unbalanced-force ratio reaches relax.ratio, no overlap
 *               exceeds a thousandth of a radius, or relax.steps have run.
 *   expand      PFC's radius expansion: non-overlapping placement at
 *               reduced radii, then growth by stages of at most 2 % to
 *               the radii of the target porosity, cycling between stages,
 *               then the same relaxation.
 *   lattice     regular packings of touching balls: square or hex (2D),
 *               cubic or fcc (3D); every site whose ball lies in the region.
 * Radii: `radius = r` or `{rmin, rmax}` with distribution "uniform"
 * (default), "normal" or "lognormal" (mean, std of the radius; truncated to
 * [rmin, rmax]), or `psd`, a grading curve: the fraction of the solid
 * volume in balls up to each radius, linear in the radius between its
 * points (a sieve curve's mass passing). When both
 * count and porosity are given (distribute, expand), the drawn radii are
 * scaled by one factor to reach the porosity exactly.
 * Clumps: `template = name` generates clumps of that template instead
 * (method random), `scale` taking the place of the radius (its
 * distribution the same), each with a uniformly random orientation; a
 * clump is placed when every pebble lies in the region and overlaps no
 * ball or pebble there.
 *
 * The RNG is xoshiro256** seeded through splitmix64: the same seed and
 * arguments give bit-identical assemblies on every run. Overlap checks go
 * through a uniform cell grid of the region, so placement is O(N). Every
 * working array is a Lua userdata: an error anywhere frees them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bindings.h"

enum { MAX_GENERATE = 10000000 };

/* ------------------------------------------------------------------ RNG */

typedef struct rng {
    uint64_t s[4];
} rng;

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static void rng_seed(rng *r, uint64_t seed)
{
    for (int i = 0; i < 4; i++) r->s[i] = splitmix64(&seed);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static uint64_t rng_next(rng *r)
{
    uint64_t *s = r->s;
    const uint64_t out = rotl(s[1] * 5, 7) * 9;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return out;
}

/* uniform in [0, 1) */
static double rng_uniform(rng *r) { return (double)(rng_next(r) >> 11) * 0x1.0p-53; }

/* standard normal (Box-Muller, one value per call) */
static double rng_normal(rng *r)
{
    const double u = 1 - rng_uniform(r);  // (0, 1]
    const double v = rng_uniform(r);
    return sqrt(-2 * log(u)) * cos(2 * SX_LUA_PI * v);
}

/* ------------------------------------------------------------ parameters */

enum { M_RANDOM, M_DISTRIBUTE, M_EXPAND, M_LATTICE };
static const char *const method_names[] = {"random", "distribute", "expand", "lattice", NULL};
enum { P_SQUARE, P_HEX, P_CUBIC, P_FCC };
static const char *const packing_names[] = {"square", "hex", "cubic", "fcc", NULL};
enum { D_UNIFORM, D_NORMAL, D_LOGNORMAL, D_PSD };
static const char *const dist_names[] = {"uniform", "normal", "lognormal", NULL};
enum { MAX_PSD = 100 };

typedef struct gen {
    int dim, method, packing, dist, material;
    int tpl;        /* clump template, -1 for balls */
    double unit;    /* volume of a body of size 1 over a ball's of radius 1 (1 for balls) */
    int32_t group;
    int64_t count, tries;
    bool has_count, has_porosity;
    double porosity, rmin, rmax, mean, std;
    double log_mean, log_std; /* lognormal: of ln r */
    int psd_points;
    double psd_r[MAX_PSD];    /* the grading curve's radii, increasing */
    double psd_count[MAX_PSD]; /* the fraction of the balls' count up to each (by count, not volume) */
    sx_lua_region region;
    uint64_t seed;
    bool relax;
    int64_t relax_steps, calm;
    double relax_ratio;
} gen;

static double ball_volume(int dim, double r) { return dim == 3 ? 4.0 / 3.0 * SX_LUA_PI * r * r * r : SX_LUA_PI * r * r; }

/* The volume of a generated body of size r: a ball of radius r, or a clump at scale r. */
static double body_volume(const gen *g, double r) { return g->unit * ball_volume(g->dim, r); }

/* The usual-range warning of the sizes drawn: a ball's radius, or a
 * clump's equivalent radius (its template's at scale 1 times the scale: a
 * sieve curve in m given for clumps' scales made pebbles of 0.25 um, with
 * no word where a ball that small is warned of). */
static void check_sizes(lua_State *L, const gen *g)
{
    const double unit = g->tpl >= 0 ? pow(g->unit, 1.0 / g->dim) : 1;
    const char *what = g->tpl >= 0 ? "clump size (equivalent radius)" : "radius";
    sx_lua_check_range(L, 1, what, g->rmax * unit, 1e-6, 1, "m");
    sx_lua_check_range(L, 1, what, g->rmin * unit, 1e-6, 1, "m");
}

/* The size range of the bodies: `radius` of balls, `scale` of clumps. */
static void read_radius(lua_State *L, gen *g, const char *key)
{
    lua_pushstring(L, key);
    const int t = lua_rawget(L, 2);
    if (t == LUA_TNUMBER) {
        g->rmin = g->rmax = lua_tonumber(L, -1);
    } else if (t == LUA_TTABLE && lua_rawlen(L, -1) == 2) {
        lua_rawgeti(L, -1, 1);
        lua_rawgeti(L, -2, 2);
        if (!lua_isnumber(L, -2) || !lua_isnumber(L, -1) || lua_type(L, -1) != LUA_TNUMBER || lua_type(L, -2) != LUA_TNUMBER)
            sx_lua_fielderror(L, 2, key, "two numbers {min, max} expected");
        g->rmin = lua_tonumber(L, -2);
        g->rmax = lua_tonumber(L, -1);
        lua_pop(L, 2);
    } else if (t == LUA_TNIL) {
        if (g->tpl >= 0) { /* clumps at their template's size by default */
            g->rmin = g->rmax = 1;
        } else {
            sx_lua_fielderror(L, 2, "radius", "is required: a radius r or a range {rmin, rmax} in m");
        }
    } else {
        sx_lua_fielderror(L, 2, key, lua_pushfstring(L, "a number or {min, max} expected, got %s", lua_typename(L, t)));
    }
    lua_pop(L, 1);
    if (!(g->rmin > 0 && g->rmax >= g->rmin && isfinite(g->rmax)))
        sx_lua_fielderror(L, 2, key, "sizes must be finite, > 0, and min <= max");
    check_sizes(L, g);
}

/* The grading curve {{r1, 0}, ..., {rn, 1}}: F(r), the fraction of the
 * solid volume in bodies of size up to r, linear in r between points. A
 * ball's volume goes as r^dim, so within a bin the count's density goes as
 * r^-dim; psd_count holds the count's cumulative fraction at each point. */
static void read_psd(lua_State *L, gen *g, const char *size)
{
    const int t = lua_gettop(L);
    const int n = (int)lua_rawlen(L, t);
    if (n < 2 || n > MAX_PSD)
        sx_lua_fielderror(L, 2, "psd", lua_pushfstring(L, "2 to %d points {r, F} expected, got %d", (int)MAX_PSD, n));
    double F[MAX_PSD];
    for (int i = 0; i < n; i++) {
        lua_rawgeti(L, t, i + 1);
        const bool pair = lua_type(L, -1) == LUA_TTABLE && lua_rawlen(L, -1) == 2;
        if (pair) {
            lua_rawgeti(L, -1, 1);
            lua_rawgeti(L, -2, 2);
        }
        if (!pair || lua_type(L, -1) != LUA_TNUMBER || lua_type(L, -2) != LUA_TNUMBER)
            sx_lua_fielderror(L, 2, "psd", lua_pushfstring(L, "point %d: {%s, fraction passing} (two numbers) expected", i + 1, size));
        g->psd_r[i] = lua_tonumber(L, -2);
        F[i] = lua_tonumber(L, -1);
        lua_pop(L, 3);
        if (!(g->psd_r[i] > 0 && isfinite(g->psd_r[i])) || (i > 0 && !(g->psd_r[i] > g->psd_r[i - 1])))
            sx_lua_fielderror(L, 2, "psd", lua_pushfstring(L, "point %d: the sizes (%s) must be finite, > 0 and increasing", i + 1, size));
        if (!(F[i] >= 0 && F[i] <= 1))
            sx_lua_fielderror(L, 2, "psd", lua_pushfstring(L, "point %d: a fraction passing in [0, 1] expected, got %f%s", i + 1,
                                                          F[i], F[i] > 1 && F[i] <= 100 ? " (a percentage? divide by 100)" : ""));
        if (i > 0 && F[i] < F[i - 1])
            sx_lua_fielderror(L, 2, "psd", lua_pushfstring(L, "point %d: the fractions passing must not decrease", i + 1));
    }
    if (F[0] != 0 || F[n - 1] != 1)
        sx_lua_fielderror(L, 2, "psd", lua_pushfstring(L, "the curve must start at fraction 0 (its smallest %s) and end at 1 "
                                                          "(its largest), got %f and %f", size, F[0], F[n - 1]));
    const int k = g->dim;
    double sum = 0;
    g->psd_count[0] = 0;
    for (int i = 1; i < n; i++) {
        const double a = g->psd_r[i - 1], b = g->psd_r[i];
        sum += (F[i] - F[i - 1]) / (b - a) * (pow(a, 1 - k) - pow(b, 1 - k)) / (k - 1);
        g->psd_count[i] = sum;
    }
    for (int i = 1; i < n; i++) g->psd_count[i] /= sum;
    g->psd_count[n - 1] = 1;
    g->psd_points = n;
    g->rmin = g->psd_r[0];
    g->rmax = g->psd_r[n - 1];
}

static void read_relax(lua_State *L, gen *g)
{
    static const char *const keys[] = {"steps", "ratio", "calm", NULL};
    g->relax = true;
    g->relax_steps = 20000;
    g->relax_ratio = 1e-3;
    g->calm = 10;
    lua_pushliteral(L, "relax");
    const int t = lua_rawget(L, 2);
    if (t == LUA_TBOOLEAN) {
        g->relax = lua_toboolean(L, -1);
    } else if (t == LUA_TTABLE) {
        const int r = lua_gettop(L);
        sx_lua_checksubkeys(L, r, 2, "relax", keys);
        sx_lua_optintfield(L, r, "steps", 0, 1000000000, &g->relax_steps);
        sx_lua_optintfield(L, r, "calm", 1, 1000000, &g->calm);
        if (sx_lua_optnumfield(L, r, "ratio", &g->relax_ratio) && !(g->relax_ratio > 0))
            sx_lua_fielderror(L, 2, "relax", "'ratio' must be > 0");
    } else if (t != LUA_TNIL) {
        sx_lua_fielderror(L, 2, "relax", lua_pushfstring(L, "boolean or {steps =, ratio =, calm =} expected, got %s",
                                                         lua_typename(L, t)));
    }
    lua_pop(L, 1);
}

/* Reads the arguments; leaves the region's storage (if any) on the stack. */
static void read_gen(lua_State *L, const sx_model *m, gen *g)
{
    static const char *const keys[] = {"count", "porosity", "radius", "distribution", "mean",   "std",   "region",
                                       "seed",  "material", "group",  "method",       "packing", "tries", "relax",
                                       "template", "scale", "psd", NULL};
    sx_lua_checkkeys(L, 2, keys);
    memset(g, 0, sizeof *g);
    g->dim = sx_model_dim(m);
    g->tpl = -1;
    g->unit = 1;
    lua_pushliteral(L, "template");
    const bool clumps = lua_rawget(L, 2) != LUA_TNIL;
    lua_pop(L, 1);
    if (clumps) {
        g->tpl = sx_lua_template_arg(L, m, 2, "template");
        sx_clump_props p;
        sx_lua_check(L, m, sx_clump_template_props(m, g->tpl, &p), "m:generate");
        g->unit = p.volume / ball_volume(g->dim, 1);
        static const char *const ball_only[] = {"radius", "packing", "relax", NULL};
        for (int k = 0; ball_only[k]; k++) {
            lua_pushstring(L, ball_only[k]);
            const bool given = lua_rawget(L, 2) != LUA_TNIL;
            lua_pop(L, 1);
            if (given)
                sx_lua_fielderror(L, 2, ball_only[k], k == 0 ? "clumps take 'scale' (of their template), not a radius"
                                                             : "clumps are generated by method 'random' only");
        }
    } else {
        lua_pushliteral(L, "scale");
        if (lua_rawget(L, 2) != LUA_TNIL) sx_lua_fielderror(L, 2, "scale", "only with 'template' (for clumps)");
        lua_pop(L, 1);
    }
    g->packing = sx_lua_optchoicefield(L, 2, "packing", packing_names, -1);
    g->method = sx_lua_optchoicefield(L, 2, "method", method_names, g->packing >= 0 ? M_LATTICE : M_RANDOM);
    if (clumps && g->method != M_RANDOM) sx_lua_fielderror(L, 2, "method", "clumps are generated by method 'random' only");
    if (g->packing >= 0 && g->method != M_LATTICE) sx_lua_fielderror(L, 2, "packing", "only for method = 'lattice'");
    if (g->method == M_LATTICE) {
        if (g->packing < 0) g->packing = g->dim == 2 ? P_HEX : P_FCC;
        if ((g->packing <= P_HEX) != (g->dim == 2))
            sx_lua_fielderror(L, 2, "packing", g->dim == 2 ? "'square' or 'hex' in 2D" : "'cubic' or 'fcc' in 3D");
    }
    const char *size = clumps ? "scale" : "radius";
    lua_pushliteral(L, "psd");
    const int psd_type = lua_rawget(L, 2);
    if (psd_type == LUA_TNIL) {
        lua_pop(L, 1);
        read_radius(L, g, size);
        g->dist = sx_lua_optchoicefield(L, 2, "distribution", dist_names, D_UNIFORM);
    } else {
        if (psd_type != LUA_TTABLE)
            sx_lua_fielderror(L, 2, "psd", lua_pushfstring(L, "a table of points {r, F} expected, got %s", lua_typename(L, psd_type)));
        static const char *const by_psd[] = {"radius", "scale", "distribution", NULL};
        for (int k = 0; by_psd[k]; k++) {
            lua_pushstring(L, by_psd[k]);
            const bool given = lua_rawget(L, 2) != LUA_TNIL;
            lua_pop(L, 1);
            if (given) sx_lua_fielderror(L, 2, by_psd[k], "the psd gives the sizes and their distribution: leave this out");
        }
        read_psd(L, g, size);
        lua_pop(L, 1);
        g->dist = D_PSD;
        check_sizes(L, g);
    }
    g->mean = 0.5 * (g->rmin + g->rmax);
    g->std = (g->rmax - g->rmin) / 6;
    const bool has_mean = sx_lua_optnumfield(L, 2, "mean", &g->mean), has_std = sx_lua_optnumfield(L, 2, "std", &g->std);
    const bool parametric = g->dist == D_NORMAL || g->dist == D_LOGNORMAL;
    if ((has_mean || has_std) && !parametric)
        sx_lua_fielderror(L, 2, has_mean ? "mean" : "std", "only for distribution = 'normal' or 'lognormal'");
    if (parametric) {
        if (!(g->mean >= g->rmin && g->mean <= g->rmax)) sx_lua_fielderror(L, 2, "mean", "must lie in [rmin, rmax]");
        if (!(g->std >= 0 && isfinite(g->std))) sx_lua_fielderror(L, 2, "std", "must be finite and >= 0");
    }
    if (g->dist == D_LOGNORMAL) { /* ln r's parameters for r's mean and std */
        g->log_std = sqrt(log1p((g->std / g->mean) * (g->std / g->mean)));
        g->log_mean = log(g->mean) - 0.5 * g->log_std * g->log_std;
    }
    g->has_count = sx_lua_optintfield(L, 2, "count", 0, MAX_GENERATE, &g->count);
    g->has_porosity = sx_lua_optnumfield(L, 2, "porosity", &g->porosity);
    if (g->has_porosity && !(g->porosity > 0 && g->porosity < 1))
        sx_lua_fielderror(L, 2, "porosity", "must lie in (0, 1)");
    switch (g->method) {
    case M_RANDOM:
        if (g->has_count == g->has_porosity) luaL_argerror(L, 2, "give 'count' or 'porosity' (one of them)");
        break;
    case M_DISTRIBUTE:
    case M_EXPAND:
        if (!g->has_porosity) luaL_argerror(L, 2, lua_pushfstring(L, "field 'porosity' is required by method '%s'",
                                                                  method_names[g->method]));
        break;
    case M_LATTICE:
        if (g->has_porosity) sx_lua_fielderror(L, 2, "porosity", "a lattice's porosity follows from its packing");
        if (g->rmin != g->rmax) sx_lua_fielderror(L, 2, g->dist == D_PSD ? "psd" : "radius", "a lattice takes one radius");
        break;
    }
    int64_t seed = 1;
    sx_lua_optintfield(L, 2, "seed", 0, (int64_t)1 << 53, &seed);
    g->seed = (uint64_t)seed;
    g->tries = 10000;
    sx_lua_optintfield(L, 2, "tries", 1, 100000000, &g->tries);
    read_relax(L, g);
    g->material = sx_lua_material_arg(L, m, 2, "material", sx_lua_optstrfield(L, 2, "material"));
    const char *group = sx_lua_optstrfield(L, 2, "group");
    if (group) g->group = sx_lua_group_id(L, 1, group, true);
    lua_pushliteral(L, "region");
    if (lua_rawget(L, 2) == LUA_TNIL) luaL_argerror(L, 2, "field 'region' is required");
    const int top = lua_gettop(L);
    sx_lua_region_read(L, top, g->dim, 2, "region", &g->region);
    lua_remove(L, top);  // the table; the polygon's storage, if any, stays
}

/* --------------------------------------------------------------- radii */

/* A size from the grading curve: a bin by the count's fractions, then the
 * inverse of the count's distribution in it, whose density goes as r^-dim. */
static double draw_psd(const gen *g, rng *r)
{
    const double u = rng_uniform(r);
    int i = 1;
    while (i < g->psd_points - 1 && !(u < g->psd_count[i])) i++;
    const double a = g->psd_r[i - 1], b = g->psd_r[i], e = 1 - g->dim;
    const double pa = pow(a, e), pb = pow(b, e);
    const double x = pow(pa - rng_uniform(r) * (pa - pb), 1 / e);
    return fmin(fmax(x, a), b);
}

static double draw_radius(lua_State *L, const gen *g, rng *r)
{
    if (g->rmin == g->rmax) return g->rmin;
    if (g->dist == D_UNIFORM) return g->rmin + (g->rmax - g->rmin) * rng_uniform(r);
    if (g->dist == D_PSD) return draw_psd(g, r);
    for (int k = 0; k < 100000; k++) {
        const double x = g->dist == D_NORMAL ? g->mean + g->std * rng_normal(r) : exp(g->log_mean + g->log_std * rng_normal(r));
        if (x >= g->rmin && x <= g->rmax) return x;
    }
    luaL_argerror(L, 2, lua_pushfstring(L, "the %s distribution (mean, std) almost never falls in [rmin, rmax]", dist_names[g->dist]));
    return 0;
}

/* Draws the radii: `count` of them, or as many as the porosity takes;
 * scaled to the porosity when both are given. Pushes their storage. */
static double *draw_radii(lua_State *L, gen *g, rng *r)
{
    const double target = g->has_porosity ? (1 - g->porosity) * g->region.volume : 0;
    if (!g->has_count) {
        /* count the balls first, with a copy of the generator, so one array suffices */
        rng probe = *r;
        double solid = 0;
        int64_t n = 0;
        while (solid < target) {
            if (n >= MAX_GENERATE)
                luaL_argerror(L, 2, lua_pushfstring(L, "this porosity needs more than %d balls of these radii", MAX_GENERATE));
            solid += body_volume(g, draw_radius(L, g, &probe));
            n++;
        }
        g->count = n;
    }
    double *rad = lua_newuserdatauv(L, (size_t)(g->count > 0 ? g->count : 1) * sizeof *rad, 0);
    double solid = 0;
    for (int64_t i = 0; i < g->count; i++) {
        rad[i] = draw_radius(L, g, r);
        solid += body_volume(g, rad[i]);
    }
    if (g->has_count && g->has_porosity && g->count > 0) {
        const double k = pow(target / solid, 1.0 / g->dim);
        if (!(k > 0) || !isfinite(k) || !isfinite(g->rmax * k))
            luaL_argerror(L, 2, "the radii cannot be scaled to this porosity and count (their volume overflows or "
                                "vanishes)");
        for (int64_t i = 0; i < g->count; i++) rad[i] *= k;
        /* the grain size moved: said, since a user asked for those radii (a
         * sand user's finding: 0.5 ... 0.8 mm became 1.13 ... 1.80 mm, silently) */
        if (fabs(k - 1) > 0.01 && sx_lua_parallel_says(sx_lua_tomodel(L, 1))) {
            luaL_where(L, 1);
            fprintf(stderr,
                    "seixo: warning: %sm:generate: the radii were scaled by %.4g to reach porosity %g with %lld balls: "
                    "%g ... %g m instead of %g ... %g m (give count or porosity alone to keep the radii)\n",
                    lua_tostring(L, -1), k, g->porosity, (long long)g->count, g->rmin * k, g->rmax * k, g->rmin, g->rmax);
            fflush(stderr);
            lua_pop(L, 1);
        }
        g->rmin *= k;
        g->rmax *= k;
    }
    return rad;
}

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
            p[k] = 2 * rng_uniform(r) - 1;
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
        for (int k = 0; k < g->dim; k++) x[k] = g->lo[k] + rad + (g->hi[k] - g->lo[k] - 2 * rad) * rng_uniform(r);
        return;
    case SX_REGION_SPHERE:
    case SX_REGION_DISK:
        unit_ball(r, g->dim, p);
        for (int k = 0; k < g->dim; k++) x[k] = g->c[k] + (g->r - rad) * p[k];
        return;
    case SX_REGION_CYLINDER: {
        const double t = rad + (g->len - 2 * rad) * rng_uniform(r);
        unit_ball(r, 2, p);
        for (int k = 0; k < 3; k++)
            x[k] = g->c[k] + t * g->axis[k] + (g->r - rad) * (p[0] * e1[k] + p[1] * e2[k]);
        return;
    }
    }
}

/* ------------------------------------------------------- random placement */

/* Sort order: radius descending, then index (a total order: deterministic). */
static int by_radius(const void *a, const void *b)
{
    const double *ra = *(const double *const *)a, *rb = *(const double *const *)b;
    if (*ra != *rb) return *ra < *rb ? 1 : -1;
    return ra < rb ? -1 : ra > rb;
}

/* Sorts the radii in place, largest first. */
static void sort_radii(lua_State *L, double *rad, int64_t n)
{
    const double **p = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * sizeof *p, 0);
    for (int64_t i = 0; i < n; i++) p[i] = &rad[i];
    qsort(p, (size_t)n, sizeof *p, by_radius);
    double *sorted = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * sizeof *sorted, 0);
    for (int64_t i = 0; i < n; i++) sorted[i] = *p[i];
    memcpy(rad, sorted, (size_t)n * sizeof *rad);
    lua_pop(L, 2);
}

/* Places n balls of radii rad (sorted, largest first) without overlaps
 * among them and with the model's balls; writes centres to x (3 per ball).
 * Pushes the grid's storage. */
static void place_random(lua_State *L, sx_lua_run *run, const sx_model *m, const gen *g, rng *r, const double *rad,
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

/* -------------------------------------------------------------- lattice */

/* Lattice sites in the region: centres into a pushed array; returns their number. */
static double *lattice(lua_State *L, const gen *g, int64_t *count)
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
        const double a = 2 * SX_LUA_PI * rng_uniform(r);
        q[0] = cos(0.5 * a), q[1] = q[2] = 0, q[3] = sin(0.5 * a);
        return;
    }
    const double u1 = rng_uniform(r), u2 = 2 * SX_LUA_PI * rng_uniform(r), u3 = 2 * SX_LUA_PI * rng_uniform(r);
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
static void place_clumps(lua_State *L, const sx_model *m, const gen *g, rng *r, const double *s, int64_t n, double *x,
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
    /* the model's balls near the region take part in the overlap checks, as in place_random */
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

/* Room for `more` new balls: when they are at least as many as there are,
 * the store grown once to hold them exactly, not by doubling (which may
 * leave half of it unused); fewer, and the doubling's amortised growth is
 * kept. */
static void reserve_balls(lua_State *L, sx_model *m, int64_t more)
{
    if (more >= sx_ball_count(m) && sx_ball_reserve(m, more) != SX_OK)
        luaL_error(L, "m:generate: %s", sx_lua_core_message(sx_model_error(m)));
}

/* Adds the clumps; all or none (a failure removes those added). */
static void add_clumps(lua_State *L, sx_model *m, const gen *g, const double *x, const double *q, const double *s,
                       int64_t n)
{
    int64_t *ids = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * sizeof *ids, 0);
    sx_clump_props p;
    sx_lua_check(L, m, sx_clump_template_props(m, g->tpl, &p), "m:generate");
    reserve_balls(L, m, n * p.count); /* the new balls are the pebbles */
    for (int64_t i = 0; i < n; i++) {
        sx_clump_def d = sx_clump_default_def();
        d.template_index = g->tpl;
        memcpy(d.pos, x + 3 * i, sizeof d.pos);
        memcpy(d.orientation, q + 4 * i, sizeof d.orientation);
        d.scale = s[i];
        d.material = g->material;
        if (sx_clump_add(m, &d, &ids[i]) != SX_OK) {
            lua_pushstring(L, sx_model_error(m));
            for (int64_t j = 0; j < i; j++) sx_clump_remove(m, ids[j]);
            luaL_error(L, "generate: %s", lua_tostring(L, -1));
        }
        if (g->group) sx_lua_clump_set_group(L, m, ids[i], g->group);
    }
}

/* m:generate{template = ...}: scales drawn like radii (largest first), placed, added. */
static int generate_clumps(lua_State *L, const gen *g, rng *r)
{
    gen sizes = *g;
    double *s = draw_radii(L, &sizes, r);
    const int64_t n = sizes.count;
    sort_radii(L, s, n);
    double *x = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * 3 * sizeof *x, 0);
    double *q = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * 4 * sizeof *q, 0);
    place_clumps(L, sx_lua_checkmodel(L, 1), &sizes, r, s, n, x, q);
    add_clumps(L, sx_lua_checkmodel(L, 1), &sizes, x, q, s, n);
    double solid = 0;
    for (int64_t i = 0; i < n; i++) solid += body_volume(&sizes, s[i]);
    lua_pushinteger(L, (lua_Integer)n);
    lua_pushnumber(L, 1 - solid / g->region.volume);
    return 2;
}

/* ------------------------------------------------------------- the model */

/* Restores the gravity when a relaxation ends, whichever way. */
typedef struct gravity_guard {
    sx_lua_model *ud;
    double g[3];
    bool armed;
} gravity_guard;

static int gravity_restore(lua_State *L)
{
    gravity_guard *gg = lua_touserdata(L, 1);
    if (gg && gg->armed && gg->ud->m) sx_model_set_gravity(gg->ud->m, gg->g);
    if (gg) gg->armed = false;
    return 0;
}

static void push_gravity_guard(lua_State *L, sx_lua_model *ud)
{
    gravity_guard *gg = lua_newuserdatauv(L, sizeof *gg, 0);
    gg->ud = ud;
    sx_model_gravity(ud->m, gg->g);
    gg->armed = true;
    lua_createtable(L, 0, 1);
    lua_pushcfunction(L, gravity_restore);
    lua_setfield(L, -2, "__close");
    lua_setmetatable(L, -2);
    lua_toclose(L, -1);
    static const double zero[3] = {0, 0, 0};
    sx_model_set_gravity(ud->m, zero);
}

/* Adds the balls; all or none (a failure removes those added). Pushes their ids. */
static int64_t *add_balls(lua_State *L, sx_model *m, const gen *g, const double *x, const double *rad, int64_t n)
{
    int64_t *ids = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * sizeof *ids, 0);
    reserve_balls(L, m, n);
    for (int64_t i = 0; i < n; i++) {
        sx_ball_def d = sx_ball_default_def();
        memcpy(d.pos, x + 3 * i, sizeof d.pos);
        d.radius = rad[i];
        d.material = g->material;
        ids[i] = 0;  // stays 0, no ball's id, when the add fails
        sx_status st = sx_ball_add(m, &d, &ids[i]);
        if (st == SX_OK && g->group) st = sx_ball_set_group(m, ids[i], g->group);
        if (st != SX_OK) {
            lua_pushstring(L, sx_model_error(m));
            sx_ball_remove_many(m, ids, ids[i] > 0 ? i + 1 : i);
            luaL_error(L, "m:generate: %s", sx_lua_core_message(lua_tostring(L, -1)));
        }
    }
    return ids;
}

static void calm(sx_model *m, const int64_t *ids, int64_t n)
{
    static const double zero[3] = {0, 0, 0};
    for (int64_t i = 0; i < n; i++) {
        sx_ball_set_vec(m, ids[i], SX_BALL_VEL, zero);
        sx_ball_set_vec(m, ids[i], SX_BALL_SPIN, zero);
    }
}

typedef struct overlap_scan {
    const sx_model *m;
    double worst;  // largest overlap / smaller radius
} overlap_scan;

static bool scan_overlap(const sx_contact_info *c, void *ud)
{
    overlap_scan *o = ud;
    double ra = 0, rb = 0;
    sx_ball_get(o->m, c->a, SX_BALL_RADIUS, &ra);
    if (!c->is_wall) sx_ball_get(o->m, c->b, SX_BALL_RADIUS, &rb);
    const double r = c->is_wall ? ra : fmin(ra, rb);
    if (r > 0 && c->overlap / r > o->worst) o->worst = c->overlap / r;
    return true;
}

/* Relaxed: the ratio is reached, or no overlap exceeds 1e-3 of a radius
 * (a loose assembly without gravity keeps a high ratio while its last
 * contacts part, with forces of no consequence). */
static bool relaxed(const sx_model *m, double ratio)
{
    if (sx_model_unbalanced_ratio(m) <= ratio) return true;
    overlap_scan o = {m, 0};
    sx_contact_each(m, scan_overlap, &o);
    return o.worst <= 1e-3;
}

/* Cycles `steps`, calming every g->calm steps; with a ratio, stops once relaxed. */
static void relax_cycles(lua_State *L, sx_lua_run *run, const gen *g, const int64_t *ids, int64_t n, int64_t steps,
                         double ratio)
{
    sx_lua_model *ud = sx_lua_modelud(L, 1);
    int64_t done = 0, since_check = 0;
    while (done < steps) {
        const int64_t k = steps - done < g->calm ? steps - done : g->calm;
        if (ud->decomposed) sx_lua_check_model_call(L, ud->m, "m:generate");
        sx_lua_run_cycle(L, run, k, INFINITY);
        done += k;
        since_check += k;
        calm(ud->m, ids, n);
        if (ratio > 0 && since_check >= 100) {
            since_check = 0;
            if (relaxed(ud->m, ratio)) break;
        }
    }
}

static int model_generate(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    sx_lua_model *ud = sx_lua_modelud(L, 1);
    gen g;
    read_gen(L, m, &g);
    if ((g.method == M_DISTRIBUTE || g.method == M_EXPAND) && ud->running)
        return luaL_error(L, "m:generate: method '%s' cycles the model, which a callback of a cycle cannot do",
                          method_names[g.method]);
    /* the methods that cycle hold the model as a run from here on: a Ctrl-C
     * anywhere in them, cycling or not, stops them (see run.c) */
    sx_lua_run *run = g.method == M_DISTRIBUTE || g.method == M_EXPAND ? sx_lua_run_open(L, 1, "m:generate") : NULL;
    rng r;
    rng_seed(&r, g.seed);
    int64_t n = 0;
    double *x = NULL, *rad = NULL;
    if (g.tpl >= 0) return generate_clumps(L, &g, &r);
    if (g.method == M_LATTICE) {
        x = lattice(L, &g, &n);
        rad = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * sizeof *rad, 0);
        for (int64_t i = 0; i < n; i++) rad[i] = g.rmin;
    } else {
        rad = draw_radii(L, &g, &r);
        n = g.count;
        sort_radii(L, rad, n);
        x = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * 3 * sizeof *x, 0);
        memset(x, 0, (size_t)(n > 0 ? n : 1) * 3 * sizeof *x);
    }
    /* expansion starts from radii shrunk to a solid fraction random placement reaches easily */
    double shrink = 1;
    if (g.method == M_EXPAND) {
        const double easy = g.dim == 3 ? 0.25 : 0.40;
        shrink = fmin(1, pow(easy / (1 - g.porosity), 1.0 / g.dim));
        for (int64_t i = 0; i < n; i++) rad[i] *= shrink;
    }
    if (g.method == M_RANDOM || g.method == M_EXPAND) {
        place_random(L, run, m, &g, &r, rad, n, x);
    } else if (g.method == M_DISTRIBUTE) {
        double e1[3] = {0, 0, 0}, e2[3] = {0, 0, 0};
        if (g.region.kind == SX_REGION_CYLINDER) perpendicular(g.region.axis, e1, e2);
        for (int64_t i = 0; i < n; i++) {
            if (!fits(&g.region, rad[i]))
                return luaL_argerror(L, 2, lua_pushfstring(L, "a ball of radius %f m does not fit in the region", rad[i]));
            int64_t t = 0;
            do sample(&g.region, &r, rad[i], e1, e2, x + 3 * i);
            while (!sx_lua_region_contains(&g.region, x + 3 * i, rad[i]) && ++t < g.tries);
            if (t == g.tries) return luaL_error(L, "m:generate: the region leaves no room for a ball of radius %f m", rad[i]);
        }
        const double worst = push_apart(L, run, &g, rad, n, x, 0.01);
        if (worst > 0.9)
            return luaL_error(L, "m:generate: cannot reach porosity %f in this region: overlaps stay at %f of a radius; "
                              "raise the porosity", g.porosity, worst);
        check_clear(L, sx_lua_checkmodel(L, 1), ud->overlap_limit, &g, x, rad, n);
    }
    m = sx_lua_checkmodel(L, 1);
    const int64_t *ids = add_balls(L, m, &g, x, rad, n);
    sx_lua_record_seed(L, 1, (int64_t)g.seed); /* the balls exist: the files' provenance lists it */
    /* placed over the model's balls or walls (lattice and expand do not see
     * the balls; distribute checked them: check_clear): named after the next
     * step, the relaxation's first (geometry.c); the overlaps among the new
     * balls are the relaxation's to remove, not checked */
    if (n > 0) {
        ud->unchecked = true;
        ud->fresh_lo = ud->fresh_hi = ids[0];
        for (int64_t i = 1; i < n; i++) {
            if (ids[i] < ud->fresh_lo) ud->fresh_lo = ids[i];
            if (ids[i] > ud->fresh_hi) ud->fresh_hi = ids[i];
        }
    }
    if (g.method == M_EXPAND && shrink < 1 && n > 0) {
        const int top = lua_gettop(L);
        push_gravity_guard(L, ud);
        const int stages = (int)ceil(log(1 / shrink) / log(1.02));
        for (int s = 1; s <= stages; s++) {
            const double f = s == stages ? 1 / shrink : pow(1 / shrink, (double)s / stages);
            for (int64_t i = 0; i < n; i++) sx_lua_check(L, ud->m, sx_ball_set(ud->m, ids[i], SX_BALL_RADIUS, rad[i] * f), "m:generate");
            relax_cycles(L, run, &g, ids, n, 100, 0);
        }
        lua_settop(L, top);  // restores the gravity
        for (int64_t i = 0; i < n; i++) rad[i] /= shrink;
    }
    if (g.relax && (g.method == M_DISTRIBUTE || g.method == M_EXPAND) && n > 0) {
        const int top = lua_gettop(L);
        push_gravity_guard(L, ud);
        relax_cycles(L, run, &g, ids, n, g.relax_steps, g.relax_ratio);
        lua_settop(L, top);
    }
    double solid = 0;
    for (int64_t i = 0; i < n; i++) solid += body_volume(&g, rad[i]);
    lua_pushinteger(L, (lua_Integer)n);
    lua_pushnumber(L, 1 - solid / g.region.volume);
    return 2;
}

const luaL_Reg sx_lua_generate_methods[] = {
    {"generate", model_generate},
    {NULL, NULL},
};
