/* Standard input under mpirun: mpirun gives it to rank 0 alone, and every
 * rank runs the script, so a script's io.read() had rank 0's line on rank 0
 * and nil elsewhere. While the ranks share models (seixo.decompose, on by
 * default) a read of standard input is rank 0's for every rank: rank 0
 * reads, and its values (or its error) go to the others, as the script
 * itself does for `seixo -` (sx_lua_parallel_root_text). So every rank must
 * read alike, as it makes every call that changes a model; a read some
 * ranks skip stops the run with the ranks' calls named, never a hang.
 *
 * Wrapped: io.read and io.lines() (no path) while the default input is
 * standard input. Not io.stdin:read: the file handles' methods are every
 * file's, and a method called from a wrapper names neither itself nor the
 * script in its errors. Files the script opens are rank_files.c's. */
#include "bindings.h"
#include "seixo_lua.h"

#include <stdlib.h>
#include <string.h>

/* Lua values in a byte string: a tag, then an integer's or a float's 8
 * bytes, or a string's length (8 bytes) and bytes; nil (Lua's fail at the
 * end of the input) is the tag alone. */
typedef struct packed {
    char *bytes;
    size_t n, cap;
    bool oom;
} packed;

static void put(packed *p, const void *data, size_t len)
{
    if (p->oom) return;
    if (p->n + len > p->cap) {
        size_t cap = p->cap ? 2 * p->cap : 64;
        while (cap < p->n + len) cap *= 2;
        char *q = realloc(p->bytes, cap);
        if (!q) {
            p->oom = true;
            return;
        }
        p->bytes = q, p->cap = cap;
    }
    memcpy(p->bytes + p->n, data, len);
    p->n += len;
}

static void pack_value(lua_State *L, int idx, packed *p)
{
    char tag = 'x';
    if (lua_type(L, idx) == LUA_TNUMBER) tag = lua_isinteger(L, idx) ? 'i' : 'f';
    else if (lua_type(L, idx) == LUA_TSTRING) tag = 's';
    put(p, &tag, 1);
    if (tag == 'i') {
        const int64_t v = (int64_t)lua_tointeger(L, idx);
        put(p, &v, sizeof v);
    } else if (tag == 'f') {
        const double v = lua_tonumber(L, idx);
        put(p, &v, sizeof v);
    } else if (tag == 's') {
        size_t len;
        const char *s = lua_tolstring(L, idx, &len);
        const uint64_t n = len;
        put(p, &n, sizeof n);
        put(p, s, len);
    }
}

/* Pushes the values of bytes[0, n); returns their count. */
static int unpack_values(lua_State *L, const char *bytes, size_t n)
{
    int count = 0;
    for (size_t at = 0; at < n; count++) {
        luaL_checkstack(L, 1, "too many values read");
        const char tag = bytes[at++];
        if (tag == 'i') {
            int64_t v;
            memcpy(&v, bytes + at, sizeof v);
            at += sizeof v;
            lua_pushinteger(L, (lua_Integer)v);
        } else if (tag == 'f') {
            double v;
            memcpy(&v, bytes + at, sizeof v);
            at += sizeof v;
            lua_pushnumber(L, v);
        } else if (tag == 's') {
            uint64_t len;
            memcpy(&len, bytes + at, sizeof len);
            at += sizeof len;
            lua_pushlstring(L, bytes + at, (size_t)len);
            at += (size_t)len;
        } else {
            lua_pushnil(L);
        }
    }
    return count;
}

/* Rank 0's read: the function and its arguments are the stack above base. */
typedef struct read_call {
    lua_State *L;
    int base;
} read_call;

static char *rank0_read(void *ud, size_t *len, int *mark)
{
    read_call *c = ud;
    lua_State *L = c->L;
    const int nargs = lua_gettop(L) - c->base - 1;
    *mark = lua_pcall(L, nargs, LUA_MULTRET, 0);
    packed p = {0};
    for (int k = c->base + 1; k <= lua_gettop(L); k++) pack_value(L, k, &p);
    lua_settop(L, c->base);
    if (p.oom) { /* every rank raises it, rank 0's way */
        free(p.bytes);
        p = (packed){0};
        lua_pushliteral(L, "out of memory for the values read");
        pack_value(L, lua_gettop(L), &p);
        lua_pop(L, 1);
        *mark = LUA_ERRMEM;
    }
    if (!p.bytes) p.bytes = malloc(1); /* no value: an empty text, not the end */
    *len = p.n;
    return p.bytes;
}

/* Calls fn (at index fn) with the arguments first..last on rank 0 and
 * returns its values on every rank. */
