/* seixo.model: the model userdata owns one sx_model. __gc, __close and
 * m:close() destroy it; any later use is a Lua error, never a crash (balls
 * and walls of a closed model report it too). A model cannot be closed
 * while it cycles (from one of its own callbacks): the cycle holds it.
 *
 * The userdata's uservalue is the model's Lua-side state, a table of
 * tables created on first use (sx_lua_state): group names, user extras,
 * callbacks, histories, queued removals.
 *
 * This file holds the constructor, the class (assembled from the method
 * arrays of every binding file), materials, time, timestep, gravity,
 * energies and the summary that print(m) shows; cycling is in run.c. */
#include "bindings.h"
#include "seixo_lua.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* The model userdata at idx. A method called with '.' for ':' (m.ball{...})
 * passes its arguments one place early: the message says so. */
sx_lua_model *sx_lua_modelud(lua_State *L, int idx)
{
    sx_lua_model *u = luaL_testudata(L, idx, SX_LUA_MODEL);
    if (u) return u;
    const char *got = lua_isnone(L, idx) ? "no value" : luaL_typename(L, idx);
    return (void)luaL_argerror(L, idx, lua_pushfstring(L, "%s expected, got %s%s", SX_LUA_MODEL, got,
                                                       idx == 1 ? " (a method is called with ':', as m:cycle(100))"
                                                                : "")),
           NULL;
}

sx_model *sx_lua_tomodel(lua_State *L, int idx) { return sx_lua_modelud(L, idx)->m; }

sx_model *sx_lua_checkmodel_scattered(lua_State *L, int idx)
{
    sx_model *m = sx_lua_tomodel(L, idx);
    if (!m) luaL_error(L, "the model has been closed");
    return m;
}

/* A collective step of a scattered model's call, checked under the call's
 * name as the script wrote it (m:save, b.pos: a field, through __index)
 * and marked with the step (gather, fetch), so that a rank in one step of
 * a call never meets another rank's other step of the same call; a failed
 * exchange stops every rank. */
static void collective(lua_State *L, sx_model *m, const char *self, const char *step,
                       sx_status (*fn)(sx_model *m, int64_t id), int64_t id)
{
    lua_Debug ar;
    const bool named = lua_getstack(L, 0, &ar) && lua_getinfo(L, "n", &ar) && ar.name;
    char what[96];
    if (named && strcmp(ar.namewhat, "metamethod") == 0 && lua_type(L, 2) == LUA_TSTRING)
        snprintf(what, sizeof what, "%s.%s (%s)", self, lua_tostring(L, 2), step);
    else if (named)
        snprintf(what, sizeof what, "%s:%s (%s)", self, ar.name, step);
    else
        snprintf(what, sizeof what, "a query of %s (%s)", self, step);
    sx_lua_check_model_call(L, m, what);
    if (fn(m, id) != SX_OK) {
        char msg[1024];
        luaL_where(L, 1);
        snprintf(msg, sizeof msg, "%s%s: %s", lua_tostring(L, -1), what, sx_lua_core_message(sx_model_error(m)));
        sx_lua_parallel_fail(msg);
    }
}

static sx_status gather(sx_model *m, int64_t unused)
{
    (void)unused;
    return sx_model_gather(m);
}

void sx_lua_gather(lua_State *L, sx_model *m, const char *self)
{
    if (sx_model_scattered(m)) collective(L, m, self, "gather", gather, 0);
}

void sx_lua_fetch_ball(lua_State *L, sx_model *m, const char *self, int64_t id)
{
    /* once every ball's motion is shared, a read exchanges nothing: no check either (every rank alike) */
    if (!sx_model_motion_current(m)) collective(L, m, self, "fetch", sx_ball_fetch, id);
}

static sx_status share_motion(sx_model *m, int64_t unused)
{
    (void)unused;
    return sx_model_share_motion(m);
}

sx_model *sx_lua_checkmodel_motion(lua_State *L, int idx)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, idx);
    if (!sx_model_motion_current(m)) collective(L, m, "m", "motion", share_motion, 0);
    return m;
}

static sx_status share_cracks(sx_model *m, int64_t unused)
{
    (void)unused;
    return sx_model_share_cracks(m);
}

sx_model *sx_lua_checkmodel_cracks(lua_State *L, int idx)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, idx);
    if (sx_model_scattered(m)) collective(L, m, "m", "cracks", share_cracks, 0);
    return m;
}

sx_model *sx_lua_checkmodel_summed(lua_State *L, int idx, const char *what)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, idx);
    if (sx_model_scattered(m)) sx_lua_check_model_call(L, m, what);
    return m;
}

double sx_lua_ratio(lua_State *L, int idx, const char *what)
{
    sx_model *m = sx_lua_checkmodel_summed(L, idx, what);
    const bool scattered = sx_model_scattered(m);
    const double ratio = sx_model_unbalanced_ratio(m);
    /* NaN from the ranks' chain (a cycle ends on a force that is not finite) */
    if (scattered && isnan(ratio)) luaL_error(L, "%s: the ranks could not sum the ratio", what);
    return ratio;
}

sx_model *sx_lua_checkmodel(lua_State *L, int idx)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, idx);
    sx_lua_gather(L, m, "m");
    return m;
}

void sx_lua_state(lua_State *L, int idx, const char *field)
{
    idx = lua_absindex(L, idx);
    lua_getiuservalue(L, idx, 1);
    if (lua_getfield(L, -1, field) != LUA_TTABLE) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_pushvalue(L, -1);
        lua_setfield(L, -3, field);
    }
    lua_remove(L, -2);
}

