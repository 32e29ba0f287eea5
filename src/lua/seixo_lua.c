/* The `seixo` Lua module: its loader and the embedding entry point. Each
 * binding file exports its model methods as a luaL_Reg array (bindings.h)
 * and registers its own class; this file only assembles them. A new binding
 * file adds its array to model_methods and its class to the loader. */
#include "seixo_lua.h"

#include "bindings.h"

#include <string.h>
#include <time.h>

static const luaL_Reg *const model_methods[] = {
    sx_lua_model_methods,    sx_lua_run_methods,     sx_lua_balls_methods,
    sx_lua_walls_methods,    sx_lua_contacts_methods, sx_lua_groups_methods,
    sx_lua_history_methods,  sx_lua_generate_methods, sx_lua_bonds_methods,
    sx_lua_lab_methods,      sx_lua_clumps_methods,   sx_lua_disp_methods,
    sx_lua_periodic_methods, sx_lua_joints_methods, NULL,
};

/* seixo.progress([mode[, every]]): the progress display of long cycles
 * (false, true: a terminal line, "log": plain lines every `every` s);
 * returns the previous mode. */
static int seixo_progress(lua_State *L)
{
    const int was = sx_lua_progress_mode(L);
    if (!lua_isnone(L, 1)) {
        int mode;
        if (lua_type(L, 1) == LUA_TBOOLEAN)
            mode = lua_toboolean(L, 1) ? SX_PROGRESS_TERMINAL : SX_PROGRESS_OFF;
        else if (lua_type(L, 1) == LUA_TSTRING && strcmp(lua_tostring(L, 1), "log") == 0)
            mode = SX_PROGRESS_LOG;
        else
            return luaL_argerror(L, 1, lua_pushfstring(L, "boolean or 'log' expected, got %s", luaL_typename(L, 1)));
        if (!lua_isnoneornil(L, 2)) {
            const double every = luaL_checknumber(L, 2);
            luaL_argcheck(L, every >= 0 && every < 1e9, 2, "seconds between log lines, >= 0 expected");
            sx_lua_set_progress_every(L, every);
        }
        sx_lua_set_progress(L, mode);
    }
    if (was == SX_PROGRESS_LOG)
        lua_pushliteral(L, "log");
    else
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

/* seixo.interrupts(): how many interrupts (Ctrl-C, SIGTERM) came so far. */
static int seixo_interrupts(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_lua_interrupt_count());
    return 1;
}

int luaopen_seixo(lua_State *L)
{
    static const luaL_Reg functions[] = {
        {"model", sx_lua_model_new},
        {"models", sx_lua_models},
        {"check_material", sx_lua_check_material},
        {"progress", seixo_progress},
        {"clock", seixo_clock},
        {"interrupts", seixo_interrupts},
        {NULL, NULL},
    };
    sx_lua_model_register(L, model_methods);
    sx_lua_balls_register(L);
    sx_lua_walls_register(L);
    sx_lua_lab_register(L); /* lab.c: the walls' servo, load and radius */
    sx_lua_contacts_register(L);
    sx_lua_clumps_register(L);
    luaL_newlib(L, functions);
    luaL_setfuncs(L, sx_lua_optimize_functions, 0); /* optimize.c: seixo.optimize (NLopt) */
    luaL_setfuncs(L, sx_lua_parallel_functions, 0); /* parallel.c: cores, executable, MPI ranks and messages */
    sx_lua_io_register(L); /* io.c: m:save, m:vars, m:output, seixo.load, seixo.xdmf */
    sx_lua_vec_register(L); /* vec.c: seixo.vec, the class of every vector returned */
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
    sx_lua_parallel_open(L);
}
