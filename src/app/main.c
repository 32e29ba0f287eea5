/* seixo: the executable. `seixo script.lua [args]` runs a script,
 * `seixo -e stat` a chunk, and `seixo` alone (or -i) an interactive
 * session; the `seixo` module is preloaded and global.
 *
 * Modelled on the reference interpreter lua.c: everything runs inside one
 * protected call (pmain), every chunk under lua_pcall with a message
 * handler (with a traceback on -t). A SIGINT interrupts a running cycle
 * through the bindings, or else the running Lua code through a hook; either
 * way the error unwinds to the prompt with the models intact. The handler
 * resets itself, so a second SIGINT ends a process that does not respond. */
#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifdef SX_HAVE_READLINE
#include <readline/history.h>
#include <readline/readline.h>
#endif

#include "seixo_lua.h"

static const char *const progname = "seixo";
static lua_State *global_L;  // the state the SIGINT handler stops
static bool show_traceback;  // -t

typedef struct options {
    int script;        // argv index of the script; argc when there is none
    bool interactive;  // -i
    bool has_chunks;   // some -e
} options;

static void usage(FILE *out)
{
    fprintf(out,
            "usage: %s [options] [script [args]]\n"
            "  -e stat        run the Lua chunk 'stat' (may be repeated)\n"
            "  -i             enter the interactive mode after the script\n"
            "  -t             show a traceback with each error\n"
            "  -v, --version  show the version\n"
            "  -h, --help     show this help\n"
            "  --             stop handling options\n"
            "  -              run the standard input as the script\n"
            "With no script and no -e, seixo starts the interactive mode.\n",
            progname);
}

static void message(const char *msg)
{
    fprintf(stderr, "%s: %s\n", progname, msg);
    fflush(stderr);
}

/* Prints the error message on the stack top when status is an error. */
static int report(lua_State *L, int status)
{
    if (status != LUA_OK) {
        const char *msg = lua_tostring(L, -1);
        message(msg ? msg : "(error object is not a string)");
        lua_pop(L, 1);
    }
    return status;
}

/* ------------------------------------------------------ protected calls */

static int msghandler(lua_State *L)
{
    const char *msg = lua_tostring(L, 1);
    if (!msg) {
        if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING)
            msg = lua_tostring(L, -1);
        else
            msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    }
    if (show_traceback)
        luaL_traceback(L, L, msg, 1);
    else
        lua_pushstring(L, msg);
    return 1;
}

static void stop_hook(lua_State *L, lua_Debug *ar)
{
    (void)ar;
    lua_sethook(L, NULL, 0, 0);
    luaL_error(L, "interrupted");
}

static void on_sigint(int sig)
{
    (void)sig;
    if (sx_lua_interrupt_all() == 0)
        lua_sethook(global_L, stop_hook, LUA_MASKCALL | LUA_MASKRET | LUA_MASKLINE | LUA_MASKCOUNT, 1);
}

static void set_sigint(void (*handler)(int))
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = handler;
    sa.sa_flags = SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
}

/* Calls the function below its narg arguments with SIGINT caught. */
static int docall(lua_State *L, int narg, int nres)
{
    const int base = lua_gettop(L) - narg;
    lua_pushcfunction(L, msghandler);
    lua_insert(L, base);
    global_L = L;
    set_sigint(on_sigint);
    const int status = lua_pcall(L, narg, nres, base);
    set_sigint(SIG_DFL);
    /* an interrupt that came when no Lua code was left to stop */
    if (lua_gethook(L) == stop_hook) lua_sethook(L, NULL, 0, 0);
    lua_remove(L, base);
    return status;
}

static int run_chunk(lua_State *L, const char *code)
{
    int status = luaL_loadbuffer(L, code, strlen(code), "=(command line)");
    if (status == LUA_OK) status = docall(L, 0, 0);
    return report(L, status);
}

/* The script's arguments go to `...` as well as to the global `arg`. */
static int run_script(lua_State *L, char **argv, int script, int argc)
{
    const char *fname = strcmp(argv[script], "-") == 0 ? NULL : argv[script];
    int status = luaL_loadfile(L, fname);
    if (status == LUA_OK) {
        const int n = argc - script - 1;
        luaL_checkstack(L, n, "too many arguments to the script");
        for (int i = script + 1; i < argc; i++) lua_pushstring(L, argv[i]);
        status = docall(L, n, 0);
    }
    return report(L, status);
}

/* arg[0] is the script, arg[1...] its arguments, and the program and its
 * options the negative indices, as in lua.c. */