int sx_lua_material_arg(lua_State *L, const sx_model *m, int arg, const char *key, const char *name)
{
    if (name) {
        const int i = sx_material_find(m, name);
        if (i < 0) sx_lua_fielderror(L, arg, key, lua_pushfstring(L, "no material named '%s'", name));
        return i;
    }
    const int n = sx_material_count(m);
    if (n == 0) return luaL_argerror(L, arg, "no material defined yet; add one with m:material(name, {...})");
    if (n > 1)
        return luaL_argerror(L, arg, lua_pushfstring(L, "field '%s' is required when the model has several materials", key));
    return 0;
}

/* The models of the session, for seixo.models(): a table with weak values
 * in the registry, keyed by creation number, so listing never keeps a
 * model alive. */
static const char models_key[] = "seixo.models";

static void push_model_list(lua_State *L)
{
    if (luaL_getsubtable(L, LUA_REGISTRYINDEX, models_key)) return;
    lua_createtable(L, 0, 1);
    lua_pushliteral(L, "v");
    lua_setfield(L, -2, "__mode");
    lua_setmetatable(L, -2);
}

static void list_model(lua_State *L, int model)
{
    push_model_list(L);
    lua_getfield(L, LUA_REGISTRYINDEX, "seixo.models_made");
    const lua_Integer n = lua_tointeger(L, -1) + 1;
    lua_pop(L, 1);
    lua_pushinteger(L, n);
    lua_setfield(L, LUA_REGISTRYINDEX, "seixo.models_made");
    lua_pushvalue(L, model);
    lua_rawseti(L, -2, n);
    lua_pop(L, 1);
}

int sx_lua_models(lua_State *L)
{
    push_model_list(L);
    const int list = lua_gettop(L);
    lua_getfield(L, LUA_REGISTRYINDEX, "seixo.models_made");
    const lua_Integer made = lua_tointeger(L, -1);
    lua_newtable(L);
    lua_Integer k = 0;
    for (lua_Integer i = 1; i <= made; i++) {
        if (lua_rawgeti(L, list, i) == LUA_TUSERDATA && sx_lua_tomodel(L, -1))
            lua_rawseti(L, -2, ++k);
        else
            lua_pop(L, 1);
    }
    return 1;
}

/* The models every rank makes alike (decomposed: shared) by creation
 * number, for the same-call check: a table in the registry keyed by the
 * model's address. Models a rank makes on its own (seixo.decompose(false):
 * a lab.series test, a calibration run) are not counted, as the ranks make
 * different numbers of them. */
static const char shared_key[] = "seixo.shared_models";

void sx_lua_model_share(lua_State *L, const sx_model *was, const sx_model *m)
{
    if (!luaL_getsubtable(L, LUA_REGISTRYINDEX, shared_key)) {
        lua_pushinteger(L, 0);
        lua_setfield(L, -2, "made");
    }
    lua_Integer number = 0;
    if (was && lua_rawgetp(L, -1, was) == LUA_TNUMBER) { /* seixo.load: the placeholder's number */
        number = lua_tointeger(L, -1);
        lua_pushnil(L);
        lua_rawsetp(L, -3, was);
    }
    if (was) lua_pop(L, 1);
    if (m && !number) {
        lua_getfield(L, -1, "made");
        number = lua_tointeger(L, -1) + 1;
        lua_pop(L, 1);
        lua_pushinteger(L, number);
        lua_setfield(L, -2, "made");
    }
    if (m) {
        lua_pushinteger(L, number);
        lua_rawsetp(L, -2, m);
    }
    lua_pop(L, 1);
}

/* Forgets a closed model's number (a later model may take its address). */
static void unshare(lua_State *L, const sx_model *m)
{
    if (!m) return;
    if (lua_getfield(L, LUA_REGISTRYINDEX, shared_key) != LUA_TTABLE) {
        lua_pop(L, 1);
        return;
    }
    lua_pushnil(L);
    lua_rawsetp(L, -2, m);
    lua_pop(L, 1);
}

static int model_number(lua_State *L, const sx_model *m)
{
    const int top = lua_gettop(L);
    int number = 0;
    if (lua_getfield(L, LUA_REGISTRYINDEX, shared_key) == LUA_TTABLE && lua_rawgetp(L, -1, m) == LUA_TNUMBER)
        number = (int)lua_tointeger(L, -1);
    lua_settop(L, top);
    return number;
}

void sx_lua_check_model_call(lua_State *L, const sx_model *m, const char *what)
{
    /* ranks in one call on two models (`(seixo.rank() == 0 and m1 or
     * m2):save(...)`) would pair one model's exchanges with the other's;
     * the first model keeps the plain name, as most scripts have one, and
     * the others' number comes first, where no cut of a long name drops it */
    const int number = model_number(L, m);
    if (number <= 1) {
        sx_lua_parallel_check_call(L, what);
        return;
    }
    sx_lua_parallel_check_call(L, lua_pushfstring(L, "model %d: %s", number, what));
    lua_pop(L, 1);
}

