/* seixo — the public C API of the Lua bindings (the `seixo` Lua module),
 * for programs that embed a Lua state, such as the seixo executable. */
#pragma once

#include <lua.h>

#include "seixo.h"

/// The module loader: returns the `seixo` table (seixo.model, seixo.version).
SX_API int luaopen_seixo(lua_State *L);

/// Makes the module available in L: in package.preload, in package.loaded
/// and as the global `seixo`. Needs the standard libraries opened.
SX_API void sx_lua_open(lua_State *L);

/// Interrupts every cycle running in this process: each stops at its next
/// step boundary and m:cycle raises "interrupted at step N".
/// Async-signal-safe. Returns the number of cycles that were running.
SX_API int sx_lua_interrupt_all(void);
