/* Helpers shared by the binding files: status and argument checks, vectors,
 * property tables, classes with field accessors, handles and iterators.
 *
 * A handle is a userdata holding an object id, with the model userdata as
 * its uservalue: it keeps the model alive, never holds a core pointer, and
 * checks on every use that the model is open and the object still exists.
 *
 * Property tables are read raw (no metamethods), like the unknown-key check,
 * so what is checked is exactly what is used. Field getters and setters are
 * called directly from __index/__newindex rather than through lua_call, so
 * their errors carry the script position of the access. */
#include "bindings.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* The core names its own functions ("ball_set: radius must be ..."), which
 * a script never calls: drop that name, the caller puts the Lua one. */
const char *sx_lua_core_message(const char *msg)
{
    const char *p = msg;
    while ((*p >= 'a' && *p <= 'z') || *p == '_') p++;
    return p > msg && p[0] == ':' && p[1] == ' ' ? p + 2 : msg;
}

void sx_lua_check(lua_State *L, const sx_model *m, sx_status st, const char *what)
{
    if (st == SX_EINTERRUPT) sx_lua_interrupt_answered(); /* the Ctrl-C is answered by this error */
    if (st == SX_OK) return;
    const char *msg = lua_pushfstring(L, "%s: %s", what, sx_lua_core_message(sx_model_error(m)));
    sx_lua_parallel_note_error(msg);
    luaL_error(L, "%s", msg);
}

void sx_lua_checkfield(lua_State *L, const sx_model *m, sx_status st, const char *kind)
{
    if (st != SX_OK)
        luaL_error(L, "%s field '%s': %s", kind, lua_tostring(L, 2), sx_lua_core_message(sx_model_error(m)));
}

int sx_lua_find(const char *s, const char *const list[])
{
    for (int i = 0; list[i]; i++)
        if (strcmp(s, list[i]) == 0) return i;
    return -1;
}

static void add_name(luaL_Buffer *b, int i, const char *name)
{
    if (i > 0) luaL_addstring(b, ", ");
    luaL_addstring(b, name);
}

void sx_lua_pushlist(lua_State *L, const char *const list[])
{
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    for (int i = 0; list[i]; i++) add_name(&b, i, list[i]);
    luaL_pushresult(&b);
}

static void push_names(lua_State *L, const luaL_Reg regs[])
{
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    for (int i = 0; regs && regs[i].name; i++) add_name(&b, i, regs[i].name);
    luaL_pushresult(&b);
}

/* A key as a message shows it: 'name' for strings, the value otherwise. */
static const char *push_key(lua_State *L, int idx)
{
    if (lua_type(L, idx) == LUA_TSTRING) return lua_pushfstring(L, "'%s'", lua_tostring(L, idx));
    return luaL_tolstring(L, idx, NULL);
}

/* The first key of the table at idx that is not in keys, pushed as a
 * message; NULL when every key is valid. */
static const char *bad_key(lua_State *L, int idx, const char *const keys[])
{
    idx = lua_absindex(L, idx);
    lua_pushnil(L);
    while (lua_next(L, idx)) {
        lua_pop(L, 1);
        if (lua_type(L, -1) == LUA_TSTRING && sx_lua_find(lua_tostring(L, -1), keys) >= 0) continue;
        const char *key = push_key(L, -1);
        sx_lua_pushlist(L, keys);
        return lua_pushfstring(L, "unknown key %s (valid keys: %s)", key, lua_tostring(L, -1));
    }
    return NULL;
}

void sx_lua_checkkeys(lua_State *L, int arg, const char *const keys[])
{
    luaL_checktype(L, arg, LUA_TTABLE);
    const char *msg = bad_key(L, arg, keys);
    if (msg) luaL_argerror(L, arg, msg);
}

void sx_lua_checksubkeys(lua_State *L, int idx, int arg, const char *field, const char *const keys[])
{
    if (!lua_istable(L, idx))
        sx_lua_fielderror(L, arg, field, lua_pushfstring(L, "table expected, got %s", luaL_typename(L, idx)));
    const char *msg = bad_key(L, idx, keys);
    if (msg) sx_lua_fielderror(L, arg, field, msg);
}

