/* Clumps: m:clump_template(name, pebbles | path[, {lines =}]) defines a
 * template (or returns one's properties), m:clump{...} adds a clump,
 * m:clump(id) finds one, m:clumps() iterates, m:clump_templates() lists the
 * templates. A clump object is a handle (model, id) like a ball; its
 * pebbles are balls (b.clump gives a pebble's clump). Random generation of
 * clumps is m:generate{template = ..., scale = ...} (generate.c).
 *
 * Orientations: 3D a unit quaternion {w, x, y, z} (normalised on input) or
 * {axis = {x, y, z}, angle = a}; 2D an angle about z (rad). They turn the
 * template frame into space; positions are those of the centroid. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bindings.h"

static const char *const clump_shown[] = {"pos", "mass", "vel", "template", NULL};
const sx_lua_kind sx_lua_clump_kind = {"seixo.clump", "clump", sx_clump_exists, NULL, clump_shown, false}; /* no user extras */
#define clump_kind sx_lua_clump_kind

static sx_model *check_clump(lua_State *L, int64_t *id) { return sx_lua_checkhandle(L, 1, &clump_kind, id); }

/* --------------------------------------------------------- orientations */

static void push_orientation(lua_State *L, int dim, const double q[4])
{
    if (dim == 2) {
        lua_pushnumber(L, 2 * atan2(q[3], q[0]));
        return;
    }
    lua_createtable(L, 4, 0);
    for (int k = 0; k < 4; k++) {
        lua_pushnumber(L, q[k]);
        lua_rawseti(L, -2, k + 1);
    }
}

/* An orientation at idx as a quaternion; NULL, or a message pushed. */
static const char *to_orientation(lua_State *L, int idx, int dim, double q[4])
{
    idx = lua_absindex(L, idx);
    if (dim == 2) {
        if (lua_type(L, idx) != LUA_TNUMBER) return lua_pushfstring(L, "an angle (rad) expected, got %s", luaL_typename(L, idx));
        const double a = lua_tonumber(L, idx);
        if (!isfinite(a)) return lua_pushliteral(L, "the angle must be finite");
        q[0] = cos(0.5 * a), q[1] = q[2] = 0, q[3] = sin(0.5 * a);
        return NULL;
    }
    if (!lua_istable(L, idx))
        return lua_pushfstring(L, "a quaternion {w, x, y, z} or {axis =, angle =} expected, got %s", luaL_typename(L, idx));
    lua_pushliteral(L, "axis");
    const int has_axis = lua_rawget(L, idx) != LUA_TNIL;
    lua_pop(L, 1);
    if (has_axis) {
        static const char *const keys[] = {"axis", "angle", NULL};
        lua_pushnil(L);
        while (lua_next(L, idx)) {
            lua_pop(L, 1);
            if (lua_type(L, -1) != LUA_TSTRING || sx_lua_find(lua_tostring(L, -1), keys) < 0) {
                lua_pop(L, 1);
                return lua_pushliteral(L, "an axis-angle orientation takes only 'axis' and 'angle'");
            }
        }
        double ax[3];
        lua_pushliteral(L, "axis");
        lua_rawget(L, idx);
        const char *bad = sx_lua_tovec(L, -1, 3, ax);
        if (bad) return lua_pushfstring(L, "'axis': %s", bad);
        lua_pop(L, 1);
        lua_pushliteral(L, "angle");
        lua_rawget(L, idx);
        if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(lua_tonumber(L, -1))) return lua_pushliteral(L, "'angle' must be a finite number (rad)");
        const double a = lua_tonumber(L, -1);
        lua_pop(L, 1);
        const double n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
        if (!(n > 0) || !isfinite(n)) return lua_pushliteral(L, "'axis' must be a finite nonzero vector");
        q[0] = cos(0.5 * a);
        for (int k = 0; k < 3; k++) q[k + 1] = sin(0.5 * a) * ax[k] / n;
        return NULL;
    }
    const char *bad = sx_lua_tovec(L, idx, 4, q);
    if (bad) return lua_pushfstring(L, "quaternion {w, x, y, z}: %s", bad);
    return NULL;
}

