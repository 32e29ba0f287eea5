/* The `seixo` Lua module: its loader and the embedding entry point. Each
 * object kind registers its own class and model methods (model.c,
 * balls.c, walls.c); this file only assembles them. */
#include "seixo_lua.h"

#include "bindings.h"

int luaopen_seixo(lua_State *L)
{
    static const luaL_Reg functions[] = {
        {"model", sx_lua_model_new},
        {NULL, NULL},
    };
    sx_lua_model_register(L);
    sx_lua_balls_register(L);
    sx_lua_walls_register(L);
    sx_lua_bonds_register(L);
    lua_pop(L, 1);
    luaL_newlib(L, functions);
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
