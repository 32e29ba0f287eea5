/* Laboratory-test bindings: the cylindrical wall, servo control of walls
 * and measurement regions.
 *   m:cylinder{point=, axis=, radius=, height=, radial_vel=, kn=, ks=, friction=, vel=}
 *   w:servo{target=, area=, alpha=, max_speed=}   (w:servo(nil) releases the wall)
 *   w:load()        -> normal force (N), contacts, mean contact kn (the servo's inputs)
 *   w.radius, w.radial_vel (cylinder; radial_vel writable)
 *   m:measure{sphere = {centre, radius}} or m:measure{box = {lo, hi}}
 *       -> {stress = {{...}}, porosity, coordination, fabric = {{...}}, balls, contacts, volume, solid} */
#include "bindings.h"

#include <string.h>

static int model_cylinder(lua_State *L)
{
    static const char *const keys[] = {"point", "axis", "radius", "height", "radial_vel", "kn", "ks", "friction", "vel",
                                       NULL};
    sx_model *m = sx_lua_checkmodel(L, 1);
    if (sx_model_dim(m) != 3) return luaL_error(L, "cylinder: a cylindrical wall needs a 3D model");
    luaL_checktype(L, 2, LUA_TTABLE);
    sx_lua_checkkeys(L, 2, keys);
    sx_wall_def d = sx_wall_default_def(3);
    d.kind = SX_WALL_CYLINDER;
    sx_lua_checkvecfield(L, 2, "point", 3, d.point);
    sx_lua_checkvecfield(L, 2, "axis", 3, d.normal);
    d.radius = sx_lua_checknumfield(L, 2, "radius");
    sx_lua_optnumfield(L, 2, "height", &d.height);
    sx_lua_optnumfield(L, 2, "radial_vel", &d.radial_vel);
    sx_lua_optnumfield(L, 2, "kn", &d.kn);
    sx_lua_optnumfield(L, 2, "ks", &d.ks);
    sx_lua_optnumfield(L, 2, "friction", &d.friction);
    sx_lua_optvecfield(L, 2, "vel", 3, d.vel);
    int64_t id = 0;
    sx_lua_check(L, m, sx_wall_add(m, &d, &id));
    sx_lua_pushhandle(L, 1, &sx_lua_wall_kind, id);
    return 1;
}

static int wall_servo(lua_State *L)
{
    static const char *const keys[] = {"target", "area", "alpha", "max_speed", NULL};
    int64_t id;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    if (lua_isnoneornil(L, 2)) {
        sx_lua_check(L, m, sx_wall_clear_servo(m, id));
        return 0;
    }
    luaL_checktype(L, 2, LUA_TTABLE);
    sx_lua_checkkeys(L, 2, keys);
    sx_servo_def d = sx_servo_default_def();
    d.target = sx_lua_checknumfield(L, 2, "target");
    sx_lua_optnumfield(L, 2, "area", &d.area);
    sx_lua_optnumfield(L, 2, "alpha", &d.alpha);
    sx_lua_optnumfield(L, 2, "max_speed", &d.max_speed);
    sx_lua_check(L, m, sx_wall_set_servo(m, id, &d));
    return 0;
}

static int wall_load(lua_State *L)
{
    int64_t id, contacts = 0;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    double force = 0, kn = 0;
    sx_lua_check(L, m, sx_wall_load(m, id, &force, &contacts, &kn));
    lua_pushnumber(L, force);
    lua_pushinteger(L, (lua_Integer)contacts);
    lua_pushnumber(L, kn);
    return 3;
}

static int wall_set_radial_vel(lua_State *L)
{
    int64_t id;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    sx_lua_check(L, m, sx_wall_set_radial_vel(m, id, luaL_checknumber(L, 2)));
    return 0;
}

static int wall_radius(lua_State *L)
{
    int64_t id;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    sx_wall_def d;
    sx_lua_check(L, m, sx_wall_get(m, id, &d));
    lua_pushnumber(L, d.radius);
    lua_pushnumber(L, d.radial_vel);
    return 2;
}