/* ------------------------------------------------------------ templates */

/* Reads the pebbles of the table at idx: {x, y[, z], r} or {pos =, radius =} each. */
static int64_t read_pebbles(lua_State *L, int idx, int dim, double **pos, double **rad)
{
    const lua_Unsigned n = lua_rawlen(L, idx);
    if (n < 1 || n > 1000000) luaL_argerror(L, 3, "1 to 1000000 pebbles expected");
    double *buf = lua_newuserdatauv(L, (size_t)n * (size_t)(dim + 1) * sizeof(double), 0);
    *pos = buf;
    *rad = buf + n * (lua_Unsigned)dim;
    for (lua_Unsigned i = 1; i <= n; i++) {
        lua_rawgeti(L, idx, (lua_Integer)i);
        const int p = lua_gettop(L);
        if (!lua_istable(L, p))
            luaL_argerror(L, 3, lua_pushfstring(L, "pebble %I: a table {x, y%s, r} or {pos =, radius =} expected, got %s",
                                                (lua_Integer)i, dim == 3 ? ", z" : "", luaL_typename(L, p)));
        double v[4];
        lua_pushliteral(L, "pos");
        const bool named = lua_rawget(L, p) != LUA_TNIL;
        lua_pop(L, 1);
        if (named) {
            static const char *const keys[] = {"pos", "radius", NULL};
            sx_lua_checksubkeys(L, p, 3, "pebbles", keys);
            sx_lua_checkvecfield(L, p, "pos", dim, v);
            v[dim] = sx_lua_checknumfield(L, p, "radius");
        } else {
            /* (the length checked here: sx_lua_tovec's message would name a
             * 3D model for a 2D pebble's three numbers) */
            const lua_Unsigned len = lua_rawlen(L, p);
            const char *bad = len != (lua_Unsigned)dim + 1
                                  ? lua_pushfstring(L, "%d numbers expected in a %dD model, got %I", dim + 1, dim,
                                                    (lua_Integer)len)
                                  : sx_lua_tovec(L, p, dim + 1, v);
            if (bad)
                luaL_argerror(L, 3, lua_pushfstring(L, "pebble %I: {x, y%s, r}: %s", (lua_Integer)i, dim == 3 ? ", z" : "", bad));
        }
        for (int k = 0; k < dim; k++) (*pos)[(i - 1) * (lua_Unsigned)dim + (lua_Unsigned)k] = v[k];
        (*rad)[i - 1] = v[dim];
        lua_settop(L, p - 1);
    }
    return (int64_t)n;
}

/* Reads a file of spheres: one per line, "x y [z] r" (separated by blanks
 * or commas), '#' starting a comment. Pushes the storage. */
