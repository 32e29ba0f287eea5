/* Event callbacks, PFC's fishcall events: m:on(event, fn[, opts]) with
 *   "bond_break"        fn(m, {a =, b =, pos =, mode =, bond =, fn =, fs =, time =, step =})
 *   "contact_create"    fn(m, {a =, b =, wall =, fn =, overlap =, step =})
 *   "contact_delete"    fn(m, {a =, b =, wall =, step =})
 *   "ball_leave_region" fn(m, {ball =, pos =, step =}), opts.region required
 *
 * The core never calls Lua, so events are collected from what a step
 * leaves behind and delivered after it, between steps (the model is not
 * locked then): the bonds broken are the new entries of the crack log; the
 * contacts created and deleted are the difference between the touching
 * pairs of this step and of the one before; a ball leaves a region when
 * its centre was inside after the last delivery and is not now. While a
 * contact or region event is registered the run is cycled one step at a
 * time (a step's events are delivered after that step); a bond_break alone
 * lets the run go in chunks of 100 steps (ending at multiples of 100, not
 * where the progress display would end them: a handler that changes the
 * model acts at the same step on any machine) and delivers after each
 * chunk, every event carrying the step it happened at. Cycling in chunks
 * of any size gives the same bits, so events change nothing in a run.
 *
 * Order, deterministic: the bonds broken (crack log order), then the
 * contacts deleted, then those created (each by ball id, wall contacts
 * after ball contacts), then the balls that left (in the balls' order);
 * for each event the handlers in the order they were registered. */
#include "bindings.h"

#include <stdlib.h>
#include <string.h>

static const char *const event_names[] = {"bond_break", "contact_create", "contact_delete", "ball_leave_region", NULL};
enum { EV_BOND, EV_CREATE, EV_DELETE, EV_LEAVE };

bool sx_lua_is_event(const char *name) { return name && sx_lua_find(name, event_names) >= 0; }

/* ------------------------------------------------------- touching pairs */

typedef struct pair {
    int64_t a, b;
    int wall;
    double fn, overlap;
} pair;

static int pair_cmp(const void *x, const void *y)
{
    const pair *p = x, *q = y;
    if (p->wall != q->wall) return p->wall - q->wall;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    return (p->b > q->b) - (p->b < q->b);
}

typedef struct pairs {
    pair *p;
    int64_t n, cap;
    bool oom;
} pairs;

static bool add_pair(const sx_contact_info *c, void *ud)
{
    pairs *s = ud;
    if (s->n == s->cap) {
        const int64_t cap = s->cap ? 2 * s->cap : 256;
        pair *q = realloc(s->p, (size_t)cap * sizeof *q);
        if (!q) return !(s->oom = true);
        s->p = q;
        s->cap = cap;
    }
    const bool swap = !c->is_wall && c->b < c->a;
    s->p[s->n++] = (pair){swap ? c->b : c->a, swap ? c->a : c->b, c->is_wall, c->fn, c->overlap};
    return true;
}

/* Pushes the touching pairs of the last step, sorted, as a userdata (its
 * length / sizeof(pair) of them). */
static void push_pairs(lua_State *L, const sx_model *m)
{
    pairs s = {NULL, 0, 0, false};
    sx_contact_each(m, add_pair, &s);
    if (s.oom) {
        free(s.p);
        luaL_error(L, "event callbacks: out of memory");
    }
    if (s.n > 1) qsort(s.p, (size_t)s.n, sizeof *s.p, pair_cmp);
    pair *u = lua_newuserdatauv(L, (size_t)s.n * sizeof *u, 0);
    if (s.n) memcpy(u, s.p, (size_t)s.n * sizeof *u);
    free(s.p);
}

/* -------------------------------------------------------- registration */

