/* seixo: the executable. `seixo script.lua [args]` runs a script,
 * `seixo -e stat` a chunk, and `seixo` alone (or -i) an interactive
 * session; the `seixo` module is preloaded and global, the pure-Lua library
 * (the repository's lua/ directory) is on package.path, and `help` is a
 * global that documents every function.
 *
 * The interactive session uses readline when built with it: line editing,
 * a history file and tab completion (line_edit.c). A long cycle shows
 * a progress line on stderr when stderr is a terminal, and a plain line every
 * 10 s when it is a file or a pipe (a log).
 *
 * Modelled on the reference interpreter lua.c: everything runs inside one
 * protected call (pmain), every chunk under lua_pcall with a message
 * handler (with a traceback on -t). A SIGINT interrupts a running cycle
 * through the bindings, or else the running Lua code through a hook; either
 * way the error unwinds to the prompt with the models intact. A second
 * SIGINT while the first is unanswered ends a process that does not respond. */
#include <lauxlib.h>
#include <lua.h>
#include <lualib.h>
#include <errno.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <sys/stat.h>
#include <unistd.h>

#ifdef SX_HAVE_READLINE
#include <readline/history.h>
#include <readline/readline.h>
#endif

#include "line_edit.h"
#include "seixo_lua.h"

static const char *const progname = "seixo";
static lua_State *global_L;  // the state the SIGINT handler stops
static bool show_traceback;  // -t

typedef struct options {
    int script;        // argv index of the script; argc when there is none
    bool interactive;  // -i
    bool has_chunks;   // some -e
    long threads;      // --threads N (0: not given)
    bool profile;      // --profile
    char bad[256];     // why the command line is wrong (parse: BAD)
} options;

enum { MAX_THREADS = 1024 };  // as many as sx_model_set_threads takes (model.c)

/* A thread count 1..MAX_THREADS written in v; 0 when v is none. */
static long thread_count(const char *v)
{
    char *end = NULL;
    const long t = v ? strtol(v, &end, 10) : 0;
    return v && *v && !*end && t >= 1 && t <= MAX_THREADS ? t : 0;
}

