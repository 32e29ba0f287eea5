/* The sizes of m:generate's bodies (the radii of balls, the scales of
 * clumps) and the RNG every draw of a generation takes.
 *
 * Sizes: `radius = r` or `{rmin, rmax}` with distribution "uniform"
 * (default), "normal" or "lognormal" (mean, std of the radius; truncated to
 * [rmin, rmax]), or `psd`, a grading curve: the fraction of the solid
 * volume in balls up to each radius, linear in the radius between its
 * points (a sieve curve's mass passing). When both
 * count and porosity are given (distribute, expand), the drawn radii are
 * scaled by one factor to reach the porosity exactly. A clump's `scale`
 * takes the place of the radius, its distribution the same.
 *
 * The RNG is xoshiro256** seeded through splitmix64: the same seed and
 * arguments give bit-identical assemblies on every run. */
#include <math.h>
#include <stdio.h>

#include "generate.h"

/* ------------------------------------------------------------------ RNG */

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void sx_lua_rng_seed(rng *r, uint64_t seed)
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
double sx_lua_rng_uniform(rng *r) { return (double)(rng_next(r) >> 11) * 0x1.0p-53; }

/* standard normal (Box-Muller, one value per call) */
static double rng_normal(rng *r)
{
    const double u = 1 - sx_lua_rng_uniform(r);  // (0, 1]
    const double v = sx_lua_rng_uniform(r);
    return sqrt(-2 * log(u)) * cos(2 * SX_LUA_PI * v);
}

/* ----------------------------------------------------------- reading */

static const char *const dist_names[] = {"uniform", "normal", "lognormal", NULL};

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

void sx_lua_read_sizes(lua_State *L, gen *g)
{
    const char *size = g->tpl >= 0 ? "scale" : "radius";
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
}

/* ----------------------------------------------------------- drawing */

/* A size from the grading curve: a bin by the count's fractions, then the
 * inverse of the count's distribution in it, whose density goes as r^-dim. */
static double draw_psd(const gen *g, rng *r)
{
    const double u = sx_lua_rng_uniform(r);
    int i = 1;
    while (i < g->psd_points - 1 && !(u < g->psd_count[i])) i++;
    const double a = g->psd_r[i - 1], b = g->psd_r[i], e = 1 - g->dim;
    const double pa = pow(a, e), pb = pow(b, e);
    const double x = pow(pa - sx_lua_rng_uniform(r) * (pa - pb), 1 / e);
    return fmin(fmax(x, a), b);
}

static double draw_radius(lua_State *L, const gen *g, rng *r)
{
    if (g->rmin == g->rmax) return g->rmin;
    if (g->dist == D_UNIFORM) return g->rmin + (g->rmax - g->rmin) * sx_lua_rng_uniform(r);
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
double *sx_lua_draw_radii(lua_State *L, gen *g, rng *r)
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
            sx_lua_where(L);
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