int sx_lua_events_add(lua_State *L, lua_Integer id)
{
    static const char *const keys[] = {"region", NULL};
    /* what each kind starts from, of a scattered model: the balls' places
     * (their motion shared), the contacts (a gather), the crack log (the
     * ranks' merged) */
    sx_model *m = sx_lua_checkmodel_scattered(L, 1);
    const int kind = sx_lua_find(lua_tostring(L, 2), event_names);
    luaL_checktype(L, 3, LUA_TFUNCTION);
    if (!lua_isnoneornil(L, 4)) sx_lua_checkkeys(L, 4, keys);
    lua_settop(L, 4);
    lua_createtable(L, 0, 6);
    const int e = lua_gettop(L);
    lua_pushinteger(L, id);
    lua_setfield(L, e, "id");
    lua_pushinteger(L, kind);
    lua_setfield(L, e, "kind");
    lua_pushvalue(L, 3);
    lua_setfield(L, e, "fn");
    if (kind == EV_LEAVE) {
        if (!lua_istable(L, 4) || lua_getfield(L, 4, "region") == LUA_TNIL)
            return luaL_argerror(L, 4, "ball_leave_region needs {region = {...}}");
        const int top = lua_gettop(L);
        sx_lua_region g;
        sx_lua_region_read(L, top, sx_model_dim(m), 4, "region", &g);
        m = sx_lua_checkmodel_motion(L, 1);
        /* the balls inside now: those that may leave */
        lua_newtable(L);
        for (int64_t i = 0; i < sx_ball_count(m); i++) {
            const int64_t b = sx_ball_id_at(m, i);
            double x[3];
            sx_ball_get_vec(m, b, SX_BALL_POS, x);
            if (!sx_lua_region_contains(&g, x, 0)) continue;
            lua_pushboolean(L, 1);
            lua_rawseti(L, -2, (lua_Integer)b);
        }
        lua_setfield(L, e, "inside");
        lua_settop(L, top);
        lua_setfield(L, e, "region");
    }
    if ((kind == EV_CREATE || kind == EV_DELETE)) {
        /* the contacts of now are not created by the next step */
        m = sx_lua_checkmodel(L, 1);
        sx_lua_state(L, 1, "event_state");
        if (lua_getfield(L, -1, "pairs") == LUA_TNIL) {
            push_pairs(L, m);
            lua_setfield(L, -3, "pairs");
        }
        lua_pop(L, 2);
    }
    if (kind == EV_BOND) {
        m = sx_lua_checkmodel_cracks(L, 1);
        sx_lua_state(L, 1, "event_state");
        if (lua_getfield(L, -1, "cracks_seen") == LUA_TNIL) {
            lua_pushinteger(L, (lua_Integer)sx_crack_count(m));
            lua_setfield(L, -3, "cracks_seen");
        }
        lua_pop(L, 2);
    }
    sx_lua_state(L, 1, "events");
    lua_pushvalue(L, e);
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
    lua_pushinteger(L, id);
    return 1;
}

/* Whether the handlers at `handlers` have one of `kind` (-1: of any kind but bond_break). */
static bool has(lua_State *L, int handlers, int kind)
{
    bool found = false;
    for (lua_Integer i = 1; !found; i++) {
        if (lua_rawgeti(L, handlers, i) != LUA_TTABLE) {
            lua_pop(L, 1);
            break;
        }
        lua_getfield(L, -1, "kind");
        const lua_Integer k = lua_tointeger(L, -1);
        found = kind < 0 ? k != EV_BOND : k == kind;
        lua_pop(L, 2);
    }
    return found;
}

bool sx_lua_events_on_bonds(lua_State *L, int model)
{
    sx_lua_state(L, model, "events");
    const bool on = has(L, lua_gettop(L), EV_BOND);
    lua_pop(L, 1);
    return on;
}

bool sx_lua_events_per_step(lua_State *L, int model)
{
    sx_lua_state(L, model, "events");
    const bool per_step = has(L, lua_gettop(L), -1);
    lua_pop(L, 1);
    return per_step;
}

/* ------------------------------------------------------------ delivery */