static void usage(FILE *out)
{
    fprintf(out,
            "usage: %s [options] [script [args]]\n"
            "       %s render SERIES.xmf OUT.png [SNAPSHOT]\n"
            "                 draw a snapshot of an output series to a PNG through\n"
            "                 ParaView (pvbatch), headless (scripts/render)\n"
            "  -e stat        run the Lua chunk 'stat' (may be repeated)\n"
            "  -i             enter the interactive mode after the script\n"
            "  -t             show a traceback with each error\n"
            "  --threads N    OpenMP threads for the step of every model (seixo.threads;\n"
            "                 results are bit-identical for any thread count)\n"
            "  --profile      print each model's time per stage of the step on stderr\n"
            "                 when it is closed or collected (see m:profile())\n"
            "  -v, --version  show the version\n"
            "  -h, --help     show this help\n"
            "  --             stop handling options\n"
            "  -              run the standard input as the script\n"
            "With no script and no -e, seixo starts the interactive mode.\n"
            "Environment: SEIXO_LUA_PATH (the directory of the Lua library),\n"
            "SEIXO_HISTORY (the REPL's history file; empty: none).\n",
            progname, progname);
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

/* report() for an error that ends the run: under mpirun every rank meets
 * an error in the script alike, and rank 0 alone prints it (see
 * sx_lua_parallel_failing). */
static int report_fatal(lua_State *L, int status)
{
    if (status != LUA_OK && !sx_lua_parallel_failing(lua_tostring(L, -1))) {
        lua_pop(L, 1);
        return status;
    }
    return report(L, status);
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

/* The coroutines resumed now, innermost last: a hook is per thread, so the
 * one set on the main thread would not stop a loop inside a coroutine.
 * coroutine.resume and coroutine.wrap are replaced to keep the list. */
enum { MAX_RESUMED = 256 };
static lua_State *volatile resumed[MAX_RESUMED];
static volatile sig_atomic_t nresumed;

/* Raises "interrupted" in Lua code only. At the call or return of a C
 * function it stays armed for the next Lua instruction: raising on entry
 * would skip the function's body, and when that function is a __close
 * (a seixo run giving its model back) the model would stay "cycling".
 * Armed on every running thread, it fires on each until the main thread's
 * fires, which answers the Ctrl-C; a hook left on a thread after that is
 * dropped when it fires. */
static void stop_hook(lua_State *L, lua_Debug *ar)
{
    if (!sx_lua_interrupt_pending()) {
        lua_sethook(L, NULL, 0, 0);
        return;
    }
    if ((ar->event == LUA_HOOKCALL || ar->event == LUA_HOOKRET) && lua_getinfo(L, "S", ar) && ar->what[0] == 'C')
        return;
    lua_sethook(L, NULL, 0, 0);
    if (L == global_L) sx_lua_interrupt_clear();
    luaL_error(L, "interrupted");
}

/* The handler stays armed: a script that caught one "interrupted" (pcall)
 * is stopped by the next Ctrl-C as well. A second Ctrl-C while the first is
 * still unanswered (code no hook reaches: a finaliser, a long C call) ends
 * seixo, saying so. */
static void on_sigint(int sig)
{
    (void)sig;
    /* (under mpirun a request waits for a cycle the ranks stop alike; the
     * job is ended by mpirun's own Ctrl-C or a SIGTERM) */
    if (sx_lua_interrupt_pending() && sx_lua_parallel_ranks() == 1) {
        static const char msg[] = "\nseixo: interrupted again before the running code stopped; exiting\n";
        ssize_t w = write(STDERR_FILENO, msg, sizeof msg - 1);
        (void)w;
        _exit(130);
    }
    /* under mpirun a cycle stops where the ranks agree, every rank alike
     * (sx_interrupts_agreed); Lua code that a rank's own hook stopped would
     * leave the ranks out of step */
    if (sx_lua_interrupt_all() == 0 && sx_lua_parallel_ranks() == 1) {
        const int mask = LUA_MASKCALL | LUA_MASKRET | LUA_MASKLINE | LUA_MASKCOUNT;
        const int n = nresumed;
        for (int i = 0; i < n && i < MAX_RESUMED; i++) lua_sethook(resumed[i], stop_hook, mask, 1);
        lua_sethook(global_L, stop_hook, mask, 1);
    }
}

/* Under mpirun a SIGTERM ends the rank (the launcher's, ending the job),
 * but first removes the rank's private copies of the script's files,
 * which the end of the run would have removed (they piled up in $TMPDIR,
 * as large as what the script wrote, at every job mpirun or a scheduler
 * ended). */
static void on_rank_sigterm(int sig)
{
    sx_lua_rank_files_remove_now();
    signal(sig, SIG_DFL);
    raise(sig);
}

/* SIGINT and SIGUSR1, and on one rank SIGTERM too: a batch scheduler's
 * (SLURM's scancel, `timeout`; SLURM's --signal=USR1@seconds before the
 * wall time, which mpirun forwards to every rank) is then a Ctrl-C, which
 * a script can catch to save its state, and which lets a save under way
 * finish instead of leaving its temporary file (while os.execute waits
 * for a command, as for Ctrl-C, it takes effect when the command ends).
 * (With more ranks a SIGTERM is the launcher ending the job: it ends the
 * rank, on_rank_sigterm; and mpirun ends the job on a Ctrl-C of its own.) */
static void set_sigint(void (*handler)(int))
{
    const bool ranks = sx_lua_parallel_ranks() > 1;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    /* under mpirun a SIGUSR1 is always a request, kept for the next
     * cycle, and it restarts the calls it lands in: a read failing on one
     * rank alone would set the ranks apart */
    if (ranks) sa.sa_handler = on_sigint, sa.sa_flags = SA_RESTART;
    sigaction(SIGUSR1, &sa, NULL);
    if (ranks) sa.sa_handler = on_rank_sigterm;
    sigaction(SIGTERM, &sa, NULL);
}

/* coroutine.resume, listing the coroutine while it runs (upvalue 1: the
 * library's resume). */
static int resume_listed(lua_State *L)
{
    lua_State *co = lua_tothread(L, 1);
    const sig_atomic_t depth = nresumed;
    if (co && depth < MAX_RESUMED) resumed[depth] = co;
    nresumed = depth + 1;
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    const int st = lua_pcall(L, lua_gettop(L) - 1, LUA_MULTRET, 0);
    nresumed = depth;
    if (st != LUA_OK) return lua_error(L);
    return lua_gettop(L);
}

/* The function coroutine.wrap returns (upvalue 1: the coroutine, 2: resume_listed). */
static int wrapped_call(lua_State *L)
{
    lua_pushvalue(L, lua_upvalueindex(2));
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_rotate(L, 1, 2);
    lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
    if (!lua_toboolean(L, 1)) {
        if (lua_type(L, 2) == LUA_TSTRING) { /* as the library's wrap: the caller's position */
            luaL_where(L, 1);
            lua_insert(L, 2);
            lua_concat(L, 2);
        }
        lua_settop(L, 2);
        return lua_error(L);
    }
    return lua_gettop(L) - 1;
}

static int wrap_listed(lua_State *L)
{
    luaL_checktype(L, 1, LUA_TFUNCTION);
    lua_State *co = lua_newthread(L);
    lua_pushvalue(L, 1);
    lua_xmove(L, co, 1);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_pushcclosure(L, wrapped_call, 2);
    return 1;
}

static void list_coroutines(lua_State *L)
{
    lua_getglobal(L, "coroutine");
    lua_getfield(L, -1, "resume");
    lua_pushcclosure(L, resume_listed, 1);
    lua_pushvalue(L, -1);
    lua_setfield(L, -3, "resume");
    lua_pushcclosure(L, wrap_listed, 1);
    lua_setfield(L, -2, "wrap");
    lua_pop(L, 1);
}

/* Calls the function below its narg arguments with SIGINT caught. */
static int docall(lua_State *L, int narg, int nres)
{
    const int base = lua_gettop(L) - narg;
    lua_pushcfunction(L, msghandler);
    lua_insert(L, base);
    global_L = L;
    sx_lua_interrupt_clear();
    set_sigint(on_sigint);
    const int status = lua_pcall(L, narg, nres, base);
    set_sigint(SIG_DFL);
    /* an interrupt that came when no Lua code was left to stop */
    if (lua_gethook(L) == stop_hook) lua_sethook(L, NULL, 0, 0);
    sx_lua_interrupt_clear();
    lua_remove(L, base);
    return status;
}

/* ----- a chunk's top-level locals outlive it in an interactive session
 *
 * Every example writes `local m = seixo.model{...}`; typed at the prompt, or
 * in a script run with -i, that local dies with its chunk and the next line
 * finds a nil global. A return hook copies the chunk's top-level locals into
 * globals as the chunk returns (a chunk's final return still sees them), so
 * the session goes on with them. Only the main function of the chunk named
 * keep_source counts: functions it calls, and modules it requires, return
 * untouched. A chunk that fails keeps nothing. */
static const char *keep_source;  // "=stdin" at the prompt, "@path" for a script

static void keep_locals_hook(lua_State *L, lua_Debug *ar)
{
    if (!lua_getinfo(L, "S", ar) || strcmp(ar->what, "main") != 0 || strcmp(ar->source, keep_source) != 0) return;
    const char *name;
    for (int i = 1; (name = lua_getlocal(L, ar, i)) != NULL; i++) {
        if (name[0] == '(')  // the compiler's temporaries
            lua_pop(L, 1);
        else
            lua_setglobal(L, name);
    }
}

/* docall for a chunk whose top-level locals become globals when it returns. */
static int docall_keeping_locals(lua_State *L, int narg, int nres, const char *source)
{
    keep_source = source;
    lua_sethook(L, keep_locals_hook, LUA_MASKRET, 0);
    const int status = docall(L, narg, nres);
    if (lua_gethook(L) == keep_locals_hook) lua_sethook(L, NULL, 0, 0);
    return status;
}

static int run_chunk(lua_State *L, const char *code)
{
    int status = luaL_loadbuffer(L, code, strlen(code), "=(command line)");
    if (status == LUA_OK) status = docall(L, 0, 0);
    return report_fatal(L, status);
}

/* All of standard input (NULL when it cannot be read). */
static char *read_all_input(void *ud, size_t *len, int *mark)
{
    (void)ud;
    *mark = 0;
    size_t cap = 4096, n = 0;
    char *text = malloc(cap);
    for (size_t got = 1; text && got > 0;) {
        if (n + 1 == cap) {
            char *more = realloc(text, cap *= 2);
            if (!more) free(text);
            text = more;
            if (!text) break;
        }
        got = fread(text + n, 1, cap - n - 1, stdin);
        n += got;
    }
    if (text && ferror(stdin)) {
        free(text);
        text = NULL;
    }
    if (text) text[n] = '\0';
    *len = n;
    return text;
}

/* The script read from standard input (`seixo -`): under mpirun rank 0
 * reads it and every rank runs it. A first line starting with # is a
 * comment (#!), kept as an empty line so the line numbers hold, as
 * luaL_loadfile has it. */
static int load_input(lua_State *L)
{
    size_t len;
    int mark;
    char *text = sx_lua_parallel_root_text("standard input", read_all_input, NULL, &len, &mark);
    if (!text) {
        lua_pushfstring(L, "cannot read the script from standard input: %s", strerror(errno));
        return LUA_ERRFILE;
    }
    size_t skip = 0;
    if (len > 0 && text[0] == '#')
        while (skip < len && text[skip] != '\n') skip++;
    const int status = luaL_loadbufferx(L, text + skip, len - skip, "=stdin", "t");
    free(text);
    return status;
}

/* The script's arguments go to `...` as well as to the global `arg`; with
 * -i (keep), its top-level locals become globals for the session. */
static int run_script(lua_State *L, char **argv, int script, int argc, bool keep)
{
    int status = strcmp(argv[script], "-") == 0 ? load_input(L) : sx_lua_load_source(L, argv[script]);
    if (status == LUA_OK) {
        const int n = argc - script - 1;
        luaL_checkstack(L, n, "too many arguments to the script");
        for (int i = script + 1; i < argc; i++) lua_pushstring(L, argv[i]);
        if (keep) {
            lua_Debug ar;
            lua_pushvalue(L, -n - 1);
            lua_getinfo(L, ">S", &ar);
            lua_pushstring(L, ar.source);  // the chunk's name, kept on the stack under the call
            lua_insert(L, -n - 2);
            status = docall_keeping_locals(L, n, 0, lua_tostring(L, -n - 2));
            lua_remove(L, status == LUA_OK ? -1 : -2);
        } else {
            status = docall(L, n, 0);
        }
    }
    return report_fatal(L, status);
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

#ifdef SX_HAVE_READLINE
/* ----- Ctrl-C at the prompt abandons the statement being typed
 *
 * readline's callback interface, with the wait for input in our hands (as
 * Python's REPL does): a SIGINT only sets a flag, which interrupts the
 * pselect() and is seen before the next character is read. */

static volatile sig_atomic_t prompt_interrupted;
static char *typed_line;
static bool line_done;

static void on_prompt_sigint(int sig)
{
    (void)sig;
    prompt_interrupted = 1;
}

static void on_line(char *line)
{
    typed_line = line;
    line_done = true;
    rl_callback_handler_remove();
}

/* A line typed at the prompt (malloc'd), NULL at the end of input or when
 * Ctrl-C abandoned it (then *cancelled). */
static char *read_line(const char *prompt, bool *cancelled)
{
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_prompt_sigint;  // no SA_RESTART: select() returns
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old);
    prompt_interrupted = 0;
    typed_line = NULL;
    line_done = false;
    rl_catch_signals = 0;
    /* SIGINT is blocked but while pselect() waits: one landing between the
     * flag's check and the wait still ends the wait */
    sigset_t block, orig;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigprocmask(SIG_BLOCK, &block, &orig);
    rl_callback_handler_install(prompt, on_line);
    while (!line_done) {
        fd_set in;
        FD_ZERO(&in);
        FD_SET(STDIN_FILENO, &in);
        const int ready = prompt_interrupted ? -1 : pselect(STDIN_FILENO + 1, &in, NULL, NULL, NULL, &orig);
        if (prompt_interrupted) {
            fputs("^C", stdout);
            fflush(stdout);
            rl_free_line_state();
            rl_callback_sigcleanup();
            rl_callback_handler_remove();
            rl_crlf();
            *cancelled = true;
            break;
        }
        if (ready < 0) {
            if (errno == EINTR) continue;
            rl_callback_handler_remove();
            break;
        }
        rl_callback_read_char();
    }
    sigprocmask(SIG_SETMASK, &orig, NULL);
    sigaction(SIGINT, &old, NULL);
    return typed_line;
}
#endif

/* What a line read at the prompt is (sx_lua_parallel_root_text's mark). */
enum { LINE_TYPED, LINE_CANCELLED };

/* How the prompt is shown: at a terminal, readline's when built with it;
 * under mpirun, whose ranks never have a terminal whatever mpirun's own
 * input is, always (rank 0 reads mpirun's input), and on stdout: mpirun
 * forwards stdout and stderr apart, so a prompt on stderr could come
 * before the output of the statement it follows. */
typedef enum { PROMPT_NONE, PROMPT_TTY, PROMPT_LAUNCHED } prompt_kind;

typedef struct prompt_read {
    const char *prompt;
    prompt_kind kind;
} prompt_read;

/* One line from standard input, its newline dropped (NULL at the end of
 * input); a Ctrl-C at the prompt gives an empty line marked cancelled. */
static char *read_prompt_line(void *ud, size_t *len, int *mark)
{
    const prompt_read *p = ud;
    *mark = LINE_TYPED;
#ifdef SX_HAVE_READLINE
    if (p->kind == PROMPT_TTY) {
        bool cancelled = false;
        char *line = read_line(p->prompt, &cancelled);
        if (cancelled) {
            *mark = LINE_CANCELLED;
            free(line);
            line = calloc(1, 1);
        }
        *len = line ? strlen(line) : 0;
        return line;
    }
#endif
    if (p->kind != PROMPT_NONE) {
        fputs(p->prompt, stdout);
        fflush(stdout);
    }
    char *line = NULL;
    size_t cap = 0;
    ssize_t n = getline(&line, &cap, stdin);
    if (n < 0) {
        free(line);
        return NULL;
    }
    if (n > 0 && line[n - 1] == '\n') line[--n] = '\0';
    *len = (size_t)n;
    return line;
}

/* Reads one line onto the stack (under mpirun, rank 0's, on every rank);
 * false at the end of input. A Ctrl-C at the prompt gives an empty line
 * and sets *cancelled. */
static bool push_line(lua_State *L, bool first, prompt_kind kind, bool *cancelled)
{
    prompt_read p = {first ? "> " : ">> ", kind};
    size_t len;
    int mark;
    char *line = sx_lua_parallel_root_text("the prompt", read_prompt_line, &p, &len, &mark);
    *cancelled = mark == LINE_CANCELLED;
    if (!line) return false;
    lua_pushlstring(L, line, len);
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
static int multiline(lua_State *L, prompt_kind kind)
{
    for (;;) {
        size_t len;
        const char *code = lua_tolstring(L, -1, &len);
        const int status = luaL_loadbuffer(L, code, len, "=stdin");
        bool cancelled = false;
        if (!incomplete(L, status) || !push_line(L, false, kind, &cancelled)) return status;
        if (cancelled) {  // Ctrl-C abandons the whole statement
            lua_settop(L, 0);
            lua_pushliteral(L, "");
            return luaL_loadbuffer(L, "", 0, "=stdin");
        }
        lua_remove(L, -2);  // the message
        lua_pushliteral(L, "\n");
        lua_insert(L, -2);
        lua_concat(L, 3);
    }
}

/* Reads and compiles one entry: -1 at the end of input, else the load
 * status with the chunk (or message) as the only value on the stack. */
static int load_entry(lua_State *L, prompt_kind kind)
{
    lua_settop(L, 0);
    bool cancelled;
    if (!push_line(L, true, kind, &cancelled)) return -1;
    int status = try_return(L);
    if (status != LUA_OK) status = multiline(L, kind);
#ifdef SX_HAVE_READLINE
    if (kind == PROMPT_TTY && lua_rawlen(L, 1) > 0) sx__edit_remember(lua_tostring(L, 1));
#endif
    lua_remove(L, 1);
    return status;
}

/* A Ctrl-C while C code of the REPL works through a large value: the
 * hook the handler armed fires in Lua code only. */
static void check_interrupt(lua_State *L)
{
    if (!sx_lua_interrupt_pending()) return;
    lua_sethook(L, NULL, 0, 0);
    sx_lua_interrupt_clear();
    luaL_error(L, "interrupted");
}

/* Moves the string on the stack top into parts[k + 1]; returns k + 1. */
static lua_Integer add_part(lua_State *L, int parts, lua_Integer k)
{
    lua_rawseti(L, parts, ++k);
    if (k % 1024 == 0) check_interrupt(L);
    return k;
}

/* A table shown one level deep, so vectors and energy tables read at a
 * glance: {1, 2, 3}, {kinetic = 0.5, strain = 0}. The pieces are gathered
 * in a table and joined once: a 50k-sample history prints in linear time. */
static void push_shallow(lua_State *L, int t)
{
    lua_newtable(L);
    const int parts = lua_gettop(L);
    lua_Integer k = 0;
    const lua_Integer n = (lua_Integer)lua_rawlen(L, t);
    const char *sep = "";
    for (lua_Integer i = 1; i <= n; i++, sep = ", ") {
        lua_rawgeti(L, t, i);
        lua_pushfstring(L, "%s%s", sep, luaL_tolstring(L, -1, NULL));
        k = add_part(L, parts, k);
        lua_settop(L, parts);
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
            k = add_part(L, parts, k);
            sep = ", ";
        }
        lua_settop(L, key);
    }
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    luaL_addchar(&b, '{');
    for (lua_Integer i = 1; i <= k; i++) {
        lua_rawgeti(L, parts, i);
        luaL_addvalue(&b);
    }
    luaL_addchar(&b, '}');
    luaL_pushresult(&b);
    lua_remove(L, parts);
}

/* Pushes the text of the table at t: seixo.util.show's (keys sorted, nested
 * tables in full, long arrays cut), or the one-level form when the Lua
 * library is not found. */
static void push_table(lua_State *L, int t)
{
    lua_getglobal(L, "require");
    lua_pushliteral(L, "seixo.util");
    if (lua_pcall(L, 1, 1, 0) != LUA_OK || lua_getfield(L, -1, "show") != LUA_TFUNCTION) {
        lua_settop(L, lua_gettop(L) - 2);
        push_shallow(L, t);
        return;
    }
    lua_remove(L, -2);
    lua_pushvalue(L, t);
    lua_pushinteger(L, 3);   // levels
    lua_pushinteger(L, 12);  // entries of a table shown before "..."
    lua_call(L, 3, 1);
}

/* Prints its arguments with the global print, tables without __tostring
 * shown by push_table. */
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
        push_table(L, i);
        lua_replace(L, i);
    }
    lua_getglobal(L, "print");
    lua_insert(L, 1);
    lua_call(L, n, 0);
    return 0;
}

