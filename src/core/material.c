/* The material table (sx_material_set and its queries) and the pair laws
 * mixed from it: ball-ball and ball-wall laws, refreshed before a cycle,
 * and the check that every pair's models agree. */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ materials */

sx_material_def sx_material_default_def(void)
{
    sx_material_def d;
    memset(&d, 0, sizeof d);
    d.model = SX_MODEL_LINEAR;
    d.density = 2650;
    d.kn = 1e8;
    d.ks = 1e8;
    d.friction = 0.5;
    d.stiffness_ratio = 1;
    d.shear_modulus = 29e9;
    d.poisson = 0.15;
    return d;
}

int sx_material_find(const sx_model *m, const char *name)
{
    for (int i = 0; i < m->nmat; i++)
        if (strcmp(m->mats[i].name, name) == 0) return i;
    return -1;
}

int sx_material_count(const sx_model *m) { return m->nmat; }

const char *sx_material_name(const sx_model *m, int index)
{
    return index >= 0 && index < m->nmat ? m->mats[index].name : NULL;
}

sx_status sx_material_get(const sx_model *m, int index, sx_material_def *out)
{
    if (index < 0 || index >= m->nmat)
        return sx__fail((sx_model *)m, SX_ENOTFOUND, "material_get: no material with index %d", index);
    *out = m->mats[index].def;
    return SX_OK;
}

/* The first rule a material definition breaks, written into why, or NULL:
 * for sx_material_set and for a loaded state alike. The rules of every
 * material come first, then its law's parameters (laws.c). */
const char *sx__material_invalid(const sx_material_def *d, char *why, size_t len)
{
#define CHECK(cond, what, val) \
    if (!(cond) || !isfinite(val)) \
        return snprintf(why, len, isfinite(val) ? "%s (got %g)" : "%s, a finite number (got %g)", what, (double)(val)), why
    CHECK(d->density > 0, "density must be > 0 kg/m^3", d->density);
    CHECK(d->kn > 0, "kn must be > 0 N/m", d->kn);
    CHECK(d->ks >= 0, "ks must be >= 0 N/m", d->ks);
    CHECK(d->friction >= 0, "friction must be >= 0", d->friction);
    CHECK(d->damping >= 0 && d->damping < 1, "local damping must be in [0, 1)", d->damping);
    CHECK(d->viscous_normal >= 0, "viscous_normal must be >= 0", d->viscous_normal);
    CHECK(d->viscous_shear >= 0, "viscous_shear must be >= 0", d->viscous_shear);
    CHECK(d->modulus >= 0, "modulus must be >= 0 Pa (0: use kn, ks)", d->modulus);
    CHECK(d->stiffness_ratio > 0, "stiffness_ratio (kn/ks) must be > 0", d->stiffness_ratio);
    /* kept (and saved) by a linear material too: finite there as well */
    CHECK(d->shear_modulus >= 0, "shear_modulus must be >= 0 Pa", d->shear_modulus);
    CHECK(d->poisson >= 0 && d->poisson < 0.5, "Poisson's ratio must be in [0, 0.5)", d->poisson);
#undef CHECK
    return sx__law_check(d, why, len);
}

