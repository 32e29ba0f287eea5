/* Regions of space, as generation, groups and bulk operations take them:
 *   {box = {min = {..}, max = {..}}}  or  {box = {{..}, {..}}}   2D and 3D
 *   {sphere = {center = {x, y, z}, radius = R}}                   3D
 *   {cylinder = {p1 = {..}, p2 = {..}, radius = R}}               3D, p1, p2 the end-face centres
 *   {disk = {center = {x, y}, radius = R}}                        2D
 *   {polygon = {{x, y}, {x, y}, {x, y}, ...}}                     2D, a simple polygon
 * A ball is inside when all of it is (generation), a centre when it is
 * (selection: containment with r = 0). */
#include <math.h>
#include <string.h>

#include "bindings.h"

static const char *const shape_names[] = {"box", "sphere", "cylinder", "disk", "polygon", NULL};
static const int shape_dim[] = {0, 3, 3, 2, 2};  // 0: either

static int region_error(lua_State *L, int arg, const char *key, const char *shape, const char *msg)
{
    return sx_lua_fielderror(L, arg, key, lua_pushfstring(L, "%s: %s", shape, msg));
}

/* A vector member `name` of the shape table at t. */
static void shape_vec(lua_State *L, int t, const char *name, int dim, double *out, int arg, const char *key,
                      const char *shape)
{
    lua_getfield(L, t, name);
    if (lua_isnil(L, -1)) region_error(L, arg, key, shape, lua_pushfstring(L, "'%s' is required", name));
    const char *err = sx_lua_tovec(L, -1, dim, out);
    if (err) region_error(L, arg, key, shape, lua_pushfstring(L, "'%s': %s", name, err));
    for (int k = 0; k < dim; k++)
        if (!isfinite(out[k])) region_error(L, arg, key, shape, lua_pushfstring(L, "'%s' must be finite", name));
    lua_pop(L, 1);
}

static double shape_radius(lua_State *L, int t, int arg, const char *key, const char *shape)
{
    double r;
    shape_vec(L, t, "radius", 1, &r, arg, key, shape);
    if (!(r > 0)) region_error(L, arg, key, shape, "'radius' must be > 0");
    return r;
}

/* The table at t must be a plain array: no key but 1..#t. */
static void check_array(lua_State *L, int t, int arg, const char *key, const char *shape)
{
    const lua_Unsigned n = lua_rawlen(L, t);
    lua_Unsigned keys = 0;
    lua_pushnil(L);
    while (lua_next(L, t)) {
        lua_pop(L, 1);
        keys++;
    }
    if (keys != n) region_error(L, arg, key, shape, "an array expected, with no other keys");
}

static void read_box(lua_State *L, int t, sx_lua_region *g, int arg, const char *key)
{
    static const char *const named[] = {"min", "max", NULL};
    const bool is_pair = lua_rawlen(L, t) > 0;
    if (is_pair) check_array(L, t, arg, key, "box");
    else sx_lua_checksubkeys(L, t, arg, key, named);
    if (is_pair) {
        if (lua_rawlen(L, t) != 2) region_error(L, arg, key, "box", "{min, max} expected");
        for (int side = 0; side < 2; side++) {
            lua_rawgeti(L, t, side + 1);
            const char *err = sx_lua_tovec(L, -1, g->dim, side ? g->hi : g->lo);
            if (err) region_error(L, arg, key, "box", lua_pushfstring(L, "%s: %s", side ? "max" : "min", err));
            lua_pop(L, 1);
        }
    } else {
        shape_vec(L, t, "min", g->dim, g->lo, arg, key, "box");
        shape_vec(L, t, "max", g->dim, g->hi, arg, key, "box");
    }
    g->volume = 1;
    for (int k = 0; k < g->dim; k++) {
        if (!(isfinite(g->lo[k]) && isfinite(g->hi[k]) && g->lo[k] < g->hi[k]))
            region_error(L, arg, key, "box", "max must exceed min in every component, both finite");
        g->volume *= g->hi[k] - g->lo[k];
    }
}

