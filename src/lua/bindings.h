/* Private declarations shared by the binding files of the `seixo` Lua module.
 *
 * Objects: a model userdata owns one sx_model (model.c); balls and walls
 * are handles (util.c): an id, with the model userdata as their uservalue so
 * the model outlives them. No core pointer is ever given to Lua.
 *
 * Vectors are Lua arrays of `n` numbers, n the model's dimension; a
 * rotational quantity of a 2D model (spin, moment) has one component and is
 * a plain number, so the vector helpers treat n == 1 as a number. */
#pragma once

#include <lauxlib.h>
#include <lua.h>
#include <stdbool.h>
#include <stdint.h>

#include "seixo.h"

/// Components of a rotational vector (spin, moment): 3 in 3D, 1 (about z) in 2D.
static inline int sx_lua_rdim(int dim) { return dim == 3 ? 3 : 1; }

/* ---------------------------------------------------------- model.c */

/// seixo.model{...}: the constructor.
int sx_lua_model_new(lua_State *L);
/// Creates the model class; leaves its methods table on the stack for the
/// other files to add their model methods to.
void sx_lua_model_register(lua_State *L);
/// The model of the model userdata at idx, or NULL if it has been closed.
sx_model *sx_lua_tomodel(lua_State *L, int idx);
/// Like sx_lua_tomodel, but a closed model is a Lua error.
sx_model *sx_lua_checkmodel(lua_State *L, int idx);

/* --------------------------------------------------- balls.c, walls.c */

/// Add the ball (wall) methods to the model methods table on the top of
/// the stack, and create the ball (wall) class.
void sx_lua_balls_register(lua_State *L);
void sx_lua_walls_register(lua_State *L);

/* ---------------------------------------------------------- bonds.c */

/// Adds m:bond, m:bond_count, m:cracks, m:crack_count, m:track_energy to the
/// model methods table on the top of the stack.
void sx_lua_bonds_register(lua_State *L);
/// Reads the material keys model, shear_modulus, poisson, modulus,
/// stiffness_ratio into d and the `bond` sub-table into bpm (*has_bpm).
void sx_lua_material_extras(lua_State *L, int arg, sx_material_def *d, bool *has_bpm, sx_bpm_def *bpm);

/* ----------------------------------------------------------- util.c */

/// Raises a Lua error with the model's message unless st is SX_OK.
void sx_lua_check(lua_State *L, const sx_model *m, sx_status st);

/// Index of s in the NULL-terminated list, or -1.
int sx_lua_find(const char *s, const char *const list[]);
/// Pushes "a, b, c" for a NULL-terminated list.
void sx_lua_pushlist(lua_State *L, const char *const list[]);
/// Argument `arg` must be a table whose keys are all in `keys`.
void sx_lua_checkkeys(lua_State *L, int arg, const char *const keys[]);

/// Reads the value at idx as n numbers into out; returns NULL, or pushes and
/// returns a message saying what is wrong.
const char *sx_lua_tovec(lua_State *L, int idx, int n, double *out);
/// Pushes n components of v (a number when n == 1).
void sx_lua_pushvec(lua_State *L, const double *v, int n);
/// A value assigned to the field `field` of an object: n numbers, or an error naming the field.
void sx_lua_checkvalue(lua_State *L, int idx, int n, double *out, const char *field);

/* Fields of the property table at `arg` (read raw; a bad value is an
 * argument error naming the field). The opt variants return false and leave
 * out untouched when the field is absent; the check variants require it. */
bool sx_lua_optvecfield(lua_State *L, int arg, const char *key, int n, double *out);
void sx_lua_checkvecfield(lua_State *L, int arg, const char *key, int n, double *out);
bool sx_lua_optnumfield(lua_State *L, int arg, const char *key, double *out);
double sx_lua_checknumfield(lua_State *L, int arg, const char *key);
/// A string field, or NULL when absent; valid while the table holds it.
const char *sx_lua_optstrfield(lua_State *L, int arg, const char *key);

/// Creates the class `tname` ("seixo.ball"): metamethods `meta`, and an
/// __index/__newindex pair that resolves `methods`, then the field `getters`
/// and `setters` (called directly with the stack object, key[, value]), and
/// errors on anything else naming `kind` ("ball") and the valid fields.
/// Leaves the methods table on the stack.
void sx_lua_newclass(lua_State *L, const char *tname, const char *kind, const luaL_Reg meta[],
                     const luaL_Reg methods[], const luaL_Reg getters[], const luaL_Reg setters[]);

/// An object kind reached through handles (model, id): balls, walls.
typedef struct sx_lua_kind {
    const char *tname;                          ///< its class, "seixo.ball"
    const char *name;                           ///< its name in messages, "ball"
    bool (*exists)(const sx_model *, int64_t);  ///< whether an id is live
} sx_lua_kind;

/// Pushes a handle for the object `id` of the model userdata at `model`.
void sx_lua_pushhandle(lua_State *L, int model, const sx_lua_kind *k, int64_t id);
/// The id of the handle at idx and its model; a closed model or a removed
/// object is a Lua error.
sx_model *sx_lua_checkhandle(lua_State *L, int idx, const sx_lua_kind *k, int64_t *id);
/// __tostring of a handle: "seixo.ball 7", with "(removed)" or "(model closed)".
int sx_lua_handle_tostring(lua_State *L, const sx_lua_kind *k);
/// __eq of handles: the same class, model and id.
int sx_lua_handle_eq(lua_State *L);

/// Pushes a generic-for iterator over a snapshot of the object ids of the
/// model userdata at `model`, stepped by `next` (see sx_lua_nexthandle).
void sx_lua_pushiterator(lua_State *L, int model, int64_t (*count)(const sx_model *),
                         int64_t (*id_at)(const sx_model *, int64_t), lua_CFunction next);
/// The body of an iterator's `next`: pushes the handle of the next id of the
/// snapshot that is still live, or nil at the end.
int sx_lua_nexthandle(lua_State *L, const sx_lua_kind *k);