/* ------------------------------------------------------------- vectors */

/* The message on the stack top, with the array under it removed. */
static const char *popped_error(lua_State *L, const char *msg)
{
    lua_remove(L, -2);
    return msg;
}

const char *sx_lua_tovec(lua_State *L, int idx, int n, double *out)
{
    idx = lua_absindex(L, idx);
    if (n == 1) {
        if (lua_type(L, idx) != LUA_TNUMBER)
            return lua_pushfstring(L, "number expected, got %s", luaL_typename(L, idx));
        out[0] = lua_tonumber(L, idx);
        return NULL;
    }
    if (!lua_istable(L, idx))
        return lua_pushfstring(L, "array of %d numbers expected, got %s", n, luaL_typename(L, idx));
    idx = sx_lua_vec_array(L, idx); /* a field vector's components; popped before returning */
    const lua_Unsigned len = lua_rawlen(L, idx);
    if (len != (lua_Unsigned)n && n <= 3)
        return popped_error(L, lua_pushfstring(L, "%d components expected in a %dD model, got %I", n, n, (lua_Integer)len));
    if (len != (lua_Unsigned)n) /* a quaternion, a pebble {x, y, z, r} */
        return popped_error(L, lua_pushfstring(L, "%d components expected, got %I", n, (lua_Integer)len));
    double v[4];
    for (int k = 0; k < n; k++) {
        const int t = lua_rawgeti(L, idx, k + 1);
        v[k] = lua_tonumber(L, -1);
        lua_pop(L, 1);
        if (t != LUA_TNUMBER)
            return popped_error(L, lua_pushfstring(L, "component %d: number expected, got %s", k + 1, lua_typename(L, t)));
    }
    memcpy(out, v, (size_t)n * sizeof *v);
    lua_pop(L, 1);
    return NULL;
}

void sx_lua_pushvec(lua_State *L, const double *v, int n)
{
    if (n == 1)
        lua_pushnumber(L, v[0]);
    else
        sx_lua_pushnewvec(L, v, n);
}

void sx_lua_checkvalue(lua_State *L, int idx, int n, double *out, const char *kind, const char *field)
{
    const char *err = sx_lua_tovec(L, idx, n, out);
    if (err) luaL_error(L, "%s field '%s': %s", kind, field, err);
}

void sx_lua_setnum(lua_State *L, const char *k, double v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, k);
}

/* ----------------------------------------------------- property tables */

static int rawfield(lua_State *L, int arg, const char *key)
{
    lua_pushstring(L, key);
    return lua_rawget(L, arg);
}

int sx_lua_fielderror(lua_State *L, int arg, const char *key, const char *msg)
{
    return luaL_argerror(L, arg, lua_pushfstring(L, "field '%s': %s", key, msg));
}

static int field_error(lua_State *L, int arg, const char *key, const char *msg)
{
    return sx_lua_fielderror(L, arg, key, msg);
}

static int field_missing(lua_State *L, int arg, const char *key)
{
    return luaL_argerror(L, arg, lua_pushfstring(L, "field '%s' is required", key));
}

bool sx_lua_optvecfield(lua_State *L, int arg, const char *key, int n, double *out)
{
    if (rawfield(L, arg, key) == LUA_TNIL) {
        lua_pop(L, 1);
        return false;
    }
    const char *err = sx_lua_tovec(L, -1, n, out);
    if (err) field_error(L, arg, key, err);
    lua_pop(L, 1);
    return true;
}

void sx_lua_checkvecfield(lua_State *L, int arg, const char *key, int n, double *out)
{
    if (!sx_lua_optvecfield(L, arg, key, n, out)) field_missing(L, arg, key);
}

bool sx_lua_optnumfield(lua_State *L, int arg, const char *key, double *out)
{
    return sx_lua_optvecfield(L, arg, key, 1, out);
}

