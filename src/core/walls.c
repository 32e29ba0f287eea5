/* Wall store: planes/lines (one-sided: balls live on the normal's side),
 * rectangles and segments (two-sided, distance to the closest point).
 * Walls move only by their imposed velocity; the step records the
 * resultant force and moment of the balls on each. */
#include "model_internal.h"

#include <math.h>
#include <string.h>

sx_wall_def sx_wall_default_def(int dim)
{
    sx_wall_def d;
    memset(&d, 0, sizeof d);
    d.kind = dim == 2 ? SX_WALL_LINE : SX_WALL_PLANE;
    d.normal[dim == 2 ? 1 : 2] = 1.0;
    d.kn = 1e8;
    d.ks = 1e8;
    d.friction = 0.5;
    d.material = SX_WALL_NO_MATERIAL;
    return d;
}

/* A wall's material or rigidity (sx_wall_def): a material of the model,
 * not in the BPM modulus mode (its per-ball stiffness needs a radius). */
static sx_status check_material(sx_model *m, const char *fn, int material)
{
    if (material < SX_WALL_RIGID || material >= m->nmat)
        return sx__fail(m, SX_EINVAL,
                        "%s: material %d is not a material of the model (0 .. %d, or -1 for none, -2 for rigid)", fn,
                        material, m->nmat - 1);
    if (material >= 0 && m->mats[material].def.modulus > 0)
        return sx__fail(m, SX_EINVAL,
                        "%s: material '%s' uses the BPM modulus (its stiffness grows with a ball's radius, which a "
                        "wall has not): give the wall's material kn and ks",
                        fn, m->mats[material].name);
    return SX_OK;
}

static double norm(const double *v, int d)
{
    double s = 0;
    for (int k = 0; k < d; k++) s += v[k] * v[k];
    return sqrt(s);
}

int64_t sx__wall_index(const sx_model *m, int64_t id)
{
    for (int64_t i = 0; i < m->nwall; i++)
        if (m->walls[i].id == id) return i;
    return -1;
}

/* Derived geometry: unit normal, rectangle frame, segment length. */
static void wall_prepare(sx_model *m, sx_wall *w)
{
    const int d = m->dim;
    sx_wall_def *def = &w->def;
    if (def->kind == SX_WALL_PLANE || def->kind == SX_WALL_LINE || def->kind == SX_WALL_CYLINDER) {
        const double n = norm(def->normal, d);
        for (int k = 0; k < d; k++) def->normal[k] /= n;
    } else if (def->kind == SX_WALL_RECT) {
        w->len_u = norm(def->edge1, 3);
        w->len_v = norm(def->edge2, 3);
        for (int k = 0; k < 3; k++) {
            w->u[k] = def->edge1[k] / w->len_u;
            w->v[k] = def->edge2[k] / w->len_v;
        }
        /* the normal of a rectangle is edge1 x edge2, for reporting only */
        def->normal[0] = w->u[1] * w->v[2] - w->u[2] * w->v[1];
        def->normal[1] = w->u[2] * w->v[0] - w->u[0] * w->v[2];
        def->normal[2] = w->u[0] * w->v[1] - w->u[1] * w->v[0];
    } else if (def->kind == SX_WALL_SEGMENT) {
        w->seg_len = norm(def->edge1, 2);
        def->normal[0] = -def->edge1[1] / w->seg_len;
        def->normal[1] = def->edge1[0] / w->seg_len;
    }
}

static bool finite3(const double *v, int d)
{
    for (int k = 0; k < d; k++)
        if (!isfinite(v[k])) return false;
    return true;
}

