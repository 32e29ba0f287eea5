/* Files: snapshots that restart bit-for-bit, and output series for ParaView.
 *   m:save(path[, {compression = 0..9}])   -> skipped   write the whole model
 *   seixo.load(path[, {dim = 2 | 3}])       -> model     read it back
 *   m:vars()                                -> table     the user's variables, saved with the model
 *   m:output{path =, every =, fields =, compression =, append =} -> output
 *   output:write(), output:close(), output:count(), output:path()
 *   seixo.xdmf(path)                        rebuild the .xmf of a series
 *
 * Histories are saved with the model and come back recording (a history of
 * a function comes back detached: m:history(name, fn) reattaches it, and
 * m:save lists it among the skipped values); an output series appends the
 * histories' samples as they grow, the last ones when it closes.
 *
 * Provenance: the seeds of m:generate and m:bond are recorded (state
 * "seeds") and written as the files' `seeds` attribute; a loaded model
 * takes them back from its file.
 *
 * The user's variables (PFC saves FISH variables with the model): m:vars()
 * is a table kept with the model; whatever plain data it holds (numbers,
 * strings, booleans and nested tables of them) is saved by m:save and
 * restored by seixo.load. The Lua-side state that is data, not code (group
 * names, ball and wall extras), is saved the same way. Values that cannot be saved
 * (functions, userdata, a table met twice) are skipped and listed in the
 * table m:save returns, e.g. {"vars.callback"}. Callbacks and outputs are
 * code and open files: after a load, register them again (an output with
 * append = true continues its series).
 *
 * An output writes the model at once, then after every `every` steps
 * through an "after" callback (m:on); it closes with o:close(), when it is
 * collected, or with the Lua state. */
#include "bindings.h"
#include "seixo_io.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SX_LUA_OUTPUT "seixo.output"

/* --------------------------------------------------- Lua values <-> trees */

/* The state fields saved with the model: plain data kept by other files. */
static const char *const saved_state[] = {"groups", "group_names", "extras", "wall_extras", NULL};

/* Those saved only when the model has them, so that a model without them
 * writes what it did before: the group slots 2 and up, and the balls'
 * displacement references (disp.c: a model that never asked for b.disp
 * must not start recording them once loaded). NULL past the last. */
static const char *optional_state(int k)
{
    if (k + 2 <= SX_LUA_SLOTS) return sx_lua_slot_table(k + 2);
    return k + 2 == SX_LUA_SLOTS + 1 ? "disp_ref" : NULL;
}

typedef struct ser {
    sx_io_tree *tree;
    int seen;     /* stack index: tables already written */
    int skipped;  /* stack index: array of the paths skipped */
    bool oom;
} ser;

static void skip(lua_State *L, ser *s, const char *path, const char *why)
{
    lua_pushfstring(L, "%s (%s)", path, why);
    lua_rawseti(L, s->skipped, (lua_Integer)lua_rawlen(L, s->skipped) + 1);
}

static int64_t add(ser *s, const sx_io_node *n)
{
    const int64_t i = sx_io_tree_add(s->tree, n);
    if (i < 0) s->oom = true;
    return i;
}

/* Reads the key at idx into n; false if a key of that type cannot be saved. */
static bool key_of(lua_State *L, int idx, sx_io_node *n)
{
    switch (lua_type(L, idx)) {
    case LUA_TSTRING:
        n->key_kind = SX_IO_STRING;
        n->key_string = (char *)lua_tolstring(L, idx, &n->key_length);
        return true;
    case LUA_TNUMBER:
        if (lua_isinteger(L, idx)) {
            n->key_kind = SX_IO_INTEGER;
            n->key_integer = (int64_t)lua_tointeger(L, idx);
        } else {
            n->key_kind = SX_IO_NUMBER;
            n->key_number = lua_tonumber(L, idx);
        }
        return true;
    case LUA_TBOOLEAN:
        n->key_kind = SX_IO_BOOLEAN;
        n->key_integer = lua_toboolean(L, idx);
        return true;
    default: return false;
    }
}

/* "path.key" or "path[key]" for messages. */
static const char *child_path(lua_State *L, const char *path, int key)
{
    if (lua_type(L, key) == LUA_TSTRING) return lua_pushfstring(L, "%s.%s", path, lua_tostring(L, key));
    if (lua_type(L, key) == LUA_TNUMBER || lua_type(L, key) == LUA_TBOOLEAN) {
        lua_pushvalue(L, key);
        const char *k = luaL_tolstring(L, -1, NULL);
        const char *p = lua_pushfstring(L, "%s[%s]", path, k);
        lua_replace(L, -3);
        lua_pop(L, 1);
        return p;
    }
    return lua_pushfstring(L, "%s[%s]", path, luaL_typename(L, key));
}

