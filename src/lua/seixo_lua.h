/* seixo — the public C API of the Lua bindings (the `seixo` Lua module),
 * for programs that embed a Lua state, such as the seixo executable. */
#pragma once

#include <lua.h>

#include "seixo.h"

/// The module loader: returns the `seixo` table (seixo.model, seixo.version, ...).
SX_API int luaopen_seixo(lua_State *L);

/// Makes the module available in L: in package.preload, in package.loaded
/// and as the global `seixo`. Needs the standard libraries opened.
SX_API void sx_lua_open(lua_State *L);

/// Lua source only: load, loadfile and dofile (and the rank-aware ones
/// sx_lua_open installs over them) refuse precompiled chunks, which Lua
/// does not check and a damaged one of which crashes the interpreter.
/// Call after the standard libraries and before sx_lua_open.
SX_API void sx_lua_source_only(lua_State *L);
/// luaL_loadfilex(L, path, "t") (path NULL: standard input), a precompiled
/// chunk's refusal naming the file.
SX_API int sx_lua_load_source(lua_State *L, const char *path);

/// Interrupts every cycle running in this process: each stops at its next
/// step boundary and m:cycle (m:solve) raises "interrupted at step N".
/// Async-signal-safe. Returns the number of cycles running, or 0 when the
/// innermost one is running a Lua callback: the caller then has to stop that
/// Lua code itself (the seixo executable sets a hook, as lua.c does).
SX_API int sx_lua_interrupt_all(void);

/// A Ctrl-C (sx_lua_interrupt_all) that no code has answered yet with an
/// "interrupted" error; long C work outside the cycles polls it.
/// Async-signal-safe.
SX_API int sx_lua_interrupt_pending(void);
/// Forgets a pending Ctrl-C: the caller answered it (the executable's hook
/// raised "interrupted"), or no code was left to stop.
SX_API void sx_lua_interrupt_clear(void);
/// The interrupts requested so far (sx_lua_interrupt_all's calls):
/// seixo.interrupts(), for code that catches errors to go on.
SX_API unsigned sx_lua_interrupt_count(void);

/// The progress display of long cycles (steps, time, steps/s, ETA on stderr).
enum {
    SX_PROGRESS_OFF = 0,       ///< nothing (the default of a state)
    SX_PROGRESS_TERMINAL = 1,  ///< one line rewritten in place (the executable's, stderr a terminal)
    SX_PROGRESS_LOG = 2,       ///< a plain line every few seconds (the executable's, stderr a file or pipe)
};
/// Sets this state's progress display to one of SX_PROGRESS_*.
SX_API void sx_lua_set_progress(lua_State *L, int on);
/// This state's progress display, one of SX_PROGRESS_*.
SX_API int sx_lua_progress_mode(lua_State *L);
/// Seconds between the lines of SX_PROGRESS_LOG (default 10).
SX_API void sx_lua_set_progress_every(lua_State *L, double seconds);

/// Switches the end-of-model profile on or off for this state (off by
/// default): a model that has cycled prints its m:profile() table on
/// stderr when it is closed or collected. The executable's --profile.
SX_API void sx_lua_set_profile(lua_State *L, int on);

/// Starts MPI when the program was launched by mpirun (Open MPI's or a
/// PMI launcher's environment) and seixo was built with MPI; else nothing.
/// Call it first thing in main; seixo.rank() and seixo.ranks() tell the rest.
/// On ranks other than 0 standard output then goes to /dev/null.
SX_API void sx_lua_parallel_start(int *argc, char ***argv);

/// This process's MPI rank (0 without mpirun).
SX_API int sx_lua_parallel_rank(void);
/// The number of MPI ranks (1 without mpirun).
SX_API int sx_lua_parallel_ranks(void);
/// Removes this rank's folder of private copies of the script's files
/// (rank_files.c) from a signal handler that ends the rank: only
/// async-signal-safe calls.
SX_API void sx_lua_rank_files_remove_now(void);

/// Text rank 0 makes, on every rank: under mpirun rank 0 calls read(ud,
/// len, mark) and sends what it returns (len bytes, malloc'ed and
/// NUL-terminated; NULL: none) with *mark (an integer the caller gives
/// meaning to) to the other ranks, which return a malloc'ed copy (or NULL)
/// without calling read. Serially, read's answer. Standard input, which
/// mpirun gives to rank 0 alone (the interactive mode's lines, a script
/// read with `seixo -`), and os.tmpname's names go through it. A
/// collective call, named `what` (sx_lua_parallel_same_call): every rank
/// stops with a message if another rank is in another call.
SX_API char *sx_lua_parallel_root_text(const char *what, char *(*read)(void *ud, size_t *len, int *mark), void *ud,
                                       size_t *len, int *mark);

/// To call before reporting the error that ends the run, message (then
/// sx_lua_parallel_stop(0)): whether this process reports it. Under mpirun
/// an error every rank meets (within a few seconds) is reported by rank 0
/// alone, at once; a rank above 0 failing alone is reported by rank 0
/// within half a second when rank 0 waits for it (a collective call, a
/// cycle's exchanges, seixo.receive), else by itself after that wait.
/// Else true at once.
SX_API bool sx_lua_parallel_failing(const char *message);

/// After a line of the interactive session, which every rank runs alike:
/// when it `failed` on some ranks only (message: the error, or NULL), the
/// ranks differ from then on, and the job ends with a failing rank's
/// message, reported by rank 0. Serially, and when every rank agrees,
/// returns at once (the caller reports its error). A collective call.
SX_API void sx_lua_parallel_line_end(bool failed, const char *message);

/// Ends MPI if sx_lua_parallel_start started it: MPI_Finalize, or MPI_Abort
/// when ok is 0 and other ranks exist (they would wait for this one forever).
SX_API void sx_lua_parallel_stop(int ok);
