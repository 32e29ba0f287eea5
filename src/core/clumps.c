/* Clumps: rigid bodies made of balls ("pebbles"), seed 4.3 ("other
 * geometries are made by grouping particles") moved by Euler's equations
 * (4-42). The store is described in clumps.h; clumps_internal.h maps the
 * files that share it. This one has the bodies: a clump added from a
 * template with its pebbles, removed, read and set; its mass and inertia
 * follow its template, scale and material (clump_mass). */
#include "clump_math.h"
#include "clumps_internal.h"

#include <math.h>
#include <string.h>

/* --------------------------------------------------------------- bodies */

static int64_t clump_index(const sx_model *m, int64_t id)
{
    const sx_clumps *C = m->clumps;
    if (!C || id < 1 || id >= C->next_id) return -1;
    return C->index_of[id];
}

static int64_t lookup(const sx_model *m, int64_t id, const char *fn)
{
    const int64_t c = clump_index(m, id);
    if (c < 0) sx__fail((sx_model *)m, SX_ENOTFOUND, "%s: no clump with id %lld", fn, (long long)id);
    return c;
}

/* Clump c's pebbles from its body (the dimension's kernel, kernels/clump_motion.c). */
static double place_pebbles(sx_model *m, int64_t c, const double *R)
{
    return sx__kernels(m)->place_pebbles(m, c, R);
}

/* Mass and principal moments of clump c from its template, scale and
 * material; its pebbles carry the body's mass and smallest moment (the
 * contact dashpots use the pebble's mass as the body's). */
static void clump_mass(sx_model *m, int64_t c)
{
    sx_clumps *C = m->clumps;
    const int d = m->dim, r = m->rdim;
    const sx_clump_tpl *t = &C->tpl[C->tpl_of[c]];
    const double rho = m->mats[C->mat[c]].def.density, s = C->scale[c];
    const double sd = d == 3 ? s * s * s : s * s, sd2 = sd * s * s;
    C->mass[c] = rho * sd * t->volume;
    for (int k = 0; k < r; k++) C->inertia[c * r + k] = rho * sd2 * t->principal[k];
    sx_balls *B = &m->balls;
    for (int64_t k = 0; k < t->n; k++) {
        const int64_t i = B->index_of[C->pebble[C->first[c] + k]];
        B->inv_mass[i] = 1.0 / C->mass[c];
        B->inv_inertia[i] = 1.0 / C->inertia[c * r];
    }
    if (d == 3) { /* the spin is kept: L follows the new inertia */
        double R[9];
        body_rotation(m, c, R);
        momentum_of(R, C->inertia + c * 3, C->w + c * 3, C->L + c * 3);
    }
}

sx_clump_def sx_clump_default_def(void)
{
    sx_clump_def d;
    memset(&d, 0, sizeof d);
    d.orientation[0] = 1;
    d.scale = 1;
    return d;
}

/* The body-frame orientation of a clump from its template's and a user
 * orientation (template frame to space), checked; false with a message. */
static bool user_orientation(sx_model *m, const double *qu, const sx_clump_tpl *t, double *q, const char *fn)
{
    double u[4];
    double n2 = 0;
    for (int k = 0; k < 4; k++) {
        if (!isfinite(qu[k])) {
            sx__fail(m, SX_EINVAL, "%s: the orientation must be finite", fn);
            return false;
        }
        u[k] = qu[k];
        n2 += u[k] * u[k];
    }
    if (!(n2 > 1e-300) || !isfinite(n2)) {
        sx__fail(m, SX_EINVAL, "%s: the orientation quaternion must not be zero", fn);
        return false;
    }
    if (m->dim == 2) {
        if (u[1] != 0 || u[2] != 0) {
            sx__fail(m, SX_EINVAL, "%s: a 2D orientation is a rotation about z (x = y = 0)", fn);
            return false;
        }
        q[0] = 2 * atan2(u[3], u[0]);
        return true;
    }
    qnormalize(u);
    qmul(u, t->frame, q); /* space <- template <- body */
    qnormalize(q);
    return true;
}