static sx_status validate(sx_model *m, const sx_wall_def *def, const sx_mesh *mesh)
{
    const int d = m->dim;
    const bool ok_kind = d == 3 ? (def->kind == SX_WALL_PLANE || def->kind == SX_WALL_RECT ||
                                   def->kind == SX_WALL_CYLINDER || def->kind == SX_WALL_MESH)
                                : (def->kind == SX_WALL_LINE || def->kind == SX_WALL_SEGMENT);
    if (!ok_kind)
        return sx__fail(m, SX_EINVAL,
                        "wall_add: kind %d is not a %dD wall (3D: plane, rect, cylinder, mesh; 2D: line, segment)",
                        (int)def->kind, d);
    if (!finite3(def->point, d) || !finite3(def->vel, d) || !finite3(def->normal, d) ||
        !finite3(def->edge1, d) || !finite3(def->edge2, d))
        return sx__fail(m, SX_EINVAL, "wall_add: point, normal, edges and velocity must be finite");
    if (!(def->kn > 0) || !(def->ks >= 0) || !isfinite(def->kn) || !isfinite(def->ks))
        return sx__fail(m, SX_EINVAL, "wall_add: kn must be > 0 and ks >= 0 (got kn=%g, ks=%g)", def->kn, def->ks);
    if (!(def->friction >= 0) || !isfinite(def->friction))
        return sx__fail(m, SX_EINVAL, "wall_add: friction must be >= 0 (got %g)", def->friction);
    sx_status st = check_material(m, "wall_add", def->material);
    if (st) return st;
    switch (def->kind) {
    case SX_WALL_PLANE:
    case SX_WALL_LINE:
        if (!(norm(def->normal, d) > 0)) return sx__fail(m, SX_EINVAL, "wall_add: the normal must not be zero");
        break;
    case SX_WALL_RECT: {
        const double a = norm(def->edge1, 3), b = norm(def->edge2, 3);
        if (!(a > 0) || !(b > 0)) return sx__fail(m, SX_EINVAL, "wall_add: rect edges must not be zero");
        const double dot = def->edge1[0] * def->edge2[0] + def->edge1[1] * def->edge2[1] + def->edge1[2] * def->edge2[2];
        if (fabs(dot) > 1e-9 * a * b)
            return sx__fail(m, SX_EINVAL, "wall_add: rect edges must be orthogonal (edge1.edge2 = %g)", dot);
        break;
    }
    case SX_WALL_MESH:
        if (!mesh) return sx__fail(m, SX_EINVAL, "wall_add: a mesh wall is added with its triangles (wall_add_mesh)");
        break;
    case SX_WALL_SEGMENT:
        if (!(norm(def->edge1, 2) > 0)) return sx__fail(m, SX_EINVAL, "wall_add: the segment has zero length");
        break;
    case SX_WALL_CYLINDER:
        if (!(norm(def->normal, 3) > 0)) return sx__fail(m, SX_EINVAL, "wall_add: the cylinder axis must not be zero");
        if (!(def->radius > 0) || !isfinite(def->radius))
            return sx__fail(m, SX_EINVAL, "wall_add: the cylinder radius must be > 0 m (got %g)", def->radius);
        if (!(def->height >= 0) || !isfinite(def->height) || !isfinite(def->radial_vel))
            return sx__fail(m, SX_EINVAL, "wall_add: the cylinder height must be >= 0 m (0: infinite) and "
                                          "its radial velocity finite");
        break;
    }
    return SX_OK;
}

sx_status sx_wall_add(sx_model *m, const sx_wall_def *def, int64_t *id) { return sx__wall_add(m, def, NULL, id); }

sx_status sx__wall_add(sx_model *m, const sx_wall_def *def, sx_mesh *mesh, int64_t *id)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    if (m->locked) return sx__fail(m, SX_ELOCKED, "wall_add: the model is stepping");
    sx_status st = validate(m, def, mesh);
    if (st) return st;
    if (m->nwall == m->cap_wall) {
        const int64_t cap = m->cap_wall ? 2 * m->cap_wall : 8;
        sx_wall *q = sx_alloc_resize(&m->alloc, m->walls, (size_t)m->cap_wall, (size_t)cap, sizeof *q);
        if (!q) return sx__fail(m, SX_ENOMEM, "wall_add: out of memory");
        m->walls = q;
        m->cap_wall = cap;
    }
    sx_wall *w = &m->walls[m->nwall++];
    memset(w, 0, sizeof *w);
    w->def = *def;
    for (int k = m->dim; k < 3; k++) /* a 2D wall has no third component */
        w->def.point[k] = w->def.normal[k] = w->def.edge1[k] = w->def.edge2[k] = w->def.vel[k] = 0;
    w->id = ++m->next_wall_id;
    w->mesh = mesh;
    if (def->kind != SX_WALL_MESH) memset(w->def.spin, 0, sizeof w->def.spin); /* only a mesh turns */
    wall_prepare(m, w);
    m->build_needed = true;
    m->dt_stale = true;
    if (id) *id = w->id;
    return SX_OK;
}

