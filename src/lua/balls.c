/* Balls: m:ball{...} adds one, m:ball(id) finds one, m:balls([filter])
 * iterates. A ball object is a handle (model, id); its fields read and
 * write the core's state, and every access checks that the ball still
 * exists. Two fields live on the Lua side, in the model's state: the group
 * name (the core stores a number, groups.c maps names) and `extra`, a
 * table of user values per ball, dropped when the ball is removed. */
#include "bindings.h"

static const char *const ball_shown[] = {"pos", "radius", "vel", "material", "group", NULL};
const sx_lua_kind sx_lua_ball_kind = {"seixo.ball", "ball", sx_ball_exists, "extras", ball_shown, false};
#define ball_kind sx_lua_ball_kind

/* The ball of the handle at index 1: live, in an open model. */
static sx_model *check_ball(lua_State *L, int64_t *id) { return sx_lua_checkhandle(L, 1, &ball_kind, id); }
/* A read of a field every rank holds whole after a decomposed cycle (the
 * radius, material, fixity, group, applied loads: changed only by calls
 * that gather first). */
static sx_model *check_ball_whole(lua_State *L, int64_t *id) { return sx_lua_checkhandle_whole(L, 1, &ball_kind, id); }
/* A read of its motion, which a lazy cycle leaves current on its rank
 * alone: fetched from there (sx_lua_fetch_ball). */
static sx_model *check_ball_motion(lua_State *L, int64_t *id)
{
    sx_model *m = check_ball_whole(L, id);
    sx_lua_fetch_ball(L, m, "b", *id);
    return m;
}

/* The index of the named material, or -1 with the message pushed. */
static int find_material(lua_State *L, const sx_model *m, const char *name)
{
    const int i = sx_material_find(m, name);
    if (i < 0) lua_pushfstring(L, "no material named '%s'", name);
    return i;
}

/* ------------------------------------------------------------- fields */

static int vec_len(const sx_model *m, sx_ball_vec which)
{
    const bool rotational = which == SX_BALL_SPIN || which == SX_BALL_MOMENT || which == SX_BALL_APPLIED_MOMENT;
    return rotational ? sx_lua_rdim(sx_model_dim(m)) : sx_model_dim(m);
}

static int get_vec(lua_State *L, sx_ball_vec which)
{
    int64_t id;
    const sx_model *m = sx_lua_is_motion(which) ? check_ball_motion(L, &id) : check_ball_whole(L, &id);
    double v[3];
    sx_lua_checkfield(L, m, sx_ball_get_vec(m, id, which, v), "ball");
    sx_lua_pushvec(L, v, vec_len(m, which));
    return 1;
}

static int set_vec(lua_State *L, sx_ball_vec which)
{
    int64_t id;
    sx_model *m = check_ball(L, &id);
    double v[3] = {0, 0, 0};
    sx_lua_checkvalue(L, 3, vec_len(m, which), v, "ball", lua_tostring(L, 2));
    sx_lua_checkfield(L, m, sx_ball_set_vec(m, id, which, v), "ball");
    return 0;
}

static int get_scalar(lua_State *L, sx_ball_scalar which)
{
    int64_t id;
    const sx_model *m = check_ball_whole(L, &id);
    double v;
    sx_lua_checkfield(L, m, sx_ball_get(m, id, which, &v), "ball");
    lua_pushnumber(L, v);
    return 1;
}

static int set_scalar(lua_State *L, sx_ball_scalar which)
{
    int64_t id;
    sx_model *m = check_ball(L, &id);
    double v;
    sx_lua_checkvalue(L, 3, 1, &v, "ball", lua_tostring(L, 2));
    sx_lua_checkfield(L, m, sx_ball_set(m, id, which, v), "ball");
    return 0;
}

