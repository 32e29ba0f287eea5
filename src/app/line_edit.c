/* The interactive session's line editing (line_edit.h): readline's tab
 * completion, which walks the Lua value before the cursor (globals,
 * table keys, the methods and fields of seixo objects), and the history
 * file (~/.seixo_history, or $SEIXO_HISTORY; empty disables it). */
#include "line_edit.h"

#ifdef SX_HAVE_READLINE
#include <lauxlib.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <readline/history.h>
#include <readline/readline.h>

static lua_State *completion_L; /* the session's state, whose values completion walks */

/* ----- tab completion: walk the value before the cursor in a protected call */

static char **matches;  // the candidates of the current completion, NULL-terminated
static size_t nmatches, match_at;

static void clear_matches(void)
{
    for (size_t i = 0; i < nmatches; i++) free(matches[i]);
    free(matches);
    matches = NULL;
    nmatches = match_at = 0;
}

static void add_match(const char *prefix, size_t plen, const char *name, const char *suffix)
{
    char **grown = realloc(matches, (nmatches + 2) * sizeof *matches);
    if (!grown) return;
    matches = grown;
    const size_t n = strlen(name), k = strlen(suffix);
    char *m = malloc(plen + n + k + 1);
    if (!m) return;
    memcpy(m, prefix, plen);
    memcpy(m + plen, name, n);
    memcpy(m + plen + n, suffix, k + 1);
    matches[nmatches++] = m;
    matches[nmatches] = NULL;
}

