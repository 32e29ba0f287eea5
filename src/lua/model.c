/* seixo.model: the model userdata owns one sx_model. __gc, __close and
 * m:close() destroy it; any later use is a Lua error, never a crash (balls
 * and walls of a closed model report it too).
 *
 * A SIGINT handler cannot know the models, so the cycle binding lists the
 * model it is cycling in a small static registry that sx_lua_interrupt_all()
 * walks. Only models inside sx_model_cycle are listed: a listed model is
 * always alive. */
#include "bindings.h"
#include "seixo_lua.h"

#include <inttypes.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#define SX_LUA_MODEL "seixo.model"

typedef struct model_ud {
    sx_model *m;  // NULL once closed
} model_ud;

sx_model *sx_lua_tomodel(lua_State *L, int idx)
{
    return ((model_ud *)luaL_checkudata(L, idx, SX_LUA_MODEL))->m;
}

sx_model *sx_lua_checkmodel(lua_State *L, int idx)
{
    sx_model *m = sx_lua_tomodel(L, idx);
    if (!m) luaL_error(L, "the model has been closed");
    return m;
}

int sx_lua_model_new(lua_State *L)
{
    static const char *const keys[] = {"dim", "gravity", "timestep", "timestep_safety", "skin", NULL};
    sx_model_def d = sx_model_default_def();
    if (!lua_isnoneornil(L, 1)) {
        sx_lua_checkkeys(L, 1, keys);
        double dim = d.dim;
        sx_lua_optnumfield(L, 1, "dim", &dim);
        luaL_argcheck(L, dim == 2 || dim == 3, 1, "field 'dim': 2 or 3 expected");
        d.dim = (int)dim;
        sx_lua_optvecfield(L, 1, "gravity", d.dim, d.gravity);
        sx_lua_optnumfield(L, 1, "timestep", &d.timestep);
        sx_lua_optnumfield(L, 1, "timestep_safety", &d.timestep_safety);
        sx_lua_optnumfield(L, 1, "skin", &d.skin);
    }
    /* the userdata first: if Lua runs out of memory, no model leaks */
    model_ud *u = lua_newuserdatauv(L, sizeof *u, 0);
    u->m = NULL;
    luaL_setmetatable(L, SX_LUA_MODEL);
    char err[256];
    u->m = sx_model_create(&d, err, sizeof err);
    if (!u->m) return luaL_error(L, "%s", err);
    return 1;
}

static int model_close(lua_State *L)
{
    model_ud *u = luaL_checkudata(L, 1, SX_LUA_MODEL);
    sx_model_destroy(u->m);
    u->m = NULL;
    return 0;
}

static int model_tostring(lua_State *L)
{
    const sx_model *m = sx_lua_tomodel(L, 1);
    if (!m)
        lua_pushliteral(L, "seixo.model (closed)");
    else
        lua_pushfstring(L, "seixo.model (%dD, %I balls, %I walls, step %I, time %f s)", sx_model_dim(m),
                        (lua_Integer)sx_ball_count(m), (lua_Integer)sx_wall_count(m),
                        (lua_Integer)sx_model_step_count(m), sx_model_time(m));
    return 1;
}

static int model_material(lua_State *L)
{
    static const char *const keys[] = {"kn",      "ks",             "friction",      "density",
                                       "damping", "viscous_normal", "viscous_shear", "model",
                                       "shear_modulus", "poisson", "modulus", "stiffness_ratio",
                                       "bond",    NULL};
    sx_model *m = sx_lua_checkmodel(L, 1);
    const char *name = luaL_checkstring(L, 2);
    sx_material_def d = sx_material_default_def();
    bool has_bpm = false;
    sx_bpm_def bpm;
    memset(&bpm, 0, sizeof bpm);
    if (!lua_isnoneornil(L, 3)) {
        sx_lua_checkkeys(L, 3, keys);
        sx_lua_optnumfield(L, 3, "kn", &d.kn);
        sx_lua_optnumfield(L, 3, "ks", &d.ks);
        sx_lua_optnumfield(L, 3, "friction", &d.friction);
        sx_lua_optnumfield(L, 3, "density", &d.density);
        sx_lua_optnumfield(L, 3, "damping", &d.damping);
        sx_lua_optnumfield(L, 3, "viscous_normal", &d.viscous_normal);
        sx_lua_optnumfield(L, 3, "viscous_shear", &d.viscous_shear);
        sx_lua_material_extras(L, 3, &d, &has_bpm, &bpm);
    }
    int index = -1;
    sx_lua_check(L, m, sx_material_set(m, name, &d, &index));
    if (has_bpm) sx_lua_check(L, m, sx_material_set_bpm(m, index, &bpm));
    lua_settop(L, 2);
    return 1;  // the name: materials are referred to by name everywhere
}

/* ------------------------------------------------------------ cycling */

enum { MAX_CYCLING = 16 };  // deeper nested cycles run unlisted, not interruptible
_Static_assert(ATOMIC_POINTER_LOCK_FREE == 2 && ATOMIC_INT_LOCK_FREE == 2,
               "a signal handler may only touch lock-free atomics");
static _Atomic(sx_model *) cycling[MAX_CYCLING];
static atomic_int ncycling;
/* Set by every interrupt, cleared when a cycle starts: catches a SIGINT that
 * lands before sx_model_cycle has reset the model's own flag. */