static int get_pos(lua_State *L) { return get_vec(L, SX_BALL_POS); }
static int get_vel(lua_State *L) { return get_vec(L, SX_BALL_VEL); }
static int get_spin(lua_State *L) { return get_vec(L, SX_BALL_SPIN); }
static int get_force(lua_State *L) { return get_vec(L, SX_BALL_FORCE); }
static int get_moment(lua_State *L) { return get_vec(L, SX_BALL_MOMENT); }
static int get_applied_force(lua_State *L) { return get_vec(L, SX_BALL_APPLIED_FORCE); }
static int get_applied_moment(lua_State *L) { return get_vec(L, SX_BALL_APPLIED_MOMENT); }
static int set_pos(lua_State *L) { return set_vec(L, SX_BALL_POS); }
static int set_vel(lua_State *L) { return set_vec(L, SX_BALL_VEL); }
static int set_spin(lua_State *L) { return set_vec(L, SX_BALL_SPIN); }
static int set_applied_force(lua_State *L) { return set_vec(L, SX_BALL_APPLIED_FORCE); }
static int set_applied_moment(lua_State *L) { return set_vec(L, SX_BALL_APPLIED_MOMENT); }
static int get_radius(lua_State *L) { return get_scalar(L, SX_BALL_RADIUS); }
static int get_mass(lua_State *L) { return get_scalar(L, SX_BALL_MASS); }
static int get_inertia(lua_State *L) { return get_scalar(L, SX_BALL_INERTIA); }
static int get_damping(lua_State *L) { return get_scalar(L, SX_BALL_DAMPING); }
static int set_radius(lua_State *L) { return set_scalar(L, SX_BALL_RADIUS); }
static int set_damping(lua_State *L) { return set_scalar(L, SX_BALL_DAMPING); }

static int get_id(lua_State *L)
{
    int64_t id;
    check_ball_whole(L, &id);
    lua_pushinteger(L, (lua_Integer)id);
    return 1;
}

static int get_material(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_ball_whole(L, &id);
    int mat;
    sx_lua_checkfield(L, m, sx_ball_material(m, id, &mat), "ball");
    lua_pushstring(L, sx_material_name(m, mat));
    return 1;
}

static int set_material(lua_State *L)
{
    int64_t id;
    sx_model *m = check_ball(L, &id);
    if (lua_type(L, 3) != LUA_TSTRING)
        return luaL_error(L, "ball field 'material': material name expected, got %s", luaL_typename(L, 3));
    sx_lua_checkname(L, 3);
    const int mat = find_material(L, m, lua_tostring(L, 3));
    if (mat < 0) return luaL_error(L, "ball field 'material': %s", lua_tostring(L, -1));
    sx_lua_checkfield(L, m, sx_ball_set_material(m, id, mat), "ball");
    return 0;
}

/* Fixity words: the six components, then the groups; a 2D ball has only
 * vx, vy and wz (its scalar spin), so a 2D mask of 0 marks a word it lacks. */
static const char *const fix_names[] = {"vx", "vy", "vz", "wx", "wy", "wz", "vel", "spin", "all", NULL};
static const unsigned fix_masks[][2] = {
    /* 3D, 2D */
    {SX_FIX_VX, SX_FIX_VX},
    {SX_FIX_VY, SX_FIX_VY},
    {SX_FIX_VZ, 0},
    {SX_FIX_WX, 0},
    {SX_FIX_WY, 0},
    {SX_FIX_WZ, SX_FIX_WZ},
    {SX_FIX_VEL, SX_FIX_VX | SX_FIX_VY},
    {SX_FIX_SPIN, SX_FIX_WZ},
    {SX_FIX_VEL | SX_FIX_SPIN, SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ},
};
enum { FIX_COMPONENTS = 6 };
_Static_assert(sizeof fix_names / sizeof fix_names[0] == sizeof fix_masks / sizeof fix_masks[0] + 1,
               "one mask pair per fixity word");

