/* seixo.optimize: NLopt's derivative-free local optimisers with bounds,
 * for the calibration of micro-parameters (lua/seixo/calibrate.lua).
 *
 *   x, fmin, info = seixo.optimize(f, {x0 =, lower =, upper =,
 *       algorithm = "bobyqa" | "neldermead" | "sbplx" | "cobyla",
 *       maxeval = 200, xtol = 1e-4, ftol = 0, stopval = -inf, step =, seed = 1})
 *
 * f(x) gets a Lua array and returns a number. NLopt calls it from C; a Lua
 * error must not longjmp through NLopt's frames (they hold allocations), so
 * each call runs under lua_pcall: an error is kept on the stack, the
 * search is stopped with nlopt_force_stop, the optimiser is destroyed and
 * only then is the error raised again. Every argument is checked before the
 * optimiser exists, and the callback pushes nothing that allocates before
 * its protected call, so no other error can escape while it lives. */
#include "bindings.h"

#include <math.h>
#include <nlopt.h>
#include <string.h>

enum { MAX_DIM = 64 };  // free micro-parameters: a handful in practice

typedef struct objective {
    lua_State *L;
    int f;            // stack index of the Lua function in seixo_optimize's frame
    nlopt_opt opt;    // stopped when f fails
    int error;        // 0, or the stack index of the error raised by f
    unsigned n;       // dimension
    long evaluations;
    const double *x;  // the point of the current call
    double value;
} objective;

/* An error at the position of seixo.optimize's caller (level 2: level 1 is
 * seixo.optimize itself, which called this function through lua_pcall). */
static int bad_value(lua_State *L, const char *what)
{
    luaL_where(L, 2);
    lua_pushfstring(L, "seixo.optimize: f returned %s, not a number", what);
    lua_concat(L, 2);
    return lua_error(L);
}

/* Runs f(x) in protected mode: the arguments are the objective (a light
 * userdata) and f. */