int sx_lua_model_new(lua_State *L)
{
    static const char *const keys[] = {"dim", "gravity", "timestep", "timestep_safety", "skin", "overlap_limit", NULL};
    sx_model_def d = sx_model_default_def();
    double overlap_limit = 0.5;
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
        sx_lua_optrangefield(L, 1, "overlap_limit", 0, 1, &overlap_limit);
    }
    /* the userdata first: if Lua runs out of memory, no model leaks */
    sx_lua_model *u = lua_newuserdatauv(L, sizeof *u, 1);
    memset(u, 0, sizeof *u);
    u->overlap_limit = overlap_limit;
    u->timestep_unchecked = d.timestep > 0;
    luaL_setmetatable(L, SX_LUA_MODEL);
    lua_newtable(L);
    lua_setiuservalue(L, -2, 1);
    char err[256];
    u->m = sx_model_create(&d, err, sizeof err);
    if (!u->m) return luaL_error(L, "seixo.model: %s", sx_lua_core_message(err));
    u->decomposed = sx_lua_parallel_decompose(u->m); /* under mpirun: over the ranks */
    if (u->decomposed) sx_lua_model_share(L, NULL, u->m);
    const int self = lua_gettop(L);
    list_model(L, self);
    sx_lua_model_threads(L, u->m, "seixo.model");
    const double g = sqrt(d.gravity[0] * d.gravity[0] + d.gravity[1] * d.gravity[1] + d.gravity[2] * d.gravity[2]);
    sx_lua_check_range(L, self, "gravity", g, 0.1, 2000, "m/s^2"); /* a centrifuge's 200 g passes; mm/s^2 do not */
    lua_settop(L, self);
    return 1;
}

void sx_lua_model_threads(lua_State *L, sx_model *m, const char *fn)
{
    const int top = lua_gettop(L);
    if (lua_getglobal(L, "seixo") == LUA_TTABLE && lua_getfield(L, -1, "threads") != LUA_TNIL) {
        int isint = 0;
        const lua_Integer t = lua_tointegerx(L, -1, &isint);
        if (!isint || t < 1 || t > 1024)
            luaL_error(L, "%s: seixo.threads must be a whole number from 1 to 1024 (got %s)", fn,
                       luaL_tolstring(L, -1, NULL));
        if (m) {
            sx_model_set_threads(m, (int)t);
            sx_lua_parallel_check_threads((int)t);
        }
    }
    lua_settop(L, top);
}

/* With the executable's --profile, a model that cycled prints its profile
 * on stderr when it is closed or collected. */
static const char profile_key[] = "seixo.profile";

void sx_lua_set_profile(lua_State *L, int on)
{
    lua_pushboolean(L, on);
    lua_setfield(L, LUA_REGISTRYINDEX, profile_key);
}

static void push_profile_text(lua_State *L, const sx_model *m);

static void profile_at_end(lua_State *L, const sx_model *m)
{
    lua_getfield(L, LUA_REGISTRYINDEX, profile_key);
    const bool on = lua_toboolean(L, -1);
    lua_pop(L, 1);
    if (!on || !m || sx_model_profile(m).steps == 0) return;
    push_profile_text(L, m);
    /* decomposed, each rank times its own share: N tables, each named */
    char rank[48] = "";
    if (sx_model_ranks(m) > 1) snprintf(rank, sizeof rank, " (rank %d of %d)", sx_lua_parallel_rank(), sx_model_ranks(m));
    fprintf(stderr, "seixo: profile%s of a %dD model of %lld balls at step %lld:\n%s", rank, sx_model_dim(m),
            (long long)sx_ball_count(m), (long long)sx_model_step_count(m), lua_tostring(L, -1));
    lua_pop(L, 1);
}

static int model_close(lua_State *L)
{
    sx_lua_model *u = sx_lua_modelud(L, 1);
    sx_lua_runs_reap(L); /* a cycle a failed coroutine left open */
    if (u->running) return luaL_error(L, "the model is cycling; close it after the cycle returns");
    profile_at_end(L, u->m);
    unshare(L, u->m);
    sx_model_destroy(u->m);
    u->m = NULL;
    return 0;
}

/* __gc cannot run while the model cycles (the cycle holds it on the stack). */
static int model_gc(lua_State *L)
{
    sx_lua_model *u = sx_lua_modelud(L, 1);
    profile_at_end(L, u->m);
    unshare(L, u->m);
    sx_model_destroy(u->m);
    u->m = NULL;
    return 0;
}

/* ------------------------------------------------------------ summary */

/* Pushes "a, b, c" for the strings of the array at idx, "none" when empty. */
static void push_joined(lua_State *L, int idx)
{
    idx = lua_absindex(L, idx);
    const lua_Integer n = (lua_Integer)lua_rawlen(L, idx);
    if (n == 0) {
        lua_pushliteral(L, "none");
        return;
    }
    luaL_checkstack(L, 2, NULL);
    lua_pushliteral(L, "");
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, idx, i);
        lua_pushfstring(L, "%s%s", i > 1 ? ", " : "", luaL_tolstring(L, -1, NULL));
        lua_remove(L, -2);
        lua_remove(L, -2);
        lua_concat(L, 2);
    }
}

