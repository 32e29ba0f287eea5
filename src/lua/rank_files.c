/* Files under mpirun. Every rank runs the script, so every rank would write
 * each file the script writes: a log opened with "a" would get each line
 * once per rank, and ranks opening one file with "w" truncate each other's
 * lines at their own pace. While the ranks share models (seixo.decompose,
 * on by default: sx_lua_parallel_sharing), rank 0 alone writes the real files; a
 * rank above 0 writes a shadow, a private copy of the file in a folder of
 * its own, and reads a file back from its shadow: as it made the same
 * calls as rank 0, its shadow holds rank 0's bytes, without waiting for
 * rank 0 to have written them (the ranks are not in step outside a cycle)
 * and on a disk rank 0 may not share.
 *
 * Wrapped on ranks above 0: io.open, io.lines, io.input and io.output (a
 * path: through io.open), dofile and loadfile (read from the shadow),
 * os.remove and os.rename (a shadow is removed or renamed; the real file
 * is rank 0's to change). (On rank 0 too, where
 * they change nothing, for the names written while the ranks do not share
 * files: drop_shadow.) A name the script removed
 * or renamed away is remembered as gone, so a rank that runs ahead does
 * not find rank 0's file still there. Devices (/dev/null), FIFOs and
 * sockets are not shadowed. A write that rank 0 would be refused (no
 * folder, no permission) is refused alike: the real file is probed first,
 * without being changed. Of a file that was on the disk before the run
 * and that the script did not write, the disk answers, as it is when the
 * rank asks (rank 0 may have changed it already). C functions that read a
 * file the script may have written (an STL mesh, a clump template's
 * spheres) take its path through sx_lua_rank_file; a file every rank can
 * make alike and the script may read back or append to (a history's CSV)
 * is written by the others into a shadow (sx_lua_rank_shadow_new, and
 * sx_lua_rank_shadow_take once every rank wrote its own); after rank 0 has
 * written a file for every rank (m:save, m:output, os.tmpname's),
 * sx_lua_rank_file_written sends the others to the disk for it, and
 * remembers it as there: a rank that runs late removes or renames it
 * after rank 0 did, and must not find it missing. */
#define _XOPEN_SOURCE 700 /* realpath, mkdtemp */
#include "bindings.h"
#include "seixo_lua.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char shadows_key[] = "seixo.shadows"; /* registry: real name -> shadow's path, or false: gone */
static char shadow_dir[PATH_MAX];                  /* this rank's folder of shadows, made with the first */
static unsigned shadow_count;                      /* the shadows made, which name them */

/* Rank 0's files are the real ones when this process is a rank above 0 of shared models. */
static bool shadowing(void) { return !sx_lua_parallel_writes(sx_lua_parallel_sharing()); }

/* Lua's modes: r, w or a, then + maybe, then b's. */
static bool valid_mode(const char *mode)
{
    if (!*mode || !strchr("rwa", *mode)) return false;
    mode++;
    if (*mode == '+') mode++;
    return strspn(mode, "b") == strlen(mode);
}

/* The folder of path into dir (PATH_MAX): "." for a bare name; the name
 * after it in *base. False with errno if it does not fit. */
static bool folder_of(const char *path, char *dir, const char **base)
{
    const char *slash = strrchr(path, '/');
    *base = slash ? slash + 1 : path;
    const size_t n = !slash ? 1 : slash == path ? 1 : (size_t)(slash - path);
    if (n >= PATH_MAX) {
        errno = ENAMETOOLONG;
        return false;
    }
    memcpy(dir, slash ? path : ".", n);
    dir[n] = '\0';
    return true;
}

/* Whether rank 0 may add or remove a name in path's folder (false with
 * errno as the call would set it). */
static bool folder_writable(const char *path)
{
    char dir[PATH_MAX];
    const char *base;
    return folder_of(path, dir, &base) && access(dir, W_OK | X_OK) == 0;
}

/* Pushes the file's absolute name (its folder resolved, so that two
 * spellings of one file find one shadow); false with errno (fopen's) if
 * the folder is not there or the name is no file's. */