/* A key of a table to save, for the order of keys_in_order. */
typedef struct saved_key {
    int kind; /* booleans, then numbers, then strings, then the rest (skipped with a message) */
    bool integer;
    lua_Integer i;
    lua_Number d;
    const char *str;
    size_t len;
    lua_Integer slot; /* the key's place in the list keys_in_order pushes */
} saved_key;

static int key_kind(int type) { return type == LUA_TBOOLEAN ? 0 : type == LUA_TNUMBER ? 1 : type == LUA_TSTRING ? 2 : 3; }

static int compare_keys(const void *pa, const void *pb)
{
    const saved_key *a = pa, *b = pb;
    if (a->kind != b->kind) return a->kind < b->kind ? -1 : 1;
    if (a->kind == 1) {
        if (a->integer && b->integer) return (a->i > b->i) - (a->i < b->i);
        const lua_Number x = a->integer ? (lua_Number)a->i : a->d, y = b->integer ? (lua_Number)b->i : b->d;
        if (x != y) return x < y ? -1 : 1;
        if (a->integer != b->integer) return a->integer ? -1 : 1; /* 2^63 - 1 and 2^63.0, equal as doubles: the integer first */
    } else if (a->kind == 0 || a->kind == 2) {
        const size_t n = a->len < b->len ? a->len : b->len;
        const int c = a->kind == 2 ? memcmp(a->str, b->str, n) : 0;
        if (c) return c;
        if (a->kind == 0 && a->i != b->i) return a->i < b->i ? -1 : 1;
        if (a->len != b->len) return a->len < b->len ? -1 : 1;
    }
    return (a->slot > b->slot) - (a->slot < b->slot); /* the rest (skipped): as Lua lists them */
}

/* Pushes the keys of the table at idx as a list, in a fixed order
 * (booleans, numbers, strings, each by value, strings bytewise), not in
 * the order of Lua's hash, which is seeded per run: the same tables save
 * to the same file on every run (and the first of two places holding one
 * table is the same). Returns their count. */
static lua_Integer keys_in_order(lua_State *L, int idx)
{
    lua_newtable(L);
    const int list = lua_gettop(L);
    lua_Integer n = 0;
    for (lua_pushnil(L); lua_next(L, idx); lua_pop(L, 1)) {
        lua_pushvalue(L, -2);
        lua_rawseti(L, list, ++n);
    }
    saved_key *k = lua_newuserdatauv(L, (size_t)(n ? n : 1) * sizeof *k, 0); /* collected, also after an error */
    for (lua_Integer j = 0; j < n; j++) {
        const int type = lua_rawgeti(L, list, j + 1);
        saved_key *e = &k[j];
        memset(e, 0, sizeof *e);
        e->kind = key_kind(type), e->slot = j + 1;
        if (type == LUA_TNUMBER && (e->integer = lua_isinteger(L, -1))) e->i = lua_tointeger(L, -1);
        else if (type == LUA_TNUMBER) e->d = lua_tonumber(L, -1);
        else if (type == LUA_TBOOLEAN) e->i = lua_toboolean(L, -1);
        else if (type == LUA_TSTRING) e->str = lua_tolstring(L, -1, &e->len); /* held by the list */
        lua_pop(L, 1);
    }
    if (n) qsort(k, (size_t)n, sizeof *k, compare_keys);
    lua_createtable(L, n < INT_MAX ? (int)n : 0, 0);
    for (lua_Integer j = 0; j < n; j++) {
        lua_rawgeti(L, list, k[j].slot);
        lua_rawseti(L, -2, j + 1);
    }
    lua_replace(L, list);
    lua_settop(L, list);
    return n;
}

/* Tables deeper than this are skipped (named in the save's skipped list):
 * the walk recurses, and a table nested 50,000 deep ran the C stack out
 * (a segmentation fault) before Lua's stack checks could say so. */
enum { SAVE_DEPTH_MAX = 1000 };

/* Writes the entries of the table at idx as children of node `parent`,
 * itself `depth` tables deep. */