double sx_lua_checknumfield(lua_State *L, int arg, const char *key)
{
    double v = 0;
    sx_lua_checkvecfield(L, arg, key, 1, &v);
    return v;
}

bool sx_lua_optintfield(lua_State *L, int arg, const char *key, int64_t lo, int64_t hi, int64_t *out)
{
    double v = 0;
    if (!sx_lua_optnumfield(L, arg, key, &v)) return false;
    /* the bounds are checked on the double, so no conversion overflows */
    if (!(v >= (double)lo && v <= (double)hi) || v != floor(v))
        field_error(L, arg, key,
                    lua_pushfstring(L, "integer in [%I, %I] expected, got %f", (lua_Integer)lo, (lua_Integer)hi, v));
    *out = (int64_t)v;
    if (*out < lo) *out = lo;  // hi rounded up to a double may admit hi + 1
    if (*out > hi) *out = hi;
    return true;
}

bool sx_lua_optrangefield(lua_State *L, int arg, const char *key, double lo, double hi, double *out)
{
    double v = 0;
    if (!sx_lua_optnumfield(L, arg, key, &v)) return false;
    if (!(v >= lo && v <= hi)) field_error(L, arg, key, lua_pushfstring(L, "number in [%f, %f] expected, got %f", lo, hi, v));
    *out = v;
    return true;
}

#define NUL_IN_NAME "a name or path with a zero byte ('\\0') in it: C would cut it there"

const char *sx_lua_optstrfield(lua_State *L, int arg, const char *key)
{
    const int t = rawfield(L, arg, key);
    if (t != LUA_TNIL && t != LUA_TSTRING)
        field_error(L, arg, key, lua_pushfstring(L, "string expected, got %s", lua_typename(L, t)));
    size_t len = 0;
    const char *s = lua_tolstring(L, -1, &len);
    if (s && strlen(s) != len) field_error(L, arg, key, NUL_IN_NAME);
    lua_pop(L, 1);
    return s;
}

int sx_lua_optchoicefield(lua_State *L, int arg, const char *key, const char *const names[], int dflt)
{
    const char *s = sx_lua_optstrfield(L, arg, key);
    if (!s) return dflt;
    const int i = sx_lua_find(s, names);
    if (i < 0) {
        sx_lua_pushlist(L, names);
        field_error(L, arg, key, lua_pushfstring(L, "unknown '%s' (valid: %s)", s, lua_tostring(L, -1)));
    }
    return i;
}

/* A name or path reaches C as a C string, cut at a zero byte: "sand\0wet"
 * and "sand\0dry" were one material, "x.h5\0junk" the file x.h5. */
const char *sx_lua_checkname(lua_State *L, int arg)
{
    size_t len;
    const char *s = luaL_checklstring(L, arg, &len);
    if (strlen(s) != len) luaL_argerror(L, arg, NUL_IN_NAME);
    return s;
}

/* ------------------------------------------------------------- classes */

/* The edit distance of a and b: insertions, deletions, substitutions and
 * swaps of two neighbours (the commonest typo: slove for solve), over the
 * first 32 characters, enough to tell a typo from another name. */
static int edit_distance(const char *a, const char *b)
{
    enum { N = 32 };
    int d[N + 1][N + 1];
    const int la = (int)strnlen(a, N), lb = (int)strnlen(b, N);
    for (int i = 0; i <= la; i++) d[i][0] = i;
    for (int j = 0; j <= lb; j++) d[0][j] = j;
    for (int i = 1; i <= la; i++)
        for (int j = 1; j <= lb; j++) {
            int v = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
            if (d[i - 1][j] + 1 < v) v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v) v = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[la][lb];
}

/* The string key of the tables at upvalues 1 and 2 closest to `key`, or
 * NULL when none is near enough to be a typo of it (at most a third of its
 * letters wrong, at least one allowed). */
