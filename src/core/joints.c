/* Smooth joints: the model's joint planes, their checks, and their
 * installation on the pairs they cross (the law: laws/smoothjoint.h; the
 * step: kernels/pair_contacts.c, smooth_joint). */
#include "joints.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

sx_joint_def sx_joint_default_def(void)
{
    sx_joint_def d;
    memset(&d, 0, sizeof d);
    d.normal[1] = 1;
    d.friction = 0.5;
    d.radius_multiplier = 1;
    return d;
}

/* The first rule def breaks, written to why; NULL when it is valid. */
static const char *joint_invalid(int dim, const sx_joint_def *d, char *why, size_t len)
{
    double n2 = 0;
    for (int k = 0; k < dim; k++) {
        if (!isfinite(d->point[k]) || !isfinite(d->normal[k])) {
            snprintf(why, len, "point and normal must be finite");
            return why;
        }
        n2 += d->normal[k] * d->normal[k];
    }
    if (!(n2 > 0)) {
        snprintf(why, len, "normal must not be zero%s", dim == 2 ? " in the plane of the model" : "");
        return why;
    }
    struct {
        const char *name;
        double v, lo, hi;
        bool open_lo, open_hi;
    } rules[] = {
        {"kn (Pa/m)", d->kn, 0, INFINITY, true, true},
        {"ks (Pa/m)", d->ks, 0, INFINITY, true, true},
        {"friction", d->friction, 0, INFINITY, false, true},
        {"dilation (degrees)", d->dilation, 0, 90, false, true},
        {"tension (Pa)", d->tension, 0, INFINITY, false, true},
        {"cohesion (Pa)", d->cohesion, 0, INFINITY, false, true},
        {"friction_angle (degrees)", d->friction_angle, 0, 90, false, true},
        {"radius_multiplier", d->radius_multiplier, 0, INFINITY, true, true},
        {"radius (m)", d->radius, 0, INFINITY, false, true},
    };
    for (size_t k = 0; k < sizeof rules / sizeof *rules; k++) {
        const double v = rules[k].v;
        if (!(v == v) || (rules[k].open_lo ? v <= rules[k].lo : v < rules[k].lo) ||
            (rules[k].open_hi ? v >= rules[k].hi : v > rules[k].hi)) {
            snprintf(why, len, "%s must be in %s%g, %g%s (got %g)", rules[k].name, rules[k].open_lo ? "(" : "[",
                     rules[k].lo, rules[k].hi, rules[k].open_hi ? ")" : "]", v);
            return why;
        }
    }
    if ((d->tension > 0) != (d->cohesion > 0)) {
        snprintf(why, len, "a bonded joint needs both tension and cohesion > 0, an unbonded one neither (got %g and %g)",
                 d->tension, d->cohesion);
        return why;
    }
    return NULL;
}

/* Appends def (valid) with its normal made unit. */
static sx_status joint_append(sx_model *m, const sx_joint_def *def)
{
    if (m->njoint == m->cap_joint) {
        const int64_t cap = m->cap_joint ? 2 * m->cap_joint : 4;
        sx_joint *q = sx_alloc_resize(&m->alloc, m->joints, (size_t)m->cap_joint, (size_t)cap, sizeof *q);
        if (!q) return SX_ENOMEM;
        m->joints = q;
        m->cap_joint = cap;
    }
    sx_joint *j = &m->joints[m->njoint++];
    j->def = *def;
    if (m->dim == 2) j->def.point[2] = j->def.normal[2] = 0;
    const double len = sqrt(j->def.normal[0] * j->def.normal[0] + j->def.normal[1] * j->def.normal[1] +
                            j->def.normal[2] * j->def.normal[2]);
    for (int k = 0; k < 3; k++) j->def.normal[k] /= len;
    const double deg = 3.14159265358979323846 / 180;
    j->law = (sx_law_sj){def->kn, def->ks, def->friction, tan(def->dilation * deg), def->tension, def->cohesion,
                         tan(def->friction_angle * deg), def->radius_multiplier};
    return SX_OK;
}

sx_status sx__joints_reserve_pairs(sx_model *m)
{
    sx_pairs *p = &m->bb;
    if (p->joint) return SX_OK;
    if (sx__pairs_reserve(m, p, 1)) return SX_ENOMEM;
    p->joint = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)p->cap, sizeof *p->joint);
    p->jnormal = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(p->cap * m->dim), sizeof *p->jnormal);
    p->jun = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)p->cap, sizeof *p->jun);
    return p->joint && p->jnormal && p->jun ? SX_OK : SX_ENOMEM;
}

/* Joint k on pair c of the store (its centres on opposite sides, unit
 * normal nrm from a's side to b's): a bond is cut, and replaced by the
 * joint's when the joint is bonded; a contact takes the joint's law with
 * its overlap along the joint normal. Returns bit 1 when a bond was
 * replaced or cut, bit 2 when the pair is now an unbonded joint contact. */
