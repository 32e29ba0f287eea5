/* Files under mpirun. Every rank runs the script, so every rank would write
 * each file the script writes: a log opened with "a" would get each line
 * once per rank, and ranks opening one file with "w" truncate each other's
 * lines at their own pace. While models are shared (seixo.decompose, on by
 * default) rank 0 alone writes the real files; a rank above 0 writes a
 * shadow, a private unnamed copy of the file, and reads a file back from
 * its shadow: as it made the same calls as rank 0, its shadow holds rank
 * 0's bytes, without waiting for rank 0 to have written them (the ranks
 * are not in step outside a cycle) and on a disk rank 0 may not share.
 *
 * Wrapped on ranks above 0: io.open, io.lines, io.input and io.output (a
 * path: through io.open), os.remove and os.rename (a shadow is removed or
 * renamed; the real file is rank 0's to change, and the answer is the one
 * rank 0 gets when the file is there). Devices (/dev/null), FIFOs and
 * sockets are not shadowed. A write that rank 0 would be refused (no
 * folder, no permission) is refused alike: the real file is probed first,
 * without being changed. C functions that read a file the script may have
 * written (an STL mesh, a clump template's spheres) take its path through
 * sx_lua_rank_file. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "bindings.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char shadows_key[] = "seixo.shadows"; /* registry: real path -> shadow's descriptor */

/* Rank 0's files are real when this process is a rank above 0 of shared models. */
static bool shadowing(void) { return !sx_lua_parallel_writes(sx_lua_parallel_sharing()); }

/* Lua's modes: r, w or a, then + maybe, then b's. */
static bool valid_mode(const char *mode)
{
    if (!*mode || !strchr("rwa", *mode)) return false;
    mode++;
    if (*mode == '+') mode++;
    return strspn(mode, "b") == strlen(mode);
}

/* Pushes the file's absolute name (its folder resolved, so that two
 * spellings of one file find one shadow); false with errno if the folder
 * is not there. */
static bool push_real_name(lua_State *L, const char *path)
{
    const char *slash = strrchr(path, '/');
    char dir[PATH_MAX], real[PATH_MAX];
    if (!slash) {
        strcpy(dir, ".");
    } else {
        const size_t n = slash == path ? 1 : (size_t)(slash - path);
        if (n >= sizeof dir) {
            errno = ENAMETOOLONG;
            return false;
        }
        memcpy(dir, path, n);
        dir[n] = '\0';
    }
    if (!realpath(dir, real)) return false;
    lua_pushfstring(L, "%s/%s", real, slash ? slash + 1 : path);
    return true;
}

static void push_shadows(lua_State *L)
{
    if (lua_getfield(L, LUA_REGISTRYINDEX, shadows_key) != LUA_TTABLE) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_pushvalue(L, -1);
        lua_setfield(L, LUA_REGISTRYINDEX, shadows_key);
    }
}

/* What the table says of a file: its shadow's descriptor (>= 0), or: */
enum {
    NO_SHADOW = -1, /* the script has not written it: the disk's file */
    GONE = -2,      /* the script removed it, or renamed it away */
};

/* The shadow of the file named at the top of the stack. */
static int shadow_of(lua_State *L)
{
    push_shadows(L);
    lua_pushvalue(L, -2);
    const int t = lua_gettable(L, -2);
    const int fd = t == LUA_TNUMBER ? (int)lua_tointeger(L, -1) : t == LUA_TBOOLEAN ? GONE : NO_SHADOW;
    lua_pop(L, 2);
    return fd;
}

/* Records v as the shadow of the name at the top of the stack. */
static void put_shadow(lua_State *L, int v)
{
    push_shadows(L);
    lua_pushvalue(L, -2);
    if (v >= 0) lua_pushinteger(L, v);
    else if (v == GONE) lua_pushboolean(L, 0);
    else lua_pushnil(L);
    lua_settable(L, -3);
    lua_pop(L, 1);
}