/* Pushes the names of the state's histories and the number of callbacks. */
static void push_histories(lua_State *L, int *ncb)
{
    sx_lua_state(L, 1, "histories");
    const int t = lua_gettop(L);
    lua_newtable(L);
    for (lua_Integer i = 1; lua_rawgeti(L, t, i) == LUA_TTABLE; i++) {
        lua_getfield(L, -1, "name");
        lua_rawseti(L, t + 1, i);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
    push_joined(L, -1);
    lua_replace(L, t);
    lua_settop(L, t);
    sx_lua_state(L, 1, "callbacks");
    *ncb = 0;
    lua_pushnil(L);
    while (lua_next(L, -2)) {
        lua_pop(L, 1);
        ++*ncb;
    }
    lua_pop(L, 1);
}

static int model_summary(lua_State *L)
{
    sx_model *m = sx_lua_tomodel(L, 1);
    if (!m) {
        lua_pushliteral(L, "seixo.model (closed)");
        return 1;
    }
    sx_lua_gather(L, m, "m");
    lua_settop(L, 1);
    const int dim = sx_model_dim(m);
    const double dt = sx_model_timestep(m);
    double g[3];
    sx_model_gravity(m, g);
    lua_createtable(L, sx_material_count(m), 0);
    for (int i = 0; i < sx_material_count(m); i++) {
        lua_pushstring(L, sx_material_name(m, i));
        lua_rawseti(L, -2, i + 1);
    }
    push_joined(L, -1);
    lua_replace(L, 2);
    sx_lua_state(L, 1, "group_names");
    push_joined(L, -1);
    lua_replace(L, 3);
    int ncb;
    push_histories(L, &ncb);
    const sx_energy e = sx_model_energy(m);
    if (sx_clump_count(m) > 0) /* the balls include the clumps' pebbles */
        lua_pushfstring(L, "seixo.model %dD: %I balls (pebbles of %I clumps among them), %I walls, %I contacts\n", dim,
                        (lua_Integer)sx_ball_count(m), (lua_Integer)sx_clump_count(m), (lua_Integer)sx_wall_count(m),
                        (lua_Integer)sx_contact_count(m));
    else
        lua_pushfstring(L, "seixo.model %dD: %I balls, %I walls, %I contacts\n", dim, (lua_Integer)sx_ball_count(m),
                        (lua_Integer)sx_wall_count(m), (lua_Integer)sx_contact_count(m));
    lua_pushfstring(L, "  step %I, time %f s, timestep ", (lua_Integer)sx_model_step_count(m), sx_model_time(m));
    if (isnan(dt))
        lua_pushliteral(L, "automatic (no ball yet)\n");
    else
        lua_pushfstring(L, "%f s\n", dt);
    if (dim == 3)
        lua_pushfstring(L, "  gravity {%f, %f, %f} m/s^2\n", g[0], g[1], g[2]);
    else
        lua_pushfstring(L, "  gravity {%f, %f} m/s^2\n", g[0], g[1]);
    lua_pushfstring(L, "  materials: %s; groups: %s\n", lua_tostring(L, 2), lua_tostring(L, 3));
    lua_pushfstring(L, "  unbalanced ratio %f, kinetic energy %f J\n", sx_model_unbalanced_ratio(m), e.kinetic);
    lua_pushfstring(L, "  histories: %s; callbacks: %d", lua_tostring(L, 4), ncb);
    lua_concat(L, 7);
    return 1;
}

/* ----------------------------------------------------------- materials */

/* A material's keys into the table on top, as m:material takes them. */
static void push_material(lua_State *L, sx_material_def *d)
{
    lua_pushstring(L, sx_law_name(d->model));
    lua_setfield(L, -2, "model");
    sx_lua_setnum(L, "density", d->density);
    sx_lua_setnum(L, "kn", d->kn);
    sx_lua_setnum(L, "ks", d->ks);
    sx_lua_setnum(L, "friction", d->friction);
    sx_lua_setnum(L, "damping", d->damping);
    sx_lua_setnum(L, "viscous_normal", d->viscous_normal);
    sx_lua_setnum(L, "viscous_shear", d->viscous_shear);
    sx_lua_setnum(L, "modulus", d->modulus);
    sx_lua_setnum(L, "stiffness_ratio", d->stiffness_ratio);
    for (int law = 0; law < sx_law_count(); law++)
        for (int k = 0; k < sx_law_param_count(law); k++)
            sx_lua_setnum(L, sx_law_param_name(law, k, NULL), *sx_law_param_value(d, law, k));
}

/* The material keys of the table at arg into d (keys already checked). */
static void read_material(lua_State *L, int arg, sx_material_def *d, bool *has_bpm, sx_bpm_def *bpm)
{
    sx_lua_optnumfield(L, arg, "kn", &d->kn);
    sx_lua_optnumfield(L, arg, "ks", &d->ks);
    sx_lua_optnumfield(L, arg, "friction", &d->friction);
    sx_lua_optnumfield(L, arg, "density", &d->density);
    sx_lua_optnumfield(L, arg, "damping", &d->damping);
    sx_lua_optnumfield(L, arg, "viscous_normal", &d->viscous_normal);
    sx_lua_optnumfield(L, arg, "viscous_shear", &d->viscous_shear);
    sx_lua_material_extras(L, arg, d, has_bpm, bpm);
}

/* Warnings for values the core accepted but that are unusual for rocks and
 * grains (wrong units, most likely): only after the core's checks, so an
 * invalid value has had its error and no warning. */
static void warn_unusual(lua_State *L, const sx_material_def *d)
{
    sx_lua_check_range(L, 1, "density", d->density, 100, 3e4, "kg/m^3");
    sx_lua_check_range(L, 1, "modulus", d->modulus, 1e5, 1e12, "Pa");
    sx_lua_check_range(L, 1, "shear_modulus", d->shear_modulus, 1e5, 1e12, "Pa");
    if (d->friction > 2) /* (a rough rock joint's is about 1) */
        sx_lua_warn_once(L, 1, "friction",
                         "friction %g is a coefficient, the tangent of the friction angle, usually 0 ... 1: an angle of "
                         "30 degrees is friction = math.tan(math.rad(30)) = 0.577",
                         d->friction);
}

/* The material table at arg (if any) into d and bpm, its keys checked. */
static void check_material(lua_State *L, int arg, sx_material_def *d, bool *has_bpm, sx_bpm_def *bpm)
{
    const char *keys[48] = {"kn",      "ks",             "friction",      "density", "damping",
                            "viscous_normal", "viscous_shear", "model", "modulus", "stiffness_ratio",
                            "bond"};
    sx_lua_law_keys(L, keys, 11, 48); /* and the laws' parameters */
    *d = sx_material_default_def();
    *has_bpm = false;
    memset(bpm, 0, sizeof *bpm);
    if (lua_isnoneornil(L, arg)) return;
    sx_lua_checkkeys(L, arg, keys);
    read_material(L, arg, d, has_bpm, bpm);
}

static int model_material(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    const char *name = sx_lua_checkname(L, 2);
    sx_material_def d;
    bool has_bpm;
    sx_bpm_def bpm;
    check_material(L, 3, &d, &has_bpm, &bpm);
    int index = -1;
    sx_lua_check(L, m, sx_material_set(m, name, &d, &index), "m:material");
    if (has_bpm) sx_lua_check(L, m, sx_material_set_bpm(m, index, &bpm), "m:material");
    warn_unusual(L, &d);
    lua_settop(L, 2);
    return 1;  // the name: materials are referred to by name everywhere
}

/* seixo.check_material({...}) -> true, or m:material's error: the table
 * checked as m:material checks it (its keys, then the core's ranges), on a
 * core model of its own that no script sees: no model is made, counted or
 * shared between ranks, and no warning printed (lab.rock checks its
 * overrides so). */
int sx_lua_check_material(lua_State *L)
{
    luaL_checktype(L, 1, LUA_TTABLE);
    sx_material_def d;
    bool has_bpm;
    sx_bpm_def bpm;
    check_material(L, 1, &d, &has_bpm, &bpm);
    char err[256];
    sx_model_def md = sx_model_default_def();
    sx_model *m = sx_model_create(&md, err, sizeof err);
    if (!m) return luaL_error(L, "seixo.check_material: %s", sx_lua_core_message(err));
    int index = -1;
    sx_status st = sx_material_set(m, "material", &d, &index);
    if (st == SX_OK && has_bpm) st = sx_material_set_bpm(m, index, &bpm);
    if (st != SX_OK) {
        static const char named[] = "material 'material': "; /* the core's prefix: no name here */
        const char *why = sx_lua_core_message(sx_model_error(m));
        if (!strncmp(why, named, sizeof named - 1)) why += sizeof named - 1;
        luaL_where(L, 1);
        lua_pushfstring(L, "seixo.check_material: %s", why);
        lua_concat(L, 2);
        sx_model_destroy(m);
        return lua_error(L);
    }
    sx_model_destroy(m);
    lua_pushboolean(L, 1);
    return 1;
}

/* The two names of field `key` of the table at arg ({"x", "y"}, or one
 * name for both) as group numbers or material indices. */
static void pair_field(lua_State *L, int arg, const char *key, bool groups, int32_t *a, int32_t *b)
{
    const sx_model *m = sx_lua_checkmodel(L, 1);
    lua_getfield(L, arg, key);
    const int t = lua_gettop(L);
    const int n = lua_type(L, t) == LUA_TSTRING ? 1 : lua_istable(L, t) ? (int)lua_rawlen(L, t) : 0;
    if (n < 1 || n > 2 || (lua_istable(L, t) && lua_rawlen(L, t) != (size_t)n))
        sx_lua_fielderror(L, arg, key, "a name or a list of two names expected");
    int32_t v[2];
    for (int k = 0; k < n; k++) {
        if (lua_istable(L, t)) lua_rawgeti(L, t, k + 1);
        else lua_pushvalue(L, t);
        if (lua_type(L, -1) != LUA_TSTRING) sx_lua_fielderror(L, arg, key, "names expected");
        const char *name = lua_tostring(L, -1);
        if (groups) {
            v[k] = sx_lua_group_id(L, 1, name, true); /* a group may be named before it has balls */
        } else {
            v[k] = sx_material_find(m, name);
            if (v[k] < 0) sx_lua_fielderror(L, arg, key, lua_pushfstring(L, "no material named '%s'", name));
        }
        lua_pop(L, 1);
    }
    *a = v[0], *b = v[n - 1];
    lua_settop(L, t - 1);
}

/* m:contact_model{groups = {g1, g2} | materials = {m1, m2} | default = true,
 * model = law, material = base, name = ..., its law's keys}: a row of the
 * contact-model table (cmodel.c) -> its number. */
static int model_contact_model(lua_State *L)
{
    const char *keys[56] = {"kn",      "ks",      "friction", "density",  "damping",    "viscous_normal",
                            "viscous_shear", "model", "modulus", "stiffness_ratio", "groups", "materials",
                            "default", "material", "name", "wall"};
    sx_lua_law_keys(L, keys, 16, 56); /* and the laws' parameters */
    sx_model *m = sx_lua_checkmodel(L, 1);
    luaL_checktype(L, 2, LUA_TTABLE);
    sx_lua_checkkeys(L, 2, keys);
    sx_cmodel_def d;
    memset(&d, 0, sizeof d);
    const bool groups = lua_getfield(L, 2, "groups") != LUA_TNIL, materials = lua_getfield(L, 2, "materials") != LUA_TNIL,
               dflt = lua_getfield(L, 2, "default") != LUA_TNIL;
    if (dflt && !lua_toboolean(L, -1)) luaL_argerror(L, 2, "field 'default': true expected (or leave it out)");
    lua_pop(L, 3);
    if (lua_getfield(L, 2, "wall") != LUA_TNIL) { /* a row of a wall's contacts: one ball group or material, or any */
        int64_t wid;
        const char *bad = sx_lua_toid(L, lua_gettop(L), 1, &sx_lua_wall_kind, &wid);
        if (bad) sx_lua_fielderror(L, 2, "wall", bad);
        if (!sx_wall_exists(m, wid)) sx_lua_fielderror(L, 2, "wall", lua_pushfstring(L, "no wall with id %I", (lua_Integer)wid));
        lua_pop(L, 1);
        if (dflt) luaL_argerror(L, 2, "with wall = ..., leave out default (a row of the wall's contacts with any ball)");
        if (groups && materials) luaL_argerror(L, 2, "with wall = ..., one of groups = a or materials = a (or neither)");
        const char *key = groups ? "groups" : "materials";
        if ((groups || materials) && lua_getfield(L, 2, key) == LUA_TTABLE && lua_rawlen(L, -1) != 1)
            sx_lua_fielderror(L, 2, key, "with wall = ..., one name (the ball's) expected");
        if (groups || materials) lua_pop(L, 1);
        if (wid > INT32_MAX) luaL_argerror(L, 2, "field 'wall': its id is beyond the table's range");
        d.match = groups ? SX_CMODEL_WALL_GROUP : materials ? SX_CMODEL_WALL_MATERIAL : SX_CMODEL_WALL;
        d.b = (int32_t)wid;
        if (groups || materials) pair_field(L, 2, key, groups, &d.a, &(int32_t){0});
    } else {
        lua_pop(L, 1);
        if (groups + materials + dflt != 1)
            luaL_argerror(L, 2, "exactly one of groups = {a, b}, materials = {a, b}, default = true or wall = w expected");
        d.match = groups ? SX_CMODEL_GROUPS : materials ? SX_CMODEL_MATERIALS : SX_CMODEL_DEFAULT;
        if (!dflt) pair_field(L, 2, groups ? "groups" : "materials", groups, &d.a, &d.b);
    }
    const bool wall_row = d.match >= SX_CMODEL_WALL_GROUP;
    d.law = sx_material_default_def();
    const char *base = sx_lua_optstrfield(L, 2, "material");
    if (base) sx_lua_check(L, m, sx_material_get(m, sx_lua_material_arg(L, m, 2, "material", base), &d.law),
                           "m:contact_model");
    bool has_bpm;
    sx_bpm_def bpm;
    read_material(L, 2, &d.law, &has_bpm, &bpm);
    const char *name = sx_lua_optstrfield(L, 2, "name");
    char auto_name[64];
    if (!name && dflt) name = "default";
    if (!name) { /* its match, for reports: "a-b" ("a-wall 3", "any-wall 3") */
        const sx_cmodel_def *p = &d;
        char both[2][64];
        for (int k = 0; k < 2; k++) {
            const int32_t v = k ? p->b : p->a;
            if (wall_row && k) lua_pushfstring(L, "wall %d", (int)v);
            else if (d.match == SX_CMODEL_WALL) lua_pushliteral(L, "any");
            else if (groups) sx_lua_push_group_name(L, 1, v);
            else lua_pushstring(L, sx_material_name(m, v));
            snprintf(both[k], sizeof both[k], "%s", lua_tostring(L, -1) ? lua_tostring(L, -1) : "none");
            lua_pop(L, 1);
        }
        snprintf(auto_name, sizeof auto_name, "%.31s-%.31s", both[0], both[1]);
        name = auto_name;
    }
    int row = 0;
    sx_lua_check(L, m, sx_cmodel_add(m, name, &d, &row), "m:contact_model");
    warn_unusual(L, &d.law);
    lua_pushinteger(L, row);
    return 1;
}

/* m:contact_models(): the table's rows in order, each as m:contact_model takes it. */
static int model_contact_models(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* what every rank holds alike: no gather */
    const int n = sx_cmodel_count(m);
    lua_createtable(L, n, 0);
    for (int r = 1; r <= n; r++) {
        sx_cmodel_def d;
        const char *name;
        sx_lua_check(L, m, sx_cmodel_get(m, r, &d, &name), "m:contact_models");
        lua_createtable(L, 0, 16);
        lua_pushstring(L, name);
        lua_setfield(L, -2, "name");
        if (d.match == SX_CMODEL_DEFAULT) {
            lua_pushboolean(L, 1);
            lua_setfield(L, -2, "default");
        } else if (d.match >= SX_CMODEL_WALL_GROUP) { /* the wall (its id once removed) and the ball's match */
            if (sx_wall_exists(m, d.b)) sx_lua_pushhandle(L, 1, &sx_lua_wall_kind, d.b);
            else lua_pushinteger(L, d.b);
            lua_setfield(L, -2, "wall");
            if (d.match == SX_CMODEL_WALL_GROUP) sx_lua_push_group_name(L, 1, d.a);
            if (d.match == SX_CMODEL_WALL_MATERIAL) lua_pushstring(L, sx_material_name(m, d.a));
            if (d.match != SX_CMODEL_WALL) lua_setfield(L, -2, d.match == SX_CMODEL_WALL_GROUP ? "groups" : "materials");
        } else {
            lua_createtable(L, 2, 0);
            for (int k = 0; k < 2; k++) {
                const int32_t v = k ? d.b : d.a;
                if (d.match == SX_CMODEL_GROUPS) sx_lua_push_group_name(L, 1, v);
                else lua_pushstring(L, sx_material_name(m, v));
                lua_rawseti(L, -2, k + 1);
            }
            lua_setfield(L, -2, d.match == SX_CMODEL_GROUPS ? "groups" : "materials");
        }
        push_material(L, &d.law);
        lua_rawseti(L, -2, r);
    }
    return 1;
}

/* m:materials(): name -> its properties, as m:material takes them. */
static int model_materials(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* what every rank holds alike: no gather */
    const int n = sx_material_count(m);
    lua_createtable(L, 0, n);
    for (int i = 0; i < n; i++) {
        sx_material_def d;
        sx_lua_check(L, m, sx_material_get(m, i, &d), "m:materials");
        lua_createtable(L, 0, 12);
        push_material(L, &d);
        if (sx_lua_push_bpm(L, m, i)) lua_setfield(L, -2, "bond");
        lua_setfield(L, -2, sx_material_name(m, i));
    }
    return 1;
}

/* ----------------------------------------------------- time and state */

static int model_dim(lua_State *L)
{
    lua_pushinteger(L, sx_model_dim(sx_lua_checkmodel_scattered(L, 1)));
    return 1;
}

static int model_time(lua_State *L)
{
    lua_pushnumber(L, sx_model_time(sx_lua_checkmodel_scattered(L, 1)));
    return 1;
}

static int model_step(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_model_step_count(sx_lua_checkmodel_scattered(L, 1)));
    return 1;
}

