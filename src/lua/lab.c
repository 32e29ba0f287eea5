/* Laboratory-test bindings: the cylindrical wall, servo control of walls
 * and measurement regions.
 *   m:wall{kind = "cylinder", point=, axis=, radius=, height=, radial_vel=, ...} (in walls.c)
 *   w:servo{target=, area=, alpha=, max_speed=}   (w:servo(nil) releases the wall)
 *   w:load()        -> normal force (N), contacts, mean contact kn (the servo's inputs)
 *   w:radius() -> radius, radial_vel; w:set_radius(r), w:set_radial_vel(v) (cylinder)
 *   m:measure{sphere = {center =, radius =}} (2D: disk) or m:measure{box = {min, max}}
 *       -> {stress = {{...}}, porosity, coordination, fabric = {{...}}, balls, contacts, volume, solid} */
#include "bindings.h"

#include <string.h>

static int wall_servo(lua_State *L)
{
    static const char *const keys[] = {"target", "area", "alpha", "max_speed", NULL};
    int64_t id;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    if (lua_isnoneornil(L, 2)) {
        sx_lua_check(L, m, sx_wall_clear_servo(m, id), "w:servo");
        return 0;
    }
    luaL_checktype(L, 2, LUA_TTABLE);
    sx_lua_checkkeys(L, 2, keys);
    sx_servo_def d = sx_servo_default_def();
    d.target = sx_lua_checknumfield(L, 2, "target");
    sx_lua_optnumfield(L, 2, "area", &d.area);
    sx_lua_optnumfield(L, 2, "alpha", &d.alpha);
    sx_lua_optnumfield(L, 2, "max_speed", &d.max_speed);
    sx_lua_check(L, m, sx_wall_set_servo(m, id, &d), "w:servo");
    /* after the core accepted the target: an invalid one gets its error, not a warning */
    lua_getiuservalue(L, 1, 1);
    sx_lua_check_range(L, lua_gettop(L), "servo target stress", d.target, 1e3, 1e10, "Pa");
    lua_pop(L, 1);
    return 0;
}

static int wall_load(lua_State *L)
{
    int64_t id, contacts = 0;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    double force = 0, kn = 0;
    sx_lua_check(L, m, sx_wall_load(m, id, &force, &contacts, &kn), "w:load");
    lua_pushnumber(L, force);
    lua_pushinteger(L, (lua_Integer)contacts);
    lua_pushnumber(L, kn);
    return 3;
}

static int wall_set_radial_vel(lua_State *L)
{
    int64_t id;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    sx_lua_check(L, m, sx_wall_set_radial_vel(m, id, luaL_checknumber(L, 2)), "w:set_radial_vel");
    return 0;
}

static int wall_set_radius(lua_State *L)
{
    int64_t id;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    sx_lua_check(L, m, sx_wall_set(m, id, SX_WALL_RADIUS, luaL_checknumber(L, 2)), "w:set_radius");
    return 0;
}

static int wall_radius(lua_State *L)
{
    int64_t id;
    sx_model *m = sx_lua_checkhandle(L, 1, &sx_lua_wall_kind, &id);
    sx_wall_def d;
    sx_lua_check(L, m, sx_wall_get(m, id, &d), "w:radius");
    if (d.kind != SX_WALL_CYLINDER) /* as w:set_radius says: a 0 read as a radius is no answer */
        return luaL_error(L, "w:radius: wall %d is not a cylinder; only a cylinder has a radius", (int)id);
    lua_pushnumber(L, d.radius);
    lua_pushnumber(L, d.radial_vel);
    return 2;
}

/* The measurement region from the same region table generation uses
 * ({sphere = {center =, radius =}}, {disk = ...} in 2D, {box = {min, max}}). */
static void read_region(lua_State *L, sx_model *m, int arg, sx_region *r)
{
    const int dim = sx_model_dim(m);
    const int top = lua_gettop(L);
    sx_lua_region g;
    sx_lua_region_read(L, arg, dim, arg, "region", &g);
    memset(r, 0, sizeof *r);
    if (g.kind == SX_REGION_BOX) {
        r->shape = SX_SHAPE_BOX;
        memcpy(r->lo, g.lo, sizeof r->lo);
        memcpy(r->hi, g.hi, sizeof r->hi);
    } else if (g.kind == SX_REGION_SPHERE || g.kind == SX_REGION_DISK) {
        r->shape = SX_SHAPE_SPHERE;
        memcpy(r->centre, g.c, sizeof r->centre);
        r->radius = g.r;
    } else {
        luaL_argerror(L, arg, "measure: a box, a sphere (3D) or a disk (2D) region expected");
    }
    lua_settop(L, top);
}

void sx_lua_push_tensor(lua_State *L, const double t[3][3], int dim)
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
    sx_lua_check(L, m, sx_measure(m, &r, &out), "m:measure");
    const int dim = sx_model_dim(m);
    lua_createtable(L, 0, 8);
    sx_lua_push_tensor(L, out.stress, dim);
    lua_setfield(L, -2, "stress");
    sx_lua_push_tensor(L, out.fabric, dim);
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

const luaL_Reg sx_lua_lab_methods[] = {
    {"measure", model_measure},
    {NULL, NULL},
};

void sx_lua_lab_register(lua_State *L)
{
    /* the wall class exists (walls are registered first): add its lab methods */
    static const luaL_Reg wall_methods[] = {
        {"servo", wall_servo},
        {"load", wall_load},
        {"radius", wall_radius},
        {"set_radial_vel", wall_set_radial_vel},
        {"set_radius", wall_set_radius},
        {NULL, NULL},
    };
    luaL_getmetatable(L, sx_lua_wall_kind.tname);
    lua_getfield(L, -1, "__methods");
    luaL_setfuncs(L, wall_methods, 0);
    lua_pop(L, 2);
}
