/* Contacts: m:contacts([filter]) iterates over a snapshot of the contacts of
 * the last step's force evaluation (sx_contact_each), as contact objects.
 *
 * A contact object holds the values of the snapshot (not a live handle:
 * contacts come and go every step). Its entities are `a`, always a ball,
 * and `b`, a ball or a wall, as handles. Conventions, as in PFC: the normal
 * points from a to b, and `force` is the contact force on b (so a feels
 * -force); fn > 0 in compression. The core reports ball-wall contacts with
 * the normal from the wall to the ball, so they are flipped here. */
#include <stddef.h>
#include <string.h>

#include "bindings.h"

#define SX_LUA_CONTACT "seixo.contact"

/* ------------------------------------------------------------ snapshot */

typedef struct collect {
    sx_contact_info *out;  // NULL: count only
    int64_t n, cap;
    int64_t ball, wall;    // filters, -1: any
    int kind;              // 0 any, 1 ball-ball, 2 ball-wall
} collect;

static bool keep(const sx_contact_info *c, const collect *k)
{
    if (k->kind == 1 && c->is_wall) return false;
    if (k->kind == 2 && !c->is_wall) return false;
    if (k->ball >= 0 && c->a != k->ball && (c->is_wall || c->b != k->ball)) return false;
    if (k->wall >= 0 && !(c->is_wall && c->b == k->wall)) return false;
    return true;
}

static bool on_contact(const sx_contact_info *c, void *ud)
{
    collect *k = ud;
    if (!keep(c, k)) return true;
    if (k->out) {
        if (k->n >= k->cap) return false;  // cannot happen: the store does not change between the passes
        sx_contact_info *o = &k->out[k->n];
        *o = *c;
        if (c->is_wall) {
            for (int i = 0; i < 3; i++) {
                o->normal[i] = -c->normal[i];
                o->shear[i] = -c->shear[i];
            }
        }
    }
    k->n++;
    return true;
}

/* --------------------------------------------------------------- class */

static const sx_contact_info *check_contact(lua_State *L) { return luaL_checkudata(L, 1, SX_LUA_CONTACT); }

/* The contact's model (a closed one is an error), its dimension. */
static int contact_dim(lua_State *L)
{
    lua_getiuservalue(L, 1, 1);
    const int dim = sx_model_dim(sx_lua_checkmodel(L, -1));
    lua_pop(L, 1);
    return dim;
}

static int get_a(lua_State *L)
{
    const sx_contact_info *c = check_contact(L);
    lua_getiuservalue(L, 1, 1);
    sx_lua_pushhandle(L, -1, &sx_lua_ball_kind, c->a);
    return 1;
}

static int get_b(lua_State *L)
{
    const sx_contact_info *c = check_contact(L);
    lua_getiuservalue(L, 1, 1);
    sx_lua_pushhandle(L, -1, c->is_wall ? &sx_lua_wall_kind : &sx_lua_ball_kind, c->b);
    return 1;
}

static int get_kind(lua_State *L)
{
    lua_pushstring(L, check_contact(L)->is_wall ? "ball-wall" : "ball-ball");
    return 1;
}

static int push_vec(lua_State *L, size_t offset, bool rotational)
{
    const sx_contact_info *c = check_contact(L);
    const int dim = contact_dim(L);
    sx_lua_pushvec(L, (const double *)((const char *)c + offset), rotational ? sx_lua_rdim(dim) : dim);
    return 1;
}

static int push_num(lua_State *L, size_t offset)
{
    lua_pushnumber(L, *(const double *)((const char *)check_contact(L) + offset));
    return 1;
}

static int get_normal(lua_State *L) { return push_vec(L, offsetof(sx_contact_info, normal), false); }
static int get_point(lua_State *L) { return push_vec(L, offsetof(sx_contact_info, point), false); }
static int get_fs(lua_State *L) { return push_vec(L, offsetof(sx_contact_info, shear), false); }
static int get_pb_fs(lua_State *L) { return push_vec(L, offsetof(sx_contact_info, pb_fs), false); }
static int get_pb_moment(lua_State *L) { return push_vec(L, offsetof(sx_contact_info, pb_moment), true); }
static int get_shift(lua_State *L) { return push_vec(L, offsetof(sx_contact_info, shift), false); }
static int get_overlap(lua_State *L) { return push_num(L, offsetof(sx_contact_info, overlap)); }
static int get_fn(lua_State *L) { return push_num(L, offsetof(sx_contact_info, fn)); }
static int get_kn(lua_State *L) { return push_num(L, offsetof(sx_contact_info, kn)); }
static int get_ks(lua_State *L) { return push_num(L, offsetof(sx_contact_info, ks)); }
static int get_pb_fn(lua_State *L) { return push_num(L, offsetof(sx_contact_info, pb_fn)); }
static int get_pb_radius(lua_State *L) { return push_num(L, offsetof(sx_contact_info, pb_radius)); }

/* The total contact force on b: fn along the normal plus the shear force. */
static int get_force(lua_State *L)
{
    const sx_contact_info *c = check_contact(L);
    const int dim = contact_dim(L);
    double f[3];
    for (int k = 0; k < 3; k++) f[k] = c->fn * c->normal[k] + c->shear[k];
    sx_lua_pushvec(L, f, dim);
    return 1;
}

/* The contact-model row the contact took (from 1), nil for its materials' law. */
static int get_contact_model(lua_State *L)
{
    const int r = check_contact(L)->cmodel;
    if (r) lua_pushinteger(L, r);
    else lua_pushnil(L);
    return 1;
}