/* The core reports a failed timestep query as NaN with a message. */
static int push_timestep(lua_State *L, const sx_model *m, double dt, const char *what)
{
    if (isnan(dt)) return luaL_error(L, "%s: %s", what, sx_lua_core_message(sx_model_error(m)));
    lua_pushnumber(L, dt);
    return 1;
}

static int model_timestep(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_summed(L, 1, "m:timestep"); /* scattered: the ranks' least rating */
    return push_timestep(L, m, sx_model_timestep(m), "m:timestep");
}

static int model_critical_timestep(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_summed(L, 1, "m:critical_timestep"); /* scattered: the ranks' least */
    return push_timestep(L, m, sx_model_critical_timestep(m), "m:critical_timestep");
}

/* m:set_timestep(dt) fixes it; m:set_timestep() or ("auto") returns to the automatic one. */
static int model_set_timestep(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel(L, 1);
    double dt = 0;
    if (lua_type(L, 2) == LUA_TSTRING) {
        if (strcmp(lua_tostring(L, 2), "auto") != 0) return luaL_argerror(L, 2, "number expected (a timestep in s) or 'auto'");
    } else {
        dt = luaL_optnumber(L, 2, 0);
    }
    sx_lua_check(L, m, sx_model_set_timestep(m, dt), "m:set_timestep");
    sx_lua_modelud(L, 1)->timestep_unchecked = dt > 0; /* rated after the next run's first step */
    return 0;
}