static int fix_word(lua_State *L, int dim, int idx, const char *what)
{
    if (lua_type(L, idx) != LUA_TSTRING)
        return luaL_error(L, "%s: fixity name expected, got %s", what, luaL_typename(L, idx));
    const char *word = lua_tostring(L, idx);
    const int i = sx_lua_find(word, fix_names);
    if (i < 0) {
        sx_lua_pushlist(L, fix_names);
        return luaL_error(L, "%s: unknown fixity '%s' (valid: %s)", what, word, lua_tostring(L, -1));
    }
    const unsigned mask = fix_masks[i][dim == 3 ? 0 : 1];
    if (!mask) return luaL_error(L, "%s: a 2D model has no '%s' (only vx, vy, wz)", what, word);
    return (int)mask;
}

/* nil or {} frees every component; a word or an array of words fixes those. */
unsigned sx_lua_fixmask(lua_State *L, int dim, int idx, const char *what)
{
    if (lua_isnil(L, idx)) return 0;
    if (lua_type(L, idx) == LUA_TSTRING) return (unsigned)fix_word(L, dim, idx, what);
    if (!lua_istable(L, idx))
        luaL_error(L, "%s: string or array of strings expected, got %s", what, luaL_typename(L, idx));
    unsigned mask = 0;
    const lua_Unsigned n = lua_rawlen(L, idx);
    for (lua_Unsigned k = 1; k <= n; k++) {
        lua_rawgeti(L, idx, (lua_Integer)k);
        mask |= (unsigned)fix_word(L, dim, lua_gettop(L), what);
        lua_pop(L, 1);
    }
    return mask;
}

void sx_lua_pushfixmask(lua_State *L, unsigned mask)
{
    lua_newtable(L);
    int n = 0;
    for (int i = 0; i < FIX_COMPONENTS; i++) {
        if (!(mask & fix_masks[i][0])) continue;
        lua_pushstring(L, fix_names[i]);
        lua_rawseti(L, -2, ++n);
    }
}

static int get_fix(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_ball_whole(L, &id);
    unsigned mask;
    sx_lua_checkfield(L, m, sx_ball_fixity(m, id, &mask), "ball");
    sx_lua_pushfixmask(L, mask);
    return 1;
}

/* b.clump: the clump a pebble belongs to, nil for a free ball. */
static int get_clump(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_ball_whole(L, &id);
    const int64_t c = sx_ball_clump(m, id);
    if (!c) return 0;
    lua_getiuservalue(L, 1, 1);
    sx_lua_pushhandle(L, lua_gettop(L), &sx_lua_clump_kind, c);
    return 1;
}

static int set_fix(lua_State *L)
{
    int64_t id;
    sx_model *m = check_ball(L, &id);
    const unsigned mask = sx_lua_fixmask(L, sx_model_dim(m), 3, "ball field 'fix'");
    sx_lua_checkfield(L, m, sx_ball_set_fixity(m, id, mask), "ball");
    return 0;
}

/* --------------------------------------------------- group and extras */

static int get_group(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_ball_whole(L, &id);
    int32_t g;
    sx_lua_checkfield(L, m, sx_ball_group(m, id, &g), "ball");
    lua_getiuservalue(L, 1, 1);
    sx_lua_push_group_name(L, lua_gettop(L), g);
    return 1;
}

static int set_group(lua_State *L)
{
    int64_t id;
    sx_model *m = check_ball(L, &id);
    if (!lua_isnil(L, 3) && lua_type(L, 3) != LUA_TSTRING)
        return luaL_error(L, "ball field 'group': group name or nil expected, got %s", luaL_typename(L, 3));
    if (!lua_isnil(L, 3)) sx_lua_checkname(L, 3);
    lua_getiuservalue(L, 1, 1);
    const int32_t g = lua_isnil(L, 3) ? 0 : sx_lua_group_id(L, lua_gettop(L), lua_tostring(L, 3), true);
    sx_lua_checkfield(L, m, sx_ball_set_group(m, id, g), "ball");
    return 0;
}