static int64_t read_sphere_file(lua_State *L, const char *path, int dim, double **pos, double **rad)
{
    FILE *f = fopen(sx_lua_rank_file(L, path), "r"); /* the script's own file, maybe */
    lua_pop(L, 1);
    if (!f) luaL_error(L, "clump_template: cannot open '%s': %s", path, strerror(errno));
    luaL_Buffer b;
    luaL_buffinit(L, &b); /* the numbers, as doubles, grown in the buffer */
    char line[4096];
    int64_t n = 0, lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        if (!strchr(line, '\n') && !feof(f)) { /* a line fgets would split, its numbers read as two lines' */
            fclose(f);
            return luaL_error(L, "clump_template: %s:%I: a line longer than %d characters", path, (lua_Integer)lineno,
                              (int)sizeof line - 2);
        }
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        for (char *c = line; *c; c++)
            if (*c == ',') *c = ' ';
        double v[4];
        int k = 0;
        char *s = line, *end;
        for (;;) {
            while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n') s++;
            if (!*s) break;
            const double x = strtod(s, &end);
            if (end == s || k == dim + 1 || !isfinite(x)) {
                fclose(f);
                return luaL_error(L, "clump_template: %s:%I: %d numbers (x, y%s, r) expected", path, (lua_Integer)lineno,
                                  dim + 1, dim == 3 ? ", z" : "");
            }
            v[k++] = x;
            s = end;
        }
        if (k == 0) continue;
        if (k != dim + 1) {
            fclose(f);
            return luaL_error(L, "clump_template: %s:%I: %d numbers (x, y%s, r) expected, found %d", path,
                              (lua_Integer)lineno, dim + 1, dim == 3 ? ", z" : "", k);
        }
        if (n >= 1000000) {
            fclose(f);
            return luaL_error(L, "clump_template: %s: more than 1000000 spheres", path);
        }
        luaL_addlstring(&b, (const char *)v, (size_t)(dim + 1) * sizeof(double));
        n++;
    }
    const bool failed = ferror(f);
    fclose(f);
    if (failed) return luaL_error(L, "clump_template: cannot read '%s'", path);
    if (n == 0) return luaL_error(L, "clump_template: '%s' lists no sphere", path);
    luaL_pushresult(&b);
    const double *v = (const double *)lua_tostring(L, -1);
    double *buf = lua_newuserdatauv(L, (size_t)n * (size_t)(dim + 1) * sizeof(double), 0);
    *pos = buf;
    *rad = buf + n * dim;
    for (int64_t i = 0; i < n; i++) {
        double row[4];
        memcpy(row, v + i * (dim + 1), (size_t)(dim + 1) * sizeof(double)); /* the string may be unaligned */
        for (int k = 0; k < dim; k++) (*pos)[i * dim + k] = row[k];
        (*rad)[i] = row[dim];
    }
    return n;
}

/* Pushes a vector of n numbers from a 3-array. */
static void push_numbers(lua_State *L, const double *v, int n)
{
    lua_createtable(L, n, 0);
    for (int k = 0; k < n; k++) {
        lua_pushnumber(L, v[k]);
        lua_rawseti(L, -2, k + 1);
    }
}

/* Pushes a 3x3 matrix as rows. */
static void push_matrix(lua_State *L, const double a[3][3])
{
    lua_createtable(L, 3, 0);
    for (int i = 0; i < 3; i++) {
        push_numbers(L, a[i], 3);
        lua_rawseti(L, -2, i + 1);
    }
}

/* Pushes the properties of template t. */
static void push_template(lua_State *L, const sx_model *m, int t)
{
    const int dim = sx_model_dim(m);
    sx_clump_props p;
    sx_lua_check(L, m, sx_clump_template_props(m, t, &p), "m:clump_templates");
    lua_createtable(L, 0, 9);
    lua_pushstring(L, sx_clump_template_name(m, t));
    lua_setfield(L, -2, "name");
    lua_createtable(L, (int)p.count, 0);
    for (int64_t k = 0; k < p.count; k++) {
        double x[4], r; /* the centre, then the radius */
        sx_lua_check(L, m, sx_clump_template_pebble(m, t, k, x, &r), "m:clump_templates");
        x[dim] = r;
        push_numbers(L, x, dim + 1);
        lua_rawseti(L, -2, (lua_Integer)k + 1);
    }
    lua_setfield(L, -2, "pebbles");
    lua_pushnumber(L, p.volume);
    lua_setfield(L, -2, "volume");
    push_numbers(L, p.centroid, dim);
    lua_setfield(L, -2, "centroid");
    if (dim == 3) {
        push_matrix(L, p.inertia);
        lua_setfield(L, -2, "inertia");
        push_numbers(L, p.principal, 3);
        lua_setfield(L, -2, "principal");
        push_matrix(L, p.axes);
        lua_setfield(L, -2, "axes");
    } else {
        lua_pushnumber(L, p.inertia[2][2]);
        lua_setfield(L, -2, "inertia");
        lua_pushnumber(L, p.principal[0]);
        lua_setfield(L, -2, "principal");
    }
    lua_pushboolean(L, p.overlapping);
    lua_setfield(L, -2, "overlapping");
    lua_pushnumber(L, p.error);
    lua_setfield(L, -2, "error");
}

