/* Smooth joints (core sx_joint_add; law src/core/laws/smoothjoint.h):
 *   m:joint{point=, normal= | dip= [, dip_direction=], kn=, ks=, friction=,
 *           dilation=, tension=, cohesion=, friction_angle=,
 *           radius_multiplier=, radius=}  -> number, bonds cut or replaced, contacts taken
 *   m:joints()                      -> the joints as given, numbered from 1 */
#include "bindings.h"

#include <math.h>

static const char *const joint_keys[] = {"point",    "normal",   "dip",      "dip_direction",  "kn",
                                         "ks",       "friction", "dilation", "tension",        "cohesion",
                                         "friction_angle",       "radius_multiplier",          "radius",
                                         NULL};

/* The plane's normal from dip angles: 3D, dip d below the horizontal
 * towards the dip direction a (clockwise from +y, north, with x east and
 * z up): the upward normal (sin d sin a, sin d cos a, cos d); 2D, a line
 * at dip d counter-clockwise from +x: the normal (-sin d, cos d). */
static void normal_of_dip(int dim, double dip, double dir, double *n)
{
    const double d = dip * SX_LUA_PI / 180, a = dir * SX_LUA_PI / 180;
    if (dim == 3) n[0] = sin(d) * sin(a), n[1] = sin(d) * cos(a), n[2] = cos(d);
    else n[0] = -sin(d), n[1] = cos(d), n[2] = 0;
}

static int model_joint(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    sx_lua_checkkeys(L, 2, joint_keys);
    const int dim = sx_model_dim(m);
    sx_joint_def def = sx_joint_default_def();
    def.normal[1] = 0;
    sx_lua_checkvecfield(L, 2, "point", dim, def.point);
    const bool has_normal = sx_lua_optvecfield(L, 2, "normal", dim, def.normal);
    double dip = NAN, dir = NAN;
    const bool has_dip = sx_lua_optrangefield(L, 2, "dip", -360, 360, &dip);
    const bool has_dir = sx_lua_optrangefield(L, 2, "dip_direction", -360, 360, &dir);
    if (has_normal == has_dip) return sx_lua_fielderror(L, 2, has_dip ? "dip" : "normal", "give either normal or dip");
    if (has_dir && (dim == 2 || !has_dip))
        return sx_lua_fielderror(L, 2, "dip_direction", dim == 2 ? "a 2D joint has a dip only" : "needs dip");
    if (has_dip) normal_of_dip(dim, dip, has_dir ? dir : 0, def.normal);
    def.kn = sx_lua_checknumfield(L, 2, "kn");
    def.ks = sx_lua_checknumfield(L, 2, "ks");
    sx_lua_optnumfield(L, 2, "friction", &def.friction);
    sx_lua_optnumfield(L, 2, "dilation", &def.dilation);
    sx_lua_optnumfield(L, 2, "tension", &def.tension);
    sx_lua_optnumfield(L, 2, "cohesion", &def.cohesion);
    sx_lua_optnumfield(L, 2, "friction_angle", &def.friction_angle);
    sx_lua_optnumfield(L, 2, "radius_multiplier", &def.radius_multiplier);
    sx_lua_optnumfield(L, 2, "radius", &def.radius);
    int64_t bonds = 0, contacts = 0;
    sx_lua_check(L, m, sx_joint_add(m, &def, &bonds, &contacts), "m:joint");
    lua_pushinteger(L, (lua_Integer)sx_joint_count(m));
    lua_pushinteger(L, (lua_Integer)bonds);
    lua_pushinteger(L, (lua_Integer)contacts);
    return 3;
}

static int model_joints(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* what every rank holds alike: no gather */
    const int dim = sx_model_dim(m);
    const int64_t n = sx_joint_count(m);
    lua_createtable(L, (int)n, 0);
    for (int64_t k = 0; k < n; k++) {
        sx_joint_def d;
        sx_joint_get(m, k, &d);
        lua_createtable(L, 0, 11);
        sx_lua_pushvec(L, d.point, dim);
        lua_setfield(L, -2, "point");
        sx_lua_pushvec(L, d.normal, dim);
        lua_setfield(L, -2, "normal");
        sx_lua_setnum(L, "kn", d.kn);
        sx_lua_setnum(L, "ks", d.ks);
        sx_lua_setnum(L, "friction", d.friction);
        sx_lua_setnum(L, "dilation", d.dilation);
        sx_lua_setnum(L, "tension", d.tension);
        sx_lua_setnum(L, "cohesion", d.cohesion);
        sx_lua_setnum(L, "friction_angle", d.friction_angle);
        sx_lua_setnum(L, "radius_multiplier", d.radius_multiplier);
        sx_lua_setnum(L, "radius", d.radius);
        lua_rawseti(L, -2, (lua_Integer)(k + 1));
    }
    return 1;
}

const luaL_Reg sx_lua_joints_methods[] = {
    {"joint", model_joint},
    {"joints", model_joints},
    {NULL, NULL},
};