/* b.groups: {[slot] = name} of the slots that hold a group */
static int get_groups(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_ball_whole(L, &id);
    lua_getiuservalue(L, 1, 1);
    const int model = lua_gettop(L);
    lua_newtable(L);
    for (int k = 1; k <= SX_LUA_SLOTS; k++) {
        const int32_t g = sx_lua_slot_group(L, model, m, id, k);
        if (!g) continue;
        sx_lua_push_group_name(L, model, g);
        lua_rawseti(L, -2, k);
    }
    return 1;
}

/* b:set_group(name | nil, slot): PFC's group slots (slot 1 is b.group) */
static int ball_set_group(lua_State *L)
{
    int64_t id;
    sx_model *m = check_ball(L, &id);
    if (!lua_isnil(L, 2) && lua_type(L, 2) != LUA_TSTRING) return luaL_typeerror(L, 2, "group name or nil");
    const lua_Integer slot = luaL_checkinteger(L, 3);
    luaL_argcheck(L, slot >= 1 && slot <= SX_LUA_SLOTS, 3, "a group slot from 1 to 8 expected");
    lua_getiuservalue(L, 1, 1);
    const int model = lua_gettop(L);
    const int32_t g = lua_isnil(L, 2) ? 0 : sx_lua_group_id(L, model, lua_tostring(L, 2), true);
    sx_lua_set_slot_group(L, model, m, id, (int)slot, g, "b:set_group");
    return 0;
}

static int get_extra(lua_State *L) { return sx_lua_extra_table(L, &ball_kind); }
static int set_extra_table(lua_State *L) { return sx_lua_set_extra_table(L, &ball_kind); }
static int ball_set_extra(lua_State *L) { return sx_lua_set_extra(L, &ball_kind); }
static int ball_get_extra(lua_State *L) { return sx_lua_get_extra(L, &ball_kind); }

/* ------------------------------------------------- methods, metamethods */

/* Queued removals: ball ids positive, wall ids negative, in the state's `queue`. */
static bool queue_removal(lua_State *L, int model, int64_t signed_id)
{
    if (sx_lua_modelud(L, model)->callback == 0) return false;
    sx_lua_state(L, model, "queue");
    lua_pushinteger(L, (lua_Integer)signed_id);
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
    lua_pop(L, 1);
    return true;
}

void sx_lua_remove_balls(lua_State *L, int model, const int64_t *ids, int64_t n, const char *what)
{
    model = lua_absindex(L, model);
    if (sx_lua_modelud(L, model)->callback > 0) {
        for (int64_t i = 0; i < n; i++) queue_removal(L, model, ids[i]);
        return;
    }
    sx_model *m = sx_lua_checkmodel(L, model);
    sx_lua_check(L, m, sx_ball_remove_many(m, ids, n), what);
    for (int64_t i = 0; i < n; i++) {
        sx_lua_forget_extras(L, model, &ball_kind, ids[i]);
        sx_lua_slots_forget(L, model, ids[i]);
    }
}

static void remove_ball(lua_State *L, int model, int64_t id, const char *what)
{
    sx_lua_remove_balls(L, model, &id, 1, what);
}

/* A wall goes with its extras. */
static void remove_wall_now(lua_State *L, int model, sx_model *m, int64_t id, const char *what)
{
    sx_lua_check(L, m, sx_wall_remove(m, id), what);
    sx_lua_forget_extras(L, model, &sx_lua_wall_kind, id);
}

void sx_lua_remove_wall(lua_State *L, int model, int64_t id, const char *what)
{
    model = lua_absindex(L, model);
    if (queue_removal(L, model, -id)) return;
    remove_wall_now(L, model, sx_lua_checkmodel(L, model), id, what);
}