sx_status sx_clump_add(sx_model *m, const sx_clump_def *def, int64_t *out_id)
{
    m->guard_dirty = true;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "clump_add: the model is stepping; add clumps between cycles");
    const sx_clump_tpl *t = sx__clump_template_at(m, def->template_index, "clump_add");
    if (!t) return SX_ENOTFOUND;
    if (def->material < 0 || def->material >= m->nmat)
        return sx__fail(m, SX_ENOTFOUND, "clump_add: no material with index %d", def->material);
    if (!(def->scale > 0) || !isfinite(def->scale) || def->scale > 1e100)
        return sx__fail(m, SX_EINVAL, "clump_add: scale must be a finite number > 0 (got %g)", def->scale);
    const int d = m->dim, r = m->rdim;
    for (int k = 0; k < d; k++)
        if (!isfinite(def->pos[k]) || !isfinite(def->vel[k]))
            return sx__fail(m, SX_EINVAL, "clump_add: position and velocity must be finite");
    for (int k = 0; k < r; k++)
        if (!isfinite(def->spin[k])) return sx__fail(m, SX_EINVAL, "clump_add: spin must be finite");
    double q[4];
    if (!user_orientation(m, def->orientation, t, q, "clump_add")) return SX_EINVAL;
    sx_clumps *C = m->clumps;
    if (C->next_id >= INT32_MAX) return sx__fail(m, SX_ENOMEM, "clump_add: clump ids exhausted");
    const int64_t np = t->n;
    if (sx__clump_reserve(m, np))
        return sx__fail(m, SX_ENOMEM, "clump_add: out of memory at %lld clumps", (long long)C->n);
    t = &C->tpl[def->template_index];
    /* the pebbles, at the template's radii scaled; placed below */
    const int64_t first = C->pn;
    for (int64_t k = 0; k < np; k++) {
        sx_ball_def bd = sx_ball_default_def();
        for (int j = 0; j < d; j++) bd.pos[j] = def->pos[j];
        bd.radius = def->scale * C->tp_rad[t->first + k];
        bd.material = def->material;
        int64_t bid;
        const sx_status st = sx_ball_add(m, &bd, &bid);
        if (st) {
            for (int64_t j = first; j < first + k; j++) sx_ball_remove(m, C->pebble[j]);
            return st;
        }
        C->pebble[first + k] = (int32_t)bid;
    }
    const int64_t c = C->n++, id = C->next_id++;
    C->pn += np;
    C->id[c] = (int32_t)id;
    C->index_of[id] = (int32_t)c;
    C->tpl_of[c] = def->template_index;
    C->mat[c] = (uint16_t)def->material;
    C->fix[c] = 0;
    C->scale[c] = def->scale;
    C->alpha[c] = m->mats[def->material].def.damping;
    C->first[c] = first;
    for (int k = 0; k < d; k++) {
        C->x[c * d + k] = def->pos[k];
        C->v[c * d + k] = def->vel[k];
        C->f[c * d + k] = 0;
    }
    for (int k = 0; k < r; k++) {
        C->w[c * r + k] = def->spin[k];
        C->t[c * r + k] = 0;
    }
    memcpy(C->q + c * qdim(m), q, (size_t)qdim(m) * sizeof(double));
    for (int64_t k = 0; k < np; k++) m->balls.clump[m->balls.index_of[C->pebble[first + k]]] = (int32_t)id;
    clump_mass(m, c); /* also L from the spin */
    double R[9];
    body_rotation(m, c, R);
    place_pebbles(m, c, R);
    m->build_needed = true;
    m->dt_stale = true;
    if (out_id) *out_id = id;
    return SX_OK;
}

sx_status sx_clump_remove(sx_model *m, int64_t id)
{
    m->guard_dirty = true;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "clump_remove: the model is stepping");
    const int64_t c = lookup(m, id, "clump_remove");
    if (c < 0) return SX_ENOTFOUND;
    sx_clumps *C = m->clumps;
    const int64_t np = C->tpl[C->tpl_of[c]].n, first = C->first[c];
    for (int64_t k = 0; k < np; k++) {
        const int64_t bid = C->pebble[first + k];
        m->balls.clump[m->balls.index_of[bid]] = 0; /* a free ball now, removable */
        sx_ball_remove(m, bid);
    }
    /* close the gaps, keeping the order (and so the step's order) of the others */
    memmove(C->pebble + first, C->pebble + first + np, (size_t)(C->pn - first - np) * sizeof *C->pebble);
    C->pn -= np;
    const int d = m->dim, r = m->rdim, qd = qdim(m);
    const int64_t tail = C->n - c - 1;