sx_status sx_wall_remove(sx_model *m, int64_t id)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    if (m->locked) return sx__fail(m, SX_ELOCKED, "wall_remove: the model is stepping");
    const int64_t i = sx__wall_index(m, id);
    if (i < 0) return sx__fail(m, SX_ENOTFOUND, "wall_remove: no wall with id %lld", (long long)id);
    const int64_t last = m->nwall - 1;
    sx_pairs *p = &m->bw;
    int64_t k = 0;
    for (int64_t c = 0; c < p->n; c++) {
        if (p->b[c] == i) continue;
        sx__pair_move(m, p, k, c);
        if (p->b[k] == last) p->b[k] = (int32_t)i;
        k++;
    }
    p->n = k;
    sx__mesh_free(m, m->walls[i].mesh);
    m->walls[i] = m->walls[last];
    m->nwall--;
    m->build_needed = true;
    m->dt_stale = true;
    return SX_OK;
}

int64_t sx_wall_count(const sx_model *m) { return m->nwall; }

int64_t sx_wall_id_at(const sx_model *m, int64_t i) { return i >= 0 && i < m->nwall ? m->walls[i].id : -1; }

bool sx_wall_exists(const sx_model *m, int64_t id) { return sx__wall_index(m, id) >= 0; }

static const sx_wall *lookup(const sx_model *m, int64_t id, const char *fn)
{
    const int64_t i = sx__wall_index(m, id);
    if (i < 0) {
        sx__fail((sx_model *)m, SX_ENOTFOUND, "%s: no wall with id %lld", fn, (long long)id);
        return NULL;
    }
    return &m->walls[i];
}

sx_status sx_wall_get(const sx_model *m, int64_t id, sx_wall_def *out)
{
    const sx_wall *w = lookup(m, id, "wall_get");
    if (!w) return SX_ENOTFOUND;
    *out = w->def;
    return SX_OK;
}

sx_status sx_wall_set_radial_vel(sx_model *m, int64_t id, double radial_vel)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    sx_wall *w = (sx_wall *)lookup(m, id, "wall_set_radial_vel");
    if (!w) return SX_ENOTFOUND;
    if (w->def.kind != SX_WALL_CYLINDER)
        return sx__fail(m, SX_EINVAL, "wall_set_radial_vel: wall %lld is not a cylinder", (long long)id);
    if (!isfinite(radial_vel)) return sx__fail(m, SX_EINVAL, "wall_set_radial_vel: the velocity must be finite");
    w->def.radial_vel = radial_vel;
    sx__wall_speed_changed(m, w);
    return SX_OK;
}

sx_status sx_wall_set_vel(sx_model *m, int64_t id, const double vel[3])
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    sx_wall *w = (sx_wall *)lookup(m, id, "wall_set_vel");
    if (!w) return SX_ENOTFOUND;
    if (!finite3(vel, m->dim)) return sx__fail(m, SX_EINVAL, "wall_set_vel: velocity must be finite");
    for (int k = 0; k < m->dim; k++) w->def.vel[k] = vel[k];
    sx__wall_speed_changed(m, w);
    return SX_OK;
}

sx_status sx_wall_set_point(sx_model *m, int64_t id, const double p[3])
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    sx_wall *w = (sx_wall *)lookup(m, id, "wall_set_point");
    if (!w) return SX_ENOTFOUND;
    if (!finite3(p, m->dim)) return sx__fail(m, SX_EINVAL, "wall_set_point: the point must be finite");
    for (int k = 0; k < m->dim; k++) w->def.point[k] = p[k];
    if (w->mesh) sx__mesh_pose(w);
    m->build_needed = true; /* a jump, not a motion the skin covers */
    return SX_OK;
}

sx_status sx_wall_set_material(sx_model *m, int64_t id, int material)
{
    sx_wall *w = (sx_wall *)lookup(m, id, "wall_set_material");
    if (!w) return SX_ENOTFOUND;
    sx_status st = check_material(m, "wall_set_material", material);
    if (st) return st;
    w->def.material = material;
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    m->dt_stale = true;    /* the critical timestep sees the wall's contacts */
    return SX_OK;
}

