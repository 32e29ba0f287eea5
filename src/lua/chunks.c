/* Lua source only: the executable's load, loadfile and dofile take text
 * chunks, never precompiled ones. Lua does not check binary chunks (its
 * manual: "maliciously crafted bytecode can crash the interpreter"), and a
 * damaged luac file did crash seixo (SIGSEGV or abort in 30 of 300
 * mutated files: a robustness tester's finding); a text chunk is parsed,
 * and its errors are messages. */
#include <lauxlib.h>
#include <string.h>

#include "bindings.h"
#include "seixo_lua.h"

/* Lua's message for a binary chunk refused ("attempt to load a binary
 * chunk (mode is 't')") names neither the file nor why: the message at the
 * top, if it is that one, replaced by one that does. */
static void name_binary(lua_State *L, const char *name)
{
    const char *msg = lua_tostring(L, -1);
    if (!msg || !strstr(msg, "attempt to load a binary chunk")) return;
    lua_pushfstring(L, "%s: a precompiled (luac) chunk: seixo loads Lua source only (Lua does not check precompiled "
                       "code, and a damaged chunk can crash it)",
                    name ? name : "the chunk");
    lua_replace(L, -2);
}

int sx_lua_load_source(lua_State *L, const char *path)
{
    const int status = luaL_loadfilex(L, path, "t");
    if (status != LUA_OK) name_binary(L, path ? path : "stdin");
    return status;
}

/* load(chunk, name, mode, env) and loadfile(path, mode, env): Lua's own
 * (upvalue 1) with mode "t" at argument upvalue 2, the arguments after it
 * passed as given (an absent env stays absent: a nil one would be set). */
static int text_only(lua_State *L)
{
    const int at = (int)lua_tointeger(L, lua_upvalueindex(2));
    /* the arguments checked here, where an error names this function
     * ('load', 'loadfile'): called from C, Lua's own is '?' */
    if (at == 3) {
        if (lua_type(L, 1) != LUA_TSTRING && lua_type(L, 1) != LUA_TFUNCTION) luaL_typeerror(L, 1, "string or function");
        luaL_optstring(L, 2, NULL);
    } else {
        luaL_optstring(L, 1, NULL);
    }
    if (lua_gettop(L) < at) lua_settop(L, at);
    lua_pushliteral(L, "t");
    lua_replace(L, at);
    lua_pushvalue(L, at == 2 ? 1 : 2); /* loadfile's path, load's chunk name: kept below the call */
    lua_insert(L, 1);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 2);
    lua_call(L, lua_gettop(L) - 2, LUA_MULTRET);
    const int results = lua_gettop(L) - 1;
    if (results == 2 && lua_isnil(L, 2)) name_binary(L, lua_type(L, 1) == LUA_TSTRING ? lua_tostring(L, 1) : NULL);
    lua_remove(L, 1);
    return results;
}

static int dofile_results(lua_State *L, int status, lua_KContext ctx)
{
    (void)status;
    (void)ctx;
    return lua_gettop(L) - 1; /* what the chunk returned, above the path */
}

/* dofile([path]): the file (standard input without one) as text, run as
 * Lua's dofile runs it (a continuation: a coroutine may yield inside) */
static int text_dofile(lua_State *L)
{
    const char *path = luaL_optstring(L, 1, NULL);
    lua_settop(L, 1);
    if (sx_lua_load_source(L, path) != LUA_OK) return lua_error(L);
    lua_callk(L, 0, LUA_MULTRET, 0, dofile_results);
    return dofile_results(L, LUA_OK, 0);
}

static void wrap_mode(lua_State *L, const char *name, int mode_arg)
{
    lua_getglobal(L, name);
    if (lua_type(L, -1) != LUA_TFUNCTION) {
        lua_pop(L, 1);
        return;
    }
    lua_pushinteger(L, mode_arg);
    lua_pushcclosure(L, text_only, 2);
    lua_setglobal(L, name);
}

void sx_lua_source_only(lua_State *L)
{
    wrap_mode(L, "load", 3);
    wrap_mode(L, "loadfile", 2);
    lua_pushcfunction(L, text_dofile);
    lua_setglobal(L, "dofile");
}
