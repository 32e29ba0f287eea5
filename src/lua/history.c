/* Histories: time series recorded while the model cycles.
 *   m:history(name, source[, {every = N}])   start recording
 *   m:history(name)                           -> {name, every, steps, times, values}
 *   m:histories()                             -> the names, in creation order
 *   m:history_remove(name)
 *   m:history_csv(path[, names])              write step, time and each history as CSV (src/io)
 * A source is a function(m) -> number, a builtin name (time, step,
 * timestep, ratio, contacts, balls, or an energy term: kinetic,
 * gravitational, strain, ...), or a field of one ball or wall:
 * {ball = b, field = "pos", component = "z"}.
 *
 * A history with every = N records after each step s with s % N == 0
 * (run.c calls sx_lua_history_record at every such boundary, after the
 * "after" callbacks), so its samples do not depend on how the cycling was
 * split. The samples live in Lua arrays in the model's state, one entry
 * per history: {name, every, kind, fn | builtin | id, field, comp, steps,
 * times, values, last}.
 *
 * Histories go to files through the I/O layer (sx_io_history): m:save
 * writes them with the model and seixo.load brings them back recording; an
 * output series appends their new samples as it goes. A function cannot be
 * saved: a history of a function comes back "detached", with its samples
 * but recording nothing until m:history(name, fn) gives it a function
 * again. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bindings.h"
#include "seixo_io.h"

enum { SRC_FUNCTION, SRC_BUILTIN, SRC_BALL, SRC_WALL };

static const char *const builtin_names[] = {"time",          "step",       "timestep",    "ratio",
                                            "contacts",      "balls",      "kinetic",     "gravitational",
                                            "strain",        "bond_strain", "slip",       "local_damping",
                                            "viscous",       "boundary_work", "bond_released", NULL};
enum { B_TIME, B_STEP, B_TIMESTEP, B_RATIO, B_CONTACTS, B_BALLS, B_ENERGY0 };

static const char *const ball_fields[] = {"pos",    "vel",    "spin",    "force", "moment", "applied_force",
                                          "applied_moment", "radius", "mass", "inertia", "damping", NULL};
static const int ball_which[] = {SX_BALL_POS, SX_BALL_VEL, SX_BALL_SPIN, SX_BALL_FORCE, SX_BALL_MOMENT,
                                 SX_BALL_APPLIED_FORCE, SX_BALL_APPLIED_MOMENT, SX_BALL_RADIUS, SX_BALL_MASS,
                                 SX_BALL_INERTIA, SX_BALL_DAMPING};
enum { BALL_FIRST_LOAD = 5, BALL_FIRST_SCALAR = 7 }; /* the motion (a step's), the loads, the properties */
static const char *const wall_fields[] = {"force", "moment", "vel", "point", NULL};
static const char *const comp_names[] = {"x", "y", "z", NULL};

/* Components of a field: 1 for a scalar (or a 2D rotational quantity). */
static int field_len(int src, int field, int dim)
{
    if (src == SRC_BALL) {
        if (field >= BALL_FIRST_SCALAR) return 1;
        const int w = ball_which[field];
        const bool rot = w == SX_BALL_SPIN || w == SX_BALL_MOMENT || w == SX_BALL_APPLIED_MOMENT;
        return rot ? sx_lua_rdim(dim) : dim;
    }
    return field == 1 ? sx_lua_rdim(dim) : dim;  // walls: moment is rotational
}

/* ------------------------------------------------------------- sampling */

static double energy_term(sx_model *m, int k)
{
    const sx_energy e = sx_model_energy(m);
    const double terms[] = {e.kinetic, e.gravitational, e.strain, e.bond_strain, e.slip,
                            e.local_damping, e.viscous, e.boundary_work, e.bond_released};
    return terms[k];
}

