/* Histories: time series recorded while the model cycles.
 *   m:history(name, source[, {every = N}])   start recording
 *   m:history(name)                           -> {name, every, steps, times, values}
 *   m:histories()                             -> the names, in creation order
 *   m:history_remove(name)
 *   m:history_csv(path[, names])              write step, time and each history as CSV
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
 * times, values}. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bindings.h"

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
enum { BALL_FIRST_SCALAR = 7 };
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

static double sample_builtin(sx_model *m, int b)
{
    switch (b) {
    case B_TIME: return sx_model_time(m);
    case B_STEP: return (double)sx_model_step_count(m);
    case B_TIMESTEP: return sx_model_timestep(m);
    case B_RATIO: return sx_model_unbalanced_ratio(m);
    case B_CONTACTS: return (double)sx_contact_count(m);
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
        const int64_t at = next_multiple(s, (int64_t)lua_tointeger(L, -1));
        if (at < next) next = at;
        lua_pop(L, 2);
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
        sx_model *m = sx_lua_checkmodel(L, model);
        const int64_t s = sx_model_step_count(m);
        lua_getfield(L, e, "every");
        lua_getfield(L, e, "last");
        const bool due = s % lua_tointeger(L, e + 1) == 0 && (lua_isnil(L, e + 2) || lua_tointeger(L, e + 2) != s);
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
            m = sx_lua_checkmodel(L, model);  // the function may have closed it
        } else {
            lua_getfield(L, e, "builtin");
            lua_getfield(L, e, "id");
            lua_getfield(L, e, "field");
            lua_getfield(L, e, "comp");
            if (src == SRC_BUILTIN)
                value = sample_builtin(m, (int)lua_tointeger(L, e + 1));
            else
                value = sample_entity(m, src, (int64_t)lua_tointeger(L, e + 2), (int)lua_tointeger(L, e + 3),
                                      (int)lua_tointeger(L, e + 4));
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

/* Pushes the entry of the named history and returns its position, or 0 (nothing pushed). */
static lua_Integer find_history(lua_State *L, const char *name)
{
    sx_lua_state(L, 1, "histories");
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

/* The record of a history: a copy of its samples. */
static int history_get(lua_State *L, const char *name)
{
    if (!find_history(L, name)) return luaL_argerror(L, 2, lua_pushfstring(L, "no history named '%s'", name));
    const int e = lua_gettop(L);
    lua_createtable(L, 0, 5);
    lua_pushstring(L, name);
    lua_setfield(L, -2, "name");
    lua_getfield(L, e, "every");
    lua_setfield(L, -2, "every");
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
    const sx_model *m = sx_lua_checkmodel(L, 1);
    const char *name = luaL_checkstring(L, 2);
    if (lua_isnoneornil(L, 3)) return history_get(L, name);
    luaL_argcheck(L, *name && !strpbrk(name, ",\"\n\r"), 2, "a name without commas, quotes or newlines expected");
    int64_t every = 1;
    if (!lua_isnoneornil(L, 4)) {
        sx_lua_checkkeys(L, 4, keys);
        sx_lua_optintfield(L, 4, "every", 1, INT64_MAX / 2, &every);
    }
    if (find_history(L, name)) return luaL_argerror(L, 2, lua_pushfstring(L, "a history named '%s' exists", name));
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
    sx_lua_checkmodel(L, 1);
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
    sx_lua_checkmodel(L, 1);
    const char *name = luaL_checkstring(L, 2);
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

/* ----------------------------------------------------------------- CSV */

typedef struct series {
    int entry;       // stack index of the history's entry
    lua_Integer at;  // next sample, 1-based
    lua_Integer n;
} series;

static lua_Integer step_at(lua_State *L, const series *s)
{
    lua_getfield(L, s->entry, "steps");
    lua_rawgeti(L, -1, s->at);
    const lua_Integer v = lua_tointeger(L, -1);
    lua_pop(L, 2);
    return v;
}

static double number_at(lua_State *L, const series *s, const char *array)
{
    lua_getfield(L, s->entry, array);
    lua_rawgeti(L, -1, s->at);
    const double v = lua_tonumber(L, -1);
    lua_pop(L, 2);
    return v;
}

/* m:history_csv(path[, names]): the union of the histories' steps as rows
 * (ascending), a column per history, empty where it has no sample. */
static int model_history_csv(lua_State *L)
{
    sx_lua_checkmodel(L, 1);
    const char *path = luaL_checkstring(L, 2);
    lua_settop(L, 3);
    /* the histories to write: the given names, else all */
    if (lua_isnil(L, 3)) {
        lua_pushcfunction(L, model_histories);
        lua_pushvalue(L, 1);
        lua_call(L, 1, 1);
        lua_replace(L, 3);
    }
    luaL_checktype(L, 3, LUA_TTABLE);
    const lua_Integer nh = (lua_Integer)lua_rawlen(L, 3);
    luaL_argcheck(L, nh > 0, 3, "no history to write");
    luaL_checkstack(L, (int)(nh + 20), "too many histories");
    series *s = lua_newuserdatauv(L, (size_t)nh * sizeof *s, 0);
    const int base = lua_gettop(L);
    for (lua_Integer i = 1; i <= nh; i++) {
        lua_rawgeti(L, 3, i);
        if (lua_type(L, -1) != LUA_TSTRING) return luaL_argerror(L, 3, "history names expected");
        const char *name = lua_tostring(L, -1);
        lua_pop(L, 1);
        if (!find_history(L, name)) return luaL_argerror(L, 3, lua_pushfstring(L, "no history named '%s'", name));
        s[i - 1].entry = lua_gettop(L);
        s[i - 1].at = 1;
        lua_getfield(L, -1, "steps");
        s[i - 1].n = (lua_Integer)lua_rawlen(L, -1);
        lua_pop(L, 1);
    }
    (void)base;
    const char *tmp = lua_pushfstring(L, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) return luaL_error(L, "m:history_csv: cannot write '%s': %s", tmp, strerror(errno));
    fputs("step,time", f);
    for (lua_Integer i = 0; i < nh; i++) {
        lua_getfield(L, s[i].entry, "name");
        fprintf(f, ",%s", lua_tostring(L, -1));
        lua_pop(L, 1);
    }
    fputc('\n', f);
    for (;;) {
        lua_Integer row = LUA_MAXINTEGER;
        double t = 0;
        for (lua_Integer i = 0; i < nh; i++)
            if (s[i].at <= s[i].n) {
                const lua_Integer st = step_at(L, &s[i]);
                if (st < row) {
                    row = st;
                    t = number_at(L, &s[i], "times");
                }
            }
        if (row == LUA_MAXINTEGER) break;
        fprintf(f, "%lld,%.17g", (long long)row, t);
        for (lua_Integer i = 0; i < nh; i++) {
            fputc(',', f);
            if (s[i].at <= s[i].n && step_at(L, &s[i]) == row) {
                fprintf(f, "%.17g", number_at(L, &s[i], "values"));
                s[i].at++;
            }
        }
        fputc('\n', f);
    }
    const bool ok = !ferror(f);
    if (fclose(f) != 0 || !ok) {
        remove(tmp);
        return luaL_error(L, "m:history_csv: writing '%s' failed", tmp);
    }
    if (rename(tmp, path) != 0) {
        const int err = errno;
        remove(tmp);
        return luaL_error(L, "m:history_csv: cannot rename '%s' to '%s': %s", tmp, path, strerror(err));
    }
    return 0;
}

const luaL_Reg sx_lua_history_methods[] = {
    {"history", model_history},
    {"histories", model_histories},
    {"history_remove", model_history_remove},
    {"history_csv", model_history_csv},
    {NULL, NULL},
};