static bool is_name(const char *s)
{
    if (!(*s == '_' || (*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z'))) return false;
    for (s++; *s; s++)
        if (!(*s == '_' || (*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9')))
            return false;
    return true;
}

/* Adds the string keys of the table at t that start with `partial`;
 * functions get "(" after them, and only functions when methods_only. */
static void add_keys(lua_State *L, int t, const char *prefix, size_t plen, const char *partial, bool methods_only)
{
    const size_t n = strlen(partial);
    lua_pushnil(L);
    while (lua_next(L, t)) {
        if (lua_type(L, -2) == LUA_TSTRING) {
            const char *k = lua_tostring(L, -2);
            const bool fn = lua_type(L, -1) == LUA_TFUNCTION;
            if (strncmp(k, partial, n) == 0 && is_name(k) && (fn || !methods_only) && strncmp(k, "__", 2) != 0)
                add_match(prefix, plen, k, fn ? "(" : "");
        }
        lua_pop(L, 1);
    }
}

/* Adds the names the value at v offers after `.` (or `:` when methods_only). */
static void add_members(lua_State *L, int v, const char *prefix, size_t plen, const char *partial, bool methods_only)
{
    if (lua_type(L, v) == LUA_TTABLE) add_keys(L, v, prefix, plen, partial, methods_only);
    if (!lua_getmetatable(L, v)) return;
    const int mt = lua_gettop(L);
    /* a seixo class: its methods and fields */
    if (lua_getfield(L, mt, "__methods") == LUA_TTABLE) add_keys(L, lua_gettop(L), prefix, plen, partial, methods_only);
    lua_pop(L, 1);
    if (!methods_only && lua_getfield(L, mt, "__getters") == LUA_TTABLE) {
        const int g = lua_gettop(L);
        const size_t n = strlen(partial);
        lua_pushnil(L);
        while (lua_next(L, g)) {
            const char *k = lua_tostring(L, -2);
            if (k && strncmp(k, partial, n) == 0) add_match(prefix, plen, k, "");
            lua_pop(L, 1);
        }
    }
    lua_settop(L, mt);
    /* an __index table (strings, plain Lua classes), one level */
    if (lua_getfield(L, mt, "__index") == LUA_TTABLE) add_keys(L, lua_gettop(L), prefix, plen, partial, methods_only);
    lua_settop(L, mt - 1);
}

/* The completion proper, run under lua_pcall: the text is the light userdata argument. */
static int gather(lua_State *L)
{
    static const char *const keywords[] = {"and",  "break", "do",     "else", "elseif", "end",   "false",
                                           "for",  "function", "goto", "if",   "in",     "local", "nil",
                                           "not",  "or",    "repeat", "return", "then",  "true",  "until",
                                           "while", NULL};
    const char *text = lua_touserdata(L, 1);
    const char *sep = strpbrk(text, ".:") ? text + strlen(text) : NULL;
    if (sep)
        while (sep > text && sep[-1] != '.' && sep[-1] != ':') sep--;
    if (!sep) {  // a global name or a keyword
        lua_pushglobaltable(L);
        add_keys(L, lua_gettop(L), "", 0, text, false);
        for (int i = 0; keywords[i]; i++)
            if (strncmp(keywords[i], text, strlen(text)) == 0) add_match("", 0, keywords[i], " ");
        return 0;
    }
    /* walk a.b.c, the part before the last separator */
    lua_pushglobaltable(L);
    const char *p = text;
    while (p < sep - 1) {
        const char *q = p;
        while (q < sep - 1 && *q != '.' && *q != ':') q++;
        if (*q == ':' && q < sep - 1) return 0;  // a method call in the middle: nothing to walk
        lua_pushlstring(L, p, (size_t)(q - p));
        if (!is_name(lua_tostring(L, -1))) return 0;
        lua_gettable(L, -2);  // may run __index: hence the protected call
        lua_remove(L, -2);
        p = q + 1;
    }
    add_members(L, lua_gettop(L), text, (size_t)(sep - text), sep, sep[-1] == ':');
    return 0;
}

static char *next_match(const char *text, int state)
{
    (void)text;
    if (state == 0) match_at = 0;
    return match_at < nmatches ? strdup(matches[match_at++]) : NULL;
}

static char **complete(const char *text, int start, int end)
{
    (void)start;
    (void)end;
    rl_attempted_completion_over = 1;  // no file names
    rl_completion_append_character = '\0';
    clear_matches();
    lua_State *L = completion_L;
    const int top = lua_gettop(L);
    lua_pushcfunction(L, gather);
    lua_pushlightuserdata(L, (void *)text);
    lua_pcall(L, 1, 0, 0);  // a failure only means fewer matches
    lua_settop(L, top);
    return nmatches ? rl_completion_matches(text, next_match) : NULL;
}

/* ----- the history file */

static char *history_path(void)
{
    const char *env = getenv("SEIXO_HISTORY");
    if (env) return *env ? strdup(env) : NULL;
    const char *home = getenv("HOME");
    if (!home || !*home) return NULL;
    const char *name = "/.seixo_history";
    char *path = malloc(strlen(home) + strlen(name) + 1);
    if (path) {
        strcpy(path, home);
        strcat(path, name);
    }
    return path;
}

/* The history file: each entry is appended as it is entered (so os.exit or
 * a crash loses nothing), and the file keeps the last 1000 entries.
 *
 * An entry is a whole statement, newlines and all. The file is readline's
 * format with timestamps (bash's lithist): each entry follows a "#<seconds>"
 * line, and readline reads a line without one as the continuation of the
 * entry before, so a multi-line statement comes back whole. That takes a
 * file that starts with a timestamp; a file of bare lines (written before)
 * is rewritten in this format when it is opened. */
static char *hist_path;

static bool starts_with_timestamp(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) return false;
    char head[2] = {0, 0};
    const bool stamped = fread(head, 1, 2, f) == 2 && head[0] == '#' && head[1] >= '0' && head[1] <= '9';
    fclose(f);
    return stamped;
}

static void open_history(void)
{
    hist_path = history_path();
    if (!hist_path) return;
    history_comment_char = '#';  // the timestamps' mark
    history_write_timestamps = 1;
    const bool read = read_history(hist_path) == 0;
    /* create it, or give it timestamps (entries read get the current time) */
    if (!read || (history_length > 0 && !starts_with_timestamp(hist_path))) write_history(hist_path);
}

static void remember(const char *entry)
{
    add_history(entry);
    if (hist_path) append_history(1, hist_path);
}

/* Cuts the file to its last 1000 entries: read back whole (the history is
 * stifled to 1000), written anew. history_truncate_file counts lines, and
 * could leave the file starting inside a multi-line entry. */
static void close_history(void)
{
    if (hist_path) {
        clear_history();
        if (read_history(hist_path) == 0) write_history(hist_path);
    }
    free(hist_path);
    hist_path = NULL;
}

void sx__edit_start(lua_State *L)
{
    completion_L = L;
    rl_readline_name = "seixo";
    rl_attempted_completion_function = complete;
    rl_completer_word_break_characters = " \t\n\"\\'`@$><=;|&{}()[],+-*/%^~#";
    stifle_history(1000);
    open_history();
}

void sx__edit_remember(const char *entry) { remember(entry); }

void sx__edit_end(void)
{
    close_history();
    clear_matches();
}
#endif
