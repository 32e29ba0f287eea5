/* Geometry and units checked where the user makes them, so that an error
 * names the thing that is wrong rather than its first symptom.
 *
 * A ball placed behind a wall, or two balls placed overlapping by most of a
 * radius, are accepted by the core (a model may be built in any order) but
 * the first step then fails as "unstable ... lower the timestep". So:
 * - m:ball checks the new ball against the model's planes and lines (few,
 *   and "behind" has a meaning only for them): behind, or overlapping by
 *   more than the limit, is an error naming the wall;
 * - the first step after a ball or a wall was added is taken alone, and its
 *   contacts are scanned: an overlap beyond the limit (of the smaller
 *   radius) is an error naming the two entities. One O(contacts) scan, once
 *   per batch of additions; the run's bits do not change (only where a
 *   chunk ends). When that step failed as unstable, the balls are swept
 *   instead (the failure leaves no contact list), so the error names the
 *   placement rather than the timestep.
 * The limit is seixo.model{overlap_limit = 0.5}: a fraction of the radius.
 *
 * Values far outside the physical range of a granular material (a density
 * in g/cm^3, a stress in MPa) warn on stderr once per model and kind of
 * value, with the unit expected: they may be intended (a scaled model). */
#include "bindings.h"
#include "seixo_lua.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --------------------------------------------------------------- walls */

void sx_lua_check_ball_walls(lua_State *L, int model, const sx_model *m, const double *x, double r)
{
    const double limit = sx_lua_modelud(L, model)->overlap_limit;
    const int dim = sx_model_dim(m);
    for (int64_t i = 0; i < sx_wall_count(m); i++) {
        const int64_t id = sx_wall_id_at(m, i);
        sx_wall_def w;
        if (sx_wall_get(m, id, &w) != SX_OK || (w.kind != SX_WALL_PLANE && w.kind != SX_WALL_LINE)) continue;
        double d = 0, nn = 0;
        for (int k = 0; k < dim; k++) {
            d += (x[k] - w.point[k]) * w.normal[k];
            nn += w.normal[k] * w.normal[k];
        }
        d /= sqrt(nn);  // the signed distance of the centre, > 0 on the balls' side
        if (d < 0)
            luaL_error(L, "m:ball: the ball of radius %f m lies behind wall %I (its centre is %f m on the far side "
                          "of the wall's normal): place it on the side the normal points to",
                       r, (lua_Integer)id, -d);
        if (r - d > limit * r * (1 + 1e-9))
            luaL_error(L, "m:ball: the ball of radius %f m would overlap wall %I by %f m, %d%% of its radius "
                          "(more than the %d%% of seixo.model{overlap_limit}): move it %f m further from the wall",
                       r, (lua_Integer)id, r - d, (int)lround(100 * (r - d) / r), (int)lround(100 * limit),
                       r - d - limit * r);
    }
}

/* ------------------------------------------- the first step's contacts */

typedef struct worst {
    const sx_model *m;
    int64_t fresh_lo, fresh_hi; // two balls of m:generate's: not checked (sx_lua_model)
    double ratio;               // overlap over the smaller radius
    double overlap, radius;
    int64_t a, b;
    bool wall;
} worst;

static void consider(worst *w, double overlap, double r, int64_t a, int64_t b, bool wall)
{
    if (!wall && a >= w->fresh_lo && a <= w->fresh_hi && b >= w->fresh_lo && b <= w->fresh_hi) return;
    if (r > 0 && overlap / r > w->ratio)
        w->ratio = overlap / r, w->overlap = overlap, w->radius = r, w->a = a, w->b = b, w->wall = wall;
}

typedef struct placed {
    double lo;  // x - r: the key of the sweep
    int64_t i;  // the ball's index
} placed;

static int by_lo(const void *a, const void *b)
{
    const double x = ((const placed *)a)->lo, y = ((const placed *)b)->lo;
    return (x > y) - (x < y);
}

/* A step that failed leaves no contact list: the balls are swept along x
 * instead (sorted by x - r, each met with those starting before it ends),
 * O(n log n) plus the neighbours in a slab, and the planes and lines
 * checked ball by ball. An error path only. */
static void sweep(lua_State *L, worst *w)
{
    const sx_model *m = w->m;
    const int dim = sx_model_dim(m);
    const int64_t n = sx_ball_count(m);
    double *x = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * 4 * sizeof *x, 0), *r = x + 3 * n;
    placed *order = lua_newuserdatauv(L, (size_t)(n > 0 ? n : 1) * sizeof *order, 0);
    for (int64_t i = 0; i < n; i++) {
        const int64_t id = sx_ball_id_at(m, i);
        sx_ball_get_vec(m, id, SX_BALL_POS, x + 3 * i);
        sx_ball_get(m, id, SX_BALL_RADIUS, r + i);
        order[i] = (placed){x[3 * i] - r[i], i};
    }
    qsort(order, (size_t)n, sizeof *order, by_lo);
    for (int64_t s = 0; s < n; s++) {
        const int64_t i = order[s].i;
        for (int64_t t = s + 1; t < n && order[t].lo < x[3 * i] + r[i]; t++) {
            const int64_t j = order[t].i, a = sx_ball_id_at(m, i), b = sx_ball_id_at(m, j);
            double d2 = 0;
            for (int k = 0; k < dim; k++) d2 += (x[3 * i + k] - x[3 * j + k]) * (x[3 * i + k] - x[3 * j + k]);
            const int64_t ca = sx_ball_clump(m, a);
            if (ca > 0 && ca == sx_ball_clump(m, b)) continue;  // a clump's pebbles overlap by design
            consider(w, r[i] + r[j] - sqrt(d2), fmin(r[i], r[j]), a < b ? a : b, a < b ? b : a, false);
        }
    }
    for (int64_t k = 0; k < sx_wall_count(m); k++) {
        sx_wall_def wd;
        const int64_t wid = sx_wall_id_at(m, k);
        if (sx_wall_get(m, wid, &wd) != SX_OK || (wd.kind != SX_WALL_PLANE && wd.kind != SX_WALL_LINE)) continue;
        const double nn = sqrt(wd.normal[0] * wd.normal[0] + wd.normal[1] * wd.normal[1] + wd.normal[2] * wd.normal[2]);
        for (int64_t i = 0; i < n; i++) {
            double d = 0;
            for (int c = 0; c < dim; c++) d += (x[3 * i + c] - wd.point[c]) * wd.normal[c];
            consider(w, r[i] - d / nn, r[i], sx_ball_id_at(m, i), wid, true);
        }
    }
    lua_pop(L, 2);
}