static int shared_call(lua_State *L, int fn, int first, int last, const char *what)
{
    const int base = lua_gettop(L);
    lua_pushvalue(L, fn);
    for (int k = first; k <= last; k++) lua_pushvalue(L, k);
    read_call c = {L, base};
    size_t len;
    int status = LUA_OK;
    char *bytes = sx_lua_parallel_root_text(what, rank0_read, &c, &len, &status);
    lua_settop(L, base); /* the ranks above 0 did not call it */
    if (!bytes) return luaL_error(L, "%s: out of memory", what);
    const int n = unpack_values(L, bytes, len);
    free(bytes);
    if (status != LUA_OK) { /* rank 0's message, with the script's place as the script's own call has it */
        if (lua_type(L, -1) == LUA_TSTRING) {
            luaL_where(L, 1);
            lua_insert(L, -2);
            lua_concat(L, 2);
        }
        return lua_error(L);
    }
    return n;
}

/* Is the value at idx standard input? (upvalue 2 of the wrappers) */
static bool is_stdin(lua_State *L, int idx) { return lua_rawequal(L, idx, lua_upvalueindex(2)); }

/* Is the default input standard input? */
static bool input_is_stdin(lua_State *L)
{
    lua_getglobal(L, "io");
    lua_getfield(L, -1, "input");
    lua_call(L, 0, 1);
    const bool yes = is_stdin(L, -1);
    lua_pop(L, 2);
    return yes;
}

/* Lua's formats of read from argument first on: a count, or n, l, L or a
 * (a * before it allowed), checked here so that the error names the
 * script's call (Lua's read, called from C, could not). */
static void check_formats(lua_State *L, int first, int last)
{
    for (int k = first; k <= last; k++) {
        if (lua_type(L, k) == LUA_TNUMBER) {
            luaL_checkinteger(L, k);
            continue;
        }
        const char *f = luaL_checkstring(L, k);
        if (*f == '*') f++;
        luaL_argcheck(L, *f && strchr("nlLa", *f), k, "invalid format");
    }
}

/* io.read(formats...): upvalue 1 Lua's own, 2 io.stdin */
static int stdin_read(lua_State *L)
{
    const int nargs = lua_gettop(L);
    check_formats(L, 1, nargs);
    if (sx_lua_parallel_sharing() && input_is_stdin(L))
        return shared_call(L, lua_upvalueindex(1), 1, nargs, "io.read (standard input)");
    return sx_lua_call_own(L, nargs);
}

/* The iterator of lines of standard input: upvalue 1 the read method, 2
 * io.stdin, 3 on a table of the formats. */
static int stdin_lines_next(lua_State *L)
{
    lua_settop(L, 0);
    lua_pushvalue(L, lua_upvalueindex(2));
    const int nformats = (int)lua_rawlen(L, lua_upvalueindex(3));
    luaL_checkstack(L, nformats, "too many formats");
    for (int k = 1; k <= nformats; k++) lua_rawgeti(L, lua_upvalueindex(3), k);
    if (nformats == 0) lua_pushliteral(L, "l");
    return shared_call(L, lua_upvalueindex(1), 1, lua_gettop(L), "io.lines (standard input)");
}

static int push_stdin_lines(lua_State *L, int first, int last)
{
    lua_getglobal(L, "io");
    lua_getfield(L, -1, "stdin");
    lua_getfield(L, -1, "read"); /* the file handles' method */
    lua_insert(L, -2); /* io, read, stdin */
    lua_createtable(L, last - first + 1, 0);
    for (int k = first; k <= last; k++) {
        lua_pushvalue(L, k);
        lua_rawseti(L, -2, k - first + 1);
    }
    lua_pushcclosure(L, stdin_lines_next, 3);
    return 1;
}

/* io.lines([path, formats...]): upvalue 1 the function wrapped, 2 io.stdin */
static int stdin_lines(lua_State *L)
{
    const int nargs = lua_gettop(L);
    if (sx_lua_parallel_sharing() && lua_isnoneornil(L, 1) && input_is_stdin(L)) {
        check_formats(L, 2, nargs);
        return push_stdin_lines(L, 2, nargs);
    }
    return sx_lua_call_own(L, nargs);
}

/* table[name] = closure(fn; table[name], io.stdin) */
static void wrap_with_stdin(lua_State *L, int table, const char *name, lua_CFunction fn, int stdin_at)
{
    lua_getfield(L, table, name);
    lua_pushvalue(L, stdin_at);
    lua_pushcclosure(L, fn, 2);
    lua_setfield(L, table, name);
}

void sx_lua_rank_stdin_open(lua_State *L)
{
    if (lua_getglobal(L, "io") != LUA_TTABLE) {
        lua_pop(L, 1);
        return;
    }
    const int io = lua_gettop(L);
    lua_getfield(L, io, "stdin");
    const int in = lua_gettop(L);
    wrap_with_stdin(L, io, "read", stdin_read, in);
    wrap_with_stdin(L, io, "lines", stdin_lines, in);
    lua_pop(L, 2);
}
