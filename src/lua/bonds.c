/* Bonds, cracks and the bonded-particle material parameters:
 *   m:bond{kind=, gap=, seed=, materials=, ...}   install bonds (PFC-style)
 *   m:bond_count()                                 intact bonds
 *   m:cracks()                                     the crack log, a table of events
 *   m:crack_count([mode])                          broken bonds (all, "tension", "shear")
 *   m:flatjoint(a, b), m:flatjoint_unbond(a, b, e) a flat joint's elements; make one a slit
 *   m:track_energy(on)                             accumulate dissipation and work
 * and the material keys model (a law of the registry), its laws' parameters,
 * modulus/stiffness_ratio and the `bond` sub-table read by m:material. */
#include "bindings.h"

#include <math.h>
#include <string.h>

/* The bond kinds' micro-parameter keys from the registry (sx_bond_key),
 * after n keys already in keys (room for cap), NULL-terminated; their count. */
enum { BOND_KEYS_MAX = 64 };
static int bond_keys(const char **keys, int n, int cap)
{
    for (int k = 0; k < sx_bond_key_count() && n < cap - 1; k++) keys[n++] = sx_bond_key(k, NULL);
    keys[n] = NULL;
    return n;
}

static const char *kind_name(sx_bond_kind k)
{
    if (k == SX_BOND_SMOOTHJOINT) return "smoothjoint"; /* installed by m:joint, not m:bond */
    sx_bond_kind bit;
    for (int i = 0; i < sx_bond_kind_count(); i++)
        if (sx_bond_kind_name(i, &bit) && bit == k) return sx_bond_kind_name(i, NULL);
    return "?";
}

static void read_bpm(lua_State *L, int arg, sx_bpm_def *b)
{
    for (int k = 0; k < sx_bond_key_count(); k++) sx_lua_optnumfield(L, arg, sx_bond_key(k, NULL), sx_bond_key_material(b, k));
}

bool sx_lua_push_bpm(lua_State *L, const sx_model *m, int material)
{
    sx_bpm_def b;
    sx_lua_check(L, m, sx_material_get_bpm(m, material, &b), "m:materials");
    bool any = false;
    for (int k = 0; k < sx_bond_key_count(); k++) any |= *sx_bond_key_material(&b, k) != 0;
    if (!any) return false; /* a material without bond parameters lists none */
    lua_createtable(L, 0, sx_bond_key_count());
    for (int k = 0; k < sx_bond_key_count(); k++) sx_lua_setnum(L, sx_bond_key(k, NULL), *sx_bond_key_material(&b, k));
    return true;
}

void sx_lua_law_keys(lua_State *L, const char **keys, int n, int room)
{
    for (int law = 0; law < sx_law_count(); law++)
        for (int k = 0; k < sx_law_param_count(law); k++) {
            const char *key = sx_law_param_name(law, k, NULL);
            bool seen = false;
            for (int j = 0; j < n && !seen; j++) seen = strcmp(keys[j], key) == 0;
            if (seen) continue;
            /* a law registered with more parameters than the list has room
             * for: its keys would be refused as unknown */
            if (n + 1 >= room) luaL_error(L, "seixo: the contact laws' parameters outgrew a key list (%d entries): "
                                             "enlarge it in src/lua/model.c", room);
            keys[n++] = key;
        }
    keys[n] = NULL;
}

void sx_lua_material_extras(lua_State *L, int arg, sx_material_def *d, bool *has_bpm, sx_bpm_def *bpm)
{
    const char *model = sx_lua_optstrfield(L, arg, "model");
    if (model) {
        const int k = sx_law_find(model);
        if (!sx_law_is_model(k)) {
            luaL_Buffer b;
            luaL_buffinit(L, &b);
            for (int i = 0; sx_law_is_model(i); i++) {
                if (i) luaL_addstring(&b, ", ");
                lua_pushfstring(L, "'%s'", sx_law_name(i));
                luaL_addvalue(&b);
            }
            luaL_pushresult(&b);
            luaL_argerror(L, arg,
                          lua_pushfstring(L, "field 'model': one of %s expected, got '%s'", lua_tostring(L, -1), model));
        }
        d->model = (sx_contact_model)k;
    }
    /* every law's parameters: a material may be switched to another law later */
    for (int law = 0; law < sx_law_count(); law++)
        for (int k = 0; k < sx_law_param_count(law); k++)
            sx_lua_optnumfield(L, arg, sx_law_param_name(law, k, NULL), sx_law_param_value(d, law, k));
    sx_lua_optnumfield(L, arg, "modulus", &d->modulus);
    sx_lua_optnumfield(L, arg, "stiffness_ratio", &d->stiffness_ratio);
    *has_bpm = false;
    if (lua_getfield(L, arg, "bond") != LUA_TNIL) {
        if (!lua_istable(L, -1)) luaL_argerror(L, arg, "field 'bond': a table of bond micro-parameters expected");
        const int t = lua_gettop(L);
        const char *keys[BOND_KEYS_MAX];
        bond_keys(keys, 0, BOND_KEYS_MAX);
        sx_lua_checkkeys(L, t, keys);
        read_bpm(L, t, bpm);
        *has_bpm = true;
    }
    lua_pop(L, 1);
}