static const char *nearest_name(lua_State *L, const char *key)
{
    const char *best = NULL;
    int best_d = (int)strlen(key) / 3 > 1 ? (int)strlen(key) / 3 : 1;
    for (int u = 1; u <= 2; u++) {
        lua_pushnil(L);
        while (lua_next(L, lua_upvalueindex(u))) {
            lua_pop(L, 1);
            const char *name = lua_tostring(L, -1);
            const int d = edit_distance(key, name);
            if (d < best_d || (d == best_d && !best)) {
                best = name;  // kept alive by the class's table
                best_d = d;
            }
        }
    }
    return best;
}

static int no_field(lua_State *L, const char *what)
{
    const char *kind = lua_tostring(L, lua_upvalueindex(3));
    const char *names = lua_tostring(L, lua_upvalueindex(4));
    const char *near = lua_type(L, 2) == LUA_TSTRING ? nearest_name(L, lua_tostring(L, 2)) : NULL;
    const char *key = push_key(L, 2);
    const char *hint = near ? lua_pushfstring(L, " (did you mean '%s'?)", near) : "";
    if (!*names) return luaL_error(L, "%s has no %s %s%s; help(\"%s\") lists what it has", kind, what, key, hint, kind);
    return luaL_error(L, "%s has no %s %s%s (%ss: %s)", kind, what, key, hint, what, names);
}

/* upvalues: methods, getters, kind, the readable field names, setters.
 * A vector field is returned sealed: b.pos[1] = 5 is an error, not a
 * change to a copy. */
static int object_index(lua_State *L)
{
    lua_settop(L, 2);
    lua_pushvalue(L, 2);
    if (lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL) return 1;
    lua_pushvalue(L, 2);
    lua_rawget(L, lua_upvalueindex(2));
    const lua_CFunction get = lua_tocfunction(L, -1);
    lua_settop(L, 2);
    if (!get) return no_field(L, "field");
    const int results = get(L);
    if (results != 1) return results;
    lua_pushvalue(L, 2);
    const bool writable = lua_rawget(L, lua_upvalueindex(5)) != LUA_TNIL;
    lua_pop(L, 1);
    sx_lua_vec_seal(L, lua_tostring(L, lua_upvalueindex(3)), lua_tostring(L, 2), writable);
    return 1;
}

/* upvalues: setters, getters, kind, the writable field names */
static int object_newindex(lua_State *L)
{
    lua_settop(L, 3);
    lua_pushvalue(L, 2);
    lua_rawget(L, lua_upvalueindex(1));
    const lua_CFunction set = lua_tocfunction(L, -1);
    lua_settop(L, 3);
    if (set) return set(L);
    lua_pushvalue(L, 2);
    if (lua_rawget(L, lua_upvalueindex(2)) != LUA_TNIL)
        return luaL_error(L, "%s field %s is read-only", lua_tostring(L, lua_upvalueindex(3)), push_key(L, 2));
    return no_field(L, "writable field");
}

static void push_regs(lua_State *L, const luaL_Reg regs[])
{
    lua_newtable(L);
    if (regs) luaL_setfuncs(L, regs, 0);
}

void sx_lua_newclass(lua_State *L, const char *tname, const char *kind, const luaL_Reg meta[],
                     const luaL_Reg methods[], const luaL_Reg getters[], const luaL_Reg setters[])
{
    luaL_newmetatable(L, tname);
    const int mt = lua_gettop(L);
    luaL_setfuncs(L, meta, 0);
    push_regs(L, methods);
    const int methods_at = lua_gettop(L);
    push_regs(L, getters);
    const int getters_at = lua_gettop(L);

    lua_pushvalue(L, methods_at);
    lua_pushvalue(L, getters_at);
    lua_pushstring(L, kind);
    push_names(L, getters);
    push_regs(L, setters);
    lua_pushcclosure(L, object_index, 5);
    lua_setfield(L, mt, "__index");

    push_regs(L, setters);
    lua_pushvalue(L, getters_at);
    lua_pushstring(L, kind);
    push_names(L, setters);
    lua_pushcclosure(L, object_newindex, 4);
    lua_setfield(L, mt, "__newindex");

    /* the class's names, for completion and help() */
    lua_pushvalue(L, methods_at);
    lua_setfield(L, mt, "__methods");
    lua_pushvalue(L, getters_at);
    lua_setfield(L, mt, "__getters");
    push_regs(L, setters);
    lua_setfield(L, mt, "__setters");

    lua_settop(L, methods_at);
    lua_remove(L, mt);
}

