/* The `seixo` Lua module: its loader and the embedding entry point. Each
 * binding file exports its model methods as a luaL_Reg array (bindings.h)
 * and registers its own class; this file only assembles them. A new binding
 * file adds its array to model_methods and its class to the loader. */
#include "seixo_lua.h"

#include "bindings.h"

#include <time.h>

static const luaL_Reg *const model_methods[] = {
    sx_lua_model_methods,    sx_lua_run_methods,     sx_lua_balls_methods,
    sx_lua_walls_methods,    sx_lua_contacts_methods, sx_lua_groups_methods,
    sx_lua_history_methods,  sx_lua_generate_methods, sx_lua_bonds_methods,
    sx_lua_lab_methods,      sx_lua_clumps_methods, sx_lua_periodic_methods, NULL,
};

/* seixo.progress([on]): the progress line of long cycles; returns the previous setting. */
static int seixo_progress(lua_State *L)
{
    lua_getfield(L, LUA_REGISTRYINDEX, "seixo.progress");
    const int was = lua_toboolean(L, -1);
    if (!lua_isnone(L, 1)) {
        luaL_checktype(L, 1, LUA_TBOOLEAN);
        sx_lua_set_progress(L, lua_toboolean(L, 1));
    }
    lua_pushboolean(L, was);
    return 1;
}

/* seixo.clock(): wall-clock seconds from a monotonic clock, for timing runs
 * (os.clock counts the CPU time of all threads, os.time whole seconds). */
static int seixo_clock(lua_State *L)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    lua_pushnumber(L, (double)t.tv_sec + 1e-9 * (double)t.tv_nsec);
    return 1;
}

int luaopen_seixo(lua_State *L)
{
    static const luaL_Reg functions[] = {
        {"model", sx_lua_model_new},
        {"progress", seixo_progress},
        {"clock", seixo_clock},
        {NULL, NULL},
    };
    sx_lua_model_register(L, model_methods);
    sx_lua_balls_register(L);
    sx_lua_walls_register(L);
    sx_lua_lab_register(L); /* lab.c: the walls' servo, load and radius */
    sx_lua_contacts_register(L);
    sx_lua_clumps_register(L);
    luaL_newlib(L, functions);
    sx_lua_io_register(L); /* io.c: m:save, m:vars, m:output, seixo.load, seixo.xdmf */
    lua_pushliteral(L, SX_VERSION);
    lua_setfield(L, -2, "version");
    return 1;
}

void sx_lua_open(lua_State *L)
{
    luaL_getsubtable(L, LUA_REGISTRYINDEX, LUA_PRELOAD_TABLE);
    lua_pushcfunction(L, luaopen_seixo);
    lua_setfield(L, -2, "seixo");
    lua_pop(L, 1);
    luaL_requiref(L, "seixo", luaopen_seixo, 1);
    lua_pop(L, 1);
}