sx_status sx_material_set(sx_model *m, const char *name, const sx_material_def *d, int *out)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "material: the model is stepping");
    if (!name || !*name || strlen(name) >= sizeof m->mats[0].name)
        return sx__fail(m, SX_EINVAL, "material: the name must have 1 to %zu characters", sizeof m->mats[0].name - 1);
    char why[256];
    if (sx__material_invalid(d, why, sizeof why)) return sx__fail(m, SX_EINVAL, "material '%s': %s", name, why);
    int i = sx_material_find(m, name);
    if (i < 0) {
        if (m->nmat >= UINT16_MAX) return sx__fail(m, SX_EINVAL, "material: too many materials");
        if (m->nmat == m->cap_mat) {
            const int cap = m->cap_mat ? 2 * m->cap_mat : 8;
            sx_material *q = sx_alloc_resize(&m->alloc, m->mats, (size_t)m->cap_mat, (size_t)cap, sizeof *q);
            if (!q) return sx__fail(m, SX_ENOMEM, "material: out of memory");
            m->mats = q;
            m->cap_mat = cap;
        }
        i = m->nmat++;
        snprintf(m->mats[i].name, sizeof m->mats[i].name, "%s", name);
    }
    const bool density_changed = m->mats[i].def.density != d->density;
    const bool damping_changed = m->mats[i].def.damping != d->damping;
    /* a clump's pebbles keep one density, its material's: a pebble of
     * another material of that density (its friction, its stiffness) may
     * not have it redefined apart from the clump's (sx_ball_set_material
     * refuses the like; this took it silently) */
    if (density_changed && m->balls.clump)
        for (int64_t b = 0; b < m->balls.n; b++) {
            int cm;
            if (!m->balls.clump[b] || sx_clump_material(m, m->balls.clump[b], &cm) != SX_OK) continue;
            const int pm = m->balls.mat[b];
            if ((pm == i) == (cm == i)) continue;
            const double other = m->mats[pm == i ? cm : pm].def.density;
            if (other != d->density)
                return sx__fail(m, SX_EINVAL,
                                "material '%s': a density of %g kg/m^3 would part pebble %lld of clump %lld from its "
                                "clump's density (%g kg/m^3, material '%s'): a clump's pebbles keep one density",
                                name, d->density, (long long)m->balls.id[b], (long long)m->balls.clump[b], other,
                                m->mats[pm == i ? cm : pm].name);
        }
    m->mats[i].def = *d;
    sx__material_derive(&m->mats[i]);
    for (int64_t b = 0; b < m->balls.n; b++) {
        if (m->balls.mat[b] != i) continue;
        if (density_changed) sx__ball_update_mass(m, b);
        if (damping_changed && m->balls.alpha) m->balls.alpha[b] = d->damping; /* else it follows the material */
    }
    if ((density_changed || damping_changed) && m->clumps) /* the bodies of the material, as its balls */
        sx__clumps_material_changed(m, i, density_changed, damping_changed);
    m->dt_stale = true;
    m->guard_dirty = true;
    if (out) *out = i;
    return SX_OK;
}

static double series(double a, double b) { return a + b > 0 ? a * b / (a + b) : 0; }

/* 4-22, 4-23 (springs in series), 4-30 (the smaller friction); a is a
 * material, the other side given by its stiffnesses (a material's or a wall's). */
static sx_pair_law combine(const sx_material_def *a, double kn, double ks, double ec, double ratio, double mu,
                           double bn, double bs)
{
    sx_pair_law l;
    memset(&l, 0, sizeof l);
    l.kn = series(a->kn, kn);
    l.ks = series(a->ks, ks);
    l.mu = a->friction < mu ? a->friction : mu;
    l.beta_n = bn;
    l.beta_s = bs;
    l.dash_n = 4 * bn * bn * l.kn;
    l.per_radius = a->modulus > 0 || ec > 0;
    l.kn_a = a->kn, l.ks_a = a->ks, l.ec_a = a->modulus, l.ratio_a = a->stiffness_ratio;
    l.kn_b = kn, l.ks_b = ks, l.ec_b = ec, l.ratio_b = ratio;
    return l;
}

/* A ball against a wall. A wall of a material mixes with the ball's as a
 * ball's would (the law and its parts see it as b); a plain wall puts its
 * springs in series and the ball's law completes the contact from the
 * ball's material alone (b NULL); a rigid one adds no spring of its own
 * (the ball's kn, ks; for Hertz, laws/hertz.h's rigid plane). */
sx_pair_law sx__wall_law(const sx_model *m, int mat, const sx_wall *w)
{
    return sx__wall_law_of(&m->mats[mat], w->def.material >= 0 ? &m->mats[w->def.material] : NULL, &w->def);
}

sx_pair_law sx__wall_law_of(const sx_material *ball, const sx_material *wm, const sx_wall_def *w)
{
    const sx_material_def *a = &ball->def;
    sx_pair_law l;
    if (wm)
        l = combine(a, wm->def.kn, wm->def.ks, 0, 1, wm->def.friction, 0.5 * (a->viscous_normal + wm->def.viscous_normal),
                    0.5 * (a->viscous_shear + wm->def.viscous_shear));
    else
        l = combine(a, w->kn, w->ks, 0, 1, w->friction, a->viscous_normal, a->viscous_shear);
    const bool rigid = w->material == SX_WALL_RIGID;
    if (rigid) { /* springs in series with an infinite one: the ball's alone */
        l.kn = a->kn, l.ks = a->ks;
        l.dash_n = 4 * l.beta_n * l.beta_n * l.kn;
    }
    l.wall = true;
    l.rigid = rigid;
    l.law = (uint8_t)a->model;
    sx__law(l.law)->mix(&l, ball, wm, l.law);
    sx__law_parts_mix(&l, ball, wm);
    return l;
}