static atomic_int pending;

int sx_lua_interrupt_all(void)
{
    atomic_store(&pending, 1);
    const int n = atomic_load(&ncycling);
    for (int i = 0; i < n; i++) {
        sx_model *m = atomic_load(&cycling[i]);
        if (m) sx_model_interrupt(m);
    }
    return n;
}

static sx_status cycle_listed(sx_model *m, int64_t n)
{
    atomic_store(&pending, 0);
    const int slot = atomic_load(&ncycling);
    const bool listed = slot < MAX_CYCLING;
    if (listed) {
        atomic_store(&cycling[slot], m);
        atomic_store(&ncycling, slot + 1);
    }
    sx_status st = sx_model_cycle(m, n);
    if (listed) {
        atomic_store(&ncycling, slot);
        atomic_store(&cycling[slot], NULL);
    }
    if (st == SX_OK && atomic_load(&pending)) st = SX_EINTERRUPT;
    return st;
}

static int model_cycle(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    const lua_Integer n = luaL_checkinteger(L, 2);
    luaL_argcheck(L, n >= 0, 2, "the number of steps must be >= 0");
    const sx_status st = cycle_listed(m, (int64_t)n);
    if (st == SX_EINTERRUPT) return luaL_error(L, "interrupted at step %I", (lua_Integer)sx_model_step_count(m));
    sx_lua_check(L, m, st);
    return 0;
}

/* ----------------------------------------------------- time and state */

static int model_dim(lua_State *L)
{
    lua_pushinteger(L, sx_model_dim(sx_lua_checkmodel(L, 1)));
    return 1;
}

static int model_time(lua_State *L)
{
    lua_pushnumber(L, sx_model_time(sx_lua_checkmodel(L, 1)));
    return 1;
}

static int model_step(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_model_step_count(sx_lua_checkmodel(L, 1)));
    return 1;
}

/* The core reports a failed timestep query as NaN with a message. */
static int push_timestep(lua_State *L, const sx_model *m, double dt)
{
    if (isnan(dt)) return luaL_error(L, "%s", sx_model_error(m));
    lua_pushnumber(L, dt);
    return 1;
}

static int model_timestep(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    return push_timestep(L, m, sx_model_timestep(m));
}

static int model_critical_timestep(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    return push_timestep(L, m, sx_model_critical_timestep(m));
}

static int model_set_timestep(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    sx_lua_check(L, m, sx_model_set_timestep(m, luaL_optnumber(L, 2, 0)));
    return 0;
}

static int model_gravity(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel(L, 1);
    double g[3];
    sx_model_gravity(m, g);
    sx_lua_pushvec(L, g, sx_model_dim(m));
    return 1;
}

static int model_set_gravity(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    double g[3] = {0, 0, 0};
    const char *err = sx_lua_tovec(L, 2, sx_model_dim(m), g);
    if (err) return luaL_argerror(L, 2, err);
    sx_lua_check(L, m, sx_model_set_gravity(m, g));
    return 0;
}

static int model_contact_count(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_contact_count(sx_lua_checkmodel(L, 1)));
    return 1;
}

static int model_energy(lua_State *L)
{
    const sx_energy e = sx_model_energy(sx_lua_checkmodel(L, 1));
    const struct {
        const char *name;
        double value;
    } terms[] = {{"kinetic", e.kinetic},     {"gravitational", e.gravitational}, {"strain", e.strain},
                 {"bond_strain", e.bond_strain}, {"slip", e.slip},           {"local_damping", e.local_damping},
                 {"viscous", e.viscous},     {"boundary_work", e.boundary_work}, {"bond_released", e.bond_released}};
    lua_createtable(L, 0, (int)(sizeof terms / sizeof *terms));
    for (size_t k = 0; k < sizeof terms / sizeof *terms; k++) {
        lua_pushnumber(L, terms[k].value);
        lua_setfield(L, -2, terms[k].name);
    }
    return 1;
}

static int model_hash(lua_State *L)
{
    char hex[17];
    snprintf(hex, sizeof hex, "%016" PRIx64, sx_model_state_hash(sx_lua_checkmodel(L, 1)));
    lua_pushstring(L, hex);
    return 1;
}

static int model_bytes(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_model_bytes(sx_lua_checkmodel(L, 1)));
    return 1;
}

void sx_lua_model_register(lua_State *L)
{
    static const luaL_Reg meta[] = {
        {"__gc", model_close},
        {"__close", model_close},
        {"__tostring", model_tostring},
        {NULL, NULL},
    };
    static const luaL_Reg methods[] = {
        {"close", model_close},
        {"material", model_material},
        {"cycle", model_cycle},
        {"dim", model_dim},
        {"time", model_time},
        {"step", model_step},
        {"timestep", model_timestep},
        {"set_timestep", model_set_timestep},
        {"critical_timestep", model_critical_timestep},
        {"gravity", model_gravity},
        {"set_gravity", model_set_gravity},
        {"contact_count", model_contact_count},
        {"energy", model_energy},
        {"hash", model_hash},
        {"bytes", model_bytes},
        {NULL, NULL},
    };
    sx_lua_newclass(L, SX_LUA_MODEL, "model", meta, methods, NULL, NULL);
}
