/* A snapshot's walls (/walls, one row per wall of every kind, format-2
 * cylinders and servos included) and its mesh walls' triangles
 * (/walls/mesh_<id>). */
#include "snapshot_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --------------------------------------------------------------- walls */

static const char *const wall_kind_names[] = {"plane", "line", "rect", "segment", "cylinder", "mesh"};
static const int wall_kind_values[] = {SX_WALL_PLANE,   SX_WALL_LINE,     SX_WALL_RECT,
                                       SX_WALL_SEGMENT, SX_WALL_CYLINDER, SX_WALL_MESH};
enum { WALL_KINDS = sizeof wall_kind_values / sizeof *wall_kind_values };

/* The walls' arrays, gathered from (or scattered to) the array of structs. */
typedef struct wall_cols {
    int64_t *id, *contacts;
    int *kind;
    int32_t *material;
    uint8_t *servo_on;
    double *point, *normal, *edge1, *edge2, *vel, *kn, *ks, *friction;
    double *u, *v, *len_u, *len_v, *seg_len, *force, *moment, *moved;
    double *radius, *height, *radial_vel, *load, *kn_sum;
    double *target, *area, *alpha, *max_speed;
    double *spin;
} wall_cols;

static bool wall_cols_alloc(wall_cols *c, int64_t n)
{
    memset(c, 0, sizeof *c);
    const size_t k = (size_t)(n > 0 ? n : 1);
    c->id = calloc(k, sizeof *c->id);
    c->contacts = calloc(k, sizeof *c->contacts);
    c->kind = calloc(k, sizeof *c->kind);
    c->servo_on = calloc(k, sizeof *c->servo_on);
    c->material = calloc(k, sizeof *c->material);
    double **vec[] = {&c->point, &c->normal, &c->edge1, &c->edge2, &c->vel, &c->u, &c->v, &c->force, &c->moment, &c->spin};
    double **sc[] = {&c->kn,     &c->ks,     &c->friction,   &c->len_u, &c->len_v,  &c->seg_len, &c->moved,
                     &c->radius, &c->height, &c->radial_vel, &c->load,  &c->kn_sum, &c->target,  &c->area,
                     &c->alpha,  &c->max_speed};
    bool ok = c->id && c->contacts && c->kind && c->servo_on && c->material;
    for (size_t i = 0; c->material && i < k; i++) c->material[i] = SX_WALL_NO_MATERIAL; /* a file from before them */
    for (size_t i = 0; i < sizeof vec / sizeof *vec; i++) ok &= (*vec[i] = calloc(3 * k, sizeof(double))) != NULL;
    for (size_t i = 0; i < sizeof sc / sizeof *sc; i++) ok &= (*sc[i] = calloc(k, sizeof(double))) != NULL;
    return ok;
}

static void wall_cols_free(wall_cols *c)
{
    void *p[] = {c->id,       c->contacts, c->kind,    c->servo_on,   c->point,  c->normal, c->edge1,  c->edge2,
                 c->vel,      c->kn,       c->ks,      c->friction,   c->u,      c->v,      c->len_u,  c->len_v,
                 c->seg_len,  c->force,    c->moment,  c->moved,      c->radius, c->height, c->radial_vel,
                 c->load,     c->kn_sum,   c->target,  c->area,       c->alpha,  c->max_speed, c->spin,
                 c->material};
    for (size_t i = 0; i < sizeof p / sizeof *p; i++) free(p[i]);
}

/* The fields of format 2: cylinders, and the servo with the inputs it read
 * in the last step (what sx_wall_load reports). */
static int wall_fields2(const sx_model *m, const wall_cols *c, field *f)
{
    const bool d3 = m->dim == 3; /* a 2D servo acts per unit thickness */
    int n = 0;
    f[n++] = F("radius", T_F64, c->radius, 1, "m");
    f[n++] = F("height", T_F64, c->height, 1, "m");
    f[n++] = F("radial_velocity", T_F64, c->radial_vel, 1, "m/s");
    f[n++] = F("normal_load", T_F64, c->load, 1, "N");
    f[n++] = F("normal_stiffness_sum", T_F64, c->kn_sum, 1, "N/m");
    f[n++] = F("contact_count", T_I64, c->contacts, 1, NULL);
    f[n++] = F("servo", T_U8, c->servo_on, 1, NULL);
    f[n++] = F("servo_target", T_F64, c->target, 1, d3 ? "Pa" : "N/m");
    f[n++] = F("servo_area", T_F64, c->area, 1, d3 ? "m^2" : "m");
    f[n++] = F("servo_alpha", T_F64, c->alpha, 1, "1");
    f[n++] = F("servo_max_speed", T_F64, c->max_speed, 1, "m/s");
    return n;
}