static int get_bond(lua_State *L)
{
    const unsigned b = check_contact(L)->bond;
    if (!b) lua_pushnil(L);
    else if (b == (SX_BOND_CONTACT | SX_BOND_PARALLEL)) lua_pushliteral(L, "both");
    else if (b & SX_BOND_FLATJOINT) lua_pushliteral(L, "flatjoint");
    else if (b & SX_BOND_SMOOTHJOINT) lua_pushliteral(L, "smoothjoint");
    else lua_pushstring(L, b & SX_BOND_CONTACT ? "contact" : "parallel");
    return 1;
}

/* c.joint: the smooth joint whose law the contact takes (m:joint's number), or nil. */
static int get_joint(lua_State *L)
{
    const sx_contact_info *c = check_contact(L);
    if (c->joint) lua_pushinteger(L, (lua_Integer)c->joint);
    else lua_pushnil(L);
    return 1;
}

static int contact_tostring(lua_State *L)
{
    const sx_contact_info *c = check_contact(L);
    lua_pushfstring(L, "seixo.contact ball %I - %s %I (fn %f N, overlap %f m)", (lua_Integer)c->a,
                    c->is_wall ? "wall" : "ball", (lua_Integer)c->b, c->fn, c->overlap);
    return 1;
}

/* ----------------------------------------------------------- iterator */

/* upvalues: the model userdata, the snapshot userdata, the position */
static int next_contact(lua_State *L)
{
    sx_lua_checkmodel(L, lua_upvalueindex(1));
    const sx_contact_info *all = lua_touserdata(L, lua_upvalueindex(2));
    const lua_Integer n = (lua_Integer)(lua_rawlen(L, lua_upvalueindex(2)) / sizeof *all);
    const lua_Integer i = lua_tointeger(L, lua_upvalueindex(3));
    if (i >= n) return 0;
    lua_pushinteger(L, i + 1);
    lua_replace(L, lua_upvalueindex(3));
    sx_contact_info *c = lua_newuserdatauv(L, sizeof *c, 1);
    *c = all[i];
    luaL_setmetatable(L, SX_LUA_CONTACT);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_setiuservalue(L, -2, 1);
    return 1;
}

static int64_t entity_filter(lua_State *L, int arg, const char *key, const sx_lua_kind *k)
{
    lua_pushstring(L, key);
    if (lua_rawget(L, arg) == LUA_TNIL) {
        lua_pop(L, 1);
        return -1;
    }
    int64_t id;
    const char *err = sx_lua_toid(L, -1, 1, k, &id);
    if (err) sx_lua_fielderror(L, arg, key, err);
    lua_pop(L, 1);
    return id;
}

/* m:contacts([{ball = b, wall = w, kind = "ball-ball" | "ball-wall"}]) */
static int model_contacts(lua_State *L)
{
    static const char *const keys[] = {"ball", "wall", "kind", NULL};
    static const char *const kinds[] = {"ball-ball", "ball-wall", NULL};
    const sx_model *m = sx_lua_checkmodel(L, 1);
    collect k = {NULL, 0, 0, -1, -1, 0};
    if (!lua_isnoneornil(L, 2)) {
        sx_lua_checkkeys(L, 2, keys);
        k.ball = entity_filter(L, 2, "ball", &sx_lua_ball_kind);
        k.wall = entity_filter(L, 2, "wall", &sx_lua_wall_kind);
        const char *kind = sx_lua_optstrfield(L, 2, "kind");
        if (kind) {
            const int i = sx_lua_find(kind, kinds);
            if (i < 0) sx_lua_fielderror(L, 2, "kind", "'ball-ball' or 'ball-wall' expected");
            k.kind = i + 1;
        }
    }
    lua_settop(L, 1);
    sx_contact_each(m, on_contact, &k);
    k.cap = k.n;
    k.out = lua_newuserdatauv(L, (size_t)(k.cap > 0 ? k.cap : 1) * sizeof *k.out, 0);
    k.n = 0;
    sx_contact_each(m, on_contact, &k);
    /* the snapshot's length is its byte size: keep only what was filled */
    if (k.n < k.cap || k.cap == 0) {
        sx_contact_info *exact = lua_newuserdatauv(L, (size_t)k.n * sizeof *exact, 0);
        if (k.n) memcpy(exact, k.out, (size_t)k.n * sizeof *exact);
        lua_remove(L, -2);
    }
    lua_pushinteger(L, 0);
    lua_pushcclosure(L, next_contact, 3);
    return 1;
}

const luaL_Reg sx_lua_contacts_methods[] = {
    {"contacts", model_contacts},
    {NULL, NULL},
};

void sx_lua_contacts_register(lua_State *L)
{
    static const luaL_Reg meta[] = {
        {"__tostring", contact_tostring},
        {NULL, NULL},
    };
    static const luaL_Reg getters[] = {
        {"a", get_a},
        {"b", get_b},
        {"kind", get_kind},
        {"normal", get_normal},
        {"point", get_point},
        {"overlap", get_overlap},
        {"fn", get_fn},
        {"fs", get_fs},
        {"force", get_force},
        {"kn", get_kn},
        {"ks", get_ks},
        {"bond", get_bond},
        {"pb_fn", get_pb_fn},
        {"pb_fs", get_pb_fs},
        {"pb_moment", get_pb_moment},
        {"pb_radius", get_pb_radius},
        {"shift", get_shift},
        {"contact_model", get_contact_model},
        {"joint", get_joint},
        {NULL, NULL},
    };
    sx_lua_newclass(L, SX_LUA_CONTACT, "contact", meta, NULL, getters, NULL);
    lua_pop(L, 1);
}