/* put_shadow, closing the shadow it replaces. */
static void set_shadow(lua_State *L, int v)
{
    const int old = shadow_of(L);
    if (old >= 0 && old != v) close(old);
    put_shadow(L, v);
}

/* Whether rank 0 may open path with mode, found without changing the file:
 * false with errno as its fopen would set it. */
static bool may_write(const char *path, const char *mode)
{
    struct stat st;
    if (stat(path, &st) == 0) {
        const int fd = open(path, (mode[0] == 'r' || strchr(mode, '+') ? O_RDWR : O_WRONLY) | O_NONBLOCK | O_NOCTTY);
        if (fd < 0) return false;
        close(fd);
        return true;
    }
    if (errno != ENOENT || mode[0] == 'r') return false;
    const char *slash = strrchr(path, '/');
    char dir[PATH_MAX];
    if (!slash) {
        strcpy(dir, ".");
    } else {
        const size_t n = slash == path ? 1 : (size_t)(slash - path);
        memcpy(dir, path, n); /* shorter than PATH_MAX: push_real_name resolved it */
        dir[n] = '\0';
    }
    return access(dir, W_OK | X_OK) == 0;
}

/* A new shadow of path (NULL: of a file the script removed): its descriptor, or -1 with errno. Opened to update
 * ("r+"), it holds the real file's bytes; opened to append, it starts
 * empty: rank 0 may be appending already (the ranks are not in step), so
 * what the real file holds now is not what it held when rank 0 opened it.
 * A log appended by this run then reads back alike on every rank; one
 * that was there before the run holds, on the ranks above 0, this run's
 * lines. */
