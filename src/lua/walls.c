/* Walls: m:wall{kind = ...} adds a plane or rect (3D), a line or segment
 * (2D), or a box: the planes (lines) of an axis-aligned box, facing inward.
 * m:walls() iterates. A wall object is a handle (model, id) like a ball:
 * its fields read and write the core's state (its point, velocity,
 * stiffnesses and friction are writable; its orientation and extent are
 * fixed when it is made), and `extra` holds user values, as a ball's. */
#include "bindings.h"
#include "seixo_io.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const kind_names[] = {"plane", "line", "rect", "segment", "cylinder", "mesh", "box", NULL};
enum { KIND_BOX = 6 };
_Static_assert(SX_WALL_PLANE == 0 && SX_WALL_LINE == 1 && SX_WALL_RECT == 2 && SX_WALL_SEGMENT == 3 &&
                   SX_WALL_CYLINDER == 4 && SX_WALL_MESH == 5,
               "kind_names is indexed by sx_wall_kind");

static const char *const plane_keys[] = {"kind", "point", "normal", "kn", "ks", "friction", "vel", "material", "rigid",
                                         NULL};
static const char *const cylinder_keys[] = {"kind", "point", "axis", "radius", "height", "radial_vel", "kn",
                                            "ks",   "friction", "vel", "material", "rigid", NULL};
static const char *const rect_keys[] = {"kind", "corner", "point", "edge1", "edge2", "kn", "ks", "friction", "vel",
                                        "material", "rigid", NULL};
static const char *const segment_keys[] = {"kind", "p1", "p2", "kn", "ks", "friction", "vel", "material", "rigid", NULL};
static const char *const mesh_keys[] = {"kind", "file",   "triangles", "vertices", "point", "vel", "spin",
                                        "kn",   "ks",     "friction",  "repair",   "material", "rigid", "scale", NULL};
static const char *const box_keys[] = {"kind", "min", "max", "kn", "ks", "friction", "material", "rigid", NULL};

/* What a wall kind needs: its dimension, its counterpart in the other
 * dimension (for the error message) and its valid keys. */
static const struct shape {
    int dim;
    const char *other;
    const char *const *keys;
} shapes[] = {
    [SX_WALL_PLANE] = {3, "'line'", plane_keys},
    [SX_WALL_LINE] = {2, "'plane'", plane_keys},
    [SX_WALL_RECT] = {3, "'segment'", rect_keys},
    [SX_WALL_SEGMENT] = {2, "'rect'", segment_keys},
    [SX_WALL_CYLINDER] = {3, "two 'line' walls (a kind 'cylinder' has none)", cylinder_keys},
    [SX_WALL_MESH] = {3, "'segment' walls (a kind 'mesh' has none)", mesh_keys},
};

static const char *const wall_shown[] = {"kind", "point", "normal", "vel", "force", NULL};
const sx_lua_kind sx_lua_wall_kind = {"seixo.wall", "wall", sx_wall_exists, "wall_extras", wall_shown, true};
#define wall_kind sx_lua_wall_kind

/* The wall of the handle at index 1: live, in an open model. */
static sx_model *check_wall(lua_State *L, int64_t *id) { return sx_lua_checkhandle(L, 1, &wall_kind, id); }

/* ------------------------------------------------------------- fields */

static const sx_model *wall_def(lua_State *L, sx_wall_def *d)
{
    int64_t id;
    const sx_model *m = check_wall(L, &id);
    sx_lua_checkfield(L, m, sx_wall_get(m, id, d), "wall");
    return m;
}

/* A vector or number field of the definition, by its offset in sx_wall_def. */
static int push_def_vec(lua_State *L, size_t offset)
{
    sx_wall_def d;
    const sx_model *m = wall_def(L, &d);
    sx_lua_pushvec(L, (const double *)((const char *)&d + offset), sx_model_dim(m));
    return 1;
}

/* A vector of the definition that only some kinds have (a bit of 1 << kind
 * in `kinds`): nil for the others, whose slot holds no such thing (a
 * cylinder keeps its axis where a plane keeps its normal). */