sx_status sx_wall_set(sx_model *m, int64_t id, sx_wall_scalar which, double value)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    sx_wall *w = (sx_wall *)lookup(m, id, "wall_set");
    if (!w) return SX_ENOTFOUND;
    if ((which == SX_WALL_KN || which == SX_WALL_KS) && w->def.material != SX_WALL_NO_MATERIAL)
        return sx__fail(m, SX_EINVAL, "wall_set: wall %lld is %s: its stiffness is not its own kn, ks", (long long)id,
                        w->def.material == SX_WALL_RIGID ? "rigid" : "of a material");
    if (which == SX_WALL_FRICTION && w->def.material >= 0)
        return sx__fail(m, SX_EINVAL, "wall_set: wall %lld's friction is its material's ('%s')", (long long)id,
                        m->mats[w->def.material].name);
    switch (which) {
    case SX_WALL_KN:
        if (!(value > 0) || !isfinite(value))
            return sx__fail(m, SX_EINVAL, "wall_set: kn must be a finite number > 0 N/m (got %g)", value);
        w->def.kn = value;
        m->dt_stale = true; /* the critical timestep sees the wall's contacts */
        return SX_OK;
    case SX_WALL_KS:
        if (!(value >= 0) || !isfinite(value))
            return sx__fail(m, SX_EINVAL, "wall_set: ks must be a finite number >= 0 N/m (got %g)", value);
        w->def.ks = value;
        m->dt_stale = true;
        return SX_OK;
    case SX_WALL_FRICTION:
        if (!(value >= 0) || !isfinite(value))
            return sx__fail(m, SX_EINVAL, "wall_set: friction must be a finite number >= 0 (got %g)", value);
        w->def.friction = value;
        return SX_OK;
    case SX_WALL_RADIUS:
        if (w->def.kind != SX_WALL_CYLINDER)
            return sx__fail(m, SX_EINVAL, "wall_set: wall %lld is not a cylinder; only a cylinder has a radius",
                            (long long)id);
        if (!(value > 0) || !isfinite(value))
            return sx__fail(m, SX_EINVAL, "wall_set: the cylinder radius must be a finite number > 0 m (got %g)", value);
        w->def.radius = value;
        m->build_needed = true; /* a jump, not a motion the skin covers */
        return SX_OK;
    }
    return sx__fail(m, SX_EINVAL, "wall_set: unknown field %d", (int)which);
}

sx_status sx_wall_force(const sx_model *m, int64_t id, double force[3], double moment[3])
{
    const sx_wall *w = lookup(m, id, "wall_force");
    if (!w) return SX_ENOTFOUND;
    for (int k = 0; k < 3; k++) {
        if (force) force[k] = w->force[k];
        if (moment) moment[k] = w->moment[k];
    }
    return SX_OK;
}

sx_servo_def sx_servo_default_def(void)
{
    sx_servo_def d;
    memset(&d, 0, sizeof d);
    d.area = 1;
    d.alpha = 0.5;
    d.max_speed = 1;
    return d;
}

sx_status sx_wall_set_servo(sx_model *m, int64_t id, const sx_servo_def *def)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    sx_wall *w = (sx_wall *)lookup(m, id, "wall_set_servo");
    if (!w) return SX_ENOTFOUND;
    if (w->mesh) return sx__fail(m, SX_EINVAL, "wall_set_servo: wall %lld is a mesh, which has no one normal to servo along", (long long)id);
    if (!isfinite(def->target))
        return sx__fail(m, SX_EINVAL, "wall_set_servo: the target stress must be finite (got %g)", def->target);
    if (def->target < 0) /* a sand user's finding: a negative target was taken, and the wall ran off */
        return sx__fail(m, SX_EINVAL, "wall_set_servo: the target stress must be >= 0 Pa: a wall only pushes (got %g)",
                        def->target);
    if (!(def->area > 0) || !isfinite(def->area))
        return sx__fail(m, SX_EINVAL, "wall_set_servo: the area must be > 0 (got %g)", def->area);
    if (!(def->alpha > 0 && def->alpha <= 1))
        return sx__fail(m, SX_EINVAL, "wall_set_servo: alpha must be in (0, 1] (got %g)", def->alpha);
    if (!(def->max_speed > 0) || !isfinite(def->max_speed))
        return sx__fail(m, SX_EINVAL, "wall_set_servo: max_speed must be > 0 m/s (got %g)", def->max_speed);
    w->servo = *def;
    w->servo_on = true;
    return SX_OK;
}

sx_status sx_wall_clear_servo(sx_model *m, int64_t id)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    sx_wall *w = (sx_wall *)lookup(m, id, "wall_clear_servo");
    if (!w) return SX_ENOTFOUND;
    w->servo_on = false;
    return SX_OK;
}

sx_status sx_wall_load(const sx_model *m, int64_t id, double *normal_force, int64_t *contacts, double *kn)
{
    const sx_wall *w = lookup(m, id, "wall_load");
    if (!w) return SX_ENOTFOUND;
    if (normal_force) *normal_force = w->load;
    if (contacts) *contacts = w->contacts;
    if (kn) *kn = w->contacts ? w->kn_sum / (double)w->contacts : 0;
    return SX_OK;
}

