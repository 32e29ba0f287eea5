/* Groups, selections and bulk operations over balls, in C so that a script
 * over 100k balls stays fast:
 *   m:group(name, selector)   put the selected balls in a group -> count
 *   m:groups()                group name -> number of balls
 *   m:set{filter..., field = value, ...}   set fields of the selected balls -> count
 *   m:sum(field, filter), m:mean(...), m:min(...), m:max(...)
 *   m:count(filter)           number of selected balls
 *   m:remove_balls(filter)    remove the selected balls -> count
 * A filter is a table with optional keys group (a name), region (see
 * region.c; a ball is in when its centre is) and where (a predicate
 * function(ball) -> boolean); no filter selects every ball.
 *
 * The core stores a group number per ball (0: none); names live in the
 * model's state: `groups` maps a name to its number, `group_names` the
 * number back to its name.
 *
 * A ball has SX_LUA_SLOTS group slots, as in PFC: slot 1 is the core's
 * group (b.group, the output files' group); slots 2 and up are tables of
 * the model's state (`slot2`, ...: ball id -> group number), made when a
 * group is first put in them, so a model that uses one slot pays nothing.
 * A filter's group matches a ball that has it in any slot, or in the slot
 * given by the filter's `slot`. m:save writes slots 2 and up with the rest
 * of the Lua state (io.c), seixo.load restores them, and m:hash() covers
 * them (sx_lua_slots_digest). */
#include <math.h>
#include <string.h>

#include "bindings.h"

/* -------------------------------------------------------------- names */

int32_t sx_lua_group_id(lua_State *L, int model, const char *name, bool create)
{
    model = lua_absindex(L, model);
    if (!*name) luaL_error(L, "a group name must not be empty");
    sx_lua_state(L, model, "groups");
    lua_getfield(L, -1, name);
    int32_t g = (int32_t)lua_tointeger(L, -1);
    lua_pop(L, 1);
    if (!g && create) {
        sx_lua_state(L, model, "group_names");
        const lua_Unsigned n = lua_rawlen(L, -1);
        if (n >= INT32_MAX - 1) luaL_error(L, "too many groups");
        g = (int32_t)n + 1;
        lua_pushstring(L, name);
        lua_rawseti(L, -2, g);
        lua_pop(L, 1);
        lua_pushinteger(L, g);
        lua_setfield(L, -2, name);
    }
    lua_pop(L, 1);
    return g;
}

void sx_lua_push_group_name(lua_State *L, int model, int32_t g)
{
    if (g == 0) {
        lua_pushnil(L);
        return;
    }
    sx_lua_state(L, model, "group_names");
    if (lua_rawgeti(L, -1, g) == LUA_TNIL) {
        lua_pop(L, 1);
        lua_pushinteger(L, g);  // a number set outside the Lua layer
    }
    lua_remove(L, -2);
}

/* ------------------------------------------------------------ filters */

/* ---------------------------------------------------------------- slots */

static const char *const slot_names[] = {NULL, NULL, "slot2", "slot3", "slot4", "slot5", "slot6", "slot7", "slot8"};
_Static_assert(sizeof slot_names / sizeof *slot_names == SX_LUA_SLOTS + 1, "a table name per slot");

int32_t sx_lua_slot_group(lua_State *L, int model, const sx_model *m, int64_t id, int slot)
{
    int32_t g = 0;
    if (slot == 1) {
        sx_ball_group(m, id, &g);
        return g;
    }
    lua_getiuservalue(L, model, 1);
    if (lua_getfield(L, -1, slot_names[slot]) == LUA_TTABLE) {
        lua_rawgeti(L, -1, (lua_Integer)id);
        g = (int32_t)lua_tointeger(L, -1);
        lua_pop(L, 1);
    }
    lua_pop(L, 2);
    return g;
}

const char *sx_lua_slot_table(int slot)
{
    return slot >= 2 && slot <= SX_LUA_SLOTS ? slot_names[slot] : NULL;
}