/* m:clump_template(name, pebbles | path[, {lines = N}]) -> info;  m:clump_template(name) -> info | nil */
static int model_clump_template(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* a lookup reads the templates every rank holds */
    const char *name = sx_lua_checkname(L, 2);
    const int dim = sx_model_dim(m);
    if (lua_isnoneornil(L, 3)) {
        const int t = sx_clump_template_find(m, name);
        if (t < 0) return 0;
        push_template(L, m, t);
        return 1;
    }
    m = sx_lua_checkmodel(L, 1);
    int64_t lines = 0;
    if (!lua_isnoneornil(L, 4)) {
        static const char *const keys[] = {"lines", NULL};
        sx_lua_checkkeys(L, 4, keys);
        sx_lua_optintfield(L, 4, "lines", 0, 1 << 20, &lines);
    }
    double *pos = NULL, *rad = NULL;
    int64_t n;
    if (lua_type(L, 3) == LUA_TSTRING) n = read_sphere_file(L, sx_lua_checkname(L, 3), dim, &pos, &rad);
    else if (lua_istable(L, 3)) n = read_pebbles(L, 3, dim, &pos, &rad);
    else return luaL_typeerror(L, 3, "table of pebbles or file name");
    const sx_clump_template_def def = {pos, rad, n, lines};
    int t;
    sx_lua_check(L, m, sx_clump_template_add(m, name, &def, &t), "m:clump_template");
    push_template(L, m, t);
    return 1;
}

/* m:clump_templates() -> {name = info, ...} */
static int model_clump_templates(lua_State *L)
{
    const sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* what every rank holds alike: no gather */
    const int n = sx_clump_template_count(m);
    lua_createtable(L, 0, n);
    for (int t = 0; t < n; t++) {
        push_template(L, m, t);
        lua_setfield(L, -2, sx_clump_template_name(m, t));
    }
    return 1;
}

/* The template named by field `key` of the table at arg (an argument error otherwise). */
int sx_lua_template_arg(lua_State *L, const sx_model *m, int arg, const char *key)
{
    const char *name = sx_lua_optstrfield(L, arg, key);
    if (!name) return sx_lua_fielderror(L, arg, key, "is required: the name of a clump template");
    const int t = sx_clump_template_find(m, name);
    if (t < 0)
        sx_lua_fielderror(L, arg, key, lua_pushfstring(L, "no clump template named '%s' (define it with m:clump_template)", name));
    return t;
}

/* ------------------------------------------------------------- fields */

static int get_vec(lua_State *L, sx_clump_vec which)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    double v[3];
    sx_lua_checkfield(L, m, sx_clump_get_vec(m, id, which, v), "clump");
    const bool rot = which == SX_CLUMP_SPIN || which == SX_CLUMP_MOMENT || which == SX_CLUMP_ANGULAR_MOMENTUM;
    sx_lua_pushvec(L, v, rot ? sx_lua_rdim(sx_model_dim(m)) : sx_model_dim(m));
    return 1;
}

static int set_vec(lua_State *L, sx_clump_vec which)
{
    int64_t id;
    sx_model *m = check_clump(L, &id);
    double v[3] = {0, 0, 0};
    const int n = which == SX_CLUMP_SPIN ? sx_lua_rdim(sx_model_dim(m)) : sx_model_dim(m);
    sx_lua_checkvalue(L, 3, n, v, "clump", lua_tostring(L, 2));
    sx_lua_checkfield(L, m, sx_clump_set_vec(m, id, which, v), "clump");
    return 0;
}