/* A material name or index of the model; a Lua error names the argument. */
static int material_index(lua_State *L, sx_model *m, int arg, const char *name)
{
    const int k = sx_material_find(m, name);
    if (k < 0) luaL_argerror(L, arg, lua_pushfstring(L, "no material named '%s'", name));
    return k;
}

static int model_bond(lua_State *L)
{
    const char *keys[BOND_KEYS_MAX] = {"kind", "gap", "seed", "materials", "gapped"};
    bond_keys(keys, 5, BOND_KEYS_MAX); /* and the kinds' micro-parameters */
    sx_model *m = sx_lua_checkmodel(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    sx_lua_checkkeys(L, 2, keys);
    sx_bond_def d = sx_bond_default_def();
    const char *kind = sx_lua_optstrfield(L, 2, "kind");
    if (kind) {
        int k = 0;
        while (k < sx_bond_kind_count() && strcmp(sx_bond_kind_name(k, NULL), kind) != 0) k++;
        if (k == sx_bond_kind_count()) {
            luaL_Buffer b;
            luaL_buffinit(L, &b);
            for (int i = 0; i < sx_bond_kind_count(); i++) {
                lua_pushfstring(L, "%s'%s'", i ? ", " : "", sx_bond_kind_name(i, NULL));
                luaL_addvalue(&b);
            }
            luaL_pushresult(&b);
            luaL_argerror(L, 2, lua_pushfstring(L, "field 'kind': one of %s expected, got '%s'", lua_tostring(L, -1), kind));
        }
        sx_bond_kind_name(k, &d.kind);
    }
    sx_lua_optnumfield(L, 2, "gap", &d.gap);
    double seed = 1;
    if (sx_lua_optnumfield(L, 2, "seed", &seed))
        luaL_argcheck(L, seed >= 0 && seed < 9007199254740992.0 && seed == (double)(int64_t)seed, 2,
                      "field 'seed': a non-negative integer expected");
    d.seed = (uint64_t)seed;
    if (lua_getfield(L, 2, "materials") != LUA_TNIL) {
        /* one name, or a pair {a, b}: bonds only between those materials */
        if (lua_type(L, -1) == LUA_TSTRING) {
            d.material_a = material_index(L, m, 2, lua_tostring(L, -1));
        } else if (lua_istable(L, -1) && lua_rawlen(L, -1) >= 1 && lua_rawlen(L, -1) <= 2) {
            for (int k = 1; k <= (int)lua_rawlen(L, -1); k++) {
                lua_rawgeti(L, -1, k);
                if (lua_type(L, -1) != LUA_TSTRING) luaL_argerror(L, 2, "field 'materials': material names expected");
                const int idx = material_index(L, m, 2, lua_tostring(L, -1));
                if (k == 1) d.material_a = idx;
                else d.material_b = idx;
                lua_pop(L, 1);
            }
        } else {
            luaL_argerror(L, 2, "field 'materials': a material name or a list of one or two names expected");
        }
    }
    lua_pop(L, 1);
    for (int k = 0; k < sx_bond_key_count(); k++) /* NaN is the core's "not given": a NaN given is refused */
        if (sx_lua_optnumfield(L, 2, sx_bond_key(k, NULL), sx_bond_key_call(&d, k)) && isnan(*sx_bond_key_call(&d, k)))
            luaL_argerror(L, 2, lua_pushfstring(L, "field '%s': a number expected, got nan", sx_bond_key(k, NULL)));
    if (lua_getfield(L, 2, "gapped") != LUA_TNIL) {
        luaL_argcheck(L, lua_isboolean(L, -1), 2, "field 'gapped': true or false expected");
        d.gapped = lua_toboolean(L, -1);
    }
    lua_pop(L, 1);
    int64_t count = 0;
    sx_lua_check(L, m, sx_bond_install(m, &d, &count), "m:bond");
    sx_lua_record_seed(L, 1, (int64_t)d.seed); /* the strengths drawn from it: the files' provenance lists it */
    lua_pushinteger(L, (lua_Integer)count);
    return 1;
}

/* The intact bonds and the cracks by mode (sx_model_bond_counts: without
 * a gather under mpirun). */
static void bond_counts(lua_State *L, const char *what, int64_t counts[3])
{
    const sx_model *m = sx_lua_checkmodel_summed(L, 1, what);
    if (!sx_model_bond_counts(m, counts)) luaL_error(L, "%s: out of memory, or the ranks could not exchange", what);
}

static int model_bond_count(lua_State *L)
{
    int64_t counts[3];
    bond_counts(L, "m:bond_count", counts);
    lua_pushinteger(L, (lua_Integer)counts[0]);
    return 1;
}

static int model_cracks(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel_cracks(L, 1); /* the log alone: no gather */
    const int64_t n = sx_crack_count(m);
    lua_createtable(L, n > 0 && n < INT32_MAX ? (int)n : 0, 0);
    for (int64_t i = 0; i < n; i++) {
        sx_crack c;
        sx_lua_check(L, m, sx_crack_get(m, i, &c), "m:cracks");
        lua_createtable(L, 0, 11);
        sx_lua_setnum(L, "time", c.time);
        lua_pushinteger(L, (lua_Integer)c.step);
        lua_setfield(L, -2, "step");
        sx_lua_pushvec(L, c.pos, sx_model_dim(m));
        lua_setfield(L, -2, "pos");
        lua_pushstring(L, c.mode == SX_CRACK_TENSION ? "tension" : "shear");
        lua_setfield(L, -2, "mode");
        lua_pushstring(L, kind_name(c.kind));
        lua_setfield(L, -2, "kind");
        if (c.element >= 0) { /* a flat joint's element, numbered from 1 as Lua does */
            lua_pushinteger(L, c.element + 1);
            lua_setfield(L, -2, "element");
        }
        lua_pushinteger(L, (lua_Integer)c.a);
        lua_setfield(L, -2, "a");
        lua_pushinteger(L, (lua_Integer)c.b);
        lua_setfield(L, -2, "b");
        sx_lua_setnum(L, "fn", c.fn);
        sx_lua_setnum(L, "fs", c.fs);
        sx_lua_setnum(L, "mn", c.mn);
        sx_lua_setnum(L, "ms", c.ms);
        lua_rawseti(L, -2, (lua_Integer)(i + 1));
    }
    return 1;
}

static int model_crack_count(lua_State *L)
{
    static const char *const modes[] = {"tension", "shear", NULL};
    const int mode = lua_isnoneornil(L, 2) ? -1 : luaL_checkoption(L, 2, NULL, modes);
    int64_t counts[3];
    bond_counts(L, "m:crack_count", counts);
    lua_pushinteger(L, (lua_Integer)(mode < 0 ? counts[1] + counts[2] : counts[1 + mode]));
    return 1;
}

/* m:flatjoint(a, b): the elements of the flat joint between balls a and b
 * (nil when there is none), each {state=, area=, centroid=, gap=, fn=, fs=,
 * tensile_strength=, cohesion=}, numbered from 1. */
static int model_flatjoint(lua_State *L)
{
    static const char *const states[] = {"unbonded", "bonded", "tension", "shear"};
    const sx_model *m = sx_lua_checkmodel(L, 1);
    const lua_Integer a = luaL_checkinteger(L, 2), b = luaL_checkinteger(L, 3);
    const int n = sx_flatjoint_get(m, a, b, -1, NULL);
    if (n == 0) {
        lua_pushnil(L);
        return 1;
    }
    lua_createtable(L, n, 0);
    for (int e = 0; e < n; e++) {
        sx_fj_element el;
        sx_flatjoint_get(m, a, b, e, &el);
        lua_createtable(L, 0, 8);
        lua_pushstring(L, states[el.state]);
        lua_setfield(L, -2, "state");
        sx_lua_setnum(L, "area", el.area);
        sx_lua_pushvec(L, el.centroid, sx_model_dim(m));
        lua_setfield(L, -2, "centroid");
        sx_lua_setnum(L, "gap", el.gap);
        sx_lua_setnum(L, "fn", el.fn);
        sx_lua_setnum(L, "fs", el.fs);
        sx_lua_setnum(L, "tensile_strength", el.tensile_strength);
        sx_lua_setnum(L, "cohesion", el.cohesion);
        lua_rawseti(L, -2, e + 1);
    }
    return 1;
}

/* m:flatjoint_unbond(a, b, e): element e (from 1) of the joint becomes a
 * slit. The range is checked here, in the user's numbering (the core's
 * message counts from 0: "element 4 out of range" for e = 5). */
static int model_flatjoint_unbond(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    const lua_Integer a = luaL_checkinteger(L, 2), b = luaL_checkinteger(L, 3);
    int whole = 0;
    const lua_Integer e = lua_tointegerx(L, 4, &whole);
    if (!whole)
        return luaL_error(L, "m:flatjoint_unbond: the element must be a whole number (got %s)", luaL_tolstring(L, 4, NULL));
    const int n = sx_flatjoint_get(m, a, b, -1, NULL);
    if (n > 0 && (e < 1 || e > n))
        return luaL_error(L, "m:flatjoint_unbond: element %I out of range: the joint between balls %I and %I has "
                             "elements 1 to %d", e, a, b, n);
    /* (no joint: the core says so; e is then in no range to pass on) */
    sx_lua_check(L, m, sx_flatjoint_unbond(m, a, b, n > 0 ? (int)e - 1 : 0), "m:flatjoint_unbond");
    return 0;
}

static int model_track_energy(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    luaL_checktype(L, 2, LUA_TBOOLEAN);
    sx_model_track_energy(m, lua_toboolean(L, 2));
    return 0;
}

const luaL_Reg sx_lua_bonds_methods[] = {
    {"bond", model_bond},
    {"bond_count", model_bond_count},
    {"cracks", model_cracks},
    {"crack_count", model_crack_count},
    {"track_energy", model_track_energy},
    {"flatjoint", model_flatjoint},
    {"flatjoint_unbond", model_flatjoint_unbond},
    {NULL, NULL},
};