static int push_kind_vec(lua_State *L, size_t offset, unsigned kinds)
{
    sx_wall_def d;
    const sx_model *m = wall_def(L, &d);
    if (!(kinds & 1u << d.kind)) return lua_pushnil(L), 1;
    sx_lua_pushvec(L, (const double *)((const char *)&d + offset), sx_model_dim(m));
    return 1;
}

#define FLAT_KINDS (1u << SX_WALL_PLANE | 1u << SX_WALL_LINE | 1u << SX_WALL_RECT | 1u << SX_WALL_SEGMENT)
static int get_point(lua_State *L) { return push_def_vec(L, offsetof(sx_wall_def, point)); }
static int get_normal(lua_State *L) { return push_kind_vec(L, offsetof(sx_wall_def, normal), FLAT_KINDS); }
static int get_axis(lua_State *L) { return push_kind_vec(L, offsetof(sx_wall_def, normal), 1u << SX_WALL_CYLINDER); }
static int get_edge1(lua_State *L)
{
    return push_kind_vec(L, offsetof(sx_wall_def, edge1), 1u << SX_WALL_RECT | 1u << SX_WALL_SEGMENT);
}
static int get_edge2(lua_State *L) { return push_kind_vec(L, offsetof(sx_wall_def, edge2), 1u << SX_WALL_RECT); }
static int get_vel(lua_State *L) { return push_def_vec(L, offsetof(sx_wall_def, vel)); }
/* a 2D wall never turns: its spin, a 2D rotation, a plain 0 */
static int get_spin(lua_State *L)
{
    sx_wall_def d;
    const sx_model *m = wall_def(L, &d);
    if (sx_model_dim(m) == 2) return lua_pushnumber(L, 0), 1;
    return push_def_vec(L, offsetof(sx_wall_def, spin));
}
/* A stiffness or the friction as the contacts use it: the wall's own, its
 * material's, or a rigid wall's infinite stiffness (and its own friction). */
static int push_spring(lua_State *L, size_t wall_offset, size_t material_offset)
{
    sx_wall_def d;
    const sx_model *m = wall_def(L, &d);
    if (d.material == SX_WALL_RIGID && wall_offset != offsetof(sx_wall_def, friction)) {
        lua_pushnumber(L, HUGE_VAL);
    } else if (d.material >= 0) {
        sx_material_def md;
        sx_lua_checkfield(L, m, sx_material_get(m, d.material, &md), "wall");
        lua_pushnumber(L, *(const double *)((const char *)&md + material_offset));
    } else {
        lua_pushnumber(L, *(const double *)((const char *)&d + wall_offset));
    }
    return 1;
}

static int get_kn(lua_State *L) { return push_spring(L, offsetof(sx_wall_def, kn), offsetof(sx_material_def, kn)); }
static int get_ks(lua_State *L) { return push_spring(L, offsetof(sx_wall_def, ks), offsetof(sx_material_def, ks)); }
static int get_friction(lua_State *L)
{
    return push_spring(L, offsetof(sx_wall_def, friction), offsetof(sx_material_def, friction));
}

/* The wall's material by name (nil: none) and its rigidity. */
static int get_material(lua_State *L)
{
    sx_wall_def d;
    const sx_model *m = wall_def(L, &d);
    if (d.material >= 0) lua_pushstring(L, sx_material_name(m, d.material));
    else lua_pushnil(L);
    return 1;
}

static int get_rigid(lua_State *L)
{
    sx_wall_def d;
    wall_def(L, &d);
    lua_pushboolean(L, d.material == SX_WALL_RIGID);
    return 1;
}

static int get_kind(lua_State *L)
{
    sx_wall_def d;
    wall_def(L, &d);
    lua_pushstring(L, kind_names[d.kind]);
    return 1;
}

static int get_id(lua_State *L)
{
    int64_t id;
    check_wall(L, &id);
    lua_pushinteger(L, (lua_Integer)id);
    return 1;
}