/* Meshes' spin (3D), optional: a file without meshes may lack it. */
static int wall_fields_mesh(const sx_model *m, const wall_cols *c, field *f)
{
    int n = 0;
    if (m->dim == 3) f[n++] = F("spin", T_F64, c->spin, 3, "rad/s");
    return n;
}

/* A wall's material (its index among /materials; -1: none, -2: rigid),
 * optional: a file from before wall materials has none. */
static int wall_fields_material(const wall_cols *c, field *f)
{
    int n = 0;
    f[n++] = F("material", T_I32, c->material, 1, NULL);
    return n;
}

/* The fields of format 1. Vectors of dim components (the moment: rdim); scalars one. */
static int wall_fields(const sx_model *m, const wall_cols *c, field *f)
{
    const int d = m->dim, r = m->rdim;
    int n = 0;
    f[n++] = F("point", T_F64, c->point, d, "m");
    f[n++] = F("normal", T_F64, c->normal, d, "1");
    f[n++] = F("edge1", T_F64, c->edge1, d, "m");
    f[n++] = F("edge2", T_F64, c->edge2, d, "m");
    f[n++] = F("velocity", T_F64, c->vel, d, "m/s");
    f[n++] = F("kn", T_F64, c->kn, 1, "N/m");
    f[n++] = F("ks", T_F64, c->ks, 1, "N/m");
    f[n++] = F("friction", T_F64, c->friction, 1, "1");
    f[n++] = F("frame_u", T_F64, c->u, d, "1");
    f[n++] = F("frame_v", T_F64, c->v, d, "1");
    f[n++] = F("length_u", T_F64, c->len_u, 1, "m");
    f[n++] = F("length_v", T_F64, c->len_v, 1, "m");
    f[n++] = F("segment_length", T_F64, c->seg_len, 1, "m");
    f[n++] = F("force", T_F64, c->force, d, "N");
    f[n++] = F("moment", T_F64, c->moment, r, "N m");
    f[n++] = F("moved", T_F64, c->moved, 1, "m");
    return n;
}

static void wall_copy(const sx_model *m, sx_wall *w, wall_cols *c, int64_t i, bool to_cols)
{
    const int d = m->dim, r = m->rdim;
#define V(arr, fld, k)                                                       \
    do {                                                                     \
        for (int j = 0; j < (k); j++) {                                      \
            if (to_cols) c->arr[i * (k) + j] = fld[j];                       \
            else fld[j] = c->arr[i * (k) + j];                               \
        }                                                                    \
    } while (0)
#define S(arr, fld)                              \
    do {                                         \
        if (to_cols) c->arr[i] = fld;            \
        else fld = c->arr[i];                    \
    } while (0)
    V(point, w->def.point, d);
    V(normal, w->def.normal, d);
    V(edge1, w->def.edge1, d);
    V(edge2, w->def.edge2, d);
    V(vel, w->def.vel, d);
    V(u, w->u, d);
    V(v, w->v, d);
    V(force, w->force, d);
    V(moment, w->moment, r);
    V(spin, w->def.spin, 3);
    S(kn, w->def.kn);
    S(ks, w->def.ks);
    S(friction, w->def.friction);
    S(len_u, w->len_u);
    S(len_v, w->len_v);
    S(seg_len, w->seg_len);
    S(moved, w->moved);
    S(id, w->id);
    S(radius, w->def.radius);
    S(height, w->def.height);
    S(radial_vel, w->def.radial_vel);
    S(load, w->load);
    S(kn_sum, w->kn_sum);
    S(contacts, w->contacts);
    S(target, w->servo.target);
    S(area, w->servo.area);
    S(alpha, w->servo.alpha);
    S(max_speed, w->servo.max_speed);
    S(material, w->def.material);
    if (to_cols) c->kind[i] = (int)w->def.kind, c->servo_on[i] = w->servo_on;
    else w->def.kind = (sx_wall_kind)c->kind[i], w->servo_on = c->servo_on[i] != 0;
#undef V
#undef S
}

/* A mesh wall's group /walls/mesh_<id>: its vertices in its own frame
 * (relative to the wall's point), its triangles and its orientation, from
 * which the vertices where they are follow (sx__mesh_pose). */
static void mesh_group_name(const sx_wall *w, char *name, size_t len)
{
    snprintf(name, len, "mesh_%lld", (long long)w->id);
}

static void save_mesh(sx_h5 *h, hid_t walls, const sx_wall *w)
{
    char name[64];
    mesh_group_name(w, name, sizeof name);
    hid_t g = sx_h5_group(h, walls, name);
    const sx_mesh *s = w->mesh;
    sx_h5_write(h, g, "body_vertices", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, s->body, s->nv, 3, "m");
    sx_h5_write(h, g, "triangles", H5T_NATIVE_INT32, H5T_STD_I32LE, s->tri, s->nt, 3, NULL);
    sx_h5_write(h, g, "orientation", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, s->q, 1, 4, "1");
    sx_h5_close(g);
}