/* Calls every handler of `kind` with (m, the event table at ev). */
static void dispatch(lua_State *L, int model, int handlers, int kind, int ev)
{
    for (lua_Integer i = 1; lua_rawgeti(L, handlers, i) == LUA_TTABLE; i++) {
        lua_getfield(L, -1, "kind");
        lua_getfield(L, -2, "removed");  // by m:off from another handler
        const bool mine = lua_tointeger(L, -2) == kind && !lua_toboolean(L, -1);
        lua_pop(L, 2);
        if (mine) {
            lua_getfield(L, -1, "fn");
            lua_pushvalue(L, model);
            lua_pushvalue(L, ev);
            sx_lua_user_call(L, model, 2, 0);
        }
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

static void setint(lua_State *L, const char *k, int64_t v)
{
    lua_pushinteger(L, (lua_Integer)v);
    lua_setfield(L, -2, k);
}

static void setball(lua_State *L, int model, const char *k, int64_t id, bool wall)
{
    sx_lua_pushhandle(L, model, wall ? &sx_lua_wall_kind : &sx_lua_ball_kind, id);
    lua_setfield(L, -2, k);
}

static void deliver_bonds(lua_State *L, int model, int handlers, int state, const sx_model *m)
{
    lua_getfield(L, state, "cracks_seen");
    int64_t seen = (int64_t)lua_tointeger(L, -1);
    lua_pop(L, 1);
    const int dim = sx_model_dim(m);
    while (seen < sx_crack_count(m)) {
        sx_crack c;
        sx_crack_get(m, seen++, &c);
        lua_pushinteger(L, (lua_Integer)seen);
        lua_setfield(L, state, "cracks_seen");  // before the handlers: one that cycles sees the rest
        lua_createtable(L, 0, 10);
        setball(L, model, "a", c.a, false);
        setball(L, model, "b", c.b, false);
        sx_lua_pushvec(L, c.pos, dim);
        lua_setfield(L, -2, "pos");
        lua_pushstring(L, c.mode == SX_CRACK_TENSION ? "tension" : "shear");
        lua_setfield(L, -2, "mode");
        lua_pushstring(L, c.kind == SX_BOND_PARALLEL      ? "parallel"
                          : c.kind == SX_BOND_FLATJOINT   ? "flatjoint"
                          : c.kind == SX_BOND_SMOOTHJOINT ? "smoothjoint"
                                                          : "contact");
        lua_setfield(L, -2, "bond");
        sx_lua_setnum(L, "fn", c.fn);
        sx_lua_setnum(L, "fs", c.fs);
        sx_lua_setnum(L, "time", c.time);
        setint(L, "step", c.step);
        dispatch(L, model, handlers, EV_BOND, lua_gettop(L));
        lua_pop(L, 1);
    }
}

static void pair_event(lua_State *L, int model, int handlers, int kind, const pair *p, int64_t step)
{
    lua_createtable(L, 0, 6);
    setball(L, model, "a", p->a, false);
    setball(L, model, "b", p->b, p->wall);
    lua_pushboolean(L, p->wall);
    lua_setfield(L, -2, "wall");
    if (kind == EV_CREATE) {
        sx_lua_setnum(L, "fn", p->fn);
        sx_lua_setnum(L, "overlap", p->overlap);
    }
    setint(L, "step", step);
    dispatch(L, model, handlers, kind, lua_gettop(L));
    lua_pop(L, 1);
}

static void deliver_contacts(lua_State *L, int model, int handlers, int state, const sx_model *m)
{
    lua_getfield(L, state, "pairs");
    const int old_at = lua_gettop(L);
    push_pairs(L, m);
    const int now_at = lua_gettop(L);
    lua_pushvalue(L, now_at);
    lua_setfield(L, state, "pairs");
    const pair *old = lua_touserdata(L, old_at), *now = lua_touserdata(L, now_at);
    const int64_t no = old ? (int64_t)(lua_rawlen(L, old_at) / sizeof *old) : 0;
    const int64_t nn = (int64_t)(lua_rawlen(L, now_at) / sizeof *now);
    const int64_t step = sx_model_step_count(m);
    /* two merges of the sorted lists: the deleted, then the created */
    for (int pass = 0; pass < 2; pass++) {
        const int kind = pass == 0 ? EV_DELETE : EV_CREATE;
        if (!has(L, handlers, kind)) continue;
        const pair *x = pass == 0 ? old : now, *y = pass == 0 ? now : old;
        const int64_t nx = pass == 0 ? no : nn, ny = pass == 0 ? nn : no;
        for (int64_t i = 0, j = 0; i < nx; i++) {
            while (j < ny && pair_cmp(y + j, x + i) < 0) j++;
            if (j < ny && pair_cmp(y + j, x + i) == 0) continue;
            pair_event(L, model, handlers, kind, x + i, step);
        }
    }
    lua_settop(L, old_at - 1);
}

static void deliver_leaves(lua_State *L, int model, int handlers, const sx_model *m)
{
    const int dim = sx_model_dim(m);
    for (lua_Integer h = 1; lua_rawgeti(L, handlers, h) == LUA_TTABLE; h++) {
        const int e = lua_gettop(L);
        lua_getfield(L, e, "kind");
        const bool leave = lua_tointeger(L, -1) == EV_LEAVE;
        lua_pop(L, 1);
        if (!leave) {
            lua_pop(L, 1);
            continue;
        }
        lua_getfield(L, e, "inside");
        const int inside = lua_gettop(L);
        lua_getfield(L, e, "region");
        sx_lua_region g;
        sx_lua_region_read(L, inside + 1, dim, 2, "region", &g);
        const int top = lua_gettop(L);
        for (int64_t i = 0; i < sx_ball_count(m); i++) {
            const int64_t b = sx_ball_id_at(m, i);
            double x[3];
            sx_ball_get_vec(m, b, SX_BALL_POS, x);
            const bool in = sx_lua_region_contains(&g, x, 0);
            const bool was = lua_rawgeti(L, inside, (lua_Integer)b) != LUA_TNIL;
            lua_pop(L, 1);
            if (in == was) continue;
            if (in) {
                lua_pushboolean(L, 1);
                lua_rawseti(L, inside, (lua_Integer)b);
                continue;
            }
            lua_pushnil(L);
            lua_rawseti(L, inside, (lua_Integer)b);
            lua_createtable(L, 0, 3);
            setball(L, model, "ball", b, false);
            sx_lua_pushvec(L, x, dim);
            lua_setfield(L, -2, "pos");
            setint(L, "step", sx_model_step_count(m));
            lua_getfield(L, e, "fn");
            lua_pushvalue(L, model);
            lua_pushvalue(L, -3);
            sx_lua_user_call(L, model, 2, 0);
            lua_settop(L, top);
        }
        lua_settop(L, e - 1);
    }
    lua_pop(L, 1);
}

void sx_lua_events_deliver(lua_State *L, int model)
{
    model = lua_absindex(L, model);
    sx_model *m = sx_lua_checkmodel_scattered(L, model);
    sx_lua_state(L, model, "events");
    const int handlers = lua_gettop(L);
    if (lua_rawlen(L, handlers) == 0) {
        lua_pop(L, 1);
        return;
    }
    /* what the events are made of: the contacts (a gather), or the crack
     * log and the balls' places alone (no gather: a scattered model's next
     * cycle goes on from where this one stopped) */
    if (has(L, handlers, EV_CREATE) || has(L, handlers, EV_DELETE)) sx_lua_gather(L, m, "m");
    if (has(L, handlers, EV_BOND)) sx_lua_checkmodel_cracks(L, model);
    if (has(L, handlers, EV_LEAVE)) sx_lua_checkmodel_motion(L, model);
    /* the handlers may change the list: deliver from a copy */
    lua_newtable(L);
    for (lua_Integer i = 1; lua_rawgeti(L, handlers, i) != LUA_TNIL; i++) lua_rawseti(L, -2, i);
    lua_pop(L, 1);
    lua_replace(L, handlers);
    sx_lua_state(L, model, "event_state");
    const int state = lua_gettop(L);
    if (has(L, handlers, EV_BOND)) deliver_bonds(L, model, handlers, state, m);
    if (has(L, handlers, EV_CREATE) || has(L, handlers, EV_DELETE)) deliver_contacts(L, model, handlers, state, m);
    if (has(L, handlers, EV_LEAVE)) deliver_leaves(L, model, handlers, m);
    lua_settop(L, handlers - 1);
}