static void ser_table(lua_State *L, ser *s, int idx, int64_t parent, const char *path, int depth)
{
    idx = lua_absindex(L, idx);
    luaL_checkstack(L, 8, "tables nested too deeply to save");
    lua_pushvalue(L, idx);
    lua_pushboolean(L, 1);
    lua_rawset(L, s->seen);
    const lua_Integer nkeys = keys_in_order(L, idx);
    const int keys = lua_gettop(L);
    for (lua_Integer j = 1; j <= nkeys && !s->oom; j++) {
        lua_rawgeti(L, keys, j);
        lua_pushvalue(L, -1);
        lua_rawget(L, idx);
        const int key = lua_gettop(L) - 1, val = key + 1;
        const char *p = child_path(L, path, key);
        sx_io_node n;
        memset(&n, 0, sizeof n);
        n.parent = parent;
        if (!key_of(L, key, &n)) {
            skip(L, s, p, "its key is not a string, number or boolean");
        } else {
            switch (lua_type(L, val)) {
            case LUA_TBOOLEAN:
                n.kind = SX_IO_BOOLEAN;
                n.integer = lua_toboolean(L, val);
                add(s, &n);
                break;
            case LUA_TNUMBER:
                if (lua_isinteger(L, val)) n.kind = SX_IO_INTEGER, n.integer = (int64_t)lua_tointeger(L, val);
                else n.kind = SX_IO_NUMBER, n.number = lua_tonumber(L, val);
                add(s, &n);
                break;
            case LUA_TSTRING:
                n.kind = SX_IO_STRING;
                n.string = (char *)lua_tolstring(L, val, &n.length);
                add(s, &n);
                break;
            case LUA_TTABLE:
                lua_pushvalue(L, val);
                if (lua_rawget(L, s->seen) != LUA_TNIL) {
                    lua_pop(L, 1);
                    skip(L, s, p, "a table already saved at another place");
                    break;
                }
                lua_pop(L, 1);
                if (depth >= SAVE_DEPTH_MAX) {
                    char why[64];
                    snprintf(why, sizeof why, "tables nested deeper than %d", SAVE_DEPTH_MAX);
                    skip(L, s, p, why);
                    break;
                }
                n.kind = SX_IO_TABLE;
                const int64_t me = add(s, &n);
                /* a field vector (b.pos) is saved as its components */
                if (me >= 0) ser_table(L, s, sx_lua_vec_array(L, val), me, p, depth + 1);
                break;
            default: skip(L, s, p, luaL_typename(L, val)); break;
            }
        }
        lua_settop(L, keys);
    }
    lua_pop(L, 1);
}

/* Builds the Lua table of a tree and leaves it on the stack. */
static void push_tree(lua_State *L, const sx_io_tree *t)
{
    luaL_checkstack(L, 6, NULL);
    lua_newtable(L);
    const int root = lua_gettop(L);
    lua_createtable(L, t->n < 1000000 ? (int)t->n : 0, 0); /* node index -> its table */
    const int tables = root + 1;
    for (int64_t i = 0; i < t->n; i++) {
        const sx_io_node *n = &t->node[i];
        if (n->parent < 0) lua_pushvalue(L, root);
        else lua_rawgeti(L, tables, (lua_Integer)n->parent + 1);
        switch (n->key_kind) {
        case SX_IO_STRING: lua_pushlstring(L, n->key_string, n->key_length); break;
        case SX_IO_INTEGER: lua_pushinteger(L, (lua_Integer)n->key_integer); break;
        case SX_IO_BOOLEAN: lua_pushboolean(L, n->key_integer != 0); break;
        default:
            if (n->key_number != n->key_number) { /* NaN: not a key Lua can hold */
                lua_pop(L, 1);
                continue;
            }
            lua_pushnumber(L, n->key_number);
            break;
        }
        switch (n->kind) {
        case SX_IO_BOOLEAN: lua_pushboolean(L, n->integer != 0); break;
        case SX_IO_INTEGER: lua_pushinteger(L, (lua_Integer)n->integer); break;
        case SX_IO_NUMBER: lua_pushnumber(L, n->number); break;
        case SX_IO_STRING: lua_pushlstring(L, n->string, n->length); break;
        default:
            lua_newtable(L);
            lua_pushvalue(L, -1);
            lua_rawseti(L, tables, (lua_Integer)i + 1);
            break;
        }
        lua_rawset(L, -3);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

/* ----------------------------------------------------------- save, load */

/* The script a worker runs for (seixo.script(path): a seixo.pool job's
 * parent script), in the registry. */
static const char script_key[] = "seixo.script";

/* The path of the script being run (its main chunk "@path"), or the one a
 * worker was given, or NULL. */
static const char *script_path(lua_State *L)
{
    lua_Debug ar;
    const char *found = NULL;
    for (int level = 0; lua_getstack(L, level, &ar); level++) {
        if (!lua_getinfo(L, "S", &ar)) continue;
        if (strcmp(ar.what, "main") == 0 && ar.source[0] == '@') found = ar.source + 1;
    }
    if (found) return found;
    lua_getfield(L, LUA_REGISTRYINDEX, script_key);
    found = lua_tostring(L, -1); /* kept alive by the registry */
    lua_pop(L, 1);
    return found;
}

/* seixo.script([path]) -> the script the files name as their provenance:
 * the one being run, or, in a worker that runs a -e chunk for a script
 * (seixo.pool's), the path given, relative to the worker's directory. */
static int seixo_script(lua_State *L)
{
    if (!lua_isnoneornil(L, 1)) {
        lua_pushstring(L, luaL_checkstring(L, 1));
        lua_setfield(L, LUA_REGISTRYINDEX, script_key);
    }
    const char *path = script_path(L);
    if (path) lua_pushstring(L, path);
    else lua_pushnil(L);
    return 1;
}

void sx_lua_record_seed(lua_State *L, int model, int64_t seed)
{
    sx_lua_state(L, model, "seeds");
    const lua_Integer n = (lua_Integer)lua_rawlen(L, -1);
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, -1, i);
        const bool seen = lua_tointeger(L, -1) == (lua_Integer)seed;
        lua_pop(L, 1);
        if (seen) {
            lua_pop(L, 1);
            return;
        }
    }
    lua_pushinteger(L, (lua_Integer)seed);
    lua_rawseti(L, -2, n + 1);
    lua_pop(L, 1);
}