/* ------------------------------------------------------------- handles */

typedef struct handle {
    int64_t id;
} handle;

void sx_lua_pushhandle(lua_State *L, int model, const sx_lua_kind *k, int64_t id)
{
    model = lua_absindex(L, model);
    handle *h = lua_newuserdatauv(L, sizeof *h, 1);
    h->id = id;
    luaL_setmetatable(L, k->tname);
    lua_pushvalue(L, model);
    lua_setiuservalue(L, -2, 1);
}

/* The id of the handle at idx and its model, NULL if the model is closed. */
static sx_model *tohandle(lua_State *L, int idx, const sx_lua_kind *k, int64_t *id)
{
    idx = lua_absindex(L, idx);
    const handle *h = luaL_checkudata(L, idx, k->tname);
    *id = h->id;
    lua_getiuservalue(L, idx, 1);
    sx_model *m = sx_lua_tomodel(L, -1);
    lua_pop(L, 1);
    return m;
}

sx_model *sx_lua_checkhandle_whole(lua_State *L, int idx, const sx_lua_kind *k, int64_t *id)
{
    sx_model *m = tohandle(L, idx, k, id);
    if (!m) luaL_error(L, "the model has been closed");
    if (!k->exists(m, *id)) luaL_error(L, "%s %I has been removed", k->name, (lua_Integer)*id);
    return m;
}

sx_model *sx_lua_checkhandle(lua_State *L, int idx, const sx_lua_kind *k, int64_t *id)
{
    sx_model *m = sx_lua_checkhandle_whole(L, idx, k, id); /* the ids every rank holds alike */
    if (!k->replicated) {
        const char self[2] = {k->name[0], 0}; /* b.pos, b:remove: as the manual writes a ball's calls */
        sx_lua_gather(L, m, self);
    }
    return m;
}

/* Pushes a shown value as text: numbers in %.6g, arrays of numbers as {a, b, c}. */
static void push_shown(lua_State *L, int v)
{
    char num[40];
    if (lua_type(L, v) == LUA_TNUMBER && !lua_isinteger(L, v)) {
        snprintf(num, sizeof num, "%.6g", lua_tonumber(L, v));
        lua_pushstring(L, num);
    } else if (lua_type(L, v) == LUA_TTABLE) {
        lua_pushliteral(L, "{");
        lua_Integer i = 1;
        for (; lua_rawgeti(L, v, i) == LUA_TNUMBER; i++) {
            snprintf(num, sizeof num, "%s%.6g", i > 1 ? ", " : "", lua_tonumber(L, -1));
            lua_pop(L, 1);
            lua_pushstring(L, num);
        }
        lua_pop(L, 1);
        lua_pushliteral(L, "}");
        lua_concat(L, (int)i + 1);
    } else {
        luaL_tolstring(L, v, NULL);
    }
}

/* A live object shows the kind's fields, read through the class's own
 * getters (what b.pos gives, formatted): "seixo.ball 7 {pos = {...}, ...}". */