/* A builtin but the ratio (sx_lua_ratio raises when the ranks cannot sum it). */
static double sample_builtin(sx_model *m, int b)
{
    switch (b) {
    case B_TIME: return sx_model_time(m);
    case B_STEP: return (double)sx_model_step_count(m);
    case B_TIMESTEP: return sx_model_timestep(m);
    case B_CONTACTS: {
        const int64_t n = sx_contact_count(m);
        return n < 0 ? NAN : (double)n; /* (-1: the ranks could not exchange) */
    }
    case B_BALLS: return (double)sx_ball_count(m);
    default: return energy_term(m, b - B_ENERGY0);
    }
}

/* A field component of a ball or wall; NaN once it has been removed. */
static double sample_entity(const sx_model *m, int src, int64_t id, int field, int comp)
{
    double v[3] = {NAN, NAN, NAN}, other[3];
    if (src == SRC_BALL) {
        if (!sx_ball_exists(m, id)) return NAN;
        if (field >= BALL_FIRST_SCALAR) {
            sx_ball_get(m, id, (sx_ball_scalar)ball_which[field], v);
            return v[0];
        }
        sx_ball_get_vec(m, id, (sx_ball_vec)ball_which[field], v);
        return v[comp];
    }
    if (!sx_wall_exists(m, id)) return NAN;
    if (field <= 1) {
        sx_wall_force(m, id, field == 0 ? v : other, field == 0 ? other : v);
        return v[comp];
    }
    sx_wall_def d;
    if (sx_wall_get(m, id, &d) != SX_OK) return NAN;
    return field == 2 ? d.vel[comp] : d.point[comp];
}

static void append(lua_State *L, int entry, const char *array, lua_Number v, bool integer)
{
    lua_getfield(L, entry, array);
    if (integer) lua_pushinteger(L, (lua_Integer)v);
    else lua_pushnumber(L, v);
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
    lua_pop(L, 1);
}

static int64_t next_multiple(int64_t s, int64_t every)
{
    const int64_t q = s / every + 1;
    return q > INT64_MAX / every ? INT64_MAX : q * every;
}

int64_t sx_lua_history_next(lua_State *L, int model, int64_t s)
{
    int64_t next = INT64_MAX;
    sx_lua_state(L, model, "histories");
    for (lua_Integer i = 1; lua_rawgeti(L, -1, i) == LUA_TTABLE; i++) {
        lua_getfield(L, -1, "every");
        lua_getfield(L, -2, "detached");
        const int64_t at = next_multiple(s, (int64_t)lua_tointeger(L, -2));
        if (at < next && !lua_toboolean(L, -1)) next = at;
        lua_pop(L, 3);
    }
    lua_pop(L, 2);
    return next;
}