/* The resultant of the last step: its force (which = 0) or moment (1). */
static int push_resultant(lua_State *L, int which)
{
    int64_t id;
    const sx_model *m = check_wall(L, &id);
    double fm[2][3];
    sx_lua_checkfield(L, m, sx_wall_force(m, id, fm[0], fm[1]), "wall");
    const int dim = sx_model_dim(m);
    sx_lua_pushvec(L, fm[which], which ? sx_lua_rdim(dim) : dim);
    return 1;
}

static int get_force(lua_State *L) { return push_resultant(L, 0); }
static int get_moment(lua_State *L) { return push_resultant(L, 1); }

static int set_vel(lua_State *L)
{
    int64_t id;
    sx_model *m = check_wall(L, &id);
    double v[3] = {0, 0, 0};
    sx_lua_checkvalue(L, 3, sx_model_dim(m), v, "wall", "vel");
    sx_lua_checkfield(L, m, sx_wall_set_vel(m, id, v), "wall");
    return 0;
}

static int set_spin(lua_State *L)
{
    int64_t id;
    sx_model *m = check_wall(L, &id);
    if (sx_model_dim(m) == 2) return luaL_error(L, "wall field 'spin': a 2D wall does not turn (only a 3D mesh wall spins)");
    double v[3] = {0, 0, 0};
    sx_lua_checkvalue(L, 3, 3, v, "wall", "spin");
    sx_lua_checkfield(L, m, sx_wall_set_spin(m, id, v), "wall");
    return 0;
}

/* A mesh's vertex (which = 0) or facet (1) count. */
static int push_mesh_count(lua_State *L, int which)
{
    int64_t id, n[2];
    const sx_model *m = check_wall(L, &id);
    sx_lua_checkfield(L, m, sx_wall_mesh_size(m, id, &n[0], &n[1]), "wall");
    lua_pushinteger(L, (lua_Integer)n[which]);
    return 1;
}

/* A mesh's vertices where they are now ({x, y, z} each), or its
 * triangles (three 1-based vertex numbers each). */
static int push_mesh(lua_State *L, bool triangles)
{
    int64_t id, n[2];
    const sx_model *m = check_wall(L, &id);
    sx_lua_checkfield(L, m, sx_wall_mesh_size(m, id, &n[0], &n[1]), "wall");
    double *x = lua_newuserdatauv(L, (size_t)n[0] * 3 * sizeof *x, 0);
    int32_t *t = lua_newuserdatauv(L, (size_t)n[1] * 3 * sizeof *t, 0);
    sx_lua_checkfield(L, m, sx_wall_mesh_get(m, id, x, t), "wall");
    const int64_t count = triangles ? n[1] : n[0];
    lua_createtable(L, (int)count, 0);
    for (int64_t e = 0; e < count; e++) {
        if (triangles) {
            lua_createtable(L, 3, 0);
            for (int j = 0; j < 3; j++) {
                lua_pushinteger(L, t[3 * e + j] + 1);
                lua_rawseti(L, -2, j + 1);
            }
        } else {
            sx_lua_pushvec(L, x + 3 * e, 3);
        }
        lua_rawseti(L, -2, e + 1);
    }
    return 1;
}

static int get_vertices(lua_State *L) { return push_mesh(L, false); }
static int get_triangles(lua_State *L) { return push_mesh(L, true); }

static int get_vertex_count(lua_State *L) { return push_mesh_count(L, 0); }
static int get_facet_count(lua_State *L) { return push_mesh_count(L, 1); }

static int set_point(lua_State *L)
{
    int64_t id;
    sx_model *m = check_wall(L, &id);
    double p[3] = {0, 0, 0};
    sx_lua_checkvalue(L, 3, sx_model_dim(m), p, "wall", "point");
    sx_lua_checkfield(L, m, sx_wall_set_point(m, id, p), "wall");
    return 0;
}