/* The first process a launcher started (mpirun's rank 0, one rank or
 * more), which reads mpirun's input; by the launcher's word, so that a
 * build without MPI, whose every process is rank 0 of its own run, shows
 * the prompt in one process alone. */
static bool launched_first(void)
{
    const char *r = getenv("OMPI_COMM_WORLD_RANK");
    if (!r) r = getenv("PMI_RANK");
    return r && strcmp(r, "0") == 0;
}

static void repl(lua_State *L)
{
    const bool tty = isatty(STDIN_FILENO);
    const prompt_kind kind = tty ? PROMPT_TTY : launched_first() ? PROMPT_LAUNCHED : PROMPT_NONE;
    if (tty) printf("seixo %s (%s); help() for help, Ctrl-D quits, Ctrl-C stops a cycle\n", SX_VERSION, LUA_RELEASE);
    else if (kind == PROMPT_LAUNCHED)
        printf("seixo %s (%s) on %d rank%s; help() for help, Ctrl-D quits; a SIGUSR1 to mpirun stops a cycle "
               "(Ctrl-C is mpirun's: it ends the job)\n",
               SX_VERSION, LUA_RELEASE, sx_lua_parallel_ranks(), sx_lua_parallel_ranks() == 1 ? "" : "s");
#ifdef SX_HAVE_READLINE
    if (tty) sx__edit_start(L);
#endif
    int status;
    while ((status = load_entry(L, kind)) != -1) {
        if (status == LUA_OK) status = docall_keeping_locals(L, 0, LUA_MULTRET, "=stdin");
        if (status == LUA_OK && lua_gettop(L) > 0) {
            lua_pushcfunction(L, show);
            lua_insert(L, 1);
            status = docall(L, lua_gettop(L) - 1, 0);
        }
        /* under mpirun every rank runs the line alike on the same model:
         * rank 0 reports its error; a line that failed on some ranks only
         * leaves the ranks different, and ends the job with its message */
        sx_lua_parallel_line_end(status != LUA_OK, status != LUA_OK ? lua_tostring(L, -1) : NULL);
        if (status != LUA_OK && sx_lua_parallel_rank() != 0) lua_pop(L, 1);
        else report(L, status);
    }
    lua_settop(L, 0);
    if (kind != PROMPT_NONE) putchar('\n');
#ifdef SX_HAVE_READLINE
    if (tty) sx__edit_end();
#endif
}