void sx_lua_history_record(lua_State *L, int model)
{
    model = lua_absindex(L, model);
    sx_lua_state(L, model, "histories");
    const int t = lua_gettop(L);
    for (lua_Integer i = 1; lua_rawgeti(L, t, i) == LUA_TTABLE; i++) {
        const int e = lua_gettop(L);
        sx_model *m = sx_lua_checkmodel_scattered(L, model);
        const int64_t s = sx_model_step_count(m);
        lua_getfield(L, e, "every");
        lua_getfield(L, e, "last");
        lua_getfield(L, e, "detached"); /* a function not given again after a load */
        const bool due = s % lua_tointeger(L, e + 1) == 0 && (lua_isnil(L, e + 2) || lua_tointeger(L, e + 2) != s) &&
                         !lua_toboolean(L, e + 3);
        lua_settop(L, e);
        if (!due) {
            lua_settop(L, t);
            continue;
        }
        lua_getfield(L, e, "kind");
        const int src = (int)lua_tointeger(L, -1);
        lua_pop(L, 1);
        double value;
        if (src == SRC_FUNCTION) {
            lua_getfield(L, e, "fn");
            lua_pushvalue(L, model);
            sx_lua_user_call(L, model, 1, 1);
            if (lua_type(L, -1) != LUA_TNUMBER) {
                lua_getfield(L, e, "name");
                luaL_error(L, "history '%s': the function returned %s, a number expected", lua_tostring(L, -1),
                           luaL_typename(L, -2));
            }
            value = lua_tonumber(L, -1);
            lua_pop(L, 1);
            m = sx_lua_checkmodel_scattered(L, model);  // the function may have closed it
        } else {
            lua_getfield(L, e, "builtin");
            lua_getfield(L, e, "id");
            lua_getfield(L, e, "field");
            lua_getfield(L, e, "comp");
            /* a wall's field, the time, the step and the ball count every rank holds after a lazy cycle;
             * the ratio, the contacts, the timestep and the energies the ranks reduce without a gather */
            const int b = (int)lua_tointeger(L, e + 1);
            if (src == SRC_BUILTIN && b == B_RATIO) {
                value = sx_lua_ratio(L, model, "m:history (ratio)");
            } else {
                if (src == SRC_BUILTIN && (b == B_CONTACTS || b == B_TIMESTEP || b >= B_ENERGY0))
                    sx_lua_checkmodel_summed(L, model,
                                             b == B_CONTACTS   ? "m:history (contacts)"
                                             : b == B_TIMESTEP ? "m:history (timestep)"
                                                               : "m:history (energy)");
                else if (src == SRC_BALL && lua_tointeger(L, e + 3) < BALL_FIRST_LOAD) /* its motion from its rank */
                    sx_lua_fetch_ball(L, m, "m", (int64_t)lua_tointeger(L, e + 2));
                value = src == SRC_BUILTIN ? sample_builtin(m, b)
                                           : sample_entity(m, src, (int64_t)lua_tointeger(L, e + 2),
                                                           (int)lua_tointeger(L, e + 3), (int)lua_tointeger(L, e + 4));
            }
            lua_settop(L, e);
        }
        append(L, e, "steps", (lua_Number)sx_model_step_count(m), true);
        append(L, e, "times", sx_model_time(m), false);
        append(L, e, "values", value, false);
        lua_pushinteger(L, (lua_Integer)sx_model_step_count(m));
        lua_setfield(L, e, "last");
        lua_settop(L, t);
    }
    lua_settop(L, t - 1);
}

/* ------------------------------------------------------------- methods */

/* Pushes the entry of the named history of the model at `model` and
 * returns its position, or 0 (nothing pushed). */
static lua_Integer find_entry(lua_State *L, int model, const char *name)
{
    sx_lua_state(L, model, "histories");
    const int t = lua_gettop(L);
    for (lua_Integer i = 1; lua_rawgeti(L, t, i) == LUA_TTABLE; i++) {
        lua_getfield(L, -1, "name");
        const bool hit = strcmp(lua_tostring(L, -1), name) == 0;
        lua_pop(L, 1);
        if (hit) {
            lua_remove(L, t);
            return i;
        }
        lua_pop(L, 1);
    }
    lua_settop(L, t - 1);
    return 0;
}

static void copy_array(lua_State *L, int from, const char *key)
{
    lua_getfield(L, from, key);
    const lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    lua_createtable(L, (int)n, 0);
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, -2, i);
        lua_rawseti(L, -2, i);
    }
    lua_remove(L, -2);
    lua_setfield(L, -2, key);
}

static lua_Integer find_history(lua_State *L, const char *name) { return find_entry(L, 1, name); }

/* The record of a history: a copy of its samples. */
static int history_get(lua_State *L, const char *name)
{
    if (!find_history(L, name)) return luaL_argerror(L, 2, lua_pushfstring(L, "no history named '%s'", name));
    const int e = lua_gettop(L);
    lua_createtable(L, 0, 6);
    lua_pushstring(L, name);
    lua_setfield(L, -2, "name");
    lua_getfield(L, e, "every");
    lua_setfield(L, -2, "every");
    if (lua_getfield(L, e, "detached") == LUA_TBOOLEAN) lua_setfield(L, -2, "detached");
    else lua_pop(L, 1);
    copy_array(L, e, "steps");
    copy_array(L, e, "times");
    copy_array(L, e, "values");
    return 1;
}