static int set_scalar(lua_State *L, sx_wall_scalar which)
{
    int64_t id;
    sx_model *m = check_wall(L, &id);
    double v;
    sx_lua_checkvalue(L, 3, 1, &v, "wall", lua_tostring(L, 2));
    sx_lua_checkfield(L, m, sx_wall_set(m, id, which, v), "wall");
    return 0;
}

/* w.material = name | nil, w.rigid = true | false. */
static int set_material(lua_State *L)
{
    int64_t id;
    sx_model *m = check_wall(L, &id);
    int k = SX_WALL_NO_MATERIAL;
    if (!lua_isnil(L, 3)) {
        const char *name = lua_tostring(L, 3);
        if (!lua_isstring(L, 3) || (k = sx_material_find(m, name)) < 0)
            return luaL_error(L, "wall field 'material': %s is not a material of the model (m:material defines one)",
                              luaL_tolstring(L, 3, NULL));
    }
    sx_lua_checkfield(L, m, sx_wall_set_material(m, id, k), "wall");
    return 0;
}

static int set_rigid(lua_State *L)
{
    int64_t id;
    sx_model *m = check_wall(L, &id);
    if (!lua_isboolean(L, 3))
        return luaL_error(L, "wall field 'rigid': true or false expected, got %s", luaL_typename(L, 3));
    sx_wall_def d;
    sx_lua_checkfield(L, m, sx_wall_get(m, id, &d), "wall");
    if (lua_toboolean(L, 3) && d.material >= 0)
        return luaL_error(L, "wall field 'rigid': the wall is of material '%s'; a wall is either rigid or of a "
                             "material, not both (w.material = nil first)", sx_material_name(m, d.material));
    if (lua_toboolean(L, 3)) d.material = SX_WALL_RIGID;
    else if (d.material == SX_WALL_RIGID) d.material = SX_WALL_NO_MATERIAL;
    sx_lua_checkfield(L, m, sx_wall_set_material(m, id, d.material), "wall");
    return 0;
}

static int set_kn(lua_State *L) { return set_scalar(L, SX_WALL_KN); }
static int set_ks(lua_State *L) { return set_scalar(L, SX_WALL_KS); }
static int set_friction(lua_State *L) { return set_scalar(L, SX_WALL_FRICTION); }

static int get_extra(lua_State *L) { return sx_lua_extra_table(L, &wall_kind); }
static int set_extra_table(lua_State *L) { return sx_lua_set_extra_table(L, &wall_kind); }
static int wall_set_extra(lua_State *L) { return sx_lua_set_extra(L, &wall_kind); }
static int wall_get_extra(lua_State *L) { return sx_lua_get_extra(L, &wall_kind); }

/* ------------------------------------------------- methods, metamethods */

static int wall_remove(lua_State *L)
{
    int64_t id;
    check_wall(L, &id);
    lua_getiuservalue(L, 1, 1);
    sx_lua_remove_wall(L, -1, id, "w:remove");
    return 0;
}

static int wall_tostring(lua_State *L) { return sx_lua_handle_tostring(L, &wall_kind); }

/* ------------------------------------------------------- model methods */

/* The keys every kind shares (the box has no velocity): the wall's
 * springs and friction, or a material of the model (which gives them), or
 * rigid = true (no springs; friction kept). */