/* Seeds the script used, as recorded by sx_lua_record_seed (state "seeds"). */
static int64_t *seeds_of(lua_State *L, int model, int *n)
{
    sx_lua_state(L, model, "seeds");
    const lua_Integer k = (lua_Integer)lua_rawlen(L, -1);
    int64_t *v = k > 0 && k < 100000 ? lua_newuserdatauv(L, (size_t)k * sizeof *v, 0) : NULL;
    *n = 0;
    for (lua_Integer i = 1; v && i <= k; i++) {
        lua_rawgeti(L, -2, i);
        if (lua_isinteger(L, -1)) v[(*n)++] = (int64_t)lua_tointeger(L, -1);
        lua_pop(L, 1);
    }
    /* the userdata (if any) stays on the stack, above the seeds table */
    return v;
}

typedef struct save_job {
    sx_io_named_tree trees[2];
} save_job;

/* __gc / __close of a save job: the trees' C memory, whatever happens. */
static int job_free(lua_State *L)
{
    save_job *j = lua_touserdata(L, 1);
    for (int k = 0; k < 2; k++) sx_io_tree_free(&j->trees[k].tree);
    return 0;
}

/* m:save's and seixo.load's name (call) in the ranks' same-call check,
 * with its path, which every rank must give alike (a rank's number or its
 * clock in the name had rank 0 write its file alone): the path's last 40
 * characters and a digest of the whole (the check compares the first 96
 * characters). */
static const char *path_call(char *name, size_t size, const char *call, const char *path)
{
    uint32_t h = 2166136261u;
    for (const char *c = path; *c; c++) h = (h ^ (unsigned char)*c) * 16777619u;
    const size_t n = strlen(path), keep = 40;
    snprintf(name, size, "%s '%s%s' (%08x)", call, n > keep ? "..." : "", path + (n > keep ? n - keep : 0), (unsigned)h);
    return name;
}