static int call_objective(lua_State *L)
{
    objective *o = lua_touserdata(L, 1);
    lua_createtable(L, (int)o->n, 0);
    for (unsigned i = 0; i < o->n; i++) {
        lua_pushnumber(L, o->x[i]);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_call(L, 1, 1);  // f(x), f at 2
    int isnum = 0;
    const double v = lua_tonumberx(L, -1, &isnum);
    if (!isnum) return bad_value(L, luaL_typename(L, -1));
    if (isnan(v)) return bad_value(L, "nan (give failed points a finite penalty)");
    o->value = v;
    return 0;
}

static double nlopt_objective(unsigned n, const double *x, double *grad, void *data)
{
    (void)n;
    (void)grad;  // derivative-free algorithms only
    objective *o = data;
    lua_State *L = o->L;
    if (o->error) return HUGE_VAL;  // stopping: f is not called again
    o->x = x;
    o->evaluations++;
    /* a light C function, a light userdata and a copy: nothing allocates
     * outside the protected call; the error stays on the stack, where the
     * room was checked */
    lua_pushcfunction(L, call_objective);
    lua_pushlightuserdata(L, o);
    lua_pushvalue(L, o->f);
    if (lua_pcall(L, 2, 0, 0) != LUA_OK) {
        o->error = lua_gettop(L);
        nlopt_force_stop(o->opt);
        return HUGE_VAL;
    }
    return o->value;
}

/* The numbers of the array field `key` of the options table at 2, n of them. */
static void check_vector(lua_State *L, const char *key, double *v, unsigned n)
{
    lua_getfield(L, 2, key);
    luaL_argexpected(L, lua_istable(L, -1), 2, lua_pushfstring(L, "%s = {numbers}", key));
    if (lua_rawlen(L, -1) != n)
        luaL_error(L, "seixo.optimize: %s has %d numbers, x0 has %d", key, (int)lua_rawlen(L, -1), (int)n);
    for (unsigned i = 0; i < n; i++) {
        lua_rawgeti(L, -1, (lua_Integer)i + 1);
        int isnum = 0;
        v[i] = lua_tonumberx(L, -1, &isnum);
        if (!isnum || !isfinite(v[i])) luaL_error(L, "seixo.optimize: %s[%d] must be a finite number", key, (int)i + 1);
        lua_pop(L, 1);
    }
    lua_pop(L, 1);
}

/* A number field of the options table, or def when absent. */
static double opt_number(lua_State *L, const char *key, double def)
{
    lua_getfield(L, 2, key);
    int isnum = 0;
    const double v = lua_isnil(L, -1) ? def : lua_tonumberx(L, -1, &isnum);
    if (!lua_isnil(L, -1) && (!isnum || isnan(v))) luaL_error(L, "seixo.optimize: %s must be a number", key);
    lua_pop(L, 1);
    return v;
}

static const char *result_name(nlopt_result r)
{
    switch (r) {
    case NLOPT_SUCCESS: return "success";
    case NLOPT_STOPVAL_REACHED: return "stopval";
    case NLOPT_FTOL_REACHED: return "ftol";
    case NLOPT_XTOL_REACHED: return "xtol";
    case NLOPT_MAXEVAL_REACHED: return "maxeval";
    case NLOPT_MAXTIME_REACHED: return "maxtime";
    case NLOPT_FORCED_STOP: return "forced_stop";
    case NLOPT_ROUNDOFF_LIMITED: return "roundoff";
    case NLOPT_OUT_OF_MEMORY: return "out_of_memory";
    case NLOPT_INVALID_ARGS: return "invalid_args";
    default: return "failure";
    }
}

static int seixo_optimize(lua_State *L)
{
    static const char *const names[] = {"bobyqa", "neldermead", "sbplx", "cobyla", NULL};
    static const nlopt_algorithm algorithms[] = {NLOPT_LN_BOBYQA, NLOPT_LN_NELDERMEAD, NLOPT_LN_SBPLX, NLOPT_LN_COBYLA};
    luaL_checktype(L, 1, LUA_TFUNCTION);
    luaL_checktype(L, 2, LUA_TTABLE);
    lua_getfield(L, 2, "x0");
    luaL_argexpected(L, lua_istable(L, -1), 2, "x0 = {numbers}");
    const lua_Unsigned len = lua_rawlen(L, -1);
    lua_pop(L, 1);
    if (len < 1 || len > MAX_DIM) return luaL_error(L, "seixo.optimize: x0 needs 1 to %d numbers", MAX_DIM);
    const unsigned n = (unsigned)len;
    double x[MAX_DIM], lo[MAX_DIM], hi[MAX_DIM], step[MAX_DIM];
    check_vector(L, "x0", x, n);
    check_vector(L, "lower", lo, n);
    check_vector(L, "upper", hi, n);
    for (unsigned i = 0; i < n; i++) {
        if (!(lo[i] < hi[i])) return luaL_error(L, "seixo.optimize: lower[%d] must be below upper[%d]", i + 1, i + 1);
        if (x[i] < lo[i] || x[i] > hi[i]) return luaL_error(L, "seixo.optimize: x0[%d] is outside its bounds", i + 1);
    }
    lua_getfield(L, 2, "algorithm");
    const int which = luaL_checkoption(L, -1, "bobyqa", names);
    lua_pop(L, 1);
    const double maxeval = opt_number(L, "maxeval", 200);
    if (!(maxeval >= 1 && maxeval <= 1e6)) return luaL_error(L, "seixo.optimize: maxeval must be from 1 to 1e6");
    const double xtol = opt_number(L, "xtol", 1e-4), ftol = opt_number(L, "ftol", 0);
    if (!(xtol >= 0) || !(ftol >= 0)) return luaL_error(L, "seixo.optimize: xtol and ftol must be >= 0");
    const double stopval = opt_number(L, "stopval", -HUGE_VAL);
    const double seed = opt_number(L, "seed", 1);
    lua_getfield(L, 2, "step");
    const bool has_step = !lua_isnil(L, -1);
    lua_pop(L, 1);
    if (has_step) {
        check_vector(L, "step", step, n);
        for (unsigned i = 0; i < n; i++)
            if (!(step[i] > 0)) return luaL_error(L, "seixo.optimize: step[%d] must be positive", i + 1);
    }
    luaL_checkstack(L, 8, "seixo.optimize");
    lua_settop(L, 2);

    objective o = {.L = L, .f = 1, .n = n};
    nlopt_srand((unsigned long)seed);  // only the randomised algorithms use it; results are reproducible
    nlopt_opt opt = nlopt_create(algorithms[which], n);
    if (!opt) return luaL_error(L, "seixo.optimize: out of memory");
    o.opt = opt;
    nlopt_set_lower_bounds(opt, lo);
    nlopt_set_upper_bounds(opt, hi);
    nlopt_set_min_objective(opt, nlopt_objective, &o);
    nlopt_set_maxeval(opt, (int)maxeval);
    nlopt_set_xtol_rel(opt, xtol);
    nlopt_set_ftol_rel(opt, ftol);
    nlopt_set_stopval(opt, stopval);
    if (has_step) nlopt_set_initial_step(opt, step);
    double fmin = HUGE_VAL;
    const nlopt_result r = nlopt_optimize(opt, x, &fmin);
    nlopt_destroy(opt);
    if (o.error) {  // f failed: its error, unchanged
        lua_settop(L, o.error);
        return lua_error(L);
    }
    if (r < 0 && r != NLOPT_ROUNDOFF_LIMITED)
        return luaL_error(L, "seixo.optimize: NLopt failed (%s)", result_name(r));
    lua_createtable(L, (int)n, 0);
    for (unsigned i = 0; i < n; i++) {
        lua_pushnumber(L, x[i]);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_pushnumber(L, fmin);
    lua_createtable(L, 0, 2);
    lua_pushinteger(L, o.evaluations);
    lua_setfield(L, -2, "evaluations");
    lua_pushstring(L, result_name(r));
    lua_setfield(L, -2, "status");
    return 3;
}

const luaL_Reg sx_lua_optimize_functions[] = {
    {"optimize", seixo_optimize},
    {NULL, NULL},
};