static void read_common(lua_State *L, sx_model *m, int dim, sx_wall_def *d)
{
    const bool own = sx_lua_optnumfield(L, 2, "kn", &d->kn) | sx_lua_optnumfield(L, 2, "ks", &d->ks);
    const bool friction = sx_lua_optnumfield(L, 2, "friction", &d->friction);
    sx_lua_optvecfield(L, 2, "vel", dim, d->vel);
    bool rigid = false;
    if (lua_getfield(L, 2, "rigid") != LUA_TNIL) {
        if (!lua_isboolean(L, -1)) luaL_argerror(L, 2, "field 'rigid': true or false expected");
        rigid = lua_toboolean(L, -1);
    }
    lua_pop(L, 1);
    if (rigid) d->material = SX_WALL_RIGID;
    if (lua_getfield(L, 2, "material") != LUA_TNIL) {
        const char *name = lua_isstring(L, -1) ? lua_tostring(L, -1) : NULL;
        d->material = name ? sx_material_find(m, name) : -1;
        if (d->material < 0)
            luaL_argerror(L, 2, lua_pushfstring(L, "field 'material': %s is not a material of the model "
                                                   "(m:material defines one)", luaL_tolstring(L, -1, NULL)));
        if (own || friction)
            luaL_argerror(L, 2, "a wall of a material takes kn, ks and friction from it: give the material or them");
        if (rigid) luaL_argerror(L, 2, "a wall is either rigid or of a material, not both");
    }
    lua_pop(L, 1);
    if (rigid && own) luaL_argerror(L, 2, "a rigid wall has no kn or ks of its own (its friction stays)");
}

/* A rect's corner, given as `corner` or as `point` like the other kinds. */
static void read_corner(lua_State *L, double *corner)
{
    const bool named_corner = sx_lua_optvecfield(L, 2, "corner", 3, corner);
    const bool named_point = sx_lua_optvecfield(L, 2, "point", 3, corner);
    if (named_corner && named_point) luaL_argerror(L, 2, "give the rect's 'corner' or 'point', not both");
    if (!named_corner && !named_point) luaL_argerror(L, 2, "field 'corner' (or 'point') is required");
}

/* The triangles of a mesh wall as a soup (nine doubles per triangle) or as
 * vertices with 0-based indices, from `file` (STL), `triangles` (a list of
 * three corners each) or `vertices` with `triangles` (a list of three
 * 1-based vertex numbers each). Arrays on the Lua stack as userdata. */

/* A triangle soup of n triangles (malloc'd, 9 numbers each) copied into a
 * userdata: lua_pcall'd, as the allocation may raise. */
static int soup_to_userdata(lua_State *L)
{
    const double *soup = lua_touserdata(L, 1);
    const size_t bytes = (size_t)lua_tointeger(L, 2) * 9 * sizeof *soup;
    memcpy(lua_newuserdatauv(L, bytes, 0), soup, bytes);
    return 1;
}