static int model_gravity(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* what every rank holds alike: no gather */
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
    sx_lua_check(L, m, sx_model_set_gravity(m, g), "m:set_gravity");
    sx_lua_check_range(L, 1, "gravity", sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]), 0.1, 2000, "m/s^2");
    return 0;
}

static int model_contact_count(lua_State *L)
{
    const int64_t n = sx_contact_count(sx_lua_checkmodel_summed(L, 1, "m:contact_count"));
    if (n < 0) return luaL_error(L, "m:contact_count: the ranks could not exchange their counts");
    lua_pushinteger(L, (lua_Integer)n);
    return 1;
}

static int model_ratio(lua_State *L)
{
    lua_pushnumber(L, sx_lua_ratio(L, 1, "m:ratio"));
    return 1;
}

static int model_energy(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_summed(L, 1, "m:energy"); /* scattered: the ranks' sums chained */
    const sx_energy e = sx_model_energy(m);
    if (isnan(e.kinetic)) sx_lua_check(L, m, SX_EINVAL, "m:energy");
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

/* The core's state hash, with the group slots 2 and up (Lua state that a
 * restart restores) folded in when a ball has one. A model left scattered
 * by a lazy cycle hashes without a gather, its ranks' sums added: a
 * collective call, behind the same-call check as a gather. */
static int model_hash(lua_State *L)
{
    char hex[17];
    sx_model *m = sx_lua_checkmodel_summed(L, 1, "m:hash");
    uint64_t h = sx_model_state_hash(m);
    /* 0: a rank could not hash its part or the ranks could not add them
     * (a serial hash is 0 with odds of 2^-64) */
    if (!h && sx_model_scattered(m)) return luaL_error(L, "m:hash: the ranks could not hash the state (out of memory?)");
    const uint64_t slots = sx_lua_slots_digest(L, 1);
    if (slots) h = (h ^ slots) * 0x9e3779b97f4a7c15u + 1;
    snprintf(hex, sizeof hex, "%016" PRIx64, h);
    lua_pushstring(L, hex);
    return 1;
}

/* m:ranks() -> the number of MPI ranks its cycles are decomposed over (1: serial) */
static int model_ranks(lua_State *L)
{
    lua_pushinteger(L, sx_model_ranks(sx_lua_checkmodel_scattered(L, 1)));
    return 1;
}

static int model_bytes(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_model_bytes(sx_lua_checkmodel(L, 1)));
    return 1;
}