static void create_arg_table(lua_State *L, char **argv, int argc, int script)
{
    if (script == argc) script = 0;
    lua_createtable(L, argc - script - 1 > 0 ? argc - script - 1 : 0, script + 1);
    for (int i = 0; i < argc; i++) {
        lua_pushstring(L, argv[i]);
        lua_rawseti(L, -2, i - script);
    }
    lua_setglobal(L, "arg");
}

/* ------------------------------------------------------------------ REPL */

/* Reads one line, without its newline, onto the stack; false at the end of input. */
static bool push_line(lua_State *L, bool first, bool tty)
{
    const char *prompt = first ? "> " : ">> ";
#ifdef SX_HAVE_READLINE
    if (tty) {
        char *line = readline(prompt);
        if (!line) return false;
        lua_pushstring(L, line);
        free(line);
        return true;
    }
#endif
    if (tty) {
        fputs(prompt, stdout);
        fflush(stdout);
    }
    char *line = NULL;
    size_t cap = 0;
    ssize_t n = getline(&line, &cap, stdin);
    if (n < 0) {
        free(line);
        return false;
    }
    if (n > 0 && line[n - 1] == '\n') n--;
    lua_pushlstring(L, line, (size_t)n);
    free(line);
    return true;
}

/* Compiles "return <line>", so that an expression prints its value. On
 * success the chunk is on the stack above the line, else only the line. */
static int try_return(lua_State *L)
{
    const char *code = lua_pushfstring(L, "return %s;", lua_tostring(L, -1));
    const int status = luaL_loadbuffer(L, code, strlen(code), "=stdin");
    lua_remove(L, -2);
    if (status != LUA_OK) lua_pop(L, 1);
    return status;
}

/* A syntax error at the end of the text: the statement goes on. */
static bool incomplete(lua_State *L, int status)
{
    static const char eof[] = "<eof>";
    const size_t k = sizeof eof - 1;
    size_t len;
    const char *msg = lua_tolstring(L, -1, &len);
    return status == LUA_ERRSYNTAX && len >= k && strcmp(msg + len - k, eof) == 0;
}

/* Compiles the text at the stack top as a statement, reading more lines
 * while it is incomplete; leaves the whole text and the chunk (or message). */
static int multiline(lua_State *L, bool tty)
{
    for (;;) {
        size_t len;
        const char *code = lua_tolstring(L, -1, &len);
        const int status = luaL_loadbuffer(L, code, len, "=stdin");
        if (!incomplete(L, status) || !push_line(L, false, tty)) return status;
        lua_remove(L, -2);  // the message
        lua_pushliteral(L, "\n");
        lua_insert(L, -2);
        lua_concat(L, 3);
    }
}

/* Reads and compiles one entry: -1 at the end of input, else the load
 * status with the chunk (or message) as the only value on the stack. */
static int load_entry(lua_State *L, bool tty)
{
    lua_settop(L, 0);
    if (!push_line(L, true, tty)) return -1;
    int status = try_return(L);
    if (status != LUA_OK) status = multiline(L, tty);
#ifdef SX_HAVE_READLINE
    if (tty && lua_rawlen(L, 1) > 0) add_history(lua_tostring(L, 1));
#endif
    lua_remove(L, 1);
    return status;
}

/* Appends the string on the stack top to the string at acc. */
static void append(lua_State *L, int acc)
{
    lua_pushvalue(L, acc);
    lua_insert(L, -2);
    lua_concat(L, 2);
    lua_replace(L, acc);
}

/* A table shown one level deep, so vectors and energy tables read at a
 * glance: {1, 2, 3}, {kinetic = 0.5, strain = 0}. */
static void push_shallow(lua_State *L, int t)
{
    lua_pushliteral(L, "{");
    const int acc = lua_gettop(L);
    const lua_Integer n = (lua_Integer)lua_rawlen(L, t);
    const char *sep = "";
    for (lua_Integer i = 1; i <= n; i++, sep = ", ") {
        lua_rawgeti(L, t, i);
        lua_pushfstring(L, "%s%s", sep, luaL_tolstring(L, -1, NULL));
        append(L, acc);
        lua_settop(L, acc);
    }
    lua_pushnil(L);
    while (lua_next(L, t)) {
        const int key = lua_gettop(L) - 1;
        const bool in_array = lua_isinteger(L, key) && lua_tointeger(L, key) >= 1 && lua_tointeger(L, key) <= n;
        if (!in_array) {
            const char *value = luaL_tolstring(L, key + 1, NULL);
            if (lua_type(L, key) == LUA_TSTRING)
                lua_pushfstring(L, "%s%s = %s", sep, lua_tostring(L, key), value);
            else
                lua_pushfstring(L, "%s[%s] = %s", sep, luaL_tolstring(L, key, NULL), value);
            append(L, acc);
            sep = ", ";
        }
        lua_settop(L, key);
    }
    lua_pushliteral(L, "}");
    append(L, acc);
}