static void read_mesh(lua_State *L, sx_mesh_def *md)
{
    const bool file = lua_getfield(L, 2, "file") != LUA_TNIL;
    lua_pop(L, 1);
    const bool tris = lua_getfield(L, 2, "triangles") == LUA_TTABLE;
    const bool verts = lua_getfield(L, 2, "vertices") == LUA_TTABLE;
    if (file == tris) luaL_argerror(L, 2, "a mesh needs 'file' (an STL file) or 'triangles', one of them");
    if (verts && !tris) luaL_argerror(L, 2, "field 'vertices' goes with 'triangles' (three vertex numbers each)");
    int64_t nv, nt;
    double *x;
    if (file) {
        const char *path = sx_lua_optstrfield(L, 2, "file");
        if (!path) luaL_argerror(L, 2, "field 'file' must be a file name");
        char err[512];
        double *soup;
        const bool failed = sx_io_read_stl(sx_lua_rank_file(L, path), &soup, &nt, err, sizeof err);
        lua_pop(L, 1);
        if (failed) luaL_error(L, "m:wall: %s", err);
        /* the copy into Lua's memory may raise (out of memory): protected,
         * so that the soup is freed on either path */
        lua_pushcfunction(L, soup_to_userdata);
        lua_pushlightuserdata(L, soup);
        lua_pushinteger(L, nt);
        const int status = lua_pcall(L, 2, 1, 0);
        free(soup);
        if (status != LUA_OK) lua_error(L);
        x = lua_touserdata(L, -1);
        nv = 3 * nt;
    } else {
        nt = (int64_t)luaL_len(L, -2);
        nv = verts ? (int64_t)luaL_len(L, -1) : 3 * nt;
        x = lua_newuserdatauv(L, (size_t)(nv > 0 ? nv : 1) * 3 * sizeof *x, 0);
        for (int64_t t = 0; t < nt; t++) {
            if (lua_geti(L, -3, t + 1) != LUA_TTABLE || luaL_len(L, -1) != 3)
                luaL_error(L, "m:wall: field 'triangles': entry %d must be a list of three %s", (int)t + 1,
                           verts ? "vertex numbers" : "corners {x, y, z}");
            for (int j = 0; j < 3 && !verts; j++) {
                lua_geti(L, -1, j + 1);
                const char *why = sx_lua_tovec(L, -1, 3, x + 9 * t + 3 * j);
                if (why) luaL_error(L, "m:wall: field 'triangles': triangle %d, corner %d: %s", (int)t + 1, j + 1, why);
                lua_pop(L, 1);
            }
            lua_pop(L, 1);
        }
        for (int64_t v = 0; v < nv && verts; v++) {
            lua_geti(L, -2, v + 1);
            const char *why = sx_lua_tovec(L, -1, 3, x + 3 * v);
            if (why) luaL_error(L, "m:wall: field 'vertices': vertex %d: %s", (int)v + 1, why);
            lua_pop(L, 1);
        }
    }
    int32_t *ix = lua_newuserdatauv(L, (size_t)(nt > 0 ? nt : 1) * 3 * sizeof *ix, 0);
    for (int64_t t = 0; t < nt; t++)
        for (int j = 0; j < 3; j++) {
            if (!verts) {
                ix[3 * t + j] = (int32_t)(3 * t + j);
                continue;
            }
            lua_geti(L, -4, t + 1);
            lua_geti(L, -1, j + 1);
            int ok;
            const lua_Integer k = lua_tointegerx(L, -1, &ok);
            if (!ok || k < 1 || k > nv)
                luaL_error(L, "m:wall: field 'triangles': triangle %d, corner %d must be a vertex number from 1 to %d",
                           (int)t + 1, j + 1, (int)nv);
            ix[3 * t + j] = (int32_t)(k - 1);
            lua_pop(L, 2);
        }
    /* a CAD file in mm, say: scale = 0.001 */
    double scale = 1, lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (sx_lua_optnumfield(L, 2, "scale", &scale) && !(scale > 0 && isfinite(scale)))
        luaL_argerror(L, 2, "field 'scale' must be a positive number: the factor to m of the coordinates (0.001 for mm)");
    for (int64_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) {
            x[3 * v + k] *= scale;
            if (!isfinite(x[3 * v + k]) && file)
                luaL_error(L, "m:wall: '%s': facet %d, corner %d is not a finite number", sx_lua_optstrfield(L, 2, "file"),
                           (int)(v / 3) + 1, (int)(v % 3) + 1);
            lo[k] = fmin(lo[k], x[3 * v + k]), hi[k] = fmax(hi[k], x[3 * v + k]);
        }
    const double extent = nv > 0 ? fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2])) : 0;
    sx_lua_check_range(L, 1, "mesh size", extent, 1e-4, 50, "m"); /* a file in mm: scale = 0.001 */
    md->vertices = x, md->nv = nv;
    md->triangles = ix, md->nt = nt;
    lua_getfield(L, 2, "repair");
    md->repair = lua_toboolean(L, -1);
    lua_pop(L, 1);
}

/* A mesh wall; what a repair changed is said on stderr. */
static int add_mesh(lua_State *L, sx_model *m, sx_wall_def *d)
{
    sx_mesh_def md;
    read_mesh(L, &md);
    sx_lua_optvecfield(L, 2, "point", 3, d->point);
    sx_lua_optvecfield(L, 2, "spin", 3, d->spin);
    int64_t id;
    sx_mesh_report rep;
    sx_lua_check(L, m, sx_wall_add_mesh(m, d, &md, &id, &rep), "m:wall");
    const bool says = sx_lua_parallel_says(m);
    if (says && rep.dropped)
        fprintf(stderr, "seixo: warning: mesh wall %lld: %lld degenerate triangle(s) dropped (the first: triangle %lld)\n",
                (long long)id, (long long)rep.dropped, (long long)rep.first_dropped + 1);
    if (says && rep.flipped)
        fprintf(stderr,
                "seixo: warning: mesh wall %lld: %lld triangle(s) turned round to wind as their neighbours (the first: "
                "triangle %lld)\n",
                (long long)id, (long long)rep.flipped, (long long)rep.first_flipped + 1);
    sx_lua_pushhandle(L, 1, &wall_kind, id);
    return 1;
}