static int get_scalar(lua_State *L, sx_clump_scalar which)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    double v;
    sx_lua_checkfield(L, m, sx_clump_get(m, id, which, &v), "clump");
    lua_pushnumber(L, v);
    return 1;
}

static int get_pos(lua_State *L) { return get_vec(L, SX_CLUMP_POS); }
static int get_vel(lua_State *L) { return get_vec(L, SX_CLUMP_VEL); }
static int get_spin(lua_State *L) { return get_vec(L, SX_CLUMP_SPIN); }
static int get_force(lua_State *L) { return get_vec(L, SX_CLUMP_FORCE); }
static int get_moment(lua_State *L) { return get_vec(L, SX_CLUMP_MOMENT); }
static int get_angular_momentum(lua_State *L) { return get_vec(L, SX_CLUMP_ANGULAR_MOMENTUM); }
static int set_pos(lua_State *L) { return set_vec(L, SX_CLUMP_POS); }
static int set_vel(lua_State *L) { return set_vec(L, SX_CLUMP_VEL); }
static int set_spin(lua_State *L) { return set_vec(L, SX_CLUMP_SPIN); }
static int get_mass(lua_State *L) { return get_scalar(L, SX_CLUMP_MASS); }
static int get_volume(lua_State *L) { return get_scalar(L, SX_CLUMP_VOLUME); }
static int get_scale(lua_State *L) { return get_scalar(L, SX_CLUMP_SCALE); }
static int get_damping(lua_State *L) { return get_scalar(L, SX_CLUMP_DAMPING); }

static int set_damping(lua_State *L)
{
    int64_t id;
    sx_model *m = check_clump(L, &id);
    double v;
    sx_lua_checkvalue(L, 3, 1, &v, "clump", "damping");
    sx_lua_checkfield(L, m, sx_clump_set(m, id, SX_CLUMP_DAMPING, v), "clump");
    return 0;
}

static int get_id(lua_State *L)
{
    int64_t id;
    check_clump(L, &id);
    lua_pushinteger(L, (lua_Integer)id);
    return 1;
}

static int get_orientation(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    double q[4];
    sx_lua_checkfield(L, m, sx_clump_orientation(m, id, q), "clump");
    push_orientation(L, sx_model_dim(m), q);
    return 1;
}

static int set_orientation(lua_State *L)
{
    int64_t id;
    sx_model *m = check_clump(L, &id);
    double q[4];
    const char *bad = to_orientation(L, 3, sx_model_dim(m), q);
    if (bad) return luaL_error(L, "clump field 'orientation': %s", bad);
    sx_lua_checkfield(L, m, sx_clump_set_orientation(m, id, q), "clump");
    return 0;
}

static int get_inertia(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    double I[3][3];
    sx_lua_checkfield(L, m, sx_clump_inertia(m, id, NULL, I), "clump");
    if (sx_model_dim(m) == 2) lua_pushnumber(L, I[2][2]);
    else push_matrix(L, I);
    return 1;
}

static int get_principal(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    double p[3];
    sx_lua_checkfield(L, m, sx_clump_inertia(m, id, p, NULL), "clump");
    if (sx_model_dim(m) == 2) lua_pushnumber(L, p[0]);
    else push_numbers(L, p, 3);
    return 1;
}

static int get_pebbles(lua_State *L)
{
    int64_t id, n;
    const sx_model *m = check_clump(L, &id);
    sx_lua_checkfield(L, m, sx_clump_pebbles(m, id, NULL, 0, &n), "clump");
    int64_t *ids = lua_newuserdatauv(L, (size_t)n * sizeof *ids, 0);
    sx_lua_checkfield(L, m, sx_clump_pebbles(m, id, ids, n, &n), "clump");
    lua_getiuservalue(L, 1, 1);
    const int model = lua_gettop(L);
    lua_createtable(L, (int)n, 0);
    for (int64_t k = 0; k < n; k++) {
        sx_lua_pushhandle(L, model, &sx_lua_ball_kind, ids[k]);
        lua_rawseti(L, -2, (lua_Integer)k + 1);
    }
    return 1;
}