/* ----------------------------------------------------------------- main */

/* Runs the -e chunks before the script, in order; false after a failure. */
static bool run_chunks(lua_State *L, char **argv, int script)
{
    for (int i = 1; i < script; i++)
        if (strcmp(argv[i], "-e") == 0 && run_chunk(L, argv[++i]) != LUA_OK) return false;
    return true;
}

/* ----------------------------------------------------- the Lua library */

static bool has_library(const char *dir)
{
    struct stat st;
    lua_State *L = global_L;
    const char *probe = lua_pushfstring(L, "%s/seixo", dir);
    const bool ok = stat(probe, &st) == 0 && S_ISDIR(st.st_mode);
    lua_pop(L, 1);
    return ok;
}

/* The directory of the pure-Lua library: $SEIXO_LUA_PATH, else lua/ beside
 * the executable's directory (a build directory in the source tree) or the
 * installed share/lua/5.4 (where a stock Lua finds it too), else the source tree the executable was built
 * from. Pushes it, or nil when none has a seixo/ directory. */
static void push_library_dir(lua_State *L)
{
    const char *env = getenv("SEIXO_LUA_PATH");
    if (env && *env) {
        lua_pushstring(L, env);
        return;
    }
    char exe[4096];
    const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = 0;
        char *slash = strrchr(exe, '/');
        if (slash) *slash = 0;
        const char *const rel[] = {"/../lua", "/../share/lua/5.4"};
        for (size_t i = 0; i < sizeof rel / sizeof *rel; i++) {
            const char *dir = lua_pushfstring(L, "%s%s", exe, rel[i]);
            if (has_library(dir)) return;
            lua_pop(L, 1);
        }
    }
