/* Ball displacements, PFC's ball displacement: m:reset_disp([filter])
 * records where the (selected) balls are; b.disp is then a ball's position
 * minus that reference, both unwrapped in periodic space (a ball that
 * crossed a face has moved on, not back by the cell). A ball added after the reset is measured from
 * where it was when the next cycle started. The references are a Lua table
 * of the model's state, id -> vector (ball ids are never reused), filled
 * at the start of each run once a reset has made it: nothing is kept, and
 * nothing costs, for a model that never asks. */
#include "bindings.h"

/* Records the position of ball id as its reference in the table at refs. */
static void record(lua_State *L, const sx_model *m, int refs, int64_t id)
{
    double x[3];
    sx_ball_get_unwrapped(m, id, x);
    sx_lua_pushvec(L, x, sx_model_dim(m));
    lua_rawseti(L, refs, (lua_Integer)id);
}

/* m:reset_disp([filter]) -> n */
static int model_reset_disp(lua_State *L)
{
    sx_lua_checkmodel_scattered(L, 1); /* the positions are shared, not gathered */
    sx_lua_filter f;
    if (!lua_isnoneornil(L, 2)) sx_lua_checkkeys(L, 2, sx_lua_filter_keys);
    sx_lua_filter_read(L, 1, 2, &f);
    int64_t n;
    const int64_t *ids = sx_lua_filter_ids(L, &f, &n);
    const sx_model *m = sx_lua_checkmodel_motion(L, 1);
    sx_lua_state(L, 1, "disp_ref");
    const int refs = lua_gettop(L);
    for (int64_t i = 0; i < n; i++) record(L, m, refs, ids[i]);
    lua_pushinteger(L, (lua_Integer)n);
    return 1;
}

void sx_lua_disp_fill(lua_State *L, int model)
{
    model = lua_absindex(L, model);
    lua_getiuservalue(L, model, 1);
    if (lua_getfield(L, -1, "disp_ref") == LUA_TTABLE) {
        sx_model *m = sx_lua_checkmodel_scattered(L, model); /* the ids are every rank's */
        const int refs = lua_gettop(L);
        for (int64_t i = 0; i < sx_ball_count(m); i++) {
            const int64_t id = sx_ball_id_at(m, i);
            if (lua_rawgeti(L, refs, (lua_Integer)id) == LUA_TNIL) {
                m = sx_lua_checkmodel_motion(L, model); /* a new ball's position: every rank finds it alike */
                record(L, m, refs, id);
            }
            lua_pop(L, 1);
        }
    }
    lua_pop(L, 2);
}

int sx_lua_ball_disp(lua_State *L, const sx_model *m, int64_t id)
{
    lua_getiuservalue(L, 1, 1);  // the handle's model
    lua_getiuservalue(L, -1, 1);  // its state
    if (lua_getfield(L, -1, "disp_ref") != LUA_TTABLE)
        return luaL_error(L, "ball field 'disp': no reference position yet; m:reset_disp() starts measuring displacements");
    const int dim = sx_model_dim(m);
    double x[3], r[3];
    sx_ball_get_unwrapped(m, id, x);
    if (lua_rawgeti(L, -1, (lua_Integer)id) == LUA_TNIL) {  // added since: measured from the next cycle on
        sx_lua_pushvec(L, (const double[3]){0, 0, 0}, dim);
        return 1;
    }
    sx_lua_tovec(L, -1, dim, r);
    for (int k = 0; k < dim; k++) x[k] -= r[k];
    sx_lua_pushvec(L, x, dim);
    return 1;
}

const luaL_Reg sx_lua_disp_methods[] = {
    {"reset_disp", model_reset_disp},
    {NULL, NULL},
};