#define SHIFT(field, per) memmove(C->field + c * (per), C->field + (c + 1) * (per), (size_t)(tail * (per)) * sizeof *C->field)
    SHIFT(id, 1);
    SHIFT(tpl_of, 1);
    SHIFT(mat, 1);
    SHIFT(fix, 1);
    SHIFT(scale, 1);
    SHIFT(x, d);
    SHIFT(v, d);
    SHIFT(q, qd);
    if (C->L) SHIFT(L, 3);
    SHIFT(w, r);
    SHIFT(f, d);
    SHIFT(t, r);
    SHIFT(alpha, 1);
    SHIFT(mass, 1);
    SHIFT(inertia, r);
    SHIFT(first, 1);
#undef SHIFT
    C->n--;
    C->index_of[id] = -1;
    for (int64_t k = c; k < C->n; k++) {
        C->first[k] -= np;
        C->index_of[C->id[k]] = (int32_t)k;
    }
    return SX_OK;
}

int64_t sx_clump_count(const sx_model *m) { return m->clumps ? m->clumps->n : 0; }

int64_t sx_clump_id_at(const sx_model *m, int64_t i)
{
    return i >= 0 && i < sx_clump_count(m) ? m->clumps->id[i] : -1;
}

bool sx_clump_exists(const sx_model *m, int64_t id) { return clump_index(m, id) >= 0; }

int64_t sx_ball_clump(const sx_model *m, int64_t ball_id)
{
    const int64_t i = sx__ball_index(m, ball_id);
    return i >= 0 && m->balls.clump ? m->balls.clump[i] : 0;
}

sx_status sx_clump_get_vec(const sx_model *m, int64_t id, sx_clump_vec which, double out[3])
{
    const int64_t c = lookup(m, id, "clump_get_vec");
    if (c < 0) return SX_ENOTFOUND;
    const sx_clumps *C = m->clumps;
    const int d = m->dim, r = m->rdim;
    out[0] = out[1] = out[2] = 0;
    switch (which) {
    case SX_CLUMP_POS: memcpy(out, C->x + c * d, (size_t)d * sizeof(double)); return SX_OK;
    case SX_CLUMP_VEL: memcpy(out, C->v + c * d, (size_t)d * sizeof(double)); return SX_OK;
    case SX_CLUMP_SPIN: memcpy(out, C->w + c * r, (size_t)r * sizeof(double)); return SX_OK;
    case SX_CLUMP_FORCE: memcpy(out, C->f + c * d, (size_t)d * sizeof(double)); return SX_OK;
    case SX_CLUMP_MOMENT: memcpy(out, C->t + c * r, (size_t)r * sizeof(double)); return SX_OK;
    case SX_CLUMP_ANGULAR_MOMENTUM:
        if (d == 3) memcpy(out, C->L + c * 3, 3 * sizeof(double));
        else out[0] = C->inertia[c] * C->w[c];
        return SX_OK;
    }
    return sx__fail((sx_model *)m, SX_EINVAL, "clump_get_vec: unknown field %d", (int)which);
}

sx_status sx_clump_set_vec(sx_model *m, int64_t id, sx_clump_vec which, const double v[3])
{
    m->guard_dirty = true;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "clump_set_vec: the model is stepping");
    const int64_t c = lookup(m, id, "clump_set_vec");
    if (c < 0) return SX_ENOTFOUND;
    sx_clumps *C = m->clumps;
    const int d = m->dim, r = m->rdim;
    const int n = which == SX_CLUMP_SPIN ? r : d;
    if (which != SX_CLUMP_POS && which != SX_CLUMP_VEL && which != SX_CLUMP_SPIN)
        return sx__fail(m, SX_EINVAL, "clump_set_vec: only pos, vel and spin can be set");
    for (int k = 0; k < n; k++)
        if (!isfinite(v[k])) return sx__fail(m, SX_EINVAL, "clump_set_vec: components must be finite");
    double R[9];
    body_rotation(m, c, R);
    if (which == SX_CLUMP_POS) {
        memcpy(C->x + c * d, v, (size_t)d * sizeof(double));
        m->build_needed = true; /* a jump may skip the skin test */
        for (int64_t k = 0; k < C->tpl[C->tpl_of[c]].n; k++) sx__ball_placed(m, m->balls.index_of[C->pebble[C->first[c] + k]]);
    } else if (which == SX_CLUMP_VEL) {
        memcpy(C->v + c * d, v, (size_t)d * sizeof(double));
    } else {
        memcpy(C->w + c * r, v, (size_t)r * sizeof(double));
        if (d == 3) momentum_of(R, C->inertia + c * 3, C->w + c * 3, C->L + c * 3);
    }
    place_pebbles(m, c, R);
    if (which != SX_CLUMP_POS && sx__speed_rated(m)) m->dt_stale = true; /* (the pebbles' speeds) */
    return SX_OK;
}