lua_Integer sx_lua_removals_queued(lua_State *L, int model)
{
    lua_getiuservalue(L, model, 1);
    const lua_Integer n = lua_getfield(L, -1, "queue") == LUA_TTABLE ? (lua_Integer)lua_rawlen(L, -1) : 0;
    lua_pop(L, 2);
    return n;
}

void sx_lua_apply_removals(lua_State *L, int model)
{
    model = lua_absindex(L, model);
    sx_lua_model *ud = sx_lua_modelud(L, model);
    if (ud->callback > 0 || !ud->m) return;
    lua_getiuservalue(L, model, 1);
    if (lua_getfield(L, -1, "queue") != LUA_TTABLE) {
        lua_pop(L, 2);
        return;
    }
    /* detach the queue first: a failure below must not replay it */
    lua_pushnil(L);
    lua_setfield(L, -3, "queue");
    const int q = lua_gettop(L);
    if (lua_rawlen(L, q) > 0) sx_lua_gather(L, ud->m, "m");
    /* the balls go together, in one pass over the contacts */
    const lua_Unsigned len = lua_rawlen(L, q);
    int64_t *balls = lua_newuserdatauv(L, (size_t)(len > 0 ? len : 1) * sizeof *balls, 0);
    int64_t n = 0;
    for (lua_Integer i = 1; lua_rawgeti(L, q, i) == LUA_TNUMBER; i++) {
        const int64_t sid = (int64_t)lua_tointeger(L, -1);
        lua_pop(L, 1);
        /* an object already gone is skipped (one listed twice goes once) */
        if (sid > 0 && sx_ball_exists(ud->m, sid))
            balls[n++] = sid;
        else if (sid < 0 && sx_wall_exists(ud->m, -sid))
            remove_wall_now(L, model, ud->m, -sid, "a queued wall removal");
    }
    sx_lua_remove_balls(L, model, balls, n, "the queued ball removals");
    lua_settop(L, q - 2);
}

static int ball_remove(lua_State *L)
{
    int64_t id;
    check_ball(L, &id);
    lua_getiuservalue(L, 1, 1);
    remove_ball(L, -1, id, "b:remove");
    return 0;
}

static int get_disp(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_ball_motion(L, &id);
    return sx_lua_ball_disp(L, m, id);
}

static int ball_tostring(lua_State *L) { return sx_lua_handle_tostring(L, &ball_kind); }

/* ------------------------------------------------------- model methods */

static int add_ball(lua_State *L, sx_model *m)
{
    static const char *const keys[] = {"pos", "radius", "vel", "spin", "material", "group", NULL};
    const int dim = sx_model_dim(m);
    sx_lua_checkkeys(L, 2, keys);
    sx_ball_def d = sx_ball_default_def();
    sx_lua_checkvecfield(L, 2, "pos", dim, d.pos);
    d.radius = sx_lua_checknumfield(L, 2, "radius");
    sx_lua_optvecfield(L, 2, "vel", dim, d.vel);
    sx_lua_optvecfield(L, 2, "spin", sx_lua_rdim(dim), d.spin);
    d.material = sx_lua_material_arg(L, m, 2, "material", sx_lua_optstrfield(L, 2, "material"));
    const char *group = sx_lua_optstrfield(L, 2, "group");
    const int32_t g = group ? sx_lua_group_id(L, 1, group, true) : 0;
    int64_t id;
    if (d.radius > 0) sx_lua_check_ball_walls(L, 1, m, d.pos, d.radius);
    sx_lua_check(L, m, sx_ball_add(m, &d, &id), "m:ball");
    sx_lua_check_range(L, 1, "radius", d.radius, 1e-6, 1, "m"); /* radius = 2 meant in mm, say */
    sx_lua_modelud(L, 1)->unchecked = true;
    if (g) sx_lua_check(L, m, sx_ball_set_group(m, id, g), "m:ball");
    sx_lua_pushhandle(L, 1, &ball_kind, id);
    return 1;
}