static bool push_real_name(lua_State *L, const char *path)
{
    char dir[PATH_MAX], real[PATH_MAX];
    const char *base;
    if (!folder_of(path, dir, &base)) return false;
    if (!*base) { /* "" or a folder's "x/" */
        errno = *path ? EISDIR : ENOENT;
        return false;
    }
    if (!realpath(dir, real)) return false;
    lua_pushfstring(L, "%s/%s", real, base);
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

/* What the table says of a file: nothing (the disk's), a shadow, gone, or
 * on the disk, written there by rank 0 for every rank. */
enum shadow { NO_SHADOW, SHADOWED, GONE, ON_DISK };

/* The shadow of the file named at the top of the stack; its path into
 * path (PATH_MAX) when SHADOWED. */
static enum shadow shadow_of(lua_State *L, char *path)
{
    push_shadows(L);
    lua_pushvalue(L, -2);
    const int t = lua_gettable(L, -2);
    const enum shadow s = t == LUA_TSTRING    ? SHADOWED
                          : t == LUA_TBOOLEAN ? (lua_toboolean(L, -1) ? ON_DISK : GONE)
                                              : NO_SHADOW;
    if (s == SHADOWED) snprintf(path, PATH_MAX, "%s", lua_tostring(L, -1));
    lua_pop(L, 2);
    return s;
}

/* Records s (with the shadow's path when SHADOWED) for the name at the
 * top of the stack; a shadow it replaces is deleted unless keep. */
static void set_shadow(lua_State *L, enum shadow s, const char *path, bool keep)
{
    char old[PATH_MAX];
    if (!keep && shadow_of(L, old) == SHADOWED && !(s == SHADOWED && strcmp(old, path) == 0)) unlink(old);
    push_shadows(L);
    lua_pushvalue(L, -2);
    if (s == SHADOWED) lua_pushstring(L, path);
    else if (s == GONE || s == ON_DISK) lua_pushboolean(L, s == ON_DISK);
    else lua_pushnil(L);
    lua_settable(L, -3);
    lua_pop(L, 1);
}

/* The names this rank wrote, removed or renamed itself while the ranks
 * did not share files (a set in the registry): when they share again, the
 * other ranks' shadows of them are stale (sx_lua_rank_files_alone). */
static const char alone_key[] = "seixo.alone_writes";

/* While the ranks do not share files (seixo.decompose(false)) this rank
 * writes, removes and renames the real file itself: a shadow of that name
 * made before would be stale once they share again, here and (the name is
 * noted) on the other ranks. */
static void drop_shadow(lua_State *L, const char *path)
{
    if (!push_real_name(L, path)) return;
    set_shadow(L, NO_SHADOW, NULL, false);
    if (sx_lua_parallel_alone()) {
        luaL_getsubtable(L, LUA_REGISTRYINDEX, alone_key);
        lua_pushvalue(L, -2);
        lua_pushboolean(L, 1);
        lua_settable(L, -3);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

static int by_name(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

char *sx_lua_rank_files_alone(lua_State *L, size_t *len)
{
    /* the names in sorted order: every rank then settles the union alike */
    size_t n = 0, total = 0, cap = 0;
    const char **name = NULL;
    bool ok = true;
    if (lua_getfield(L, LUA_REGISTRYINDEX, alone_key) == LUA_TTABLE)
        for (lua_pushnil(L); lua_next(L, -2); lua_pop(L, 1)) {
            if (n == cap) {
                const char **more = realloc(name, (cap = cap ? 2 * cap : 16) * sizeof *name);
                if (!more) {
                    ok = false;
                    lua_pop(L, 2);
                    break;
                }
                name = more;
            }
            name[n] = lua_tostring(L, -2); /* the set's key, alive while the set is */
            total += strlen(name[n++]) + 1;
        }
    char *names = ok ? malloc(total + 1) : NULL;
    if (names) {
        if (n) qsort(name, n, sizeof *name, by_name); /* (no list at all when none was noted) */
        *len = 0;
        for (size_t i = 0; i < n; i++) {
            const size_t k = strlen(name[i]) + 1;
            memcpy(names + *len, name[i], k);
            *len += k;
        }
    }
    free(name);
    lua_pop(L, 1);
    if (names) {
        lua_pushnil(L);
        lua_setfield(L, LUA_REGISTRYINDEX, alone_key);
    }
    return names;
}

char *sx_lua_rank_files_there(const char *names, size_t len, size_t n)
{
    char *there = malloc(n + 1);
    struct stat st;
    size_t i = 0;
    for (size_t at = 0; there && at < len; at += strlen(names + at) + 1) there[i++] = lstat(names + at, &st) == 0;
    return there;
}

void sx_lua_rank_files_settle(lua_State *L, const char *names, size_t len, const char *there)
{
    if (!shadowing()) return; /* rank 0 holds no shadow */
    size_t i = 0;
    for (size_t at = 0; at < len; at += strlen(names + at) + 1, i++) {
        lua_pushstring(L, names + at); /* a real name already */
        set_shadow(L, there[i] ? ON_DISK : GONE, NULL, false);
        lua_pop(L, 1);
    }
}

void sx_lua_rank_files_remove(void)
{
    DIR *dir = shadow_dir[0] ? opendir(shadow_dir) : NULL;
    if (!dir) return;
    char path[PATH_MAX + 256];
    for (struct dirent *e; (e = readdir(dir));) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        snprintf(path, sizeof path, "%s/%s", shadow_dir, e->d_name);
        unlink(path);
    }
    closedir(dir);
    rmdir(shadow_dir);
}

void sx_lua_rank_files_remove_now(void)
{
    if (!shadow_dir[0]) return;
    char path[PATH_MAX + 16];
    const size_t n = strlen(shadow_dir);
    memcpy(path, shadow_dir, n);
    path[n] = '/';
    for (unsigned k = 0; k < shadow_count; k++) { /* the shadows' names are their numbers */
        char digit[16];
        int d = 0;
        unsigned v = k;
        do digit[d++] = (char)('0' + v % 10);
        while ((v /= 10));
        for (int i = 0; i < d; i++) path[n + 1 + (size_t)i] = digit[d - 1 - i];
        path[n + 1 + (size_t)d] = '\0';
        unlink(path);
    }
    rmdir(shadow_dir);
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
    return folder_writable(path);
}

/* A new shadow, its path into shadow (PATH_MAX): holding the file at path
 * (not NULL) as it is now, or empty. False with errno. Opened to update
 * ("r+"), a shadow copies the file; opened to append, it starts empty:
 * rank 0 may be appending already, so what the file holds now is not what
 * it held when rank 0 opened it. A log appended by this run then reads
 * back alike on every rank; one that was there before the run holds, on
 * the ranks above 0, this run's lines. */
static bool new_shadow(const char *path, char *shadow)
{
    if (!shadow_dir[0]) {
        const char *tmp = getenv("TMPDIR");
        snprintf(shadow_dir, sizeof shadow_dir, "%s/seixo-rank%d-XXXXXX", tmp && *tmp ? tmp : "/tmp",
                 sx_lua_parallel_rank());
        if (!mkdtemp(shadow_dir)) {
            const int e = errno;
            shadow_dir[0] = '\0';
            errno = e;
            return false;
        }
        static bool at_exit;
        if (!at_exit) at_exit = atexit(sx_lua_rank_files_remove) == 0;
    }
    snprintf(shadow, PATH_MAX, "%s/%u", shadow_dir, shadow_count++);
    const int fd = open(shadow, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) return false;
    FILE *real = path ? fopen(path, "rb") : NULL;
    bool ok = !path || real;
    int why = ok ? 0 : errno;
    char buf[65536];
    size_t got;
    while (ok && real && (got = fread(buf, 1, sizeof buf, real)) > 0)
        if (write(fd, buf, got) != (ssize_t)got) ok = false, why = errno ? errno : EIO;
    if (ok && real && ferror(real)) ok = false, why = EIO;
    if (real) fclose(real);
    if (close(fd) != 0 && ok) ok = false, why = errno;
    if (!ok) {
        unlink(shadow);
        errno = why;
    }
    return ok;
}

static int close_shadow_file(lua_State *L)
{
    luaL_Stream *p = luaL_checkudata(L, 1, LUA_FILEHANDLE);
    return luaL_fileresult(L, fclose(p->f) == 0, NULL);
}

/* Opens a shadow (with mode's truncation and position) as a Lua file. */
static int push_shadow_file(lua_State *L, const char *shadow, const char *mode, const char *path)
{
    luaL_Stream *p = lua_newuserdatauv(L, sizeof *p, 0);
    p->closef = NULL; /* not a file until it opens */
    luaL_setmetatable(L, LUA_FILEHANDLE);
    if (!(p->f = fopen(shadow, mode))) return luaL_fileresult(L, 0, path);
    p->closef = close_shadow_file;
    return 1;
}

int sx_lua_call_own(lua_State *L, int nargs)
{
    lua_settop(L, nargs);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    /* called from here, Lua's function finds this C function, not the
     * script, where it names the place of its error: the script's place
     * goes in front, as the script's own call would have it */
    if (lua_pcall(L, nargs, LUA_MULTRET, 0) != LUA_OK) {
        if (lua_type(L, -1) == LUA_TSTRING) {
            luaL_where(L, 1);
            lua_insert(L, -2);
            lua_concat(L, 2);
        }
        return lua_error(L);
    }
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
    if (!shadowing()) { /* the arguments checked here, where an error names io.open */
        const char *path = luaL_checkstring(L, 1), *mode = luaL_optstring(L, 2, "r");
        luaL_argcheck(L, valid_mode(mode), 2, "invalid mode");
        if (mode[0] != 'r' || strchr(mode, '+')) drop_shadow(L, path);
        return sx_lua_call_own(L, nargs);
    }
    const char *path = luaL_checkstring(L, 1);
    const char *mode = luaL_optstring(L, 2, "r");
    luaL_argcheck(L, valid_mode(mode), 2, "invalid mode");
    const bool writes = mode[0] != 'r' || strchr(mode, '+');
    if (!push_real_name(L, path)) return writes ? luaL_fileresult(L, 0, path) : sx_lua_call_own(L, nargs);
    char shadow[PATH_MAX];
    const enum shadow s = shadow_of(L, shadow);
    struct stat st;
    /* a file the script did not write; a device (/dev/null: plot.live's
     * sink on these ranks), a FIFO or a socket, which are not copies */
    if ((s == NO_SHADOW || s == ON_DISK) && (!writes || (stat(path, &st) == 0 && !S_ISREG(st.st_mode))))
        return sx_lua_call_own(L, nargs);
    if (s == GONE && mode[0] == 'r') return fail_with(L, ENOENT, path);
    if (s != SHADOWED) { /* a shadow stands for a file rank 0 made: only a new one is probed */
        if (!may_write(path, mode) || !new_shadow(s != GONE && mode[0] == 'r' ? path : NULL, shadow))
            return luaL_fileresult(L, 0, path);
        set_shadow(L, SHADOWED, shadow, false);
    }
    return push_shadow_file(L, shadow, mode, path);
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
    if (!lua_isnoneornil(L, 1)) luaL_checkstring(L, 1); /* io.lines' own check, naming it */
    if (!shadowing() || lua_type(L, 1) != LUA_TSTRING) return sx_lua_call_own(L, nargs);
    if (!push_real_name(L, lua_tostring(L, 1))) return sx_lua_call_own(L, nargs);
    char shadow[PATH_MAX];
    const enum shadow s = shadow_of(L, shadow);
    if (s == NO_SHADOW || s == ON_DISK) return sx_lua_call_own(L, nargs);
    lua_pop(L, 1);
    /* io.lines' own error when the file cannot be opened */
    if (s == GONE) return luaL_error(L, "cannot open file '%s' (%s)", lua_tostring(L, 1), strerror(ENOENT));
    if (push_shadow_file(L, shadow, "r", lua_tostring(L, 1)) != 1) /* nil, the message, errno */
        return luaL_error(L, "cannot open file '%s' (%s)", lua_tostring(L, 1), strerror((int)lua_tointeger(L, -1)));
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

/* A file's chunk read from its shadow, under the file's own name (a
 * script that takes anything from its path finds the same on every rank),
 * with mode and a first line starting with # skipped, as luaL_loadfilex;
 * a name the script removed, an error as on rank 0. Pushes the chunk, or
 * the message; returns the status. */
static int load_shadow(lua_State *L, const char *path, const char *shadow, enum shadow s, const char *mode)
{
    /* Lua's own messages (luaL_loadfilex's) */
    FILE *f = s == GONE ? NULL : fopen(shadow, "rb");
    if (!f) {
        lua_pushfstring(L, "cannot open %s: %s", path, strerror(s == GONE ? ENOENT : errno));
        return LUA_ERRFILE;
    }
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    char piece[4096];
    size_t n;
    while ((n = fread(piece, 1, sizeof piece, f)) > 0) luaL_addlstring(&b, piece, n);
    const bool failed = ferror(f);
    fclose(f);
    luaL_pushresult(&b);
    if (failed) {
        lua_pop(L, 1);
        lua_pushfstring(L, "cannot read %s: %s", path, strerror(EIO));
        return LUA_ERRFILE;
    }
    size_t len;
    const char *text = lua_tolstring(L, -1, &len), *start = text, *end = text + len;
    if (end - start >= 3 && memcmp(start, "\xEF\xBB\xBF", 3) == 0) start += 3; /* a UTF-8 mark, as Lua skips it */
    if (start < end && *start == '#') { /* a first line such as #!/usr/bin/env seixo (its newline kept: the lines count alike) */
        const char *nl = memchr(start, '\n', (size_t)(end - start));
        start = nl ? nl : end;
    }
    lua_pushfstring(L, "@%s", path);
    const int status = luaL_loadbufferx(L, start, (size_t)(end - start), lua_tostring(L, -1), mode);
    lua_replace(L, -3); /* the chunk (or message) where the text was */
    lua_pop(L, 1);
    return status;
}

/* The shadow of a file the script wrote into shadow: SHADOWED or GONE,
 * else NO_SHADOW (the disk's file, as Lua's own functions read it). */
static enum shadow own_file(lua_State *L, const char *path, char *shadow)
{
    if (!shadowing() || !push_real_name(L, path)) return NO_SHADOW;
    const enum shadow s = shadow_of(L, shadow);
    lua_pop(L, 1);
    return s == SHADOWED || s == GONE ? s : NO_SHADOW;
}

/* loadfile(path[, mode[, env]]): a file the script wrote is read from its
 * shadow, as io.open reads it (a rank above 0 ran ahead of rank 0's
 * write: a params.lua it had just written was not there yet). */
static int rank_loadfile(lua_State *L)
{
    const int nargs = lua_gettop(L);
    char shadow[PATH_MAX];
    const enum shadow s = lua_type(L, 1) == LUA_TSTRING ? own_file(L, lua_tostring(L, 1), shadow) : NO_SHADOW;
    if (s == NO_SHADOW) return sx_lua_call_own(L, nargs);
    const char *mode = "t"; /* source only, as the executable's loadfile (chunks.c) */
    const bool env = !lua_isnone(L, 3);
    if (load_shadow(L, lua_tostring(L, 1), shadow, s, mode) != LUA_OK) {
        luaL_pushfail(L);
        lua_insert(L, -2);
        return 2; /* nil, the message, as loadfile */
    }
    if (env) { /* the chunk's first upvalue, its _ENV */
        lua_pushvalue(L, 3);
        if (!lua_setupvalue(L, -2, 1)) lua_pop(L, 1);
    }
    return 1;
}

static int dofile_results(lua_State *L, int status, lua_KContext ctx)
{
    (void)status;
    return lua_gettop(L) - (int)ctx; /* what the chunk returned, above the path (ctx 1) or nothing (0) */
}

/* dofile([path]): as loadfile, then the chunk runs (a continuation, so a
 * coroutine may yield inside it, as Lua's dofile allows) */
static int rank_dofile(lua_State *L)
{
    char shadow[PATH_MAX];
    const enum shadow s = lua_type(L, 1) == LUA_TSTRING ? own_file(L, lua_tostring(L, 1), shadow) : NO_SHADOW;
    if (s == NO_SHADOW) { /* Lua's own, called as the script would: its chunk's errors as they are */
        lua_pushvalue(L, lua_upvalueindex(1));
        lua_insert(L, 1);
        lua_callk(L, lua_gettop(L) - 1, LUA_MULTRET, 0, dofile_results);
        return dofile_results(L, 0, 0);
    }
    lua_settop(L, 1);
    if (load_shadow(L, lua_tostring(L, 1), shadow, s, "t") != LUA_OK) return lua_error(L);
    lua_callk(L, 0, LUA_MULTRET, 1, dofile_results);
    return dofile_results(L, 0, 1);
}

/* io.input([file]) and io.output([file]): a path opens through io.open
 * (upvalue 2, the wrapped one) with mode, and Lua's own function (upvalue
 * 1) takes the file. */
static int rank_default_file(lua_State *L, const char *mode)
{
    if (!shadowing() && lua_type(L, 1) == LUA_TSTRING && mode[0] == 'w') drop_shadow(L, lua_tostring(L, 1));
    if (!shadowing() || lua_type(L, 1) != LUA_TSTRING) return sx_lua_call_own(L, lua_gettop(L));
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
    return sx_lua_call_own(L, 1);
}

static int rank_input(lua_State *L) { return rank_default_file(L, "r"); }
static int rank_output(lua_State *L) { return rank_default_file(L, "w"); }

/* Whether a name the table says s of is there for rank 0 to remove or
 * rename: false with errno as the call would set it. */
static bool present(const char *path, enum shadow s)
{
    struct stat st;
    if (s == GONE) errno = ENOENT;
    return s == SHADOWED || s == ON_DISK || (s == NO_SHADOW && lstat(path, &st) == 0);
}

/* os.remove(path) */
static int rank_remove(lua_State *L)
{
    if (!shadowing()) {
        drop_shadow(L, luaL_checkstring(L, 1));
        return sx_lua_call_own(L, lua_gettop(L));
    }
    const char *path = luaL_checkstring(L, 1);
    if (!push_real_name(L, path)) return luaL_fileresult(L, 0, path);
    char shadow[PATH_MAX];
    if (!present(path, shadow_of(L, shadow)) || !folder_writable(path)) return luaL_fileresult(L, 0, path);
    set_shadow(L, GONE, NULL, false);
    lua_pushboolean(L, 1);
    return 1;
}

/* os.rename(from, to) */
static int rank_rename(lua_State *L)
{
    if (!shadowing()) {
        const char *from = luaL_checkstring(L, 1), *to = luaL_checkstring(L, 2);
        drop_shadow(L, from);
        drop_shadow(L, to);
        return sx_lua_call_own(L, lua_gettop(L));
    }
    const char *from = luaL_checkstring(L, 1), *to = luaL_checkstring(L, 2);
    if (!push_real_name(L, from)) return luaL_fileresult(L, 0, NULL);
    char shadow[PATH_MAX];
    const enum shadow s = shadow_of(L, shadow);
    if (!present(from, s) || !push_real_name(L, to)) return luaL_fileresult(L, 0, NULL);
    /* rank 0 must be allowed to change both folders */
    if (!folder_writable(from) || !folder_writable(to)) return luaL_fileresult(L, 0, NULL);
    if (!lua_rawequal(L, -1, -2)) { /* one file under two spellings: nothing moves */
        /* to's shadow is from's, or none: the disk's file rank 0 renames */
        set_shadow(L, s, shadow, false);
        lua_pop(L, 1);
        set_shadow(L, GONE, NULL, true); /* from's shadow is to's now */
    }
    lua_pushboolean(L, 1);
    return 1;
}

const char *sx_lua_rank_file(lua_State *L, const char *path)
{
    enum shadow s = NO_SHADOW;
    char shadow[PATH_MAX];
    if (shadowing() && push_real_name(L, path)) {
        s = shadow_of(L, shadow);
        lua_pop(L, 1);
    }
    if (s == GONE) return lua_pushliteral(L, ""); /* no such file, as on rank 0 */
    return lua_pushstring(L, s == SHADOWED ? shadow : path);
}

const char *sx_lua_rank_shadow_new(lua_State *L)
{
    char shadow[PATH_MAX];
    if (!shadowing() || !new_shadow(NULL, shadow)) return NULL;
    return lua_pushstring(L, shadow);
}

void sx_lua_rank_shadow_take(lua_State *L, const char *path, const char *shadow)
{
    if (!push_real_name(L, path)) {
        remove(shadow);
        return;
    }
    set_shadow(L, SHADOWED, shadow, false);
    lua_pop(L, 1);
}

void sx_lua_rank_file_written(lua_State *L, const char *path)
{
    if (!shadowing()) { /* this rank wrote it itself: noted while the ranks do not share files */
        drop_shadow(L, path);
        return;
    }
    if (!push_real_name(L, path)) return;
    set_shadow(L, ON_DISK, NULL, false);
    lua_pop(L, 1);
}

void sx_lua_rank_files_open(lua_State *L)
{
    sx_lua_wrap(L, "io", "open", rank_open, 0);
    sx_lua_wrap(L, "io", "lines", rank_lines, 0);
    sx_lua_wrap(L, "os", "remove", rank_remove, 0);
    sx_lua_wrap(L, "os", "rename", rank_rename, 0);
    sx_lua_wrap(L, "_G", "dofile", rank_dofile, 0);
    sx_lua_wrap(L, "_G", "loadfile", rank_loadfile, 0);
    for (int k = 0; k < 2; k++) {
        if (lua_getglobal(L, "io") != LUA_TTABLE) {
            lua_pop(L, 1);
            return;
        }
        lua_getfield(L, -1, "open"); /* the wrapped io.open */
        lua_remove(L, -2);
        sx_lua_wrap(L, "io", k ? "output" : "input", k ? rank_output : rank_input, 1);
    }
}