/* Reads an entity source {ball = b, field = ..., component = ...} into the entry on the top. */
static void read_entity(lua_State *L, const sx_model *m, int src)
{
    static const char *const ball_keys[] = {"ball", "field", "component", NULL};
    static const char *const wall_keys[] = {"wall", "field", "component", NULL};
    const int dim = sx_model_dim(m);
    const sx_lua_kind *k = src == SRC_BALL ? &sx_lua_ball_kind : &sx_lua_wall_kind;
    sx_lua_checksubkeys(L, 3, 3, k->name, src == SRC_BALL ? ball_keys : wall_keys);
    lua_getfield(L, 3, k->name);
    int64_t id;
    const char *err = sx_lua_toid(L, -1, 1, k, &id);
    if (err) sx_lua_fielderror(L, 3, k->name, err);
    if (!k->exists(m, id))
        sx_lua_fielderror(L, 3, k->name, lua_pushfstring(L, "an existing %s (or its id) expected", k->name));
    lua_pop(L, 1);
    const char *const *fields = src == SRC_BALL ? ball_fields : wall_fields;
    const char *fname = sx_lua_optstrfield(L, 3, "field");
    const int field = fname ? sx_lua_find(fname, fields) : -1;
    if (field < 0) {
        sx_lua_pushlist(L, fields);
        sx_lua_fielderror(L, 3, "field", lua_pushfstring(L, "one of %s expected", lua_tostring(L, -1)));
    }
    const int n = field_len(src, field, dim);
    int comp = 0;
    lua_getfield(L, 3, "component");
    if (lua_isnil(L, -1)) {
        if (n > 1) sx_lua_fielderror(L, 3, "component", lua_pushfstring(L, "'%s' is a vector: give a component", fname));
    } else {
        if (n == 1) sx_lua_fielderror(L, 3, "component", lua_pushfstring(L, "'%s' is a number here: no component", fname));
        if (lua_type(L, -1) == LUA_TSTRING) comp = sx_lua_find(lua_tostring(L, -1), comp_names);
        else if (lua_isinteger(L, -1) && lua_tointeger(L, -1) >= 1 && lua_tointeger(L, -1) <= 3) comp = (int)lua_tointeger(L, -1) - 1;
        else comp = -1;
        if (comp < 0 || comp >= n)
            sx_lua_fielderror(L, 3, "component", lua_pushfstring(L, "1 to %d (or x, y%s) expected", n, n == 3 ? ", z" : ""));
    }
    lua_pop(L, 1);
    lua_pushinteger(L, (lua_Integer)id);
    lua_setfield(L, -2, "id");
    lua_pushinteger(L, field);
    lua_setfield(L, -2, "field");
    lua_pushinteger(L, comp);
    lua_setfield(L, -2, "comp");
}