/* Prints its arguments with the global print, tables without __tostring
 * shown shallowly. */
static int show(lua_State *L)
{
    const int n = lua_gettop(L);
    luaL_checkstack(L, LUA_MINSTACK, "too many results to print");
    for (int i = 1; i <= n; i++) {
        if (lua_type(L, i) != LUA_TTABLE) continue;
        if (luaL_getmetafield(L, i, "__tostring") != LUA_TNIL) {
            lua_pop(L, 1);
            continue;
        }
        push_shallow(L, i);
        lua_replace(L, i);
    }
    lua_getglobal(L, "print");
    lua_insert(L, 1);
    lua_call(L, n, 0);
    return 0;
}

static void repl(lua_State *L)
{
    const bool tty = isatty(STDIN_FILENO);
    if (tty) printf("seixo %s (%s); Ctrl-D quits, Ctrl-C stops a cycle\n", SX_VERSION, LUA_RELEASE);
    int status;
    while ((status = load_entry(L, tty)) != -1) {
        if (status == LUA_OK) status = docall(L, 0, LUA_MULTRET);
        if (status == LUA_OK && lua_gettop(L) > 0) {
            lua_pushcfunction(L, show);
            lua_insert(L, 1);
            status = docall(L, lua_gettop(L) - 1, 0);
        }
        report(L, status);
    }
    lua_settop(L, 0);
    if (tty) putchar('\n');
}

/* ----------------------------------------------------------------- main */

/* Runs the -e chunks before the script, in order; false after a failure. */
static bool run_chunks(lua_State *L, char **argv, int script)
{
    for (int i = 1; i < script; i++)
        if (strcmp(argv[i], "-e") == 0 && run_chunk(L, argv[++i]) != LUA_OK) return false;
    return true;
}

/* The whole session, inside one protected call. */
static int pmain(lua_State *L)
{
    const int argc = (int)lua_tointeger(L, 1);
    char **argv = lua_touserdata(L, 2);
    const options *o = lua_touserdata(L, 3);
    lua_settop(L, 0);
    luaL_checkversion(L);
    luaL_openlibs(L);
    sx_lua_open(L);
    create_arg_table(L, argv, argc, o->script);
    bool ok = run_chunks(L, argv, o->script);
    if (ok && o->script < argc) ok = run_script(L, argv, o->script, argc) == LUA_OK;
    if (ok && (o->interactive || (o->script == argc && !o->has_chunks))) repl(L);
    lua_pushboolean(L, ok);
    return 1;
}

enum parsed { RUN, DONE, BAD };

static enum parsed parse(int argc, char **argv, options *o)
{
    int i = 1;
    for (; i < argc; i++) {
        const char *a = argv[i];
        if (a[0] != '-' || strcmp(a, "-") == 0) break;  // the script
        if (strcmp(a, "--") == 0) {
            i++;
            break;
        }
        if (strcmp(a, "-e") == 0) {
            if (++i == argc) {
                message("'-e' needs an argument");
                return BAD;
            }
            o->has_chunks = true;
        } else if (strcmp(a, "-i") == 0) {
            o->interactive = true;
        } else if (strcmp(a, "-t") == 0) {
            show_traceback = true;
        } else if (strcmp(a, "-v") == 0 || strcmp(a, "--version") == 0) {
            printf("seixo %s (%s)\n", SX_VERSION, LUA_RELEASE);
            return DONE;
        } else if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage(stdout);
            return DONE;
        } else {
            fprintf(stderr, "%s: unrecognized option '%s'\n", progname, a);
            usage(stderr);
            return BAD;
        }
    }
    o->script = i < argc ? i : argc;
    return RUN;
}

int main(int argc, char **argv)
{
    options o = {0};
    switch (parse(argc, argv, &o)) {
    case DONE: return EXIT_SUCCESS;
    case BAD: return EXIT_FAILURE;
    case RUN: break;
    }
    lua_State *L = luaL_newstate();
    if (!L) {
        message("cannot create the Lua state: not enough memory");
        return EXIT_FAILURE;
    }
    lua_pushcfunction(L, pmain);
    lua_pushinteger(L, argc);
    lua_pushlightuserdata(L, argv);
    lua_pushlightuserdata(L, &o);
    const int status = lua_pcall(L, 3, 1, 0);
    const bool ok = status == LUA_OK && lua_toboolean(L, -1);
    report(L, status);
    lua_close(L);
    return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