sx_pair_law sx__pair_law_of(const sx_material *ma, const sx_material *mb)
{
    const sx_material_def *a = &ma->def, *b = &mb->def;
    sx_pair_law l = combine(a, b->kn, b->ks, b->modulus, b->stiffness_ratio, b->friction,
                            0.5 * (a->viscous_normal + b->viscous_normal), 0.5 * (a->viscous_shear + b->viscous_shear));
    /* a pair of materials of two laws is refused where it may touch (check_models) */
    l.law = (uint8_t)a->model;
    sx__law(l.law)->mix(&l, ma, mb, l.law);
    sx__law_parts_mix(&l, ma, mb);
    return l;
}

sx_pair_law sx__pair_law(const sx_model *m, int ma, int mb) { return sx__pair_law_of(&m->mats[ma], &m->mats[mb]); }

sx_status sx__refresh_laws(sx_model *m)
{
    const int n = m->nmat;
    if (n != m->law_n) {
        sx_pair_law *q = sx_alloc_resize(&m->alloc, m->law, (size_t)(m->law_n * m->law_n), (size_t)(n * n), sizeof *q);
        if (n && !q) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
        m->law = q;
        m->law_n = n;
    }
    bool plain = true;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            sx_pair_law *l = &m->law[i * n + j];
            *l = sx__pair_law(m, i, j);
            if (!l->plain || l->beta_s > 0) plain = false;
        }
    m->law_plain = plain;
    for (int i = 0; i < n; i++) { /* a law's history joins the pair stores once a material uses it */
        const sx_material_def *d = &m->mats[i].def;
        if ((d->rolling_friction > 0 && sx__pairs_expand(m, offsetof(sx_pairs, mr), m->rdim)) ||
            (d->total_shear == 1 && sx__pairs_expand(m, offsetof(sx_pairs, us), m->dim)))
            return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    }
    return SX_OK;
}

/* Pairs mixing materials of two laws are refused where balls of both
 * exist (the law of such a contact would be ambiguous), and so are bonds
 * between materials of a law that takes none. */
sx_status sx__check_models(sx_model *m)
{
    int first = -1, other = -1;
    for (int64_t i = 0; i < m->balls.n && other < 0; i++) {
        const int k = m->balls.mat[i];
        if (first < 0) first = k;
        else if (m->mats[k].def.model != m->mats[first].def.model) other = k;
    }
    if (other >= 0)
        return sx__fail(m, SX_EINVAL,
                        "contact model: balls of material '%s' (%s) and '%s' (%s) may touch; "
                        "a contact between materials of two laws is not defined: use one model for both",
                        m->mats[first].name, sx_law_name(m->mats[first].def.model), m->mats[other].name,
                        sx_law_name(m->mats[other].def.model));
    /* a wall's material mixes with the balls' under one law, and has no radius for the BPM modulus */
    for (int64_t w = 0; first >= 0 && w < m->nwall; w++) {
        const int k = m->walls[w].def.material;
        if (k < 0) continue;
        if (m->mats[k].def.model != m->mats[first].def.model)
            return sx__fail(m, SX_EINVAL,
                            "contact model: wall %lld is of material '%s' (%s) and balls of material '%s' (%s) may "
                            "touch it; a contact between materials of two laws is not defined: use one model for both",
                            (long long)m->walls[w].id, m->mats[k].name, sx_law_name(m->mats[k].def.model),
                            m->mats[first].name, sx_law_name(m->mats[first].def.model));
        if (m->mats[k].def.modulus > 0)
            return sx__fail(m, SX_EINVAL,
                            "contact model: wall %lld's material '%s' uses the BPM modulus, which needs a ball's "
                            "radius: give it kn and ks",
                            (long long)m->walls[w].id, m->mats[k].name);
    }
    /* a material switched to a law without bonds (or a ball moved onto one)
     * after bonds were installed: the rule holds whenever it is cycled */
    if (first < 0 || sx__law(m->mats[first].def.model)->bonds) return SX_OK;
    const sx_bonds *b = &m->bonds;
    for (int64_t s = 0; s < b->n; s++) {
        if (!b->kind[s]) continue;
        const int ka = m->balls.mat[m->balls.index_of[b->ida[s]]], kb = m->balls.mat[m->balls.index_of[b->idb[s]]];
        const int bad = sx__law(m->mats[ka].def.model)->bonds ? kb : ka;
        if (!sx__law(m->mats[bad].def.model)->bonds)
            return sx__fail(m, SX_EINVAL,
                            "contact model: balls %lld and %lld are bonded but material '%s' uses the %s model "
                            "(%s), which is not to be combined with bonds (seed 4.3.3); use the linear model",
                            (long long)b->ida[s], (long long)b->idb[s], m->mats[bad].name,
                            sx_law_name(m->mats[bad].def.model), sx_law_summary(m->mats[bad].def.model));
    }
    return SX_OK;
}