sx_status sx_clump_orientation(const sx_model *m, int64_t id, double q[4])
{
    const int64_t c = lookup(m, id, "clump_orientation");
    if (c < 0) return SX_ENOTFOUND;
    const sx_clumps *C = m->clumps;
    if (m->dim == 2) {
        q[0] = cos(0.5 * C->q[c]), q[1] = q[2] = 0, q[3] = sin(0.5 * C->q[c]);
        if (q[0] < 0)
            for (int k = 0; k < 4; k++) q[k] = -q[k];
        return SX_OK;
    }
    /* template -> space = (body -> space) (body -> template)^-1 */
    const double *f = C->tpl[C->tpl_of[c]].frame;
    const double inv[4] = {f[0], -f[1], -f[2], -f[3]};
    qmul(C->q + c * 4, inv, q);
    if (q[0] < 0)
        for (int k = 0; k < 4; k++) q[k] = -q[k];
    qnormalize(q);
    return SX_OK;
}

sx_status sx_clump_set_orientation(sx_model *m, int64_t id, const double q[4])
{
    m->guard_dirty = true;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "clump_set_orientation: the model is stepping");
    const int64_t c = lookup(m, id, "clump_set_orientation");
    if (c < 0) return SX_ENOTFOUND;
    sx_clumps *C = m->clumps;
    double qb[4];
    if (!user_orientation(m, q, &C->tpl[C->tpl_of[c]], qb, "clump_set_orientation")) return SX_EINVAL;
    memcpy(C->q + c * qdim(m), qb, (size_t)qdim(m) * sizeof(double));
    double R[9];
    body_rotation(m, c, R);
    if (m->dim == 3) momentum_of(R, C->inertia + c * 3, C->w + c * 3, C->L + c * 3); /* the spin is kept */
    place_pebbles(m, c, R);
    m->build_needed = true;
    return SX_OK;
}

sx_status sx_clump_get(const sx_model *m, int64_t id, sx_clump_scalar which, double *out)
{
    const int64_t c = lookup(m, id, "clump_get");
    if (c < 0) return SX_ENOTFOUND;
    const sx_clumps *C = m->clumps;
    const double s = C->scale[c];
    switch (which) {
    case SX_CLUMP_MASS: *out = C->mass[c]; return SX_OK;
    case SX_CLUMP_VOLUME: *out = C->tpl[C->tpl_of[c]].volume * (m->dim == 3 ? s * s * s : s * s); return SX_OK;
    case SX_CLUMP_SCALE: *out = s; return SX_OK;
    case SX_CLUMP_DAMPING: *out = C->alpha[c]; return SX_OK;
    }
    return sx__fail((sx_model *)m, SX_EINVAL, "clump_get: unknown field %d", (int)which);
}

sx_status sx_clump_set(sx_model *m, int64_t id, sx_clump_scalar which, double value)
{
    const int64_t c = lookup(m, id, "clump_set");
    if (c < 0) return SX_ENOTFOUND;
    if (which != SX_CLUMP_DAMPING)
        return sx__fail(m, SX_EINVAL, "clump_set: only the damping can be set (mass, volume and scale follow the template)");
    if (!(value >= 0 && value < 1))
        return sx__fail(m, SX_EINVAL, "clump_set: local damping must be in [0, 1) (got %g)", value);
    m->clumps->alpha[c] = value;
    m->guard_dirty = true;
    return SX_OK;
}

sx_status sx_clump_inertia(const sx_model *m, int64_t id, double principal[3], double tensor[3][3])
{
    const int64_t c = lookup(m, id, "clump_inertia");
    if (c < 0) return SX_ENOTFOUND;
    const sx_clumps *C = m->clumps;
    const int r = m->rdim;
    const double *I = C->inertia + c * r;
    if (principal) {
        principal[0] = principal[1] = principal[2] = 0;
        for (int k = 0; k < r; k++) principal[k] = I[k];
    }
    if (tensor) {
        memset(tensor, 0, 9 * sizeof(double));
        if (m->dim == 3) {
            double R[9];
            body_rotation(m, c, R);
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) {
                    double s = 0;
                    for (int k = 0; k < 3; k++) s += R[3 * a + k] * I[k] * R[3 * b + k];
                    tensor[a][b] = s;
                }
        } else {
            tensor[2][2] = I[0];
        }
    }
    return SX_OK;
}