static int get_template(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    int t;
    sx_lua_checkfield(L, m, sx_clump_template_of(m, id, &t), "clump");
    lua_pushstring(L, sx_clump_template_name(m, t));
    return 1;
}

static int get_material(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    int mat;
    sx_lua_checkfield(L, m, sx_clump_material(m, id, &mat), "clump");
    lua_pushstring(L, sx_material_name(m, mat));
    return 1;
}

static int set_material(lua_State *L)
{
    int64_t id;
    sx_model *m = check_clump(L, &id);
    if (lua_type(L, 3) != LUA_TSTRING)
        return luaL_error(L, "field 'material': material name expected, got %s", luaL_typename(L, 3));
    const int mat = sx_material_find(m, lua_tostring(L, 3));
    if (mat < 0) return luaL_error(L, "field 'material': no material named '%s'", lua_tostring(L, 3));
    sx_lua_checkfield(L, m, sx_clump_set_material(m, id, mat), "clump");
    return 0;
}

static int get_fix(lua_State *L)
{
    int64_t id;
    const sx_model *m = check_clump(L, &id);
    unsigned mask;
    sx_lua_checkfield(L, m, sx_clump_fixity(m, id, &mask), "clump");
    sx_lua_pushfixmask(L, mask);
    return 1;
}

static int set_fix(lua_State *L)
{
    int64_t id;
    sx_model *m = check_clump(L, &id);
    sx_lua_checkfield(L, m, sx_clump_set_fixity(m, id, sx_lua_fixmask(L, sx_model_dim(m), 3, "clump field 'fix'")), "clump");
    return 0;
}

/* ------------------------------------------------- methods, metamethods */

static int clump_remove(lua_State *L)
{
    int64_t id;
    sx_model *m = check_clump(L, &id);
    lua_getiuservalue(L, 1, 1);
    if (sx_lua_modelud(L, -1)->callback > 0)
        return luaL_error(L, "clump:remove: clumps cannot be removed inside a callback; remove them after the cycle");
    sx_lua_check(L, m, sx_clump_remove(m, id), "c:remove");
    return 0;
}

static int clump_tostring(lua_State *L) { return sx_lua_handle_tostring(L, &clump_kind); }

/* ------------------------------------------------------- model methods */

static int add_clump(lua_State *L, sx_model *m)
{
    static const char *const keys[] = {"template", "pos", "orientation", "scale", "vel", "spin", "material", "group", NULL};
    const int dim = sx_model_dim(m);
    sx_lua_checkkeys(L, 2, keys);
    sx_clump_def d = sx_clump_default_def();
    d.template_index = sx_lua_template_arg(L, m, 2, "template");
    sx_lua_checkvecfield(L, 2, "pos", dim, d.pos);
    lua_pushliteral(L, "orientation");
    if (lua_rawget(L, 2) != LUA_TNIL) {
        const char *bad = to_orientation(L, -1, dim, d.orientation);
        if (bad) sx_lua_fielderror(L, 2, "orientation", bad);
    }
    lua_pop(L, 1);
    sx_lua_optnumfield(L, 2, "scale", &d.scale);
    sx_lua_optvecfield(L, 2, "vel", dim, d.vel);
    sx_lua_optvecfield(L, 2, "spin", sx_lua_rdim(dim), d.spin);
    d.material = sx_lua_material_arg(L, m, 2, "material", sx_lua_optstrfield(L, 2, "material"));
    const char *group = sx_lua_optstrfield(L, 2, "group");
    const int32_t g = group ? sx_lua_group_id(L, 1, group, true) : 0;
    int64_t id;
    sx_lua_check(L, m, sx_clump_add(m, &d, &id), "m:clump");
    if (g) sx_lua_clump_set_group(L, m, id, g);
    sx_lua_pushhandle(L, 1, &clump_kind, id);
    return 1;
}