int sx_lua_handle_tostring(lua_State *L, const sx_lua_kind *k)
{
    int64_t id;
    lua_settop(L, 1);
    const sx_model *m = tohandle(L, 1, k, &id);
    if (!m || !k->exists(m, id)) {
        lua_pushfstring(L, "%s %I%s", k->tname, (lua_Integer)id, m ? " (removed)" : " (model closed)");
        return 1;
    }
    luaL_getmetafield(L, 1, "__getters");  // index 2
    lua_pushfstring(L, "%s %I {", k->tname, (lua_Integer)id);  // index 3, the text so far
    int shown = 0;
    for (int i = 0; k->shown && k->shown[i]; i++) {
        lua_getfield(L, 2, k->shown[i]);
        const lua_CFunction get = lua_tocfunction(L, -1);
        lua_pop(L, 1);
        if (!get) continue;
        lua_pushcfunction(L, get);
        lua_pushvalue(L, 1);
        lua_pushstring(L, k->shown[i]);
        lua_call(L, 2, 1);
        if (!lua_isnil(L, 4)) {
            lua_pushfstring(L, "%s%s = ", shown++ ? ", " : "", k->shown[i]);
            push_shown(L, 4);
            lua_remove(L, 4);
            lua_concat(L, 3);
        } else {
            lua_pop(L, 1);
        }
    }
    lua_pushliteral(L, "}");
    lua_concat(L, 2);
    return 1;
}

int sx_lua_handle_eq(lua_State *L)
{
    bool eq = lua_getmetatable(L, 1) && lua_getmetatable(L, 2) && lua_rawequal(L, -1, -2);
    lua_settop(L, 2);
    if (eq) {
        lua_getiuservalue(L, 1, 1);
        lua_getiuservalue(L, 2, 1);
        eq = lua_rawequal(L, -1, -2) &&
             ((const handle *)lua_touserdata(L, 1))->id == ((const handle *)lua_touserdata(L, 2))->id;
    }
    lua_pushboolean(L, eq);
    return 1;
}

const char *sx_lua_toid(lua_State *L, int idx, int model, const sx_lua_kind *k, int64_t *id)
{
    idx = lua_absindex(L, idx);
    model = lua_absindex(L, model);
    if (lua_isinteger(L, idx)) {
        *id = (int64_t)lua_tointeger(L, idx);
        return *id >= 1 ? NULL : lua_pushfstring(L, "%s ids are >= 1, got %I", k->name, (lua_Integer)*id);
    }
    const handle *h = luaL_testudata(L, idx, k->tname);
    if (!h) return lua_pushfstring(L, "%s or id expected, got %s", k->name, luaL_typename(L, idx));
    /* an id means nothing in another model: never read one as a plain id */
    lua_getiuservalue(L, idx, 1);
    const bool mine = lua_rawequal(L, -1, model);
    lua_pop(L, 1);
    if (!mine) return lua_pushfstring(L, "%s %I belongs to another model", k->name, (lua_Integer)h->id);
    *id = h->id;
    return NULL;
}

/* -------------------------------------------------------------- extras */

/* Pushes the extras table of the handle at index 1 (k->extras of the
 * model's state, keyed by id), created when `create`, else nil when none. */
static void push_extras(lua_State *L, const sx_lua_kind *k, bool create)
{
    int64_t id;
    sx_lua_checkhandle(L, 1, k, &id);
    lua_getiuservalue(L, 1, 1);
    sx_lua_state(L, -1, k->extras);
    lua_remove(L, -2);
    if (lua_rawgeti(L, -1, (lua_Integer)id) == LUA_TNIL && create) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_pushvalue(L, -1);
        lua_rawseti(L, -3, (lua_Integer)id);
    }
    lua_remove(L, -2);
}

int sx_lua_extra_table(lua_State *L, const sx_lua_kind *k)
{
    push_extras(L, k, true);
    return 1;
}

int sx_lua_set_extra_table(lua_State *L, const sx_lua_kind *k)
{
    int64_t id;
    sx_lua_checkhandle(L, 1, k, &id);
    if (!lua_isnil(L, 3) && !lua_istable(L, 3))
        return luaL_error(L, "%s field 'extra': table or nil expected, got %s", k->name, luaL_typename(L, 3));
    lua_getiuservalue(L, 1, 1);
    sx_lua_state(L, -1, k->extras);
    lua_pushvalue(L, 3);
    lua_rawseti(L, -2, (lua_Integer)id);
    return 0;
}