/* Reads {centre, radius} or {lo, hi} (array part) into the region. */
static void read_region(lua_State *L, sx_model *m, int arg, sx_region *r)
{
    static const char *const keys[] = {"sphere", "box", NULL};
    const int dim = sx_model_dim(m);
    luaL_checktype(L, arg, LUA_TTABLE);
    sx_lua_checkkeys(L, arg, keys);
    memset(r, 0, sizeof *r);
    const bool sphere = lua_getfield(L, arg, "sphere") == LUA_TTABLE;
    lua_pop(L, 1);
    const bool box = lua_getfield(L, arg, "box") == LUA_TTABLE;
    lua_pop(L, 1);
    if (sphere == box) luaL_argerror(L, arg, "give exactly one of sphere = {centre, radius} or box = {lo, hi}");
    lua_getfield(L, arg, sphere ? "sphere" : "box");
    const int t = lua_gettop(L);
    lua_rawgeti(L, t, 1);
    const char *why = sx_lua_tovec(L, -1, dim, sphere ? r->centre : r->lo);
    if (why) luaL_argerror(L, arg, lua_pushfstring(L, "%s[1]: %s", sphere ? "sphere" : "box", why));
    lua_pop(L, 1);
    lua_rawgeti(L, t, 2);
    if (sphere) {
        if (!lua_isnumber(L, -1)) luaL_argerror(L, arg, "sphere[2]: the radius (a number) expected");
        r->radius = lua_tonumber(L, -1);
        r->shape = SX_REGION_SPHERE;
    } else {
        why = sx_lua_tovec(L, -1, dim, r->hi);
        if (why) luaL_argerror(L, arg, lua_pushfstring(L, "box[2]: %s", why));
        r->shape = SX_REGION_BOX;
    }
    lua_settop(L, t - 1);
}

static void push_tensor(lua_State *L, const double t[3][3], int dim)
{
    lua_createtable(L, dim, 0);
    for (int i = 0; i < dim; i++) {
        lua_createtable(L, dim, 0);
        for (int j = 0; j < dim; j++) {
            lua_pushnumber(L, t[i][j]);
            lua_rawseti(L, -2, j + 1);
        }
        lua_rawseti(L, -2, i + 1);
    }
}

static int model_measure(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    sx_region r;
    read_region(L, m, 2, &r);
    sx_measurement out;
    sx_lua_check(L, m, sx_measure(m, &r, &out));
    const int dim = sx_model_dim(m);
    lua_createtable(L, 0, 8);
    push_tensor(L, out.stress, dim);
    lua_setfield(L, -2, "stress");
    push_tensor(L, out.fabric, dim);
    lua_setfield(L, -2, "fabric");
    const struct {
        const char *name;
        double value;
    } scalars[] = {{"porosity", out.porosity}, {"coordination", out.coordination}, {"volume", out.volume},
                   {"solid", out.solid}};
    for (size_t k = 0; k < sizeof scalars / sizeof *scalars; k++) {
        lua_pushnumber(L, scalars[k].value);
        lua_setfield(L, -2, scalars[k].name);
    }
    lua_pushinteger(L, (lua_Integer)out.balls);
    lua_setfield(L, -2, "balls");
    lua_pushinteger(L, (lua_Integer)out.contacts);
    lua_setfield(L, -2, "contacts");
    return 1;
}

void sx_lua_lab_register(lua_State *L)
{
    static const luaL_Reg model_methods[] = {
        {"cylinder", model_cylinder},
        {"measure", model_measure},
        {NULL, NULL},
    };
    luaL_setfuncs(L, model_methods, 0);
    /* the wall class exists (walls are registered first): add its lab methods */
    static const luaL_Reg wall_methods[] = {
        {"servo", wall_servo},
        {"load", wall_load},
        {"radius", wall_radius},
        {"set_radial_vel", wall_set_radial_vel},
        {NULL, NULL},
    };
    luaL_getmetatable(L, sx_lua_wall_kind.tname);
    lua_getfield(L, -1, "__methods");
    luaL_setfuncs(L, wall_methods, 0);
    lua_pop(L, 2);
}