static int joint_install(sx_model *m, int64_t k, int64_t c, const double *nrm)
{
    const int d = m->dim;
    sx_pairs *p = &m->bb;
    sx_bonds *b = &m->bonds;
    const sx_balls *B = &m->balls;
    const sx_joint *J = &m->joints[k];
    const int64_t i = p->a[c], j = p->b[c];
    const int32_t slot = p->bond ? p->bond[c] - 1 : -1;
    const bool bonded = slot >= 0 && b->kind[slot];
    double dx[3], dist = 0, cosn = 0;
    for (int q = 0; q < d; q++) dx[q] = B->x[j * d + q] - B->x[i * d + q], dist += dx[q] * dx[q];
    dist = sqrt(dist);
    for (int q = 0; q < d; q++) cosn += dx[q] / dist * nrm[q];
    const double un = B->rad[i] + B->rad[j] - dist;
    int what = 0;
    if (bonded && J->law.sigma_c > 0) { /* the bonded joint takes the bond's slot, stress free */
        const double ri = B->rad[i], rj = B->rad[j];
        b->kind[slot] = SX_BOND_SMOOTHJOINT;
        b->rbar[slot] = J->law.lambda * (ri < rj ? ri : rj);
        b->kn[slot] = J->law.kn, b->ks[slot] = J->law.ks;
        b->sigma_c[slot] = J->law.sigma_c, b->tau_c[slot] = J->law.coh;
        b->fn[slot] = b->mn[slot] = 0;
        for (int q = 0; q < d; q++) b->fs[slot * d + q] = 0;
        for (int q = 0; q < m->rdim; q++) b->ms[slot * m->rdim + q] = 0;
        p->jun[c] = 0;
        what = 1;
    } else {
        if (bonded) { /* cut: the joint has no bond of its own */
            sx__bond_break(m, slot, b->kind[slot]);
            p->bond[c] = 0;
            what = 1;
        }
        if (!(p->touching[c] || bonded) || un <= 0) {
            p->touching[c] = 0;
            p->joint[c] = 0;
            return what;
        }
        p->jun[c] = un * fabs(cosn);
        what |= 2;
    }
    p->joint[c] = (int32_t)(k + 1);
    for (int q = 0; q < d; q++) p->jnormal[c * d + q] = nrm[q], p->fs[c * d + q] = 0, p->geo[c * d + q] = dx[q];
    for (int q = 0; p->mr && q < m->rdim; q++) p->mr[c * m->rdim + q] = 0; /* the joint has no rolling moment */
    p->touching[c] = 1;
    return what;
}

sx_status sx_joint_add(sx_model *m, const sx_joint_def *def, int64_t *bonds, int64_t *contacts)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "joint: the model is stepping");
    char why[160];
    if (joint_invalid(m->dim, def, why, sizeof why)) return sx__fail(m, SX_EINVAL, "joint: %s", why);
    sx_status st = sx__prepare(m); /* the pairs as they are now */
    if (st) return st;
    if (sx__joints_reserve_pairs(m) || joint_append(m, def)) return sx__fail(m, SX_ENOMEM, "joint: out of memory");
    const int64_t k = m->njoint - 1;
    sx_pairs *p = &m->bb;
    int64_t nb = 0, nc = 0;
    for (int64_t c = 0; c < p->n; c++) {
        if (p->joint[c] && p->touching[c]) continue; /* an earlier joint's */
        double nrm[3];
        const int d = m->dim;
        if (sx__joint_crossed(m, d, m->balls.x + p->a[c] * d, m->balls.x + p->b[c] * d, nrm) != k + 1) continue;
        const int what = joint_install(m, k, c, nrm);
        nb += (what & 1) != 0, nc += (what & 2) != 0;
    }
    m->dt_stale = true;
    m->guard_dirty = true;
    if (bonds) *bonds = nb;
    if (contacts) *contacts = nc;
    return SX_OK;
}

int64_t sx_joint_count(const sx_model *m) { return m->njoint; }

sx_status sx_joint_get(const sx_model *m, int64_t k, sx_joint_def *out)
{
    if (k < 0 || k >= m->njoint) return SX_ENOTFOUND;
    *out = m->joints[k].def;
    return SX_OK;
}

sx_status sx__joints_restore(sx_model *m, const sx_joint_def *defs, int64_t n)
{
    char why[160];
    for (int64_t k = 0; k < n; k++) {
        if (joint_invalid(m->dim, &defs[k], why, sizeof why))
            return sx__fail(m, SX_EINVAL, "joint %lld: %s", (long long)(k + 1), why);
        if (joint_append(m, &defs[k])) return sx__fail(m, SX_ENOMEM, "joints: out of memory");
    }
    return SX_OK;
}

uint64_t sx__joints_hash(const sx_model *m, uint64_t h)
{
    h = sx__fnv(h, &m->njoint, sizeof m->njoint);
    for (int64_t k = 0; k < m->njoint; k++) h = sx__fnv(h, &m->joints[k].def, sizeof m->joints[k].def);
    return h;
}

size_t sx__joints_bytes(const sx_model *m) { return (size_t)m->cap_joint * sizeof(sx_joint); }

void sx__joints_free(sx_model *m)
{
    sx_alloc_free(&m->alloc, m->joints, (size_t)m->cap_joint, sizeof *m->joints);
    m->joints = NULL;
    m->njoint = m->cap_joint = 0;
}