#ifdef SX_LUA_DIR
    if (has_library(SX_LUA_DIR)) {
        lua_pushstring(L, SX_LUA_DIR);
        return;
    }
#endif
    lua_pushnil(L);
}

/* package.path gets the library first; `help` becomes a global. */
static void open_library(lua_State *L)
{
    push_library_dir(L);
    if (!lua_isnil(L, -1)) {
        lua_getglobal(L, "package");
        lua_pushfstring(L, "%s/?.lua;%s/?/init.lua;", lua_tostring(L, -2), lua_tostring(L, -2));
        lua_getfield(L, -2, "path");
        lua_concat(L, 2);
        lua_setfield(L, -2, "path");
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    static const char help[] =
        "function help(...)\n"
        "  local ok, h = pcall(require, 'seixo.help')\n"
        "  if not ok then error('help is not available: ' .. tostring(h), 2) end\n"
        "  return h.help(...)\n"
        "end\n";
    if (luaL_loadbuffer(L, help, sizeof help - 1, "=help") == LUA_OK) lua_call(L, 0, 0);
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
    list_coroutines(L);
    sx_lua_source_only(L);
    sx_lua_open(L);
    global_L = L;
    open_library(L);
    sx_lua_set_progress(L, isatty(STDERR_FILENO) ? SX_PROGRESS_TERMINAL : SX_PROGRESS_LOG);
    sx_lua_set_profile(L, o->profile);
    lua_getglobal(L, "seixo");
    lua_pushinteger(L, o->threads > 0 ? o->threads : 1);
    lua_setfield(L, -2, "threads");
    lua_pop(L, 1);
    create_arg_table(L, argv, argc, o->script);
    bool ok = run_chunks(L, argv, o->script);
    if (ok && o->script < argc) ok = run_script(L, argv, o->script, argc, o->interactive) == LUA_OK;
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
                snprintf(o->bad, sizeof o->bad, "'-e' needs an argument; seixo --help for usage");
                return BAD;
            }
            o->has_chunks = true;
        } else if (strcmp(a, "-i") == 0) {
            o->interactive = true;
        } else if (strcmp(a, "-t") == 0) {
            show_traceback = true;
        } else if (strcmp(a, "--threads") == 0 || strncmp(a, "--threads=", 10) == 0) {
            const char *v = a[9] == '=' ? a + 10 : (++i < argc ? argv[i] : NULL);
            const long t = thread_count(v);
            if (!t) {
                snprintf(o->bad, sizeof o->bad, "'--threads' needs a whole number from 1 to %d; seixo --help for usage",
                         MAX_THREADS);
                return BAD;
            }
            o->threads = t;
        } else if (strcmp(a, "--profile") == 0) {
            o->profile = true;
        } else if (strcmp(a, "-v") == 0 || strcmp(a, "--version") == 0) {
            printf("seixo %s (%s)\n", SX_VERSION, LUA_RELEASE);
            return DONE;
        } else if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            usage(stdout);
            return DONE;
        } else {
            /* one line, like every failure: the reason and where to look */
            snprintf(o->bad, sizeof o->bad, "unrecognized option '%s'; seixo --help for usage", a);
            return BAD;
        }
    }
    o->script = i < argc ? i : argc;
    /* without --threads, OMP_NUM_THREADS as any OpenMP program reads it;
     * a value that is no thread count is an error, not a silent 1 */
    const char *env = getenv("OMP_NUM_THREADS");
    if (!o->threads && env && *env) {
        o->threads = thread_count(env);
        if (!o->threads) {
            snprintf(o->bad, sizeof o->bad, "OMP_NUM_THREADS='%s' is not a whole number from 1 to %d", env, MAX_THREADS);
            return BAD;
        }
    }
    return RUN;
}