static int model_save(lua_State *L)
{
    static const char *const keys[] = {"compression", NULL};
    const sx_model *m = sx_lua_checkmodel(L, 1);
    const char *path = sx_lua_checkname(L, 2);
    /* the file would hold what the model holds now, and a restart would
     * keep what the run removes: they part */
    const lua_Integer queued = sx_lua_removals_queued(L, 1);
    if (queued > 0)
        return luaL_error(L,
                          "m:save: %I removal(s) queued in this callback (b:remove, w:remove, m:remove_balls ...) "
                          "take effect when it returns: save after it (in the next callback, or after the cycle)",
                          queued);
    int64_t level = 0;
    if (!lua_isnoneornil(L, 3)) {
        sx_lua_checkkeys(L, 3, keys);
        sx_lua_optintfield(L, 3, "compression", 0, 9, &level);
    }
    lua_settop(L, 3);
    /* the trees' memory belongs to a to-be-closed job, freed on any error */
    save_job *j = lua_newuserdatauv(L, sizeof *j, 0);
    memset(j, 0, sizeof *j);
    lua_createtable(L, 0, 1);
    lua_pushcfunction(L, job_free);
    lua_setfield(L, -2, "__close");
    lua_setmetatable(L, -2);
    lua_toclose(L, 4);
    lua_newtable(L); /* 5: skipped paths */
    lua_newtable(L); /* 6: tables seen */
    ser s = {.skipped = 5, .seen = 6};

    snprintf(j->trees[0].name, sizeof j->trees[0].name, "vars");
    s.tree = &j->trees[0].tree;
    sx_lua_state(L, 1, "vars");
    ser_table(L, &s, -1, -1, "vars", 1);
    lua_pop(L, 1);

    snprintf(j->trees[1].name, sizeof j->trees[1].name, "state");
    s.tree = &j->trees[1].tree;
    for (int k = 0; saved_state[k] && !s.oom; k++) {
        sx_lua_state(L, 1, saved_state[k]);
        sx_io_node n = {.parent = -1, .key_kind = SX_IO_STRING, .key_string = (char *)saved_state[k],
                        .key_length = strlen(saved_state[k]), .kind = SX_IO_TABLE};
        const int64_t me = add(&s, &n);
        if (me >= 0) ser_table(L, &s, -1, me, saved_state[k], 1);
        lua_pop(L, 1);
    }
    lua_getiuservalue(L, 1, 1);
    const char *name;
    for (int k = 0; (name = optional_state(k)) && !s.oom; k++) {
        if (lua_getfield(L, -1, name) == LUA_TTABLE) {
            sx_io_node n = {.parent = -1, .key_kind = SX_IO_STRING, .key_string = (char *)name,
                            .key_length = strlen(name), .kind = SX_IO_TABLE};
            const int64_t me = add(&s, &n);
            if (me >= 0) ser_table(L, &s, -1, me, name, 1);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    if (s.oom) return luaL_error(L, "'%s': out of memory", path);

    sx_snapshot_opts o;
    memset(&o, 0, sizeof o);
    o.compression = (int)level;
    o.trees = j->trees;
    o.ntrees = 2;
    o.histories = sx_lua_histories_push(L, 1, 0, 0, &o.nhistories);
    for (int k = 0; k < o.nhistories; k++)
        if (o.histories[k].source == SX_IO_SOURCE_FUNCTION) {
            lua_pushfstring(L, "history '%s' (its function: the samples are saved, give it again after a load)",
                            o.histories[k].name);
            lua_rawseti(L, 5, (lua_Integer)lua_rawlen(L, 5) + 1);
        }
    sx_lua_callbacks_unsaved(L, 1, 5);
    o.provenance.script = script_path(L);
    o.provenance.seeds = seeds_of(L, 1, &o.provenance.nseeds);
    char err[1024] = "";
    /* decomposed over ranks, every rank holds the same whole model between
     * cycles: rank 0 writes it, and the others wait for the outcome (the
     * file is there, or every rank raises rank 0's error: the I/O layer
     * writes a message to err with every failure) */
    const bool shared = sx_model_ranks(m) > 1;
    char call[96];
    if (shared) sx_lua_check_model_call(L, m, path_call(call, sizeof call, "m:save", path));
    if (sx_lua_parallel_writes(shared)) sx_snapshot_save(m, path, &o, err, sizeof err);
    if (sx_lua_parallel_outcome(shared, err, sizeof err, NULL)) return luaL_error(L, "%s", err);
    sx_lua_rank_file_written(L, path); /* rank 0 wrote it: no shadow stands for it */
    lua_pushvalue(L, 5);
    return 1;
}

static int info_free(lua_State *L)
{
    sx_snapshot_info_free(lua_touserdata(L, 1));
    return 0;
}

static int seixo_load(lua_State *L)
{
    static const char *const keys[] = {"dim", NULL};
    const char *path = sx_lua_checkname(L, 1);
    int64_t dim = 0;
    if (!lua_isnoneornil(L, 2)) {
        sx_lua_checkkeys(L, 2, keys);
        sx_lua_optintfield(L, 2, "dim", 2, 3, &dim);
    }
    lua_settop(L, 2);
    /* ranks sharing the model read the file each: every rank, the same path */
    char call[96];
    if (sx_lua_parallel_sharing()) sx_lua_parallel_check_call(L, path_call(call, sizeof call, "seixo.load", path));
    sx_lua_model_threads(L, NULL, "seixo.load"); /* a bad seixo.threads, named here */
    /* the userdata first, so the loaded model always has an owner */
    lua_pushcfunction(L, sx_lua_model_new);
    lua_call(L, 0, 1);
    sx_lua_model *u = sx_lua_modelud(L, 3);
    /* the trees read with it are freed by a to-be-closed value, whatever happens */
    sx_snapshot_info *info = lua_newuserdatauv(L, sizeof *info, 0); /* 4 */
    memset(info, 0, sizeof *info);
    lua_createtable(L, 0, 1);
    lua_pushcfunction(L, info_free);
    lua_setfield(L, -2, "__close");
    lua_setmetatable(L, -2);
    lua_toclose(L, 4);
    char err[1024];
    sx_model *m = sx_snapshot_load(path, (int)dim, info, err, sizeof err);
    if (!sx_lua_parallel_all_read(m != NULL, err, sizeof err)) {
        sx_model_destroy(m); /* read here, not on another rank */
        return luaL_error(L, "%s", err);
    }
    const sx_model *placeholder = u->m;
    sx_model_destroy(u->m);
    u->m = m;
    /* the file's thread count is the saving run's: --threads here wins, as for seixo.model */
    sx_lua_model_threads(L, m, "seixo.load");
    u->decomposed = sx_lua_parallel_decompose(m); /* as seixo.model: over the ranks under mpirun */
    sx_lua_model_share(L, placeholder, u->decomposed ? m : NULL); /* the placeholder's number, if shared */
    /* the trees into the model's state */
    for (int k = 0; k < info->ntrees; k++) {
        const char *name = info->trees[k].name;
        if (strcmp(name, "vars") != 0 && strcmp(name, "state") != 0) continue;
        push_tree(L, &info->trees[k].tree);
        lua_getiuservalue(L, 3, 1);
        if (strcmp(name, "vars") == 0) {
            lua_pushvalue(L, -2);
            lua_setfield(L, -2, "vars");
        } else {
            for (int q = 0; saved_state[q]; q++)
                if (lua_getfield(L, -2, saved_state[q]) == LUA_TTABLE) lua_setfield(L, -2, saved_state[q]);
                else lua_pop(L, 1);
            const char *field;
            for (int q = 0; (field = optional_state(q)); q++)
                if (lua_getfield(L, -2, field) == LUA_TTABLE) lua_setfield(L, -2, field);
                else lua_pop(L, 1);
        }
        lua_pop(L, 2);
    }
    sx_lua_histories_restore(L, 3, info->histories, info->nhistories, path);
    sx_lua_state(L, 3, "seeds");
    for (int k = 0; k < info->nseeds; k++) {
        lua_pushinteger(L, (lua_Integer)info->seeds[k]);
        lua_rawseti(L, -2, k + 1);
    }
    lua_pop(L, 1);
    lua_pushvalue(L, 3);
    return 1;
}

static int model_vars(lua_State *L)
{
    sx_lua_checkmodel(L, 1);
    sx_lua_state(L, 1, "vars");
    return 1;
}

/* -------------------------------------------------------------- outputs */

typedef struct output {
    sx_series *s;  // the open series; NULL when closed, and on ranks other than 0 of a decomposed model
    int64_t every;
    bool open;     // not closed yet
    bool shared;   // of a model decomposed over MPI ranks: rank 0 writes, every rank learns the outcome
    int64_t count; // the series' snapshots (rank 0's count, on every rank)
} output;

/* The output's uservalues: 1 the model, 2 its callback id, 3 the step of
 * the last sample of each history handed to the series (name -> step),
 * 4 its path. */
static output *check_output(lua_State *L, int idx) { return luaL_checkudata(L, idx, SX_LUA_OUTPUT); }

/* A snapshot of m (NULL: none) and the histories' new samples, of the
 * output at idx whose model userdata is at `model`. `collective`: every
 * rank of a decomposed model makes this call and raises rank 0's error
 * (not from __gc, which comes at different times on different ranks). */
static void write_now(lua_State *L, int idx, int model, const sx_model *m, bool collective)
{
    idx = lua_absindex(L, idx);
    model = lua_absindex(L, model);
    output *o = check_output(L, idx);
    if (collective && o->shared) sx_lua_check_model_call(L, sx_lua_tomodel(L, model), "an output's samples");
    lua_getiuservalue(L, idx, 3);
    const int passed = lua_gettop(L);
    int n;
    const sx_io_history *h = sx_lua_histories_push(L, model, 0, passed, &n);
    char err[1024] = "";
    if (o->s) {
        if (m) sx_series_write(o->s, m, h, n, err, sizeof err);
        else sx_series_write_histories(o->s, h, n, err, sizeof err);
        o->count = sx_series_count(o->s);
    }
    if (sx_lua_parallel_outcome(collective && o->shared, err, sizeof err, &o->count)) luaL_error(L, "%s", err);
    for (int k = 0; k < n; k++)
        if (h[k].n > 0) {
            lua_pushinteger(L, (lua_Integer)h[k].steps[h[k].n - 1]);
            lua_setfield(L, passed, h[k].name);
        }
    lua_settop(L, passed - 1);
}

/* The histories' samples since the last snapshot, before the output closes;
 * a model already closed has its state still. Upvalue 1: whether the call
 * is collective (write_now). */
static int flush_histories(lua_State *L)
{
    if (lua_getiuservalue(L, 1, 1) == LUA_TUSERDATA)
        write_now(L, 1, -1, NULL, lua_toboolean(L, lua_upvalueindex(1)));
    return 0;
}

/* The "after" callback: upvalue 1 is the output. */
static int output_callback(lua_State *L)
{
    output *o = check_output(L, lua_upvalueindex(1));
    if (o->open) write_now(L, lua_upvalueindex(1), 1, sx_lua_checkmodel(L, 1), true);
    return 0;
}

/* Writes the last samples and closes the file: `collective` as write_now;
 * err gets the first failure (empty: none). */
static void close_series(lua_State *L, int idx, bool collective, char *err, size_t size)
{
    output *o = check_output(L, idx);
    if (collective && o->shared) sx_lua_parallel_check_call(L, "o:close");
    lua_pushboolean(L, collective);
    lua_pushcclosure(L, flush_histories, 1);
    lua_pushvalue(L, idx);
    if (lua_pcall(L, 1, 0, 0) != LUA_OK) {
        const char *why = lua_tostring(L, -1);
        snprintf(err, size, "%s", why ? why : "the series' last samples could not be written");
        lua_pop(L, 1);
    }
    /* a failure to write the last samples still closes the file */
    char closing[1024] = "";
    sx_series_close(o->s, closing, sizeof closing);
    o->s = NULL;
    o->open = false;
    sx_lua_parallel_outcome(collective && o->shared, closing, sizeof closing, NULL);
    if (!err[0]) snprintf(err, size, "%s", closing);
}

static int output_close(lua_State *L)
{
    output *o = check_output(L, 1);
    if (!o->open) return 0;
    lua_settop(L, 1);
    char err[1024] = "";
    close_series(L, 1, true, err, sizeof err);
    /* stop the callback, if the model is still open */
    if (lua_getiuservalue(L, 1, 1) == LUA_TUSERDATA && sx_lua_tomodel(L, -1)) {
        lua_getiuservalue(L, 1, 2);
        sx_lua_callback_remove(L, -2, lua_tointeger(L, -1));
    }
    if (err[0]) return luaL_error(L, "%s", err);
    return 0;
}

/* Collected (or the Lua state closes) without o:close(): the last samples
 * are written too, and a failure cannot be raised from here, so it is
 * dropped (o:close() reports it). */
static int output_gc(lua_State *L)
{
    output *o = check_output(L, 1);
    if (!o->open) return 0;
    lua_settop(L, 1);
    char err[1024] = "";
    close_series(L, 1, false, err, sizeof err);
    return 0;
}

static int output_write(lua_State *L)
{
    output *o = check_output(L, 1);
    if (!o->open) return luaL_error(L, "the output has been closed");
    lua_getiuservalue(L, 1, 1);
    write_now(L, 1, -1, sx_lua_checkmodel(L, -1), true);
    return 0;
}

static int output_count(lua_State *L)
{
    output *o = check_output(L, 1);
    lua_pushinteger(L, (lua_Integer)o->count); /* closed too: what it wrote */
    return 1;
}

static int output_path(lua_State *L)
{
    output *o = check_output(L, 1);
    if (!o->open) return luaL_error(L, "the output has been closed");
    lua_getiuservalue(L, 1, 4);
    return 1;
}

static int output_tostring(lua_State *L)
{
    output *o = check_output(L, 1);
    if (o->open) {
        lua_getiuservalue(L, 1, 4);
        lua_pushfstring(L, "seixo.output %s (every %I steps, %I snapshots)", lua_tostring(L, -1), (lua_Integer)o->every,
                        (lua_Integer)o->count);
    } else {
        lua_pushliteral(L, "seixo.output (closed)");
    }
    return 1;
}

/* The SX_OUT_* bits of the `fields` array at idx (all names, or "all"). */
static unsigned fields_of(lua_State *L, int idx, int arg)
{
    if (lua_isnil(L, idx)) return SX_OUT_DEFAULT;
    if (!lua_istable(L, idx)) sx_lua_fielderror(L, arg, "fields", "an array of field names expected");
    unsigned bits = 0;
    for (lua_Integer i = 1; lua_rawgeti(L, idx, i) != LUA_TNIL; i++) {
        const char *name = lua_tostring(L, -1);
        const unsigned b = name ? sx_series_field_bit(name) : 0;
        if (name && strcmp(name, "all") == 0) {
            bits |= 2 * SX_OUT_WALLS - 1;
        } else if (!b) {
            luaL_Buffer buf;
            luaL_buffinit(L, &buf);
            for (unsigned k = 1; k <= SX_OUT_WALLS; k <<= 1) {
                luaL_addstring(&buf, sx_series_field_name(k));
                luaL_addstring(&buf, ", ");
            }
            luaL_addstring(&buf, "all");
            luaL_pushresult(&buf);
            sx_lua_fielderror(L, arg, "fields",
                              lua_pushfstring(L, "unknown field '%s' (valid: %s)", name ? name : luaL_typename(L, -2),
                                              lua_tostring(L, -1)));
        }
        bits |= b;
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    return bits ? bits : SX_OUT_DEFAULT;
}

static int model_output(lua_State *L)
{
    static const char *const keys[] = {"path", "every", "fields", "compression", "append", NULL};
    const sx_model *m = sx_lua_checkmodel(L, 1);
    sx_lua_checkkeys(L, 2, keys);
    const char *path = sx_lua_optstrfield(L, 2, "path");
    if (!path) return sx_lua_fielderror(L, 2, "path", "a file name (.h5) is required");
    int64_t every = 1000, level = 0;
    sx_lua_optintfield(L, 2, "every", 1, INT64_MAX / 2, &every);
    sx_lua_optintfield(L, 2, "compression", 0, 9, &level);
    lua_getfield(L, 2, "fields");
    const unsigned fields = fields_of(L, lua_gettop(L), 2);
    lua_getfield(L, 2, "append");
    const bool append = lua_toboolean(L, -1);
    lua_settop(L, 2);

    output *o = lua_newuserdatauv(L, sizeof *o, 4); /* 3 */
    memset(o, 0, sizeof *o);
    o->every = every;
    o->shared = sx_model_ranks(m) > 1;
    luaL_setmetatable(L, SX_LUA_OUTPUT);
    lua_pushvalue(L, 1);
    lua_setiuservalue(L, 3, 1);
    lua_newtable(L);
    lua_setiuservalue(L, 3, 3);
    sx_series_opts so;
    memset(&so, 0, sizeof so);
    so.fields = fields;
    so.compression = (int)level;
    so.append = append;
    so.check_step = true, so.step = sx_model_step_count(m);
    so.provenance.script = script_path(L);
    so.provenance.seeds = seeds_of(L, 1, &so.provenance.nseeds);
    char err[1024] = "";
    if (o->shared) sx_lua_check_model_call(L, m, "m:output");
    if (sx_lua_parallel_writes(o->shared)) {
        o->s = sx_series_open(path, sx_model_dim(m), &so, err, sizeof err);
        if (o->s) o->count = sx_series_count(o->s);
    }
    if (sx_lua_parallel_outcome(o->shared, err, sizeof err, &o->count)) return luaL_error(L, "%s", err);
    /* rank 0 made the series and its .xmf: no shadow stands for them */
    sx_lua_rank_file_written(L, path);
    char *xmf = sx_io_xmf_path(path);
    if (xmf) sx_lua_rank_file_written(L, xmf);
    free(xmf);
    o->open = true;
    lua_pushstring(L, o->s ? sx_series_path(o->s) : path);
    lua_setiuservalue(L, 3, 4);
    lua_settop(L, 3);
    /* appending at the step of the series' last snapshot (a model loaded
     * from the save made there), that snapshot is not written twice */
    int64_t again = o->s && sx_series_opened_at(o->s) == so.step;
    if (o->shared) again = sx_lua_parallel_root_value(again);
    if (!again) write_now(L, 3, 1, m, true);
    /* m:on("after", callback, {every = every}) */
    lua_getfield(L, 1, "on");
    lua_pushvalue(L, 1);
    lua_pushliteral(L, "after");
    lua_pushvalue(L, 3);
    lua_pushcclosure(L, output_callback, 1);
    lua_createtable(L, 0, 1);
    lua_pushinteger(L, (lua_Integer)every);
    lua_setfield(L, -2, "every");
    lua_call(L, 4, 1);
    sx_lua_callback_own(L, 1, lua_tointeger(L, -1), "an output's");
    lua_setiuservalue(L, 3, 2);
    return 1;
}

/* seixo.replaceable(path) -> true | false, why: whether a file written to
 * path (through a temporary name renamed over it) may replace what is
 * there; the lab library's files check it as m:save does. */
static int seixo_replaceable(lua_State *L)
{
    const char *why = sx_io_unreplaceable(sx_lua_checkname(L, 1));
    lua_pushboolean(L, why == NULL);
    if (!why) return 1;
    lua_pushstring(L, why);
    return 2;
}

static int seixo_xdmf(lua_State *L)
{
    const char *path = sx_lua_checkname(L, 1);
    char err[1024];
    if (sx_series_write_xdmf(path, err, sizeof err)) return luaL_error(L, "%s", err);
    return 0;
}

/* ------------------------------------------------------------- register */

void sx_lua_io_register(lua_State *L)
{
    static const luaL_Reg model_methods[] = {
        {"save", model_save},
        {"vars", model_vars},
        {"output", model_output},
        {NULL, NULL},
    };
    static const luaL_Reg meta[] = {
        {"__gc", output_gc},
        {"__close", output_close},
        {"__tostring", output_tostring},
        {NULL, NULL},
    };
    static const luaL_Reg methods[] = {
        {"write", output_write},
        {"close", output_close},
        {"count", output_count},
        {"path", output_path},
        {NULL, NULL},
    };
    static const luaL_Reg functions[] = {
        {"load", seixo_load},
        {"xdmf", seixo_xdmf},
        {"replaceable", seixo_replaceable},
        {"script", seixo_script},
        {NULL, NULL},
    };
    /* the module table is on the top of the stack */
    luaL_setfuncs(L, functions, 0);
    /* the model class exists: its methods table takes ours */
    luaL_getmetatable(L, SX_LUA_MODEL);
    lua_getfield(L, -1, "__methods");
    luaL_setfuncs(L, model_methods, 0);
    lua_pop(L, 2);
    sx_lua_newclass(L, SX_LUA_OUTPUT, "output", meta, methods, NULL, NULL);
    lua_pop(L, 1);
}