static void read_round(lua_State *L, int t, sx_lua_region *g, int arg, const char *key, const char *shape)
{
    static const char *const keys[] = {"center", "radius", NULL};
    sx_lua_checksubkeys(L, t, arg, key, keys);
    shape_vec(L, t, "center", g->dim, g->c, arg, key, shape);
    g->r = shape_radius(L, t, arg, key, shape);
    for (int k = 0; k < g->dim; k++) {
        g->lo[k] = g->c[k] - g->r;
        g->hi[k] = g->c[k] + g->r;
    }
    g->volume = g->dim == 3 ? 4.0 / 3.0 * SX_LUA_PI * g->r * g->r * g->r : SX_LUA_PI * g->r * g->r;
}

static void read_cylinder(lua_State *L, int t, sx_lua_region *g, int arg, const char *key)
{
    static const char *const keys[] = {"p1", "p2", "radius", NULL};
    sx_lua_checksubkeys(L, t, arg, key, keys);
    double p2[3];
    shape_vec(L, t, "p1", 3, g->c, arg, key, "cylinder");
    shape_vec(L, t, "p2", 3, p2, arg, key, "cylinder");
    g->r = shape_radius(L, t, arg, key, "cylinder");
    double len2 = 0;
    for (int k = 0; k < 3; k++) {
        g->axis[k] = p2[k] - g->c[k];
        len2 += g->axis[k] * g->axis[k];
    }
    g->len = sqrt(len2);
    if (!(g->len > 0 && isfinite(g->len))) region_error(L, arg, key, "cylinder", "p1 and p2 must differ");
    for (int k = 0; k < 3; k++) g->axis[k] /= g->len;
    /* bounding box: the end disks' extent along each axis is r sqrt(1 - a_k^2) */
    for (int k = 0; k < 3; k++) {
        const double e = g->r * sqrt(fmax(0, 1 - g->axis[k] * g->axis[k]));
        g->lo[k] = fmin(g->c[k], p2[k]) - e;
        g->hi[k] = fmax(g->c[k], p2[k]) + e;
    }
    g->volume = SX_LUA_PI * g->r * g->r * g->len;
}

static void read_polygon(lua_State *L, int t, sx_lua_region *g, int arg, const char *key)
{
    const lua_Unsigned n = lua_rawlen(L, t);
    if (n < 3 || n > 1000000) region_error(L, arg, key, "polygon", "an array of 3 to 1e6 vertices {x, y} expected");
    check_array(L, t, arg, key, "polygon");
    double *v = lua_newuserdatauv(L, 2 * n * sizeof *v, 0);
    const int keep = lua_gettop(L);
    for (lua_Unsigned i = 0; i < n; i++) {
        lua_rawgeti(L, t, (lua_Integer)i + 1);
        const char *err = sx_lua_tovec(L, -1, 2, v + 2 * i);
        if (err) region_error(L, arg, key, "polygon", lua_pushfstring(L, "vertex %I: %s", (lua_Integer)i + 1, err));
        if (!isfinite(v[2 * i]) || !isfinite(v[2 * i + 1]))
            region_error(L, arg, key, "polygon", lua_pushfstring(L, "vertex %I must be finite", (lua_Integer)i + 1));
        lua_pop(L, 1);
    }
    double area = 0;
    g->lo[0] = g->hi[0] = v[0];
    g->lo[1] = g->hi[1] = v[1];
    for (lua_Unsigned i = 0; i < n; i++) {
        const double *a = v + 2 * i, *b = v + 2 * ((i + 1) % n);
        area += a[0] * b[1] - b[0] * a[1];
        for (int k = 0; k < 2; k++) {
            g->lo[k] = fmin(g->lo[k], a[k]);
            g->hi[k] = fmax(g->hi[k], a[k]);
        }
    }
    g->volume = fabs(area) / 2;
    if (!(g->volume > 0)) region_error(L, arg, key, "polygon", "its area is zero");
    g->poly = v;
    g->n = (int)n;
    lua_settop(L, keep);
}