void sx_lua_clump_set_group(lua_State *L, sx_model *m, int64_t id, int32_t group)
{
    int64_t n;
    sx_lua_check(L, m, sx_clump_pebbles(m, id, NULL, 0, &n), "m:group");
    int64_t *ids = lua_newuserdatauv(L, (size_t)n * sizeof *ids, 0);
    sx_lua_check(L, m, sx_clump_pebbles(m, id, ids, n, &n), "m:group");
    for (int64_t k = 0; k < n; k++) sx_lua_check(L, m, sx_ball_set_group(m, ids[k], group), "m:group");
    lua_pop(L, 1);
}

/* m:clump{...} adds a clump; m:clump(id) returns the clump with that id, or nil. */
static int model_clump(lua_State *L)
{
    sx_model *m = sx_lua_checkmodel_scattered(L, 1); /* a lookup reads the ids every rank holds */
    if (lua_type(L, 2) == LUA_TTABLE) return add_clump(L, sx_lua_checkmodel(L, 1));
    if (lua_type(L, 2) != LUA_TNUMBER) return luaL_typeerror(L, 2, "table or integer");
    const int64_t id = (int64_t)luaL_checkinteger(L, 2);
    if (!sx_clump_exists(m, id)) return 0;
    sx_lua_pushhandle(L, 1, &clump_kind, id);
    return 1;
}

static int next_clump(lua_State *L) { return sx_lua_nexthandle(L, &clump_kind); }

static int model_clumps(lua_State *L)
{
    sx_lua_checkmodel_scattered(L, 1); /* the ids every rank holds (a read of a clump's state gathers) */
    sx_lua_pushiterator(L, 1, sx_clump_count, sx_clump_id_at, next_clump);
    return 1;
}

static int model_clump_count(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)sx_clump_count(sx_lua_checkmodel_scattered(L, 1)));
    return 1;
}

const luaL_Reg sx_lua_clumps_methods[] = {
    {"clump_template", model_clump_template},
    {"clump_templates", model_clump_templates},
    {"clump", model_clump},
    {"clumps", model_clumps},
    {"clump_count", model_clump_count},
    {NULL, NULL},
};

void sx_lua_clumps_register(lua_State *L)
{
    static const luaL_Reg meta[] = {
        {"__tostring", clump_tostring},
        {"__eq", sx_lua_handle_eq},
        {NULL, NULL},
    };
    static const luaL_Reg methods[] = {
        {"remove", clump_remove},
        {NULL, NULL},
    };
    static const luaL_Reg getters[] = {
        {"id", get_id},
        {"pos", get_pos},
        {"vel", get_vel},
        {"spin", get_spin},
        {"orientation", get_orientation},
        {"force", get_force},
        {"moment", get_moment},
        {"angular_momentum", get_angular_momentum},
        {"mass", get_mass},
        {"volume", get_volume},
        {"inertia", get_inertia},
        {"principal", get_principal},
        {"scale", get_scale},
        {"template", get_template},
        {"material", get_material},
        {"damping", get_damping},
        {"fix", get_fix},
        {"pebbles", get_pebbles},
        {NULL, NULL},
    };
    static const luaL_Reg setters[] = {
        {"pos", set_pos},
        {"vel", set_vel},
        {"spin", set_spin},
        {"orientation", set_orientation},
        {"material", set_material},
        {"damping", set_damping},
        {"fix", set_fix},
        {NULL, NULL},
    };
    sx_lua_newclass(L, clump_kind.tname, clump_kind.name, meta, methods, getters, setters);
    lua_pop(L, 1);
}