/* m:history(name, source[, {every = N}]), or m:history(name) for the record. */
static int model_history(lua_State *L)
{
    static const char *const keys[] = {"every", NULL};
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* the records, and ids every rank holds */
    size_t len;
    const char *name = luaL_checklstring(L, 2, &len);
    if (lua_isnoneornil(L, 3)) return history_get(L, name);
    /* a name is the name of its group in a file (and a CSV column, quoted as needed) */
    luaL_argcheck(L, len > 0 && strlen(name) == len && !strchr(name, '/') && strcmp(name, ".") != 0, 2,
                  "a name without '/' or NUL bytes, not \".\" expected (it names a group in files)");
    if (len > SX_IO_HISTORY_NAME_MAX)
        return luaL_argerror(L, 2, lua_pushfstring(L, "a name of at most %d bytes expected (got %I): files keep no longer one",
                                                   SX_IO_HISTORY_NAME_MAX, (lua_Integer)len));
    int64_t every = 1;
    const bool has_every = !lua_isnoneornil(L, 4);
    if (has_every) {
        sx_lua_checkkeys(L, 4, keys);
        sx_lua_optintfield(L, 4, "every", 1, INT64_MAX / 2, &every);
    }
    if (find_history(L, name)) {
        /* a history of a function loaded from a file takes its function again */
        lua_getfield(L, -1, "detached");
        if (!lua_toboolean(L, -1) || !lua_isfunction(L, 3))
            return luaL_argerror(L, 2, lua_pushfstring(L, "a history named '%s' exists", name));
        lua_pop(L, 1);
        lua_pushvalue(L, 3);
        lua_setfield(L, -2, "fn");
        lua_pushnil(L);
        lua_setfield(L, -2, "detached");
        if (has_every) {
            lua_pushinteger(L, (lua_Integer)every);
            lua_setfield(L, -2, "every");
        }
        return 0;
    }
    lua_settop(L, 3);
    lua_createtable(L, 0, 10);
    lua_pushstring(L, name);
    lua_setfield(L, -2, "name");
    lua_pushinteger(L, (lua_Integer)every);
    lua_setfield(L, -2, "every");
    int src;
    if (lua_isfunction(L, 3)) {
        src = SRC_FUNCTION;
        lua_pushvalue(L, 3);
        lua_setfield(L, -2, "fn");
    } else if (lua_type(L, 3) == LUA_TSTRING) {
        src = SRC_BUILTIN;
        const int b = sx_lua_find(lua_tostring(L, 3), builtin_names);
        if (b < 0) {
            sx_lua_pushlist(L, builtin_names);
            return luaL_argerror(L, 3, lua_pushfstring(L, "unknown builtin '%s' (builtins: %s)", lua_tostring(L, 3),
                                                       lua_tostring(L, -1)));
        }
        lua_pushinteger(L, b);
        lua_setfield(L, -2, "builtin");
    } else if (lua_istable(L, 3)) {
        lua_getfield(L, 3, "ball");
        lua_getfield(L, 3, "wall");
        const bool ball = !lua_isnil(L, -2), wall = !lua_isnil(L, -1);
        lua_pop(L, 2);
        if (ball == wall) return luaL_argerror(L, 3, "a table source names one ball or one wall: {ball = b, field = ...}");
        src = ball ? SRC_BALL : SRC_WALL;
        read_entity(L, m, src);
    } else {
        return luaL_typeerror(L, 3, "function, builtin name or {ball|wall = ..., field = ...}");
    }
    lua_pushinteger(L, src);
    lua_setfield(L, -2, "kind");
    lua_newtable(L);
    lua_setfield(L, -2, "steps");
    lua_newtable(L);
    lua_setfield(L, -2, "times");
    lua_newtable(L);
    lua_setfield(L, -2, "values");
    sx_lua_state(L, 1, "histories");
    lua_pushvalue(L, -2);
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
    return 0;
}