sx_status sx_clump_template_of(const sx_model *m, int64_t id, int *t)
{
    const int64_t c = lookup(m, id, "clump_template_of");
    if (c < 0) return SX_ENOTFOUND;
    *t = m->clumps->tpl_of[c];
    return SX_OK;
}

sx_status sx_clump_pebbles(const sx_model *m, int64_t id, int64_t *ids, int64_t cap, int64_t *count)
{
    const int64_t c = lookup(m, id, "clump_pebbles");
    if (c < 0) return SX_ENOTFOUND;
    const sx_clumps *C = m->clumps;
    const int64_t n = C->tpl[C->tpl_of[c]].n;
    for (int64_t k = 0; k < n && k < cap; k++) ids[k] = C->pebble[C->first[c] + k];
    if (count) *count = n;
    return SX_OK;
}

sx_status sx_clump_material(const sx_model *m, int64_t id, int *material)
{
    const int64_t c = lookup(m, id, "clump_material");
    if (c < 0) return SX_ENOTFOUND;
    *material = m->clumps->mat[c];
    return SX_OK;
}

sx_status sx_clump_set_material(sx_model *m, int64_t id, int material)
{
    m->guard_dirty = true;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "clump_set_material: the model is stepping");
    const int64_t c = lookup(m, id, "clump_set_material");
    if (c < 0) return SX_ENOTFOUND;
    if (material < 0 || material >= m->nmat)
        return sx__fail(m, SX_ENOTFOUND, "clump_set_material: no material with index %d", material);
    sx_clumps *C = m->clumps;
    C->mat[c] = (uint16_t)material;
    C->alpha[c] = m->mats[material].def.damping;
    const int64_t n = C->tpl[C->tpl_of[c]].n;
    for (int64_t k = 0; k < n; k++) {
        const int64_t i = m->balls.index_of[C->pebble[C->first[c] + k]];
        m->balls.mat[i] = (uint16_t)material;
        if (m->balls.alpha) m->balls.alpha[i] = m->mats[material].def.damping;
    }
    clump_mass(m, c);
    m->dt_stale = true;
    return SX_OK;
}

/* Fixities are stored as balls store them: in 2D the scalar spin's bit is SX_FIX_WX. */
sx_status sx_clump_fixity(const sx_model *m, int64_t id, unsigned *mask)
{
    const int64_t c = lookup(m, id, "clump_fixity");
    if (c < 0) return SX_ENOTFOUND;
    const unsigned f = m->clumps->fix[c];
    *mask = m->dim == 3 ? f : (f & (SX_FIX_VX | SX_FIX_VY)) | ((f & SX_FIX_WX) ? SX_FIX_WZ : 0);
    return SX_OK;
}

sx_status sx_clump_set_fixity(sx_model *m, int64_t id, unsigned mask)
{
    m->guard_dirty = true;
    const int64_t c = lookup(m, id, "clump_set_fixity");
    if (c < 0) return SX_ENOTFOUND;
    const unsigned valid = m->dim == 3 ? (SX_FIX_VEL | SX_FIX_SPIN) : (SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ);
    if (mask & ~valid)
        return sx__fail(m, SX_EINVAL, "clump_set_fixity: mask 0x%x has components a %dD clump does not have", mask,
                        m->dim);
    if (m->dim == 3 && (mask & SX_FIX_SPIN) && (mask & SX_FIX_SPIN) != SX_FIX_SPIN)
        return sx__fail(m, SX_EINVAL, "clump_set_fixity: a clump's spin is fixed as a whole (wx, wy and wz) or not at "
                                      "all; fixing some axes only would need a constraint torque");
    m->clumps->fix[c] =
        (uint8_t)(m->dim == 3 ? mask : (mask & (SX_FIX_VX | SX_FIX_VY)) | ((mask & SX_FIX_WZ) ? SX_FIX_WX : 0));
    return SX_OK;
}

void sx__clumps_material_changed(sx_model *m, int material, bool density, bool damping)
{
    sx_clumps *C = m->clumps;
    for (int64_t c = 0; c < C->n; c++) {
        if (C->mat[c] != material) continue;
        if (density) clump_mass(m, c);
        if (damping) C->alpha[c] = m->mats[material].def.damping;
    }
}