static int new_shadow(const char *path, const char *mode)
{
    const char *tmp = getenv("TMPDIR");
    char name[PATH_MAX];
    snprintf(name, sizeof name, "%s/seixo-shadow-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    const int fd = mkstemp(name);
    if (fd < 0) return -1;
    unlink(name); /* unnamed: gone with the process, however it ends */
    FILE *real = path && mode[0] == 'r' ? fopen(path, "rb") : NULL;
    char buf[65536];
    size_t got;
    bool ok = true;
    while (ok && real && (got = fread(buf, 1, sizeof buf, real)) > 0) ok = write(fd, buf, got) == (ssize_t)got;
    if (real) fclose(real);
    if (!ok) {
        close(fd);
        return -1;
    }
    return fd;
}

static int close_shadow_file(lua_State *L)
{
    luaL_Stream *p = luaL_checkudata(L, 1, LUA_FILEHANDLE);
    return luaL_fileresult(L, fclose(p->f) == 0, NULL);
}

/* Opens the shadow fd afresh (its own position, mode's truncation) as a Lua file. */
static int push_shadow_file(lua_State *L, int fd, const char *mode, const char *path)
{
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
    luaL_Stream *p = lua_newuserdatauv(L, sizeof *p, 0);
    p->closef = NULL; /* not a file until it opens */
    luaL_setmetatable(L, LUA_FILEHANDLE);
    if (!(p->f = fopen(proc, mode))) return luaL_fileresult(L, 0, path);
    p->closef = close_shadow_file;
    return 1;
}

/* The upvalue, Lua's own function, with this call's arguments. */
static int call_lua_own(lua_State *L, int nargs)
{
    lua_settop(L, nargs);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    lua_call(L, nargs, LUA_MULTRET);
    return lua_gettop(L);
}

/* luaL_fileresult's failure with err. */
static int fail_with(lua_State *L, int err, const char *path)
{
    errno = err;
    return luaL_fileresult(L, 0, path);
}

/* io.open(path [, mode]) */
static int rank_open(lua_State *L)
{
    const int nargs = lua_gettop(L);
    if (!shadowing()) return call_lua_own(L, nargs);
    const char *path = luaL_checkstring(L, 1);
    const char *mode = luaL_optstring(L, 2, "r");
    luaL_argcheck(L, valid_mode(mode), 2, "invalid mode");
    const bool writes = mode[0] != 'r' || strchr(mode, '+');
    if (!push_real_name(L, path)) return writes ? luaL_fileresult(L, 0, path) : call_lua_own(L, nargs);
    int fd = shadow_of(L);
    struct stat st;
    /* a file the script did not write; a device (/dev/null: plot.live's
     * sink on these ranks), a FIFO or a socket, which are not copies */
    if (fd == NO_SHADOW && (!writes || (stat(path, &st) == 0 && !S_ISREG(st.st_mode))))
        return call_lua_own(L, nargs);
    if (fd == GONE && mode[0] == 'r') return fail_with(L, ENOENT, path);
    if (fd < 0) { /* a shadow stands for a file rank 0 made: only a new one is probed */
        if (!may_write(path, mode) || (fd = new_shadow(fd == NO_SHADOW ? path : NULL, mode)) < 0)
            return luaL_fileresult(L, 0, path);
        set_shadow(L, fd);
    }
    return push_shadow_file(L, fd, mode, path);
}

/* io.lines' iterator over a shadow: the file's lines, closed at their end
 * (as io.lines closes a file it opened). Upvalues: f:lines' iterator, f. */
static int shadow_lines_next(lua_State *L)
{
    lua_settop(L, 0); /* the for loop's state and control value, both nil */
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_call(L, 0, LUA_MULTRET);
    if (lua_gettop(L) == 0 || lua_isnil(L, 1)) {
        lua_getfield(L, lua_upvalueindex(2), "close");
        lua_pushvalue(L, lua_upvalueindex(2));
        lua_call(L, 1, 0);
    }
    return lua_gettop(L);
}

/* io.lines([path, formats...]) */
static int rank_lines(lua_State *L)
{
    const int nargs = lua_gettop(L);
    if (!shadowing() || lua_type(L, 1) != LUA_TSTRING) return call_lua_own(L, nargs);
    if (!push_real_name(L, lua_tostring(L, 1))) return call_lua_own(L, nargs);
    const int fd = shadow_of(L);
    if (fd == NO_SHADOW) return call_lua_own(L, nargs);
    if (fd == GONE) return luaL_error(L, "cannot open file '%s' (%s)", lua_tostring(L, 1), strerror(ENOENT));
    lua_pop(L, 1);
    if (push_shadow_file(L, fd, "r", lua_tostring(L, 1)) != 1)
        return luaL_error(L, "%s", lua_tostring(L, -2)); /* io.lines raises what io.open returns */
    const int file = lua_gettop(L);
    lua_getfield(L, file, "lines"); /* f:lines(formats...) */
    lua_pushvalue(L, file);
    for (int k = 2; k <= nargs; k++) lua_pushvalue(L, k);
    lua_call(L, nargs, 1);
    lua_pushvalue(L, file);
    lua_pushcclosure(L, shadow_lines_next, 2);
    lua_pushnil(L);
    lua_pushnil(L);
    lua_pushvalue(L, file); /* the for loop's to-be-closed value, as io.lines gives */
    return 4;
}

/* io.input([file]) and io.output([file]): a path opens through io.open
 * (upvalue 2, the wrapped one) with mode, and Lua's own function (upvalue
 * 1) takes the file. */
static int rank_default_file(lua_State *L, const char *mode)
{
    if (!shadowing() || lua_type(L, 1) != LUA_TSTRING) return call_lua_own(L, lua_gettop(L));
    const char *path = lua_tostring(L, 1);
    lua_settop(L, 1);
    lua_pushvalue(L, lua_upvalueindex(2));
    lua_pushvalue(L, 1);
    lua_pushstring(L, mode);
    lua_call(L, 2, 3); /* the file, or nil, the message, errno */
    if (lua_isnil(L, -3))
        return luaL_error(L, "cannot open file '%s' (%s)", path, strerror((int)lua_tointeger(L, -1)));
    lua_pop(L, 2);
    lua_replace(L, 1);
    return call_lua_own(L, 1);
}

static int rank_input(lua_State *L) { return rank_default_file(L, "r"); }
static int rank_output(lua_State *L) { return rank_default_file(L, "w"); }

/* os.remove(path) */
static int rank_remove(lua_State *L)
{
    if (!shadowing()) return call_lua_own(L, lua_gettop(L));
    const char *path = luaL_checkstring(L, 1);
    if (!push_real_name(L, path)) return luaL_fileresult(L, 0, path);
    const int fd = shadow_of(L);
    struct stat st;
    if (fd == GONE) return fail_with(L, ENOENT, path);
    if (fd == NO_SHADOW && lstat(path, &st) != 0) return luaL_fileresult(L, 0, path);
    set_shadow(L, GONE);
    lua_pushboolean(L, 1);
    return 1;
}

/* os.rename(from, to) */
static int rank_rename(lua_State *L)
{
    if (!shadowing()) return call_lua_own(L, lua_gettop(L));
    const char *from = luaL_checkstring(L, 1), *to = luaL_checkstring(L, 2);
    if (!push_real_name(L, from)) return luaL_fileresult(L, 0, NULL);
    const int fd = shadow_of(L);
    struct stat st;
    if (fd == GONE) return fail_with(L, ENOENT, NULL);
    if (fd == NO_SHADOW && lstat(from, &st) != 0) return luaL_fileresult(L, 0, NULL);
    if (!push_real_name(L, to)) return luaL_fileresult(L, 0, NULL);
    if (!lua_rawequal(L, -1, -2)) { /* one file under two spellings: nothing moves */
        set_shadow(L, fd); /* to's shadow is from's, or none: the disk's file rank 0 renames */
        lua_pop(L, 1);
        put_shadow(L, GONE); /* fd is to's now */
    }
    lua_pushboolean(L, 1);
    return 1;
}

const char *sx_lua_rank_file(lua_State *L, const char *path)
{
    int fd = NO_SHADOW;
    if (shadowing() && push_real_name(L, path)) {
        fd = shadow_of(L);
        lua_pop(L, 1);
    }
    if (fd == GONE) return lua_pushliteral(L, ""); /* no such file, as on rank 0 */
    if (fd == NO_SHADOW) return lua_pushstring(L, path);
    return lua_pushfstring(L, "/proc/self/fd/%d", fd);
}

/* Replaces lib.name by fn, with Lua's own function as its first upvalue
 * and `extra` more values from the stack's top. */
static void wrap(lua_State *L, const char *lib, const char *name, lua_CFunction fn, int extra)
{
    if (lua_getglobal(L, lib) != LUA_TTABLE) { /* a script's state without that library */
        lua_pop(L, 1 + extra);
        return;
    }
    if (lua_getfield(L, -1, name) != LUA_TFUNCTION) {
        lua_pop(L, 2 + extra);
        return;
    }
    lua_insert(L, -2 - extra); /* own, extras..., table */
    lua_insert(L, -2 - extra); /* table, own, extras... */
    lua_pushcclosure(L, fn, 1 + extra);
    lua_setfield(L, -2, name);
    lua_pop(L, 1);
}

void sx_lua_rank_files_open(lua_State *L)
{
    wrap(L, "io", "open", rank_open, 0);
    wrap(L, "io", "lines", rank_lines, 0);
    wrap(L, "os", "remove", rank_remove, 0);
    wrap(L, "os", "rename", rank_rename, 0);
    for (int k = 0; k < 2; k++) {
        if (lua_getglobal(L, "io") != LUA_TTABLE) {
            lua_pop(L, 1);
            return;
        }
        lua_getfield(L, -1, "open"); /* the wrapped io.open */
        lua_remove(L, -2);
        wrap(L, "io", k ? "output" : "input", k ? rank_output : rank_input, 1);
    }
}
