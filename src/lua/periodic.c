/* Periodic space and its cell (sx_model_set_periodic, sx_cell_*):
 *   m:periodic{min =, max =, axes = "xyz", tilt = {xy =, xz =, yz =}}
 *   m:periodic(false)           back to open space
 *   m:periodic()                the cell now: {min, max, size, axes, tilt}, or nil
 *   m:cell_control{xx = {rate = r} | {stress = s}, ..., alpha =, max_rate =}
 *   m:cell_control()            the control now, in the same form
 *   m:cell_stress()             the cell's average stress (dim x dim) and volume */
#include "bindings.h"

#include <string.h>

static const char *const components[] = {"xx", "yy", "zz", "xy", "xz", "yz", NULL};

static int model_periodic(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, 1);
    const int dim = sx_model_dim(m);
    sx_periodic_def d;
    if (!lua_isnone(L, 2)) sx_lua_gather(L, m, "m"); /* a change; the query reads the cell every rank holds */
    if (lua_isnone(L, 2)) { /* the query */
        if (!sx_model_periodic(m, &d)) {
            lua_pushnil(L);
            return 1;
        }
        double hi[3], axes = 0;
        char names[4] = {0};
        for (int k = 0; k < dim; k++) {
            hi[k] = d.lo[k] + d.len[k];
            if (d.axis[k]) names[(int)axes++] = "xyz"[k];
        }
        lua_createtable(L, 0, 5);
        sx_lua_pushvec(L, d.lo, dim);
        lua_setfield(L, -2, "min");
        sx_lua_pushvec(L, hi, dim);
        lua_setfield(L, -2, "max");
        sx_lua_pushvec(L, d.len, dim);
        lua_setfield(L, -2, "size");
        lua_pushstring(L, names);
        lua_setfield(L, -2, "axes");
        lua_createtable(L, 0, 3);
        for (int c = 0; c < (dim == 3 ? 3 : 1); c++) {
            lua_pushnumber(L, d.tilt[c]);
            lua_setfield(L, -2, components[SX_CELL_XY + c]);
        }
        lua_setfield(L, -2, "tilt");
        return 1;
    }
    memset(&d, 0, sizeof d);
    if (lua_isboolean(L, 2) && !lua_toboolean(L, 2)) {
        sx_lua_check(L, m, sx_model_set_periodic(m, &d), "m:periodic");
        return 0;
    }
    static const char *const keys[] = {"min", "max", "axes", "tilt", NULL};
    sx_lua_checkkeys(L, 2, keys);
    double hi[3] = {0, 0, 0};
    sx_lua_checkvecfield(L, 2, "min", dim, d.lo);
    sx_lua_checkvecfield(L, 2, "max", dim, hi);
    const char *axes = sx_lua_optstrfield(L, 2, "axes");
    if (!axes) axes = dim == 3 ? "xyz" : "xy";
    for (const char *a = axes; *a; a++) {
        const char *at = strchr("xyz", *a);
        if (!at || at - "xyz" >= dim)
            sx_lua_fielderror(L, 2, "axes", lua_pushfstring(L, "letters of '%s' expected, got '%s'",
                                                            dim == 3 ? "xyz" : "xy", axes));
        d.axis[at - "xyz"] = true;
    }
    for (int k = 0; k < dim; k++) d.len[k] = hi[k] - d.lo[k];
    if (lua_getfield(L, 2, "tilt") != LUA_TNIL) {
        static const char *const tilts[] = {"xy", "xz", "yz", NULL};
        sx_lua_checksubkeys(L, -1, 2, "tilt", tilts);
        for (int c = 0; c < 3; c++) {
            lua_getfield(L, -1, tilts[c]);
            if (!lua_isnil(L, -1)) {
                if (!lua_isnumber(L, -1)) sx_lua_fielderror(L, 2, "tilt", "numbers expected");
                d.tilt[c] = lua_tonumber(L, -1);
            }
            lua_pop(L, 1);
        }
    }
    lua_pop(L, 1);
    sx_lua_check(L, m, sx_model_set_periodic(m, &d), "m:periodic");
    return 0;
}

static int model_cell_control(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    const int dim = sx_model_dim(m);
    sx_cell_control c;
    if (lua_isnone(L, 2)) {
        sx_cell_control_get(m, &c);
        lua_createtable(L, 0, 8);
        for (int k = 0; k < SX_CELL_COMPONENTS; k++) {
            if (c.mode[k] == SX_CELL_FIXED) continue;
            lua_createtable(L, 0, 1);
            lua_pushnumber(L, c.mode[k] == SX_CELL_RATE ? c.rate[k] : c.target[k]);
            lua_setfield(L, -2, c.mode[k] == SX_CELL_RATE ? "rate" : "stress");
            lua_setfield(L, -2, components[k]);
        }
        lua_pushnumber(L, c.alpha);
        lua_setfield(L, -2, "alpha");
        lua_pushnumber(L, c.max_rate);
        lua_setfield(L, -2, "max_rate");
        return 1;
    }
    static const char *const keys[] = {"xx", "yy", "zz", "xy", "xz", "yz", "alpha", "max_rate", NULL};
    sx_lua_checkkeys(L, 2, keys);
    c = sx_cell_default_control();
    sx_lua_optnumfield(L, 2, "alpha", &c.alpha);
    sx_lua_optnumfield(L, 2, "max_rate", &c.max_rate);
    for (int k = 0; k < SX_CELL_COMPONENTS; k++) {
        if (lua_getfield(L, 2, components[k]) == LUA_TNIL) {
            lua_pop(L, 1);
            continue;
        }
        if (dim == 2 && (k == SX_CELL_ZZ || k == SX_CELL_XZ || k == SX_CELL_YZ))
            sx_lua_fielderror(L, 2, components[k], "a 2D cell has xx, yy and xy only");
        static const char *const sub[] = {"rate", "stress", NULL};
        sx_lua_checksubkeys(L, -1, 2, components[k], sub);
        const int top = lua_gettop(L);
        const bool rate = lua_getfield(L, top, "rate") != LUA_TNIL, stress = lua_getfield(L, top, "stress") != LUA_TNIL;
        if (rate == stress) sx_lua_fielderror(L, 2, components[k], "give either rate (1/s) or stress (Pa)");
        if (!lua_isnumber(L, rate ? -2 : -1)) sx_lua_fielderror(L, 2, components[k], "a number expected");
        c.mode[k] = rate ? SX_CELL_RATE : SX_CELL_STRESS;
        if (rate) c.rate[k] = lua_tonumber(L, -2);
        else c.target[k] = lua_tonumber(L, -1);
        lua_settop(L, top - 1);
    }
    sx_lua_check(L, m, sx_cell_set_control(m, &c), "m:cell_control");
    return 0;
}

static int model_cell_stress(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_summed(L, 1, "m:cell_stress");
    double s[3][3], volume;
    sx_lua_check(L, m, sx_cell_stress(m, s, &volume), "m:cell_stress");
    sx_lua_push_tensor(L, s, sx_model_dim(m));
    lua_pushnumber(L, volume);
    return 2;
}

const luaL_Reg sx_lua_periodic_methods[] = {
    {"periodic", model_periodic},
    {"cell_control", model_cell_control},
    {"cell_stress", model_cell_stress},
    {NULL, NULL},
};