static int model_histories(lua_State *L)
{
    sx_lua_checkmodel_scattered(L, 1);
    sx_lua_state(L, 1, "histories");
    lua_newtable(L);
    for (lua_Integer i = 1; lua_rawgeti(L, -2, i) == LUA_TTABLE; i++) {
        lua_getfield(L, -1, "name");
        lua_rawseti(L, -3, i);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    return 1;
}

static int model_history_remove(lua_State *L)
{
    sx_lua_checkmodel_scattered(L, 1);
    const char *name = sx_lua_checkname(L, 2);
    const lua_Integer at = find_history(L, name);
    if (!at) return luaL_argerror(L, 2, lua_pushfstring(L, "no history named '%s'", name));
    sx_lua_state(L, 1, "histories");
    const lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    for (lua_Integer i = at; i < n; i++) {
        lua_rawgeti(L, -1, i + 1);
        lua_rawseti(L, -2, i);
    }
    lua_pushnil(L);
    lua_rawseti(L, -2, n);
    return 0;
}

/* ------------------------------------------------------ to and from files */

#define SX_LUA_EXPORT "seixo.histories_export"

/* Histories as C arrays for the I/O layer. The names are the Lua strings
 * of the entries (alive while the model's state holds them: no Lua code
 * runs while the I/O layer reads them); the arrays are the userdata's. */
typedef struct exported {
    int n;
    sx_io_history *h;
} exported;

static int exported_free(lua_State *L)
{
    exported *e = luaL_checkudata(L, 1, SX_LUA_EXPORT);
    for (int i = 0; i < e->n; i++) free(e->h[i].steps), free(e->h[i].times), free(e->h[i].values);
    free(e->h);
    e->h = NULL;
    e->n = 0;
    return 0;
}

/* The samples of steps after `after` of the entry at e, into x. */
static void export_entry(lua_State *L, int e, int64_t after, sx_io_history *x)
{
    lua_getfield(L, e, "name");
    x->name = (char *)lua_tostring(L, -1);
    lua_getfield(L, e, "every");
    x->every = (int64_t)lua_tointeger(L, -1);
    lua_getfield(L, e, "kind");
    const int src = (int)lua_tointeger(L, -1);
    lua_pop(L, 3);
    x->source = (sx_io_source)(src + 1); /* SRC_* follow sx_io_source's order */
    if (src == SRC_BUILTIN) {
        lua_getfield(L, e, "builtin");
        x->builtin = (char *)builtin_names[lua_tointeger(L, -1)];
        lua_pop(L, 1);
    } else if (src == SRC_BALL || src == SRC_WALL) {
        lua_getfield(L, e, "id");
        lua_getfield(L, e, "field");
        lua_getfield(L, e, "comp");
        x->id = (int64_t)lua_tointeger(L, -3);
        x->field = (char *)(src == SRC_BALL ? ball_fields : wall_fields)[lua_tointeger(L, -2)];
        x->component = (int)lua_tointeger(L, -1);
        lua_pop(L, 3);
    }
    lua_getfield(L, e, "steps");
    lua_getfield(L, e, "times");
    lua_getfield(L, e, "values");
    const lua_Integer n = (lua_Integer)lua_rawlen(L, -3);
    /* the first sample after `after`, searched from the end (outputs pass only new samples) */
    lua_Integer first = n + 1;
    for (; first > 1; first--) {
        lua_rawgeti(L, -3, first - 1);
        const bool later = (int64_t)lua_tointeger(L, -1) > after;
        lua_pop(L, 1);
        if (!later) break;
    }
    const size_t k = (size_t)(n - first + 1);
    x->steps = malloc((k ? k : 1) * sizeof *x->steps);
    x->times = malloc((k ? k : 1) * sizeof *x->times);
    x->values = malloc((k ? k : 1) * sizeof *x->values);
    if (!x->steps || !x->times || !x->values) luaL_error(L, "out of memory for the samples of history '%s'", x->name);
    for (lua_Integer i = first; i <= n; i++) {
        const size_t j = (size_t)(i - first);
        lua_rawgeti(L, -3, i);
        lua_rawgeti(L, -3, i);
        lua_rawgeti(L, -3, i);
        x->steps[j] = (int64_t)lua_tointeger(L, -3);
        x->times[j] = lua_tonumber(L, -2);
        x->values[j] = lua_tonumber(L, -1);
        lua_pop(L, 3);
    }
    x->n = (int64_t)k;
    lua_pop(L, 3);
}

struct sx_io_history *sx_lua_histories_push(lua_State *L, int model, int names, int passed, int *n)
{
    model = lua_absindex(L, model);
    names = names ? lua_absindex(L, names) : 0;
    passed = passed ? lua_absindex(L, passed) : 0;
    exported *e = lua_newuserdatauv(L, sizeof *e, 0);
    memset(e, 0, sizeof *e);
    if (luaL_newmetatable(L, SX_LUA_EXPORT)) {
        lua_pushcfunction(L, exported_free);
        lua_setfield(L, -2, "__gc");
        lua_pushcfunction(L, exported_free);
        lua_setfield(L, -2, "__close");
    }
    lua_setmetatable(L, -2);
    /* freed when the calling C function returns or raises, never by a
     * finaliser alone: one made while lua_close runs the finalisers (an
     * output left open at the end of a script) would never run */
    lua_toclose(L, -1);
    const int top = lua_gettop(L);
    sx_lua_state(L, model, "histories");
    const lua_Integer count = (lua_Integer)lua_rawlen(L, names ? names : top + 1);
    e->h = calloc((size_t)count + 1, sizeof *e->h);
    if (!e->h) luaL_error(L, "out of memory");
    for (lua_Integer i = 1; i <= count; i++) {
        const char *name = NULL;
        if (names) {
            lua_rawgeti(L, names, i);
            name = lua_tostring(L, -1);
            lua_pop(L, 1); /* the caller's array keeps it */
            if (!name || !find_entry(L, model, name)) luaL_error(L, "no history named '%s'", name ? name : "?");
        } else {
            lua_rawgeti(L, top + 1, i);
        }
        int64_t after = INT64_MIN;
        if (passed) {
            lua_getfield(L, -1, "name");
            if (lua_rawget(L, passed) == LUA_TNUMBER) after = (int64_t)lua_tointeger(L, -1);
            lua_pop(L, 1);
        }
        export_entry(L, lua_gettop(L), after, &e->h[e->n++]);
        lua_pop(L, 1);
    }
    lua_settop(L, top);
    *n = e->n;
    return e->h;
}

/* Raises "'<file>': damaged: history '<name>' <why>". */
static int damaged(lua_State *L, const char *path, const char *name, const char *why)
{
    return luaL_error(L, "'%s': damaged: history '%s' %s", path, name, why);
}

void sx_lua_histories_restore(lua_State *L, int model, const struct sx_io_history *h, int n, const char *path)
{
    model = lua_absindex(L, model);
    const int dim = sx_model_dim(sx_lua_checkmodel(L, model));
    sx_lua_state(L, model, "histories");
    const int t = lua_gettop(L);
    for (int i = 0; i < n; i++) {
        const sx_io_history *x = &h[i];
        lua_createtable(L, 0, 12);
        lua_pushstring(L, x->name);
        lua_setfield(L, -2, "name");
        lua_pushinteger(L, (lua_Integer)x->every);
        lua_setfield(L, -2, "every");
        const int src = (int)x->source - 1;
        lua_pushinteger(L, src);
        lua_setfield(L, -2, "kind");
        if (src == SRC_FUNCTION) {
            lua_pushboolean(L, 1);
            lua_setfield(L, -2, "detached");
        } else if (src == SRC_BUILTIN) {
            const int b = sx_lua_find(x->builtin, builtin_names);
            if (b < 0) damaged(L, path, x->name, lua_pushfstring(L, "has an unknown builtin '%s'", x->builtin));
            lua_pushinteger(L, b);
            lua_setfield(L, -2, "builtin");
        } else {
            const int f = sx_lua_find(x->field, src == SRC_BALL ? ball_fields : wall_fields);
            if (f < 0) damaged(L, path, x->name, lua_pushfstring(L, "has an unknown field '%s'", x->field));
            if (x->component >= field_len(src, f, dim))
                damaged(L, path, x->name, lua_pushfstring(L, "has component %d of '%s'", x->component, x->field));
            lua_pushinteger(L, (lua_Integer)x->id);
            lua_setfield(L, -2, "id");
            lua_pushinteger(L, f);
            lua_setfield(L, -2, "field");
            lua_pushinteger(L, x->component);
            lua_setfield(L, -2, "comp");
        }
        lua_createtable(L, x->n < INT32_MAX ? (int)x->n : 0, 0);
        lua_createtable(L, x->n < INT32_MAX ? (int)x->n : 0, 0);
        lua_createtable(L, x->n < INT32_MAX ? (int)x->n : 0, 0);
        for (int64_t k = 0; k < x->n; k++) {
            lua_pushinteger(L, (lua_Integer)x->steps[k]);
            lua_rawseti(L, -4, (lua_Integer)k + 1);
            lua_pushnumber(L, x->times[k]);
            lua_rawseti(L, -3, (lua_Integer)k + 1);
            lua_pushnumber(L, x->values[k]);
            lua_rawseti(L, -2, (lua_Integer)k + 1);
        }
        lua_setfield(L, -4, "values");
        lua_setfield(L, -3, "times");
        lua_setfield(L, -2, "steps");
        /* the last sample's step: it is not taken twice */
        if (x->n > 0) {
            lua_pushinteger(L, (lua_Integer)x->steps[x->n - 1]);
            lua_setfield(L, -2, "last");
        }
        lua_rawseti(L, t, (lua_Integer)lua_rawlen(L, t) + 1);
    }
    lua_settop(L, t - 1);
}

/* m:history_csv(path[, names]): the union of the histories' steps as rows
 * (ascending), a column per history, empty where it has no sample. */
static int model_history_csv(lua_State *L)
{
    sx_lua_checkmodel(L, 1);
    const char *path = sx_lua_checkname(L, 2);
    lua_settop(L, 3);
    /* the histories to write: the given names, else all */
    const bool all = lua_isnil(L, 3);
    if (all) {
        lua_pushcfunction(L, model_histories);
        lua_pushvalue(L, 1);
        lua_call(L, 1, 1);
        lua_replace(L, 3);
    }
    luaL_checktype(L, 3, LUA_TTABLE);
    const lua_Integer nh = (lua_Integer)lua_rawlen(L, 3);
    if (all && nh == 0) return luaL_error(L, "m:history_csv: the model records no history (add one with m:history)");
    luaL_argcheck(L, nh > 0, 3, "no history to write");
    for (lua_Integer i = 1; i <= nh; i++) {
        lua_rawgeti(L, 3, i);
        if (lua_type(L, -1) != LUA_TSTRING) return luaL_argerror(L, 3, "history names expected");
        if (!find_history(L, lua_tostring(L, -1)))
            return luaL_argerror(L, 3, lua_pushfstring(L, "no history named '%s'", lua_tostring(L, -1)));
        lua_pop(L, 2);
    }
    int n;
    const sx_io_history *h = sx_lua_histories_push(L, 1, 3, 0, &n);
    char err[1024] = "";
    /* decomposed over ranks, as m:save: rank 0 writes, every rank gets its
     * outcome (each rank writing the real path itself passed checks that
     * rank 0 alone can make, such as its open series', and raced for the
     * file on a shared disk) */
    const sx_model *m = sx_lua_tomodel(L, 1);
    const bool shared = sx_model_ranks(m) > 1;
    if (shared) sx_lua_check_model_call(L, m, "m:history_csv");
    /* the ranks above 0 write their copy into a shadow (every rank holds
     * the histories): a script appending to the file or reading it back
     * then finds rank 0's bytes on every rank, whenever rank 0 gets there
     * (the disk's file, copied late, may have rank 0's appends already, or
     * be gone). It stands for the file once rank 0's and every rank's copy
     * are written: a failure is every rank's, the shadows as they were */
    const bool writes = sx_lua_parallel_writes(shared);
    const char *shadow = shared && !writes ? sx_lua_rank_shadow_new(L) : NULL;
    char mine[1024] = "";
    if (writes) sx_history_csv_write(path, h, n, err, sizeof err);
    else if (shadow) sx_history_csv_write(shadow, h, n, mine, sizeof mine);
    else if (shared) snprintf(mine, sizeof mine, "m:history_csv: no copy of '%s' for this rank: %s", path, strerror(errno));
    bool failed = sx_lua_parallel_outcome(shared, err, sizeof err, NULL);
    if (!failed && shared && !sx_lua_parallel_all_read(mine[0] == '\0', mine, sizeof mine))
        failed = true, snprintf(err, sizeof err, "%s", mine);
    if (failed) {
        if (shadow) remove(shadow);
        return luaL_error(L, "%s", err);
    }
    if (shadow) sx_lua_rank_shadow_take(L, path, shadow);
    else sx_lua_rank_file_written(L, path);
    return 0;
}

const luaL_Reg sx_lua_history_methods[] = {
    {"history", model_history},
    {"histories", model_histories},
    {"history_remove", model_history_remove},
    {"history_csv", model_history_csv},
    {NULL, NULL},
};