void sx_lua_slots_forget(lua_State *L, int model, int64_t id)
{
    lua_getiuservalue(L, model, 1);
    for (int k = 2; k <= SX_LUA_SLOTS; k++) {
        if (lua_getfield(L, -1, slot_names[k]) == LUA_TTABLE) {
            lua_pushnil(L);
            lua_rawseti(L, -2, (lua_Integer)id);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

/* splitmix64's finaliser: one entry's bits spread over the word */
static uint64_t mix(uint64_t x)
{
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9u;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebu;
    return x ^ (x >> 31);
}

uint64_t sx_lua_slots_digest(lua_State *L, int model)
{
    model = lua_absindex(L, model);
    uint64_t sum = 0; /* a sum: the tables' order of traversal does not matter */
    lua_getiuservalue(L, model, 1);
    for (int k = 2; k <= SX_LUA_SLOTS; k++) {
        if (lua_getfield(L, -1, slot_names[k]) == LUA_TTABLE) {
            lua_pushnil(L);
            while (lua_next(L, -2)) {
                const uint64_t id = (uint64_t)lua_tointeger(L, -2), g = (uint64_t)lua_tointeger(L, -1);
                if (g) sum += mix(mix(id * 16 + (uint64_t)k) ^ g);
                lua_pop(L, 1);
            }
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    return sum;
}

void sx_lua_set_slot_group(lua_State *L, int model, sx_model *m, int64_t id, int slot, int32_t g, const char *what)
{
    if (slot == 1) {
        sx_lua_check(L, m, sx_ball_set_group(m, id, g), what);
        return;
    }
    sx_lua_state(L, model, slot_names[slot]);
    if (g) lua_pushinteger(L, g);
    else lua_pushnil(L);
    lua_rawseti(L, -2, (lua_Integer)id);
    lua_pop(L, 1);
}

/* A slot number at idx (nil: `dflt`), an argument error on arg otherwise. */
static int check_slot(lua_State *L, int idx, int arg, int dflt)
{
    if (lua_isnoneornil(L, idx)) return dflt;
    const lua_Integer k = lua_isinteger(L, idx) ? lua_tointeger(L, idx) : 0;
    if (k < 1 || k > SX_LUA_SLOTS)
        luaL_argerror(L, arg, lua_pushfstring(L, "a group slot from 1 to %d expected", SX_LUA_SLOTS));
    return (int)k;
}

const char *const sx_lua_filter_keys[] = {"group", "slot", "region", "where", NULL};

/* The group named by the string at idx; an unknown name is an error that lists the groups. */
static int32_t existing_group(lua_State *L, int model, int arg, int idx)
{
    if (lua_type(L, idx) != LUA_TSTRING)
        sx_lua_fielderror(L, arg, "group", lua_pushfstring(L, "group name expected, got %s", luaL_typename(L, idx)));
    const char *name = lua_tostring(L, idx);
    const int32_t g = *name ? sx_lua_group_id(L, model, name, false) : 0;
    if (!g) {
        sx_lua_state(L, model, "group_names");
        const int t = lua_gettop(L);
        const lua_Integer n = (lua_Integer)lua_rawlen(L, t);
        lua_pushstring(L, n ? "" : "none");
        for (lua_Integer i = 1; i <= n; i++) {
            lua_rawgeti(L, t, i);
            lua_pushfstring(L, "%s%s%s", lua_tostring(L, t + 1), i > 1 ? ", " : "", lua_tostring(L, -1));
            lua_replace(L, t + 1);
            lua_pop(L, 1);
        }
        sx_lua_fielderror(L, arg, "group",
                          lua_pushfstring(L, "no group named '%s' (groups: %s)", name, lua_tostring(L, t + 1)));
    }
    return g;
}

void sx_lua_filter_read(lua_State *L, int model, int arg, sx_lua_filter *f)
{
    memset(f, 0, sizeof *f);
    f->model = lua_absindex(L, model);
    if (lua_isnoneornil(L, arg)) return;
    arg = lua_absindex(L, arg);
    const int dim = sx_model_dim(sx_lua_checkmodel_scattered(L, model));
    if (lua_getfield(L, arg, "group") != LUA_TNIL) f->group = existing_group(L, f->model, arg, lua_gettop(L));
    lua_pop(L, 1);
    lua_getfield(L, arg, "slot");
    f->slot = check_slot(L, lua_gettop(L), arg, 0);
    lua_pop(L, 1);
    if (lua_getfield(L, arg, "region") != LUA_TNIL) {
        const int top = lua_gettop(L);
        sx_lua_region_read(L, top, dim, arg, "region", &f->region);
        f->has_region = true;
        if (lua_gettop(L) > top) lua_remove(L, top);  // keep the polygon's storage, drop the table
        else lua_pop(L, 1);
    } else {
        lua_pop(L, 1);
    }
    if (lua_getfield(L, arg, "where") != LUA_TNIL) {
        if (!lua_isfunction(L, -1))
            sx_lua_fielderror(L, arg, "where", lua_pushfstring(L, "function expected, got %s", luaL_typename(L, -1)));
        f->where = lua_gettop(L);  // stays on the stack
    } else {
        lua_pop(L, 1);
    }
}

static bool filter_match(lua_State *L, const sx_model *m, const sx_lua_filter *f, int64_t id)
{
    if (f->group) {
        bool in = false;
        for (int k = f->slot ? f->slot : 1; !in && k <= (f->slot ? f->slot : SX_LUA_SLOTS); k++)
            in = sx_lua_slot_group(L, f->model, m, id, k) == f->group;
        if (!in) return false;
    }
    if (f->has_region) {
        double x[3];
        if (sx_ball_get_vec(m, id, SX_BALL_POS, x) != SX_OK || !sx_lua_region_contains(&f->region, x, 0)) return false;
    }
    if (f->where) {
        lua_pushvalue(L, f->where);
        sx_lua_pushhandle(L, f->model, &sx_lua_ball_kind, id);
        lua_call(L, 1, 1);
        const bool ok = lua_toboolean(L, -1);
        lua_pop(L, 1);
        return ok;
    }
    return true;
}

/* The model to select from: a region reads every ball's position (shared
 * from its rank, not gathered); groups every rank holds. */
static const sx_model *selection_model(lua_State *L, const sx_lua_filter *f)
{
    return f->has_region ? sx_lua_checkmodel_motion(L, f->model) : sx_lua_checkmodel_scattered(L, f->model);
}

int64_t *sx_lua_filter_ids(lua_State *L, const sx_lua_filter *f, int64_t *n)
{
    const sx_model *m = selection_model(L, f);
    const int64_t count = sx_ball_count(m);
    int64_t *ids = lua_newuserdatauv(L, (size_t)(count > 0 ? count : 1) * sizeof *ids, 0);
    for (int64_t i = 0; i < count; i++) ids[i] = sx_ball_id_at(m, i);
    int64_t k = 0;
    for (int64_t i = 0; i < count; i++) {
        /* a predicate may remove balls or close the model */
        if (f->where) m = selection_model(L, f);
        if (!sx_ball_exists(m, ids[i])) continue;
        if (filter_match(L, m, f, ids[i])) ids[k++] = ids[i];
    }
    *n = k;
    return ids;
}

/* The selection of a bulk call: the filter in the table at arg; pushes the
 * ids' storage and returns the ids. */
static int64_t *select_balls(lua_State *L, int arg, int64_t *n)
{
    sx_lua_filter f;
    sx_lua_filter_read(L, 1, arg, &f);
    return sx_lua_filter_ids(L, &f, n);
}

/* ---------------------------------------------------- group, groups, count */

/* m:group(name, selector[, slot]): selector a filter table or a predicate. */
static int model_group(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    const char *name = sx_lua_checkname(L, 2);
    luaL_argcheck(L, *name, 2, "a group name must not be empty");
    const int slot = check_slot(L, 4, 4, 1);
    if (lua_isfunction(L, 3)) {
        lua_createtable(L, 0, 1);
        lua_pushvalue(L, 3);
        lua_setfield(L, -2, "where");
        lua_replace(L, 3);
    } else if (!lua_istable(L, 3)) {
        return luaL_typeerror(L, 3, "filter table or predicate function");
    }
    lua_settop(L, 3);
    sx_lua_checkkeys(L, 3, sx_lua_filter_keys);
    int64_t n;
    const int64_t *ids = select_balls(L, 3, &n);
    m = sx_lua_checkmodel(L, 1);  // a predicate may have closed it
    const int32_t g = sx_lua_group_id(L, 1, name, true);
    int64_t done = 0;
    for (int64_t i = 0; i < n; i++)
        if (sx_ball_exists(m, ids[i])) {
            sx_lua_set_slot_group(L, 1, m, ids[i], slot, g, "m:group");
            done++;
        }
    lua_pushinteger(L, (lua_Integer)done);
    return 1;
}

static int model_groups(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* the groups every rank holds */
    sx_lua_state(L, 1, "group_names");
    const int names = lua_gettop(L);
    const lua_Integer ng = (lua_Integer)lua_rawlen(L, names);
    lua_Integer *counts = lua_newuserdatauv(L, (size_t)(ng + 1) * sizeof *counts, 0);
    memset(counts, 0, (size_t)(ng + 1) * sizeof *counts);
    /* a ball counts once in each group it is in, whatever the slots */
    int32_t *seen = lua_newuserdatauv(L, SX_LUA_SLOTS * sizeof *seen, 0);
    const int64_t n = sx_ball_count(m);
    for (int64_t i = 0; i < n; i++) {
        const int64_t id = sx_ball_id_at(m, i);
        for (int k = 1; k <= SX_LUA_SLOTS; k++) {
            const int32_t g = seen[k - 1] = sx_lua_slot_group(L, 1, m, id, k);
            bool again = false;
            for (int j = 1; j < k; j++) again |= seen[j - 1] == g;
            if (g > 0 && g <= ng && !again) counts[g]++;
        }
    }
    lua_createtable(L, 0, (int)ng);
    for (lua_Integer g = 1; g <= ng; g++) {
        lua_rawgeti(L, names, g);
        lua_pushinteger(L, counts[g]);
        lua_rawset(L, -3);
    }
    return 1;
}

static int model_count(lua_State *L)
{
    sx_lua_checkmodel_scattered(L, 1); /* a region shares the balls' motion: no gather */
    if (!lua_isnoneornil(L, 2)) sx_lua_checkkeys(L, 2, sx_lua_filter_keys);
    lua_settop(L, 2);
    int64_t n;
    select_balls(L, 2, &n);
    lua_pushinteger(L, (lua_Integer)n);
    return 1;
}

static int model_remove_balls(lua_State *L)
{
    sx_lua_checkmodel(L, 1);
    sx_lua_checkkeys(L, 2, sx_lua_filter_keys);
    lua_settop(L, 2);
    int64_t n;
    int64_t *ids = select_balls(L, 2, &n);
    const sx_model *m = sx_lua_checkmodel(L, 1);
    /* a predicate may have removed some of the selected balls */
    int64_t live = 0;
    for (int64_t i = 0; i < n; i++)
        if (sx_ball_exists(m, ids[i])) ids[live++] = ids[i];
    sx_lua_remove_balls(L, 1, ids, live, "m:remove_balls");
    lua_pushinteger(L, (lua_Integer)live);
    return 1;
}

/* --------------------------------------------------------------- m:set */

typedef enum { F_VEC, F_SCALAR, F_MATERIAL, F_FIX } settable_kind;

static const struct settable {
    const char *name;
    settable_kind kind;
    int which;       // sx_ball_vec or sx_ball_scalar
    bool rotational;
} settables[] = {
    {"vel", F_VEC, SX_BALL_VEL, false},
    {"spin", F_VEC, SX_BALL_SPIN, true},
    {"applied_force", F_VEC, SX_BALL_APPLIED_FORCE, false},
    {"applied_moment", F_VEC, SX_BALL_APPLIED_MOMENT, true},
    {"radius", F_SCALAR, SX_BALL_RADIUS, false},
    {"damping", F_SCALAR, SX_BALL_DAMPING, false},
    {"material", F_MATERIAL, 0, false},
    {"fix", F_FIX, 0, false},
};
enum { NSETTABLE = sizeof settables / sizeof settables[0] };

typedef struct setting {
    const struct settable *f;
    double v[3];
    int material;
    unsigned mask;
} setting;

static int model_set(lua_State *L)
{
    static const char *const keys[] = {"group", "region", "where", "vel", "spin", "applied_force",
                                       "applied_moment", "radius", "damping", "material", "fix", NULL};
    sx_model *m = sx_lua_checkmodel(L, 1);
    sx_lua_checkkeys(L, 2, keys);
    lua_settop(L, 2);
    const int dim = sx_model_dim(m);
    setting todo[NSETTABLE];
    int nset = 0;
    for (int k = 0; k < NSETTABLE; k++) {
        const struct settable *f = &settables[k];
        lua_pushstring(L, f->name);
        const bool present = lua_rawget(L, 2) != LUA_TNIL;
        setting *s = &todo[nset];
        s->f = f;
        /* nil means absent here, so no fixity at all is written fix = {} */
        if (f->kind == F_FIX && present) s->mask = sx_lua_fixmask(L, dim, lua_gettop(L), "m:set: field 'fix'");
        lua_pop(L, 1);
        if (!present) continue;
        switch (f->kind) {
        case F_VEC: sx_lua_checkvecfield(L, 2, f->name, f->rotational ? sx_lua_rdim(dim) : dim, s->v); break;
        case F_SCALAR: s->v[0] = sx_lua_checknumfield(L, 2, f->name); break;
        case F_MATERIAL: {
            const char *name = sx_lua_optstrfield(L, 2, "material");
            s->material = sx_lua_material_arg(L, m, 2, "material", name);
            break;
        }
        case F_FIX: break;
        }
        nset++;
    }
    if (nset == 0) return luaL_argerror(L, 2, "nothing to set: give a field such as vel = {...} or fix = 'vel'");
    int64_t n;
    const int64_t *ids = select_balls(L, 2, &n);
    m = sx_lua_checkmodel(L, 1);
    int64_t done = 0;
    for (int64_t i = 0; i < n; i++) {
        const int64_t id = ids[i];
        if (!sx_ball_exists(m, id)) continue;
        for (int k = 0; k < nset; k++) {
            const setting *s = &todo[k];
            sx_status st = SX_OK;
            switch (s->f->kind) {
            case F_VEC: st = sx_ball_set_vec(m, id, (sx_ball_vec)s->f->which, s->v); break;
            case F_SCALAR: st = sx_ball_set(m, id, (sx_ball_scalar)s->f->which, s->v[0]); break;
            case F_MATERIAL: st = sx_ball_set_material(m, id, s->material); break;
            case F_FIX: st = sx_ball_set_fixity(m, id, s->mask); break;
            }
            if (st != SX_OK)
                return luaL_error(L, "m:set: field '%s': %s", s->f->name, sx_lua_core_message(sx_model_error(m)));
        }
        done++;
    }
    lua_pushinteger(L, (lua_Integer)done);
    return 1;
}

/* ------------------------------------------------------ sum, mean, min, max */

typedef enum { Q_VEC, Q_SCALAR, Q_VOLUME, Q_SPEED, Q_KINETIC } quantity_kind;

static const struct quantity {
    const char *name;
    quantity_kind kind;
    int which;
    bool rotational;
} quantities[] = {
    {"pos", Q_VEC, SX_BALL_POS, false},
    {"vel", Q_VEC, SX_BALL_VEL, false},
    {"spin", Q_VEC, SX_BALL_SPIN, true},
    {"force", Q_VEC, SX_BALL_FORCE, false},
    {"moment", Q_VEC, SX_BALL_MOMENT, true},
    {"applied_force", Q_VEC, SX_BALL_APPLIED_FORCE, false},
    {"applied_moment", Q_VEC, SX_BALL_APPLIED_MOMENT, true},
    {"radius", Q_SCALAR, SX_BALL_RADIUS, false},
    {"mass", Q_SCALAR, SX_BALL_MASS, false},
    {"inertia", Q_SCALAR, SX_BALL_INERTIA, false},
    {"damping", Q_SCALAR, SX_BALL_DAMPING, false},
    {"volume", Q_VOLUME, 0, false},
    {"speed", Q_SPEED, 0, false},
    {"kinetic", Q_KINETIC, 0, false},
    {NULL, 0, 0, false},
};

static const char *const quantity_names[] = {"pos",    "vel",     "spin",    "force",  "moment",
                                             "applied_force", "applied_moment", "radius", "mass", "inertia",
                                             "damping", "volume", "speed", "kinetic", NULL};

/* The value of a quantity for ball id: its n components into v. */
static void quantity_value(lua_State *L, const sx_model *m, const struct quantity *q, int64_t id, double *v,
                           const char *what)
{
    const int dim = sx_model_dim(m);
    double x[3], y[3], r;
    switch (q->kind) {
    case Q_VEC: sx_lua_check(L, m, sx_ball_get_vec(m, id, (sx_ball_vec)q->which, v), what); return;
    case Q_SCALAR: sx_lua_check(L, m, sx_ball_get(m, id, (sx_ball_scalar)q->which, v), what); return;
    case Q_VOLUME:
        sx_lua_check(L, m, sx_ball_get(m, id, SX_BALL_RADIUS, &r), what);
        v[0] = dim == 3 ? 4.0 / 3.0 * SX_LUA_PI * r * r * r : SX_LUA_PI * r * r;
        return;
    case Q_SPEED:
    case Q_KINETIC: {
        sx_lua_check(L, m, sx_ball_get_vec(m, id, SX_BALL_VEL, x), what);
        double v2 = 0;
        for (int k = 0; k < dim; k++) v2 += x[k] * x[k];
        if (q->kind == Q_SPEED) {
            v[0] = sqrt(v2);
            return;
        }
        double mass, inertia, w2 = 0;
        sx_lua_check(L, m, sx_ball_get(m, id, SX_BALL_MASS, &mass), what);
        sx_lua_check(L, m, sx_ball_get(m, id, SX_BALL_INERTIA, &inertia), what);
        sx_lua_check(L, m, sx_ball_get_vec(m, id, SX_BALL_SPIN, y), what);
        for (int k = 0; k < sx_lua_rdim(dim); k++) w2 += y[k] * y[k];
        v[0] = 0.5 * mass * v2 + 0.5 * inertia * w2;
        return;
    }
    }
}

enum { OP_SUM, OP_MEAN, OP_MIN, OP_MAX };
static const char *const op_names[] = {"m:sum", "m:mean", "m:min", "m:max"};

/* Whether a quantity reads the balls' motion, which a scattered model's
 * ranks share for it (the rest every rank holds). */
static bool reads_motion(const struct quantity *q)
{
    return q->kind == Q_SPEED || q->kind == Q_KINETIC || (q->kind == Q_VEC && sx_lua_is_motion((sx_ball_vec)q->which));
}

static int reduce(lua_State *L, int op)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1);
    const char *name = sx_lua_checkname(L, 2);
    const int qi = sx_lua_find(name, quantity_names);
    if (qi < 0) {
        sx_lua_pushlist(L, quantity_names);
        return luaL_argerror(L, 2, lua_pushfstring(L, "unknown field '%s' (fields: %s)", name, lua_tostring(L, -1)));
    }
    const struct quantity *q = &quantities[qi];
    if (!lua_isnoneornil(L, 3)) sx_lua_checkkeys(L, 3, sx_lua_filter_keys);
    lua_settop(L, 3);
    const int dim = sx_model_dim(m);
    const int nc = q->kind == Q_VEC ? (q->rotational ? sx_lua_rdim(dim) : dim) : 1;
    int64_t n;
    const int64_t *ids = select_balls(L, 3, &n);
    m = reads_motion(q) ? sx_lua_checkmodel_motion(L, 1) : sx_lua_checkmodel_scattered(L, 1);
    double acc[3] = {0, 0, 0};
    int64_t used = 0;
    for (int64_t i = 0; i < n; i++) {
        if (!sx_ball_exists(m, ids[i])) continue;
        double v[3] = {0, 0, 0};
        quantity_value(L, m, q, ids[i], v, op_names[op]);
        for (int k = 0; k < nc; k++) {
            if (op == OP_SUM || op == OP_MEAN) acc[k] += v[k];
            else if (used == 0 || (op == OP_MIN ? v[k] < acc[k] : v[k] > acc[k])) acc[k] = v[k];
        }
        used++;
    }
    if (used == 0 && op != OP_SUM) {
        lua_pushnil(L);  // no mean, min or max of nothing
        return 1;
    }
    if (op == OP_MEAN)
        for (int k = 0; k < nc; k++) acc[k] /= (double)used;
    sx_lua_pushvec(L, acc, nc);
    return 1;
}

static int model_sum(lua_State *L) { return reduce(L, OP_SUM); }
static int model_mean(lua_State *L) { return reduce(L, OP_MEAN); }
static int model_min(lua_State *L) { return reduce(L, OP_MIN); }
static int model_max(lua_State *L) { return reduce(L, OP_MAX); }

const luaL_Reg sx_lua_groups_methods[] = {
    {"group", model_group},
    {"groups", model_groups},
    {"set", model_set},
    {"sum", model_sum},
    {"mean", model_mean},
    {"min", model_min},
    {"max", model_max},
    {"count", model_count},
    {"remove_balls", model_remove_balls},
    {NULL, NULL},
};