static void load_mesh(sx_h5 *h, hid_t walls, sx_model *m, sx_wall *w)
{
    char name[64], where[96];
    mesh_group_name(w, name, sizeof name);
    snprintf(where, sizeof where, "/walls/%s", name);
    hid_t g = sx_h5_open_group(h, walls, name, true);
    if (g < 0) return;
    const int64_t nv = sx_h5_rows(h, g, where, "body_vertices", 3, true), nt = sx_h5_rows(h, g, where, "triangles", 3, true);
    if (!h->failed && (nv < 3 || nt < 1)) sx_h5_fail(h, "damaged: %s has %lld vertices and %lld triangles", where, (long long)nv, (long long)nt);
    if (!h->failed && !(w->mesh = sx__mesh_alloc(m, nv, nt))) sx_h5_fail(h, "out of memory");
    if (!h->failed) {
        sx_h5_read(h, g, where, "body_vertices", H5T_NATIVE_DOUBLE, w->mesh->body, nv, 3, true);
        sx_h5_read(h, g, where, "triangles", H5T_NATIVE_INT32, w->mesh->tri, nt, 3, true);
        sx_h5_read(h, g, where, "orientation", H5T_NATIVE_DOUBLE, w->mesh->q, 1, 4, true);
    }
    sx_h5_close(g);
}

void sx_io_save_walls(sx_h5 *h, hid_t f, const sx_model *m)
{
    hid_t g = sx_h5_group(h, f, "walls");
    const int64_t n = m->nwall;
    wall_cols c;
    hid_t mem = sx_h5_enum(H5T_NATIVE_INT, wall_kind_names, wall_kind_values, WALL_KINDS);
    hid_t file = sx_h5_enum(H5T_STD_U8LE, wall_kind_names, wall_kind_values, WALL_KINDS);
    if (!wall_cols_alloc(&c, n) || mem < 0 || file < 0) {
        sx_h5_fail(h, "out of memory");
    } else {
        for (int64_t i = 0; i < n; i++) wall_copy(m, &m->walls[i], &c, i, true);
        sx_h5_write(h, g, "id", H5T_NATIVE_INT64, H5T_STD_I64LE, c.id, n, 1, NULL);
        sx_h5_write(h, g, "kind", mem, file, c.kind, n, 1, NULL);
        field fl[MAX_FIELDS];
        sx_io_write_fields(h, g, fl, wall_fields(m, &c, fl), n);
        sx_io_write_fields(h, g, fl, wall_fields2(m, &c, fl), n);
        sx_io_write_fields(h, g, fl, wall_fields_mesh(m, &c, fl), n);
        sx_io_write_fields(h, g, fl, wall_fields_material(&c, fl), n);
        for (int64_t i = 0; i < n; i++)
            if (m->walls[i].mesh) save_mesh(h, g, &m->walls[i]);
    }
    wall_cols_free(&c);
    sx_h5_close(mem);
    sx_h5_close(file);
    sx_h5_close(g);
}

/* A format-1 file has no cylinder and no servo: its walls load with the
 * format-2 fields at zero (no servo). */
void sx_io_load_walls(sx_h5 *h, hid_t g, sx_model *m, int version)
{
    const int64_t n = m->nwall;
    wall_cols c;
    hid_t mem = sx_h5_enum(H5T_NATIVE_INT, wall_kind_names, wall_kind_values, WALL_KINDS);
    if (!wall_cols_alloc(&c, n) || mem < 0) {
        sx_h5_fail(h, "out of memory");
    } else {
        field fl[MAX_FIELDS];
        sx_h5_read(h, g, "/walls", "id", H5T_NATIVE_INT64, c.id, n, 1, true);
        sx_h5_read(h, g, "/walls", "kind", mem, c.kind, n, 1, true);
        if (sx_io_read_fields(h, g, "/walls", fl, wall_fields(m, &c, fl), n, true) &&
            sx_io_read_fields(h, g, "/walls", fl, wall_fields2(m, &c, fl), n, version >= 2) &&
            sx_io_read_fields(h, g, "/walls", fl, wall_fields_mesh(m, &c, fl), n, false) &&
            sx_io_read_fields(h, g, "/walls", fl, wall_fields_material(&c, fl), n, false))
            for (int64_t i = 0; i < n && !h->failed; i++) {
                wall_copy(m, &m->walls[i], &c, i, false);
                if (m->walls[i].def.kind == SX_WALL_MESH) load_mesh(h, g, m, &m->walls[i]);
            }
    }
    wall_cols_free(&c);
    sx_h5_close(mem);
}