void sx_lua_region_read(lua_State *L, int idx, int dim, int arg, const char *key, sx_lua_region *g)
{
    idx = lua_absindex(L, idx);
    memset(g, 0, sizeof *g);
    g->dim = dim;
    if (!lua_istable(L, idx))
        sx_lua_fielderror(L, arg, key, lua_pushfstring(L, "region table expected ({box = ...}, ...), got %s",
                                                       luaL_typename(L, idx)));
    sx_lua_checksubkeys(L, idx, arg, key, shape_names);
    int kind = -1;
    for (int k = 0; shape_names[k]; k++) {
        lua_getfield(L, idx, shape_names[k]);
        const bool here = !lua_isnil(L, -1);
        lua_pop(L, 1);
        if (!here) continue;
        if (kind >= 0) sx_lua_fielderror(L, arg, key, "one shape expected (box, sphere, cylinder, disk or polygon)");
        kind = k;
    }
    if (kind < 0) sx_lua_fielderror(L, arg, key, "a shape is required: box, sphere, cylinder (3D), disk, polygon (2D)");
    if (shape_dim[kind] && shape_dim[kind] != dim)
        sx_lua_fielderror(L, arg, key,
                          lua_pushfstring(L, "a %s is a %dD region; a %dD model takes %s", shape_names[kind],
                                          shape_dim[kind], dim, dim == 3 ? "box, sphere, cylinder" : "box, disk, polygon"));
    g->kind = kind;
    lua_getfield(L, idx, shape_names[kind]);
    const int t = lua_gettop(L);
    if (!lua_istable(L, t))
        sx_lua_fielderror(L, arg, key, lua_pushfstring(L, "%s: table expected, got %s", shape_names[kind], luaL_typename(L, t)));
    switch (kind) {
    case SX_REGION_BOX: read_box(L, t, g, arg, key); break;
    case SX_REGION_SPHERE:
    case SX_REGION_DISK: read_round(L, t, g, arg, key, shape_names[kind]); break;
    case SX_REGION_CYLINDER: read_cylinder(L, t, g, arg, key); break;
    case SX_REGION_POLYGON: read_polygon(L, t, g, arg, key); break;
    }
    if (!(g->volume > 0 && isfinite(g->volume))) sx_lua_fielderror(L, arg, key, "the region's size must be finite and > 0");
    /* keep the polygon's vertices (on the top) and drop the shape table */
    if (kind == SX_REGION_POLYGON) lua_remove(L, t);
    else lua_settop(L, t - 1);
}

/* Squared distance from p to the segment ab (2D). */
static double seg_dist2(const double *p, const double *a, const double *b)
{
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    const double l2 = ex * ex + ey * ey;
    double s = l2 > 0 ? ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / l2 : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    const double dx = p[0] - a[0] - s * ex, dy = p[1] - a[1] - s * ey;
    return dx * dx + dy * dy;
}

static bool in_polygon(const sx_lua_region *g, const double *x, double r)
{
    bool inside = false;
    for (int i = 0, j = g->n - 1; i < g->n; j = i++) {
        const double *a = g->poly + 2 * i, *b = g->poly + 2 * j;
        if ((a[1] > x[1]) != (b[1] > x[1]) && x[0] < (b[0] - a[0]) * (x[1] - a[1]) / (b[1] - a[1]) + a[0])
            inside = !inside;
    }
    if (!inside) return false;
    for (int i = 0, j = g->n - 1; r > 0 && i < g->n; j = i++)
        if (seg_dist2(x, g->poly + 2 * i, g->poly + 2 * j) < r * r) return false;
    return true;
}

bool sx_lua_region_contains(const sx_lua_region *g, const double *x, double r)
{
    switch (g->kind) {
    case SX_REGION_BOX:
        for (int k = 0; k < g->dim; k++)
            if (!(x[k] - r >= g->lo[k] && x[k] + r <= g->hi[k])) return false;
        return true;
    case SX_REGION_SPHERE:
    case SX_REGION_DISK: {
        double d2 = 0;
        for (int k = 0; k < g->dim; k++) d2 += (x[k] - g->c[k]) * (x[k] - g->c[k]);
        return r <= g->r && d2 <= (g->r - r) * (g->r - r);
    }
    case SX_REGION_CYLINDER: {
        double d[3], t = 0;
        for (int k = 0; k < 3; k++) {
            d[k] = x[k] - g->c[k];
            t += d[k] * g->axis[k];
        }
        if (!(t >= r && t <= g->len - r) || r > g->r) return false;
        double q2 = 0;
        for (int k = 0; k < 3; k++) q2 += (d[k] - t * g->axis[k]) * (d[k] - t * g->axis[k]);
        return q2 <= (g->r - r) * (g->r - r);
    }
    case SX_REGION_POLYGON: return in_polygon(g, x, r);
    }
    return false;
}