int sx_lua_set_extra(lua_State *L, const sx_lua_kind *k)
{
    luaL_checkany(L, 2);
    if (lua_isnil(L, 2) || (lua_type(L, 2) == LUA_TNUMBER && lua_tonumber(L, 2) != lua_tonumber(L, 2)))
        return luaL_argerror(L, 1, "a key other than nil and NaN expected");
    luaL_checkany(L, 3);
    push_extras(L, k, true);
    lua_pushvalue(L, 2);
    lua_pushvalue(L, 3);
    lua_rawset(L, -3);
    return 0;
}

int sx_lua_get_extra(lua_State *L, const sx_lua_kind *k)
{
    luaL_checkany(L, 2);
    lua_settop(L, 3);  // the default, nil when absent
    push_extras(L, k, false);
    if (lua_istable(L, -1)) {
        lua_pushvalue(L, 2);
        lua_rawget(L, -2);
    } else {
        lua_pushnil(L);
    }
    if (lua_isnil(L, -1)) lua_pushvalue(L, 3);
    return 1;
}

void sx_lua_forget_extras(lua_State *L, int model, const sx_lua_kind *k, int64_t id)
{
    sx_lua_state(L, model, k->extras);
    lua_pushnil(L);
    lua_rawseti(L, -2, (lua_Integer)id);
    lua_pop(L, 1);
}

/* ----------------------------------------------------------- iterators */

/* The closure's upvalues: the model userdata, the table of ids, the
 * position reached in it. */
void sx_lua_pushiterator_ids(lua_State *L, int model, int ids, lua_CFunction next)
{
    model = lua_absindex(L, model);
    ids = lua_absindex(L, ids);
    lua_pushvalue(L, model);
    lua_pushvalue(L, ids);
    lua_pushinteger(L, 0);
    lua_pushcclosure(L, next, 3);
}

void sx_lua_pushiterator(lua_State *L, int model, int64_t (*count)(const sx_model *),
                         int64_t (*id_at)(const sx_model *, int64_t), lua_CFunction next)
{
    model = lua_absindex(L, model);
    const sx_model *m = sx_lua_checkmodel_scattered(L, model); /* the ids every rank holds (a handle's reads exchange) */
    const int64_t n = count(m);
    lua_createtable(L, n < INT_MAX ? (int)n : INT_MAX, 0);
    for (int64_t i = 0; i < n; i++) {
        lua_pushinteger(L, (lua_Integer)id_at(m, i));
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    sx_lua_pushiterator_ids(L, model, -1, next);
    lua_remove(L, -2);
}

int sx_lua_nexthandle(lua_State *L, const sx_lua_kind *k)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, lua_upvalueindex(1));
    lua_Integer i = lua_tointeger(L, lua_upvalueindex(3));
    while (lua_rawgeti(L, lua_upvalueindex(2), ++i) == LUA_TNUMBER) {
        const int64_t id = (int64_t)lua_tointeger(L, -1);
        lua_pop(L, 1);
        if (!k->exists(m, id)) continue;  // removed since the snapshot
        lua_pushinteger(L, i);
        lua_replace(L, lua_upvalueindex(3));
        sx_lua_pushhandle(L, lua_upvalueindex(1), k, id);
        return 1;
    }
    return 1;  // the nil that ended the snapshot
}

void sx_lua_wrap(lua_State *L, const char *lib, const char *name, lua_CFunction fn, int extra)
{
    if (lua_getglobal(L, lib) != LUA_TTABLE) { /* a state without that library */
        lua_pop(L, 1 + extra);
        return;
    }
    if (lua_getfield(L, -1, name) != LUA_TFUNCTION) {
        lua_pop(L, 2 + extra);
        return;
    }
    lua_insert(L, -2 - extra); /* own, extras..., table */
    lua_insert(L, -2 - extra); /* table, own, extras... */
    lua_pushcclosure(L, fn, 1 + extra);
    lua_setfield(L, -2, name);
    lua_pop(L, 1);
}