static int add_wall(lua_State *L, sx_model *m, sx_wall_kind kind)
{
    const int dim = sx_model_dim(m);
    const struct shape *s = &shapes[kind];
    if (s->dim != dim)
        return luaL_argerror(L, 2, lua_pushfstring(L, "field 'kind': a %s is a %dD wall; use %s in a %dD model",
                                                   kind_names[kind], s->dim, s->other, dim));
    sx_lua_checkkeys(L, 2, s->keys);
    sx_wall_def d = sx_wall_default_def(dim);
    d.kind = kind;
    read_common(L, m, dim, &d);
    switch (kind) {
    case SX_WALL_MESH:
        return add_mesh(L, m, &d);
    case SX_WALL_PLANE:
    case SX_WALL_LINE:
        sx_lua_checkvecfield(L, 2, "point", dim, d.point);
        sx_lua_checkvecfield(L, 2, "normal", dim, d.normal);
        break;
    case SX_WALL_RECT:
        read_corner(L, d.point);
        sx_lua_checkvecfield(L, 2, "edge1", dim, d.edge1);
        sx_lua_checkvecfield(L, 2, "edge2", dim, d.edge2);
        break;
    case SX_WALL_SEGMENT: {
        double p2[3] = {0, 0, 0};
        sx_lua_checkvecfield(L, 2, "p1", dim, d.point);
        sx_lua_checkvecfield(L, 2, "p2", dim, p2);
        for (int c = 0; c < dim; c++) d.edge1[c] = p2[c] - d.point[c];
        break;
    }
    case SX_WALL_CYLINDER: /* balls inside; point on the axis, height along it (0: infinite) */
        sx_lua_checkvecfield(L, 2, "point", dim, d.point);
        sx_lua_checkvecfield(L, 2, "axis", dim, d.normal);
        d.radius = sx_lua_checknumfield(L, 2, "radius");
        sx_lua_optnumfield(L, 2, "height", &d.height);
        sx_lua_optnumfield(L, 2, "radial_vel", &d.radial_vel);
        break;
    }
    int64_t id;
    sx_lua_check(L, m, sx_wall_add(m, &d, &id), "m:wall");
    sx_lua_pushhandle(L, 1, &wall_kind, id);
    return 1;
}

/* A box is added whole or not at all: on a failure, remove the walls
 * already added, then raise the core's message. */
static int undo_box(lua_State *L, sx_model *m, const int64_t *ids, int n)
{
    lua_pushstring(L, sx_model_error(m));
    for (int i = 0; i < n; i++) sx_wall_remove(m, ids[i]);
    return luaL_error(L, "m:wall: %s", sx_lua_core_message(lua_tostring(L, -1)));
}

/* The walls of the box [min, max]: for each axis, the lower then the
 * upper side, each facing inward. */
static int add_box(lua_State *L, sx_model *m)
{
    const int dim = sx_model_dim(m);
    sx_lua_checkkeys(L, 2, box_keys);
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    sx_lua_checkvecfield(L, 2, "min", dim, lo);
    sx_lua_checkvecfield(L, 2, "max", dim, hi);
    for (int c = 0; c < dim; c++) luaL_argcheck(L, lo[c] < hi[c], 2, "field 'max': each component must exceed min's");
    sx_wall_def d = sx_wall_default_def(dim);
    read_common(L, m, dim, &d);
    int64_t ids[6];
    int n = 0;
    lua_createtable(L, 2 * dim, 0);
    for (int axis = 0; axis < dim; axis++)
        for (int side = 0; side < 2; side++) {
            memcpy(d.point, side ? hi : lo, sizeof d.point);
            memset(d.normal, 0, sizeof d.normal);
            d.normal[axis] = side ? -1 : 1;
            if (sx_wall_add(m, &d, &ids[n]) != SX_OK) return undo_box(L, m, ids, n);
            sx_lua_pushhandle(L, 1, &wall_kind, ids[n]);
            lua_rawseti(L, -2, ++n);
        }
    return 1;
}

