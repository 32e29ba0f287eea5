/* seixo.vec: a small vector type with arithmetic. A vector is a plain Lua
 * array {x, y[, z]} with a metatable, so every function that takes {x, y, z}
 * takes it as it is (they read raw array slots), and every vector the API
 * returns (b.pos, b.vel, w.force, ...) is one:
 *   local v = b.vel * m:timestep() + b.pos;  (b.pos - a.pos):norm()
 * Arithmetic: v + w, v - w, -v, v * s, s * v, v / s, v == w; methods
 * dot, cross (2D: the z component, a number), norm, unit, copy; fields x, y, z.
 * A result is a new vector. A vector read from an object's field (b.pos,
 * w.force, ...) is a read-only copy, a "field vector": its components live
 * in an inner plain vector, so that b.pos[1] = 5 reaches __newindex and
 * raises an error saying how to set the field, instead of changing a copy
 * nobody sees. Its copy() and every arithmetic result are plain vectors. */
#include "bindings.h"

#include <math.h>

static const char VEC[] = "seixo.vec";
static const char FIELD_VEC[] = "seixo.fieldvec";
/* keys (their addresses) of a field vector's hidden entries */
static const char INNER = 0, FIELD = 0, WRITABLE = 0;

int sx_lua_vec_array(lua_State *L, int idx)
{
    idx = lua_absindex(L, idx);
    if (lua_istable(L, idx)) {
        if (lua_rawgetp(L, idx, &INNER) == LUA_TTABLE) return lua_gettop(L);
        lua_pop(L, 1);
    }
    lua_pushvalue(L, idx);
    return lua_gettop(L);
}