bool sx_lua_placement_overlap(lua_State *L, sx_lua_model *ud, const char *what, bool failed)
{
    worst w = {ud->m, ud->fresh_lo, ud->fresh_hi, 0, 0, 0, 0, 0, false};
    sx_overlap o;
    if (failed)
        sweep(L, &w);
    else if (!sx_contact_deepest(ud->m, ud->fresh_lo, ud->fresh_hi, &o)) /* scattered: the ranks' own contacts */
        luaL_error(L, "%s: the ranks could not compare the placed balls' overlaps", what);
    else
        w.ratio = o.ratio, w.overlap = o.overlap, w.radius = o.radius, w.a = o.a, w.b = o.b, w.wall = o.is_wall;
    ud->unchecked = false;
    ud->fresh_lo = ud->fresh_hi = 0;
    if (w.ratio <= ud->overlap_limit * (1 + 1e-9)) return false;  // "more than": a placement at the limit, rounded, passes
    const int pct = (int)lround(100 * w.ratio), lim = (int)lround(100 * ud->overlap_limit);
    if (w.wall)
        lua_pushfstring(L, "%s: ball %I overlaps wall %I by %f m, %d%% of its radius %f m%s, as it was placed (more "
                           "than the %d%% of seixo.model{overlap_limit}): move it clear of the wall; the timestep is "
                           "not the cause",
                        what, (lua_Integer)w.a, (lua_Integer)w.b, w.overlap, pct, w.radius,
                        w.ratio > 1 ? " (its centre is behind the wall)" : "", lim);
    else
        lua_pushfstring(L, "%s: balls %I and %I overlap by %f m, %d%% of the smaller radius %f m, as they were placed "
                           "(more than the %d%% of seixo.model{overlap_limit}): move them apart or make them smaller; "
                           "the timestep is not the cause",
                        what, (lua_Integer)w.a, (lua_Integer)w.b, w.overlap, pct, w.radius, lim);
    return true;
}

void sx_lua_check_placement(lua_State *L, sx_lua_model *ud, const char *what, bool failed)
{
    /* the first step's contacts: each rank's own (a collective call), or,
     * after a failed step, every ball as placed */
    if (failed) {
        sx_lua_gather(L, ud->m, "m");
    } else if (sx_model_scattered(ud->m)) {
        char call[96];
        snprintf(call, sizeof call, "%s (placement check)", what);
        sx_lua_check_model_call(L, ud->m, call);
    }
    if (!sx_lua_placement_overlap(L, ud, what, failed)) return;
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_concat(L, 2);
    lua_error(L);
}

/* --------------------------------------------------------------- units */

/* A value the lab passes on (a servo target from lab.triaxial's confining,
 * a material from lab.specimen's) was named at the line of lab.lua that
 * passed it, not at the script's call: seixo.caller knows the library's
 * files. Without it (no Lua library loaded), or when no line is outside
 * them, the caller's line. */
void sx_lua_where(lua_State *L)
{
    const int top = lua_gettop(L);
    const unsigned interrupts = sx_lua_interrupt_count();
    if (lua_getfield(L, LUA_REGISTRYINDEX, LUA_LOADED_TABLE) == LUA_TTABLE
        && lua_getfield(L, -1, "seixo.caller") == LUA_TTABLE && lua_getfield(L, -1, "where") == LUA_TFUNCTION) {
        const int status = lua_pcall(L, 0, 1, 0);
        if (status == LUA_OK && lua_type(L, -1) == LUA_TSTRING) {
            lua_replace(L, top + 1);
            lua_settop(L, top + 1);
            return;
        }
        /* a Ctrl-C that stopped where() is the script's to answer, not lost here */
        if (status != LUA_OK && sx_lua_interrupt_count() != interrupts) lua_error(L);
    }
    lua_settop(L, top);
    luaL_where(L, 1);
}

void sx_lua_warn_once(lua_State *L, int model, const char *key, const char *fmt, ...)
{
    sx_lua_state(L, model, "warned");
    if (lua_getfield(L, -1, key) == LUA_TNIL) {
        lua_pushboolean(L, 1);
        lua_setfield(L, -3, key);
        sx_lua_where(L);
        if (sx_lua_parallel_says(sx_lua_tomodel(L, model))) {
            char text[512];
            va_list ap;
            va_start(ap, fmt);
            vsnprintf(text, sizeof text, fmt, ap);
            va_end(ap);
            fprintf(stderr, "seixo: warning: %s%s\n", lua_tostring(L, -1), text);
            fflush(stderr);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 2);
}

void sx_lua_check_range(lua_State *L, int model, const char *what, double v, double lo, double hi, const char *unit)
{
    if (!(v != 0 && (fabs(v) < lo || fabs(v) > hi))) return;
    sx_lua_warn_once(L, model, what, "%s %g is outside the usual range for DEM, %g ... %g %s (seixo's unit is %s)", what,
                     v, lo, hi, unit, unit);
}