static int model_wall(lua_State *L)
{
    if (lua_type(L, 2) == LUA_TNUMBER) { /* m:wall(id): a lookup, as m:ball(id) */
        const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* the walls every rank holds */
        const int64_t id = (int64_t)luaL_checkinteger(L, 2);
        if (!sx_wall_exists(m, id)) return 0;
        sx_lua_pushhandle(L, 1, &wall_kind, id);
        return 1;
    }
    sx_model *m = sx_lua_checkmodel(L, 1);
    if (lua_type(L, 2) != LUA_TTABLE) return luaL_typeerror(L, 2, "table or integer");
    sx_lua_modelud(L, 1)->unchecked = true;  // a wall placed over balls is named after the next step
    const char *name = sx_lua_optstrfield(L, 2, "kind");
    if (!name) return luaL_argerror(L, 2, "field 'kind' is required");
    const int kind = sx_lua_find(name, kind_names);
    if (kind < 0) {
        sx_lua_pushlist(L, kind_names);
        return luaL_argerror(L, 2, lua_pushfstring(L, "field 'kind': unknown kind '%s' (valid: %s)", name,
                                                   lua_tostring(L, -1)));
    }
    return kind == KIND_BOX ? add_box(L, m) : add_wall(L, m, (sx_wall_kind)kind);
}

static int next_wall(lua_State *L) { return sx_lua_nexthandle(L, &wall_kind); }

static int model_walls(lua_State *L)
{
    sx_lua_pushiterator(L, 1, sx_wall_count, sx_wall_id_at, next_wall);
    return 1;
}

static int model_wall_count(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_wall_count(sx_lua_checkmodel_scattered(L, 1)));
    return 1;
}

const luaL_Reg sx_lua_walls_methods[] = {
    {"wall", model_wall},
    {"walls", model_walls},
    {"wall_count", model_wall_count},
    {NULL, NULL},
};

void sx_lua_walls_register(lua_State *L)
{
    static const luaL_Reg meta[] = {
        {"__tostring", wall_tostring},
        {"__eq", sx_lua_handle_eq},
        {NULL, NULL},
    };
    static const luaL_Reg wall_methods[] = {
        {"remove", wall_remove},
        {"set_extra", wall_set_extra},
        {"get_extra", wall_get_extra},
        {NULL, NULL},
    };
    static const luaL_Reg getters[] = {
        {"id", get_id},
        {"kind", get_kind},
        {"force", get_force},
        {"moment", get_moment},
        {"vel", get_vel},
        {"point", get_point},
        {"normal", get_normal},
        {"axis", get_axis},
        {"edge1", get_edge1},
        {"edge2", get_edge2},
        {"spin", get_spin},
        {"vertex_count", get_vertex_count},
        {"vertices", get_vertices},
        {"triangles", get_triangles},
        {"facet_count", get_facet_count},
        {"kn", get_kn},
        {"ks", get_ks},
        {"friction", get_friction},
        {"material", get_material},
        {"rigid", get_rigid},
        {"extra", get_extra},
        {NULL, NULL},
    };
    static const luaL_Reg setters[] = {
        {"vel", set_vel},
        {"spin", set_spin},
        {"point", set_point},
        {"kn", set_kn},
        {"ks", set_ks},
        {"friction", set_friction},
        {"material", set_material},
        {"rigid", set_rigid},
        {"extra", set_extra_table},
        {NULL, NULL},
    };
    sx_lua_newclass(L, wall_kind.tname, wall_kind.name, meta, wall_methods, getters, setters);
    lua_pop(L, 1);
}