/* m:memory() -> {total =, peak =, balls =, contacts =, bonds =, work =, ...} */
static int model_memory(lua_State *L)
{
    const sx_memory r = sx_model_memory(sx_lua_checkmodel(L, 1));
    lua_createtable(L, 0, 11);
    const struct {
        const char *name;
        size_t v;
    } bytes[] = {{"total", r.total}, {"peak", r.peak}, {"balls", r.balls}, {"contacts", r.contacts},
                 {"bonds", r.bonds}, {"work", r.work}};
    for (size_t i = 0; i < sizeof bytes / sizeof bytes[0]; i++) {
        lua_pushinteger(L, (lua_Integer)bytes[i].v);
        lua_setfield(L, -2, bytes[i].name);
    }
    lua_pushinteger(L, (lua_Integer)r.ball_count);
    lua_setfield(L, -2, "ball_count");
    lua_pushinteger(L, (lua_Integer)r.pair_count);
    lua_setfield(L, -2, "pair_count");
    lua_pushinteger(L, (lua_Integer)r.contact_count);
    lua_setfield(L, -2, "contact_count");
    lua_pushnumber(L, r.bytes_per_ball);
    lua_setfield(L, -2, "per_ball");
    lua_pushnumber(L, r.bytes_per_contact);
    lua_setfield(L, -2, "per_contact");
    return 1;
}