/* `seixo render ...`: scripts/render, found like the Lua library: beside
 * the executable's directory (a build directory in the source tree), in
 * the installed share/seixo, else in the source tree it was built from.
 * Returns only when it cannot run it. */
static int run_render(int argc, char **argv)
{
    char exe[4096], path[4200];
    const char *dirs[3] = {NULL, NULL, NULL};
    char rel[2][4200];
    const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = 0;
        char *slash = strrchr(exe, '/');
        if (slash) *slash = 0;
        snprintf(rel[0], sizeof rel[0], "%s/../scripts", exe);
        snprintf(rel[1], sizeof rel[1], "%s/../share/seixo", exe);
        dirs[0] = rel[0], dirs[1] = rel[1];
    }
#ifdef SX_SCRIPTS_DIR
    dirs[2] = SX_SCRIPTS_DIR;
#endif
    for (int i = 0; i < 3; i++) {
        if (!dirs[i]) continue;
        snprintf(path, sizeof path, "%s/render", dirs[i]);
        if (access(path, R_OK) != 0) continue;
        char **args = calloc((size_t)argc + 2, sizeof *args);
        if (!args) break;
        args[0] = "sh";
        setenv("SEIXO_RENDER_NAME", "seixo render", 1);
        args[1] = path;
        for (int k = 2; k < argc; k++) args[k] = argv[k];
        execv("/bin/sh", args);
        fprintf(stderr, "%s render: cannot run /bin/sh %s: %s\n", progname, path, strerror(errno));
        free(args);
        return EXIT_FAILURE;
    }
    fprintf(stderr, "%s render: the render script (scripts/render, installed in share/seixo) was not found\n", progname);
    return EXIT_FAILURE;
}

int main(int argc, char **argv)
{
    options o = {0};
    /* a subcommand, before MPI or Lua: ./render runs a script named render */
    if (argc > 1 && strcmp(argv[1], "render") == 0) return run_render(argc, argv);
    sx_lua_parallel_start(&argc, &argv);  // MPI_Init under mpirun, before anything reads argv
    set_sigint(SIG_DFL);                   // under mpirun: SIGUSR1 a request, SIGTERM's clean-up, from here on
    switch (parse(argc, argv, &o)) {
    case DONE: sx_lua_parallel_stop(1); return EXIT_SUCCESS;
    case BAD: /* every rank parsed the same command line: under mpirun rank 0 says why */
        if (sx_lua_parallel_failing(o.bad)) message(o.bad);
        sx_lua_parallel_stop(0);
        return EXIT_FAILURE;
    case RUN: break;
    }
    lua_State *L = luaL_newstate();
    if (!L) {
        message("cannot create the Lua state: not enough memory");
        sx_lua_parallel_stop(0);
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
    sx_lua_parallel_stop(ok);
    return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