/* m:ball{...} adds a ball; m:ball(id) returns the ball with that id, or nil. */
static int model_ball(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* a lookup reads the ids every rank holds */
    if (lua_type(L, 2) == LUA_TTABLE) {
        sx_lua_gather(L, m, "m");
        return add_ball(L, m);
    }
    if (lua_type(L, 2) != LUA_TNUMBER) return luaL_typeerror(L, 2, "table or integer");
    const int64_t id = (int64_t)luaL_checkinteger(L, 2);
    if (!sx_ball_exists(m, id)) return 0;
    sx_lua_pushhandle(L, 1, &ball_kind, id);
    return 1;
}

static int next_ball(lua_State *L) { return sx_lua_nexthandle(L, &ball_kind); }

/* m:balls([filter]): an iterator over a snapshot of the balls (that pass the filter). */
static int model_balls(lua_State *L)
{
    if (lua_isnoneornil(L, 2)) { /* the ids every rank holds (a read of a ball's motion fetches it) */
        sx_lua_pushiterator(L, 1, sx_ball_count, sx_ball_id_at, next_ball);
        return 1;
    }
    sx_lua_checkmodel_scattered(L, 1); /* a region shares the balls' motion, not their pairs: no gather */
    sx_lua_checkkeys(L, 2, sx_lua_filter_keys);
    sx_lua_filter f;
    sx_lua_filter_read(L, 1, 2, &f);
    int64_t n;
    const int64_t *ids = sx_lua_filter_ids(L, &f, &n);
    lua_createtable(L, n < 1 << 30 ? (int)n : 1 << 30, 0);
    for (int64_t i = 0; i < n; i++) {
        lua_pushinteger(L, (lua_Integer)ids[i]);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    sx_lua_pushiterator_ids(L, 1, -1, next_ball);
    return 1;
}

static int model_ball_count(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_ball_count(sx_lua_checkmodel_scattered(L, 1)));
    return 1;
}

const luaL_Reg sx_lua_balls_methods[] = {
    {"ball", model_ball},
    {"balls", model_balls},
    {"ball_count", model_ball_count},
    {NULL, NULL},
};

void sx_lua_balls_register(lua_State *L)
{
    static const luaL_Reg meta[] = {
        {"__tostring", ball_tostring},
        {"__eq", sx_lua_handle_eq},
        {NULL, NULL},
    };
    static const luaL_Reg ball_methods[] = {
        {"remove", ball_remove},
        {"set_extra", ball_set_extra},
        {"get_extra", ball_get_extra},
        {"set_group", ball_set_group},
        {NULL, NULL},
    };
    static const luaL_Reg getters[] = {
        {"id", get_id},
        {"pos", get_pos},
        {"vel", get_vel},
        {"spin", get_spin},
        {"force", get_force},
        {"moment", get_moment},
        {"applied_force", get_applied_force},
        {"applied_moment", get_applied_moment},
        {"radius", get_radius},
        {"mass", get_mass},
        {"inertia", get_inertia},
        {"material", get_material},
        {"fix", get_fix},
        {"damping", get_damping},
        {"group", get_group},
        {"groups", get_groups},
        {"extra", get_extra},
        {"clump", get_clump},
        {"disp", get_disp},
        {NULL, NULL},
    };
    static const luaL_Reg setters[] = {
        {"pos", set_pos},
        {"vel", set_vel},
        {"spin", set_spin},
        {"applied_force", set_applied_force},
        {"applied_moment", set_applied_moment},
        {"radius", set_radius},
        {"material", set_material},
        {"fix", set_fix},
        {"damping", set_damping},
        {"group", set_group},
        {"extra", set_extra_table},
        {NULL, NULL},
    };
    sx_lua_newclass(L, ball_kind.tname, ball_kind.name, meta, ball_methods, getters, setters);
    lua_pop(L, 1);
}