/* The profile as text, for m:profile() and the executable's --profile. */
static void push_profile_text(lua_State *L, const sx_model *m)
{
    const sx_profile p = sx_model_profile(m);
    const int need = sx_profile_format(&p, sx_ball_count(m), NULL, 0);
    luaL_Buffer b;
    char *out = luaL_buffinitsize(L, &b, (size_t)need + 1);
    sx_profile_format(&p, sx_ball_count(m), out, (size_t)need + 1);
    luaL_pushresultsize(&b, (size_t)need);
}

/* m:profile([{print = true, reset = false}]) -> {broad_phase = {seconds =, calls =}, ..., total =}
 * This rank's own figures: under MPI no gather (a gather would count in
 * them) and no collective call, so rank 0 alone may ask. */
static int model_profile(lua_State *L)
{
    static const char *const keys[] = {"print", "reset", NULL};
    sx_model *m = sx_lua_checkmodel_scattered(L, 1);
    bool print = true, reset = false;
    if (!lua_isnoneornil(L, 2)) {
        sx_lua_checkkeys(L, 2, keys);
        if (lua_getfield(L, 2, "print") != LUA_TNIL) print = lua_toboolean(L, -1);
        if (lua_getfield(L, 2, "reset") != LUA_TNIL) reset = lua_toboolean(L, -1);
        lua_pop(L, 2);
    }
    const sx_profile p = sx_model_profile(m);
    if (print) {
        push_profile_text(L, m);
        size_t len;
        const char *text = lua_tolstring(L, -1, &len);
        lua_writestring(text, len);
        lua_pop(L, 1);
    }
    lua_createtable(L, 0, SX_STAGE_COUNT + 5);
    double total = 0;
    for (int s = 0; s < SX_STAGE_COUNT; s++) {
        char key[32];
        snprintf(key, sizeof key, "%s", sx_stage_name((sx_stage)s));
        for (char *c = key; *c; c++)
            if (*c == ' ') *c = '_';
        lua_createtable(L, 0, 2);
        lua_pushnumber(L, p.seconds[s]);
        lua_setfield(L, -2, "seconds");
        lua_pushinteger(L, (lua_Integer)p.calls[s]);
        lua_setfield(L, -2, "calls");
        lua_setfield(L, -2, key);
        total += p.seconds[s];
    }
    lua_pushnumber(L, total);
    lua_setfield(L, -2, "total");
    lua_pushnumber(L, p.cycle_seconds);
    lua_setfield(L, -2, "cycle_seconds");
    lua_pushinteger(L, (lua_Integer)p.steps);
    lua_setfield(L, -2, "steps");
    lua_pushinteger(L, (lua_Integer)p.cycles);
    lua_setfield(L, -2, "cycles");
    lua_pushinteger(L, (lua_Integer)p.resumed);
    lua_setfield(L, -2, "resumed");
    lua_pushinteger(L, (lua_Integer)p.gathers);
    lua_setfield(L, -2, "gathers");
    lua_pushinteger(L, (lua_Integer)p.received);
    lua_setfield(L, -2, "received");
    lua_pushinteger(L, sx_model_threads(m));
    lua_setfield(L, -2, "threads");
    if (reset) sx_model_profile_reset(m);
    return 1;
}

const luaL_Reg sx_lua_model_methods[] = {
    {"close", model_close},
    {"summary", model_summary},
    {"material", model_material},
    {"materials", model_materials},
    {"contact_model", model_contact_model},
    {"contact_models", model_contact_models},
    {"dim", model_dim},
    {"time", model_time},
    {"step", model_step},
    {"timestep", model_timestep},
    {"set_timestep", model_set_timestep},
    {"critical_timestep", model_critical_timestep},
    {"gravity", model_gravity},
    {"set_gravity", model_set_gravity},
    {"contact_count", model_contact_count},
    {"ratio", model_ratio},
    {"energy", model_energy},
    {"hash", model_hash},
    {"ranks", model_ranks},
    {"bytes", model_bytes},
    {"memory", model_memory},
    {"profile", model_profile},
    {NULL, NULL},
};

void sx_lua_model_register(lua_State *L, const luaL_Reg *const sets[])
{
    static const luaL_Reg meta[] = {
        {"__gc", model_gc},
        {"__close", model_close},
        {"__tostring", model_summary},
        {NULL, NULL},
    };
    sx_lua_newclass(L, SX_LUA_MODEL, "model", meta, NULL, NULL, NULL);
    for (int i = 0; sets[i]; i++) luaL_setfuncs(L, sets[i], 0);
    lua_pop(L, 1);
}