/* The components of the vector (or array of numbers) at idx, 1 to 4 of them. */
static int read_vec(lua_State *L, int idx, double v[4], const char *op)
{
    if (!lua_istable(L, idx))
        return luaL_error(L, "vector %s: vector or array of numbers expected, got %s", op, luaL_typename(L, idx));
    idx = sx_lua_vec_array(L, idx);
    const int n = (int)lua_rawlen(L, idx);
    if (n < 1 || n > 4) return luaL_error(L, "vector %s: 1 to 4 components expected, got %d", op, n);
    for (int k = 0; k < n; k++) {
        if (lua_rawgeti(L, idx, k + 1) != LUA_TNUMBER)
            return luaL_error(L, "vector %s: component %d is not a number", op, k + 1);
        v[k] = lua_tonumber(L, -1);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    return n;
}

void sx_lua_pushnewvec(lua_State *L, const double *v, int n)
{
    lua_createtable(L, n, 0);
    for (int k = 0; k < n; k++) {
        lua_pushnumber(L, v[k]);
        lua_rawseti(L, -2, k + 1);
    }
    luaL_setmetatable(L, VEC);
}

static int two(lua_State *L, double a[4], double b[4], const char *op)
{
    const int n = read_vec(L, 1, a, op);
    if (read_vec(L, 2, b, op) != n) return luaL_error(L, "vector %s: the two vectors differ in length", op);
    return n;
}

static int vec_add(lua_State *L)
{
    double a[4], b[4];
    const int n = two(L, a, b, "+");
    for (int k = 0; k < n; k++) a[k] += b[k];
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

static int vec_sub(lua_State *L)
{
    double a[4], b[4];
    const int n = two(L, a, b, "-");
    for (int k = 0; k < n; k++) a[k] -= b[k];
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

static int vec_unm(lua_State *L)
{
    double a[4];
    const int n = read_vec(L, 1, a, "-");
    for (int k = 0; k < n; k++) a[k] = -a[k];
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

/* v * s, s * v */
static int vec_mul(lua_State *L)
{
    const int vi = lua_type(L, 1) == LUA_TNUMBER ? 2 : 1;
    if (lua_type(L, 3 - vi) != LUA_TNUMBER)
        return luaL_error(L, "vector *: a vector times a number expected (v:dot(w) for the dot product)");
    double a[4];
    const int n = read_vec(L, vi, a, "*");
    const double s = lua_tonumber(L, 3 - vi);
    for (int k = 0; k < n; k++) a[k] *= s;
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

static int vec_div(lua_State *L)
{
    if (lua_type(L, 2) != LUA_TNUMBER) return luaL_error(L, "vector /: a vector over a number expected");
    double a[4];
    const int n = read_vec(L, 1, a, "/");
    const double s = lua_tonumber(L, 2);
    for (int k = 0; k < n; k++) a[k] /= s;
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

static int vec_eq(lua_State *L)
{
    double a[4], b[4];
    const int n = read_vec(L, 1, a, "=="), m = read_vec(L, 2, b, "==");
    bool eq = n == m;
    for (int k = 0; eq && k < n; k++) eq = a[k] == b[k];
    lua_pushboolean(L, eq);
    return 1;
}

static int vec_tostring(lua_State *L)
{
    lua_settop(L, 1);
    sx_lua_vec_array(L, 1);
    lua_replace(L, 1);
    const int n = (int)lua_rawlen(L, 1);
    lua_pushliteral(L, "{");
    for (int k = 1; k <= n; k++) {
        lua_rawgeti(L, 1, k);
        lua_pushfstring(L, "%s%s", k > 1 ? ", " : "", luaL_tolstring(L, -1, NULL));
        lua_replace(L, -3);
        lua_pop(L, 1);
        lua_concat(L, 2);
    }
    lua_pushliteral(L, "}");
    lua_concat(L, 2);
    return 1;
}

static int vec_dot(lua_State *L)
{
    double a[4], b[4], s = 0;
    const int n = two(L, a, b, "dot");
    for (int k = 0; k < n; k++) s += a[k] * b[k];
    lua_pushnumber(L, s);
    return 1;
}

static int vec_cross(lua_State *L)
{
    double a[4], b[4];
    const int n = two(L, a, b, "cross");
    if (n == 2) {
        lua_pushnumber(L, a[0] * b[1] - a[1] * b[0]);
        return 1;
    }
    if (n != 3) return luaL_error(L, "vector cross: 2 or 3 components expected");
    const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    sx_lua_pushnewvec(L, c, 3);
    return 1;
}

static double norm_of(const double *a, int n)
{
    double s = 0;
    for (int k = 0; k < n; k++) s += a[k] * a[k];
    return sqrt(s);
}

static int vec_norm(lua_State *L)
{
    double a[4];
    const int n = read_vec(L, 1, a, "norm");
    lua_pushnumber(L, norm_of(a, n));
    return 1;
}

static int vec_unit(lua_State *L)
{
    double a[4];
    const int n = read_vec(L, 1, a, "unit");
    const double s = norm_of(a, n);
    if (!(s > 0)) return luaL_error(L, "vector unit: the zero vector has no direction");
    for (int k = 0; k < n; k++) a[k] /= s;
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

static int vec_copy(lua_State *L)
{
    double a[4];
    const int n = read_vec(L, 1, a, "copy");
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

/* v.x, v.y, v.z and the methods */
static int vec_index(lua_State *L)
{
    /* a number past the components: nil, as a plain array's (ipairs stops
     * there), not the field named by its digits */
    if (lua_type(L, 2) == LUA_TNUMBER) return lua_pushnil(L), 1;
    const char *k = lua_tostring(L, 2);
    if (k && k[0] >= 'x' && k[0] <= 'z' && k[1] == 0) {
        lua_rawgeti(L, 1, k[0] - 'x' + 1);
        return 1;
    }
    lua_getfield(L, lua_upvalueindex(1), k ? k : "");
    if (lua_isnil(L, -1) && k) return luaL_error(L, "vector has no field '%s' (x, y, z, dot, cross, norm, unit, copy)", k);
    return 1;
}

/* ------------------------------------------------------- field vectors */

/* b.pos[1], b.pos.x and the methods, from the inner vector */
static int field_index(lua_State *L)
{
    lua_settop(L, 2);
    lua_rawgetp(L, 1, &INNER);
    if (lua_type(L, 2) == LUA_TNUMBER) {
        lua_pushvalue(L, 2);
        lua_rawget(L, -2);
        return 1;
    }
    lua_replace(L, 1);
    return vec_index(L);
}

/* b.pos[1] = 5: an error saying how to set the field */
static int field_newindex(lua_State *L)
{
    lua_rawgetp(L, 1, &FIELD);
    const char *field = lua_tostring(L, -1);
    const char *key = luaL_tolstring(L, 2, NULL);
    lua_rawgetp(L, 1, &WRITABLE);
    if (lua_toboolean(L, -1))
        return luaL_error(L, "%s is a copy of the field: setting its component %s would not change the object; "
                             "assign the whole vector (local v = %s:copy(); v[%s] = ...; %s = v)",
                          field, key, field, key, field);
    return luaL_error(L, "%s is a copy of a read-only field: its component %s cannot be set (local v = %s:copy() "
                         "gives a vector to change)",
                      field, key, field);
}

static int field_len(lua_State *L)
{
    lua_rawgetp(L, 1, &INNER);
    lua_pushinteger(L, (lua_Integer)lua_rawlen(L, -1));
    return 1;
}

static int inner_next(lua_State *L)
{
    lua_settop(L, 2);
    if (lua_next(L, 1)) return 2;
    lua_pushnil(L);
    return 1;
}

/* pairs(b.pos) walks the components */
static int field_pairs(lua_State *L)
{
    lua_pushcfunction(L, inner_next);
    lua_rawgetp(L, 1, &INNER);
    lua_pushnil(L);
    return 3;
}

static bool is_plain_vec(lua_State *L, int idx)
{
    if (!lua_istable(L, idx) || !lua_getmetatable(L, idx)) return false;
    luaL_getmetatable(L, VEC);
    const bool same = lua_rawequal(L, -1, -2);
    lua_pop(L, 2);
    return same;
}

void sx_lua_vec_seal(lua_State *L, const char *kind, const char *key, bool writable)
{
    if (!is_plain_vec(L, -1)) return;
    lua_createtable(L, 0, 3);
    lua_insert(L, -2);
    lua_rawsetp(L, -2, &INNER);
    lua_pushfstring(L, "%s.%s", kind, key);
    lua_rawsetp(L, -2, &FIELD);
    lua_pushboolean(L, writable);
    lua_rawsetp(L, -2, &WRITABLE);
    luaL_setmetatable(L, FIELD_VEC);
}

/* seixo.vec(x, y[, z]) or seixo.vec{x, y[, z]} */
static int seixo_vec(lua_State *L)
{
    double a[4];
    int n;
    if (lua_istable(L, 1)) {
        n = read_vec(L, 1, a, "seixo.vec");
    } else {
        n = lua_gettop(L);
        luaL_argcheck(L, n >= 2 && n <= 3, 1, "2 or 3 numbers, or an array of them, expected");
        for (int k = 0; k < n; k++) a[k] = luaL_checknumber(L, k + 1);
    }
    sx_lua_pushnewvec(L, a, n);
    return 1;
}

void sx_lua_vec_register(lua_State *L)
{
    static const luaL_Reg meta[] = {
        {"__add", vec_add}, {"__sub", vec_sub}, {"__unm", vec_unm}, {"__mul", vec_mul}, {"__div", vec_div},
        {"__eq", vec_eq},   {"__tostring", vec_tostring}, {NULL, NULL},
    };
    static const luaL_Reg methods[] = {
        {"dot", vec_dot}, {"cross", vec_cross}, {"norm", vec_norm}, {"unit", vec_unit}, {"copy", vec_copy}, {NULL, NULL},
    };
    static const luaL_Reg field_meta[] = {
        {"__newindex", field_newindex}, {"__len", field_len}, {"__pairs", field_pairs}, {NULL, NULL},
    };
    luaL_newmetatable(L, VEC);
    luaL_setfuncs(L, meta, 0);
    luaL_newlib(L, methods);
    lua_pushvalue(L, -1);
    lua_setfield(L, -3, "__methods");
    lua_pushvalue(L, -1);
    lua_pushcclosure(L, vec_index, 1);
    lua_setfield(L, -3, "__index");
    /* a field vector: the same arithmetic, read through its inner vector */
    luaL_newmetatable(L, FIELD_VEC);
    luaL_setfuncs(L, meta, 0);
    luaL_setfuncs(L, field_meta, 0);
    lua_pushvalue(L, -2);
    lua_setfield(L, -2, "__methods");
    lua_pushvalue(L, -2);
    lua_pushcclosure(L, field_index, 1);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 3);
    lua_pushcfunction(L, seixo_vec);
    lua_setfield(L, -2, "vec");  // in the module table on the stack top
}