/* A plane or a line closes on a ball at its velocity along its normal only
 * (sliding in itself it closes on nothing); another wall at its whole
 * velocity, a cylinder at its radial one too, a mesh also at its spin's
 * fastest vertex. kernels/timestep.c rates balls under a stiffening law
 * (Hertz) as if struck at the fastest wall's. */
double sx__wall_speed(const sx_model *m, const sx_wall *w)
{
    double v = 0;
    if (w->def.kind == SX_WALL_PLANE || w->def.kind == SX_WALL_LINE) {
        for (int k = 0; k < m->dim; k++) v += w->def.vel[k] * w->def.normal[k];
        v = fabs(v);
    } else {
        for (int k = 0; k < m->dim; k++) v += w->def.vel[k] * w->def.vel[k];
        v = sqrt(v);
    }
    v += fabs(w->def.radial_vel);
    if (w->mesh) v += sx__mesh_spin_speed(w->mesh, w->def.point, w->def.spin);
    return v;
}

/* A wall's speed set, by hand or by its servo: the timestep is rated again
 * at the next step if it now moves more than a quarter faster than the
 * rating took (a Hertz impact's stiffness grows with its speed; the step
 * with it as v^-1/5: a quarter is under 5 %), not at every set of the same
 * or a slower speed (a Lua servo setting it every step re-rated every step,
 * doubling the step's cost). */
void sx__wall_speed_changed(sx_model *m, const sx_wall *w)
{
    if (sx__wall_speed(m, w) > 1.25 * m->dt_wall_speed && sx__speed_rated(m)) m->dt_stale = true;
}

/* PFC's servo (DESIGN 1): the normal velocity G (sigma - target), positive
 * away from the balls, from the loads of the step just computed. It sets
 * the velocity's normal part only: a velocity along the wall (a shear
 * box's top plate riding with its upper half) goes on (it was wiped out
 * at the next step: a first-day user's finding). */
void sx__walls_servo(sx_model *m)
{
    for (int64_t i = 0; i < m->nwall; i++) {
        sx_wall *w = &m->walls[i];
        if (!w->servo_on) continue;
        const sx_servo_def *s = &w->servo;
        double speed;
        if (w->contacts == 0) {
            speed = -s->max_speed; /* nothing to push on: approach the specimen */
        } else {
            const double kn = w->kn_sum / (double)w->contacts;
            const double gain = s->alpha * s->area / (kn * (double)w->contacts * m->dt);
            speed = gain * (w->load / s->area - s->target);
            if (speed > s->max_speed) speed = s->max_speed;
            if (speed < -s->max_speed) speed = -s->max_speed;
        }
        if (w->def.kind == SX_WALL_CYLINDER) {
            w->def.radial_vel = speed;
        } else {
            const double *n = w->def.normal;
            double vn = 0;
            for (int k = 0; k < m->dim; k++) vn += w->def.vel[k] * n[k];
            /* in two steps: along an axis the normal part is then -speed exactly */
            for (int k = 0; k < m->dim; k++) w->def.vel[k] = (w->def.vel[k] - vn * n[k]) - speed * n[k];
        }
        sx__wall_speed_changed(m, w); /* a servo striking fast is rated too */
    }
}

void sx__walls_sum(sx_model *m)
{
    const int64_t nw = m->nwall;
    for (int64_t w = 0; w < nw; w++) {
        sx_wall *wl = &m->walls[w];
        memset(wl->force, 0, sizeof wl->force);
        memset(wl->moment, 0, sizeof wl->moment);
        wl->load = wl->kn_sum = 0;
        wl->contacts = 0;
    }
    for (int64_t b = 0; b < m->nblock; b++)
        for (int64_t w = 0; w < nw; w++) {
            const sx_wall_acc *a = &m->wall_acc[b * nw + w];
            sx_wall *wl = &m->walls[w];
            for (int k = 0; k < 3; k++) wl->force[k] += a->force[k], wl->moment[k] += a->moment[k];
            wl->load += a->load;
            wl->kn_sum += a->kn_sum;
            wl->contacts += a->contacts;
        }
}

bool sx__walls_read_in_step(const sx_model *m)
{
    if (m->track_energy) return true;
    for (int64_t w = 0; w < m->nwall; w++)
        if (m->walls[w].servo_on) return true;
    return false;
}

void sx__walls_free(sx_model *m)
{
    for (int64_t i = 0; i < m->nwall; i++) sx__mesh_free(m, m->walls[i].mesh);
    sx_alloc_free(&m->alloc, m->walls, (size_t)m->cap_wall, sizeof *m->walls);
    m->walls = NULL;
    m->nwall = m->cap_wall = 0;
}
