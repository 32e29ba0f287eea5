/* Bonds (contact and parallel, seed 4.3.5 and 4-32 ... 4-39, and the flat
 * joint, laws/flatjoint.h), their installation from the bonded-particle
 * micro-parameters (4.4), and the crack log of broken bonds. The bond
 * forces themselves are computed with the contact in kernels.c. */
#include "laws/bonds.h"
#include "laws/law.h"
#include "model_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

sx_bond_def sx_bond_default_def(void)
{
    sx_bond_def d;
    memset(&d, 0, sizeof d);
    d.kind = SX_BOND_PARALLEL;
    d.seed = 1;
    d.material_a = d.material_b = -1;
    /* every micro-parameter not given (NaN): the materials' mean; a 0
     * given is a 0 (a strength's sd, an unbonded fraction, a friction) */
    for (int k = 0; k < sx_bond_key_count(); k++) *sx_bond_key_call(&d, k) = NAN;
    return d;
}

/* ------------------------------------------------------------- storage */

int sx__bond_fields(const sx_model *m, sx_bonds *b, sx_bond_field *f)
{
    const int d = m->dim, r = m->rdim;
    int n = 0;
    f[n++] = (sx_bond_field){(void **)&b->kind, 1, SX_FIELD_U8, false, false};
    f[n++] = (sx_bond_field){(void **)&b->ida, 1, SX_FIELD_I32, false, false};
    f[n++] = (sx_bond_field){(void **)&b->idb, 1, SX_FIELD_I32, false, false};
    f[n++] = (sx_bond_field){(void **)&b->cb_n, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->cb_s, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->rbar, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->kn, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->ks, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->sigma_c, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->tau_c, 1, SX_FIELD_F64, false, false};
    /* the twist (a scalar about n) and the normal force keep their sign
     * when a and b swap; the shear force and bending moment on b become
     * those on a */
    f[n++] = (sx_bond_field){(void **)&b->fn, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->fs, d, SX_FIELD_F64, true, false};
    f[n++] = (sx_bond_field){(void **)&b->mn, 1, SX_FIELD_F64, false, false};
    f[n++] = (sx_bond_field){(void **)&b->ms, r, SX_FIELD_F64, true, false};
    /* a flat joint keeps the orientation it was installed in */
    f[n++] = (sx_bond_field){(void **)&b->fj_first, 1, SX_FIELD_I32, false, true};
    f[n++] = (sx_bond_field){(void **)&b->fj_nr, 1, SX_FIELD_U8, false, true};
    f[n++] = (sx_bond_field){(void **)&b->fj_na, 1, SX_FIELD_U8, false, true};
    f[n++] = (sx_bond_field){(void **)&b->fj_mu, 1, SX_FIELD_F64, false, true};
    f[n++] = (sx_bond_field){(void **)&b->fj_tanphi, 1, SX_FIELD_F64, false, true};
    f[n++] = (sx_bond_field){(void **)&b->fj_d0, 1, SX_FIELD_F64, false, true};
    f[n++] = (sx_bond_field){(void **)&b->fj_rot, d - 1, SX_FIELD_F64, false, true};
    if (d == 3) f[n++] = (sx_bond_field){(void **)&b->fj_axis, 3, SX_FIELD_F64, false, true};
    return n;
}

static sx_status bonds_reserve(sx_model *m, int64_t cap)
{
    sx_bonds *b = &m->bonds;
    if (cap <= b->cap) return SX_OK;
    if (cap < 2 * b->cap) cap = 2 * b->cap;
    if (cap < 256) cap = 256;
    if (cap > INT32_MAX - 1) return SX_ENOMEM;
    sx_bond_field f[SX_BOND_FIELDS_MAX];
    const int nf = sx__bond_fields(m, b, f);
    for (int k = 0; k < nf; k++)
        if (!sx__field_resize(&m->alloc, f[k].data, f[k].per, f[k].type, b->cap, cap)) return SX_ENOMEM;
    b->cap = cap;
    return SX_OK;
}

#define GROW(field, per)                                                                     \
    do {                                                                                     \
        void *q = sx_alloc_resize(&m->alloc, b->field, (size_t)(b->cap * (per)),             \
                                  (size_t)(cap * (per)), sizeof *b->field);                  \
        if (!q) return SX_ENOMEM;                                                            \
        b->field = q;                                                                        \
    } while (0)

/* Room for cap flat-joint elements. */
static sx_status fjels_reserve(sx_model *m, int64_t cap)
{
    sx_fjels *b = &m->fjel;
    if (cap <= b->cap) return SX_OK;
    if (cap < 2 * b->cap) cap = 2 * b->cap;
    if (cap < 256) cap = 256;
    if (cap > INT32_MAX - 1) return SX_ENOMEM;
    GROW(state, 1);
    GROW(sigma_c, 1);
    GROW(coh, 1);
    GROW(gap0, 1);
    GROW(fs, m->dim - 1);
    GROW(fn, 1);
    b->cap = cap;
    return SX_OK;
}
#undef GROW

static void fjels_free(sx_model *m)
{
    sx_fjels *e = &m->fjel;
    const size_t c = (size_t)e->cap;
    sx_alloc *a = &m->alloc;
    sx_alloc_free(a, e->state, c, 1);
    double *arrays[] = {e->sigma_c, e->coh, e->gap0, e->fn};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++) sx_alloc_free(a, arrays[k], c, sizeof(double));
    sx_alloc_free(a, e->fs, c * (size_t)(m->dim - 1), sizeof(double));
    memset(e, 0, sizeof *e);
}

void sx__bonds_free(sx_model *m)
{
    sx_bonds *b = &m->bonds;
    sx_alloc *a = &m->alloc;
    sx_bond_field f[SX_BOND_FIELDS_MAX];
    const int nf = sx__bond_fields(m, b, f);
    for (int k = 0; k < nf; k++) sx_alloc_free(a, *f[k].data, (size_t)(b->cap * f[k].per), sx__field_size(f[k].type));
    memset(b, 0, sizeof *b);
    fjels_free(m);
    sx_alloc_free(a, m->cracks.ev, (size_t)m->cracks.cap, sizeof *m->cracks.ev);
    memset(&m->cracks, 0, sizeof m->cracks);
}

size_t sx__bonds_bytes(const sx_model *m)
{
    sx_bond_field f[SX_BOND_FIELDS_MAX];
    const int nf = sx__bond_fields(m, (sx_bonds *)&m->bonds, f);
    size_t per_bond = 0;
    for (int j = 0; j < nf; j++) per_bond += (size_t)f[j].per * sx__field_size(f[j].type);
    const size_t per_element = 1 + (4 + (size_t)(m->dim - 1)) * sizeof(double);
    return (size_t)m->bonds.cap * per_bond + (size_t)m->fjel.cap * per_element +
           (size_t)m->cracks.cap * sizeof(sx_crack);
}

/* Only ball-ball pairs carry bonds. */
sx_status sx__bonds_reserve_pairs(sx_model *m)
{
    sx_pairs *p = &m->bb;
    if (p->bond || p->cap == 0) return SX_OK;
    p->bond = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)p->cap, sizeof *p->bond);
    return p->bond ? SX_OK : SX_ENOMEM;
}

void sx__bond_break(sx_model *m, int32_t slot, unsigned kind)
{
    sx_bonds *b = &m->bonds;
    const unsigned before = b->kind[slot];
    b->kind[slot] = (uint8_t)(before & ~kind);
    if (before && !b->kind[slot]) b->intact--;
}

/* A bond's vectors on the pair's b become those on a (sx__bond_fields' sign). */
void sx__bond_flip(sx_model *m, int32_t slot)
{
    sx_bond_field f[SX_BOND_FIELDS_MAX];
    const int nf = sx__bond_fields(m, &m->bonds, f);
    for (int k = 0; k < nf; k++)
        if (f[k].sign)
            for (int e = 0; e < f[k].per; e++) ((double *)*f[k].data)[slot * f[k].per + e] *= -1;
}

bool sx__crack_log(sx_model *m, const sx_crack *c)
{
    sx_cracks *k = &m->cracks;
    if (k->n == k->cap) {
        const int64_t cap = k->cap ? 2 * k->cap : 256;
        sx_crack *q = sx_alloc_resize(&m->alloc, k->ev, (size_t)k->cap, (size_t)cap, sizeof *q);
        if (!q) return false;
        k->ev = q;
        k->cap = cap;
    }
    k->ev[k->n++] = *c;
    return true;
}

int64_t sx_bond_count(const sx_model *m) { return m->bonds.intact; }
int64_t sx_crack_count(const sx_model *m) { return m->cracks.n; }

bool sx_model_bond_counts(const sx_model *m, int64_t counts[3])
{
    sx_rows_held held = {.all = true};
    uint64_t v[4] = {0, 0, 0, 0}; /* intact, tension, shear; the ranks that ran out of memory */
    const bool scattered = sx_model_scattered(m);
    if (scattered && !sx__dd_rows_held(m, &held)) v[3] = 1;
    for (int64_t s = 0; !v[3] && s < m->bonds.n; s++) v[0] += (held.all || held.bond[s]) && m->bonds.kind[s];
    for (int64_t i = 0; !v[3] && i < m->cracks.n; i++)
        if (sx__holds_crack(m, &held, i)) v[m->cracks.ev[i].mode == SX_CRACK_TENSION ? 1 : 2]++;
    free(held.bond);
    if ((scattered && !sx__dd_sum(m, v, 4)) || v[3]) return false;
    for (int k = 0; k < 3; k++) counts[k] = (int64_t)v[k];
    return true;
}

sx_status sx_crack_get(const sx_model *m, int64_t i, sx_crack *out)
{
    if (i < 0 || i >= m->cracks.n)
        return sx__fail((sx_model *)m, SX_ENOTFOUND, "crack_get: no crack %lld (there are %lld)", (long long)i,
                        (long long)m->cracks.n);
    *out = m->cracks.ev[i];
    return SX_OK;
}

/* ------------------------------------------------------- micro-parameters */

/* The micro-parameters of d (a material's sx_bpm_def, or with call an
 * installing call's sx_bond_def) in their kinds' ranges (laws/bonds.h). */
static sx_status check_bpm(sx_model *m, const char *who, const void *d, bool call)
{
    char why[256];
    if (sx__bond_params_invalid(d, call, why, sizeof why)) return sx__fail(m, SX_EINVAL, "%s: %s", who, why);
    return SX_OK;
}

sx_status sx_material_set_bpm(sx_model *m, int material, const sx_bpm_def *def)
{
    if (material < 0 || material >= m->nmat)
        return sx__fail(m, SX_ENOTFOUND, "material_set_bpm: no material with index %d", material);
    const sx_status st = check_bpm(m, "material_set_bpm", def, false);
    if (st) return st;
    m->mats[material].bpm = *def;
    return SX_OK;
}

sx_status sx_material_get_bpm(const sx_model *m, int material, sx_bpm_def *out)
{
    if (material < 0 || material >= m->nmat)
        return sx__fail((sx_model *)m, SX_ENOTFOUND, "material_get_bpm: no material with index %d", material);
    *out = m->mats[material].bpm;
    return SX_OK;
}

/* ------------------------------------------------------------ installing */

/* splitmix64: a small, well-mixed generator, so draws depend only on the seed. */
static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double uniform01(uint64_t *s) { return ((double)(next_u64(s) >> 11) + 0.5) * 0x1.0p-53; }

/* A strength from a normal distribution (Box-Muller), redrawn while negative. */
static double draw_strength(uint64_t *s, double mean, double sd)
{
    if (sd <= 0) return mean;
    for (int tries = 0; tries < 64; tries++) {
        const double u1 = uniform01(s), u2 = uniform01(s);
        const double z = sqrt(-2.0 * log(u1)) * cos(2.0 * SX_PI * u2);
        const double v = mean + sd * z;
        if (v >= 0) return v;
    }
    return mean;
}

/* The value given in the def (not NaN), or the mean of the two materials' values. */
static double param(double given, double a, double b) { return isnan(given) ? 0.5 * (a + b) : given; }

/* Whether the def's material filter admits a pair of materials (a, b). */
static bool pair_selected(const sx_bond_def *def, int a, int b)
{
    const int fa = def->material_a, fb = def->material_b;
    if (fa >= 0 && fb >= 0) return (a == fa && b == fb) || (a == fb && b == fa);
    const int f = fa >= 0 ? fa : fb;
    return f < 0 || a == f || b == f;
}

/* Whether bonds of def's kind can join materials ma and mb: their law takes
 * bonds (not Hertz: the seed, 4.3.3), and every parameter the bond needs is positive once the
 * materials' values fill what the call does not give (NaN). Checked for every
 * candidate pair before any bond is installed, so a refused call changes nothing. */
static sx_status check_pair(sx_model *m, const sx_bond_def *def, int ma, int mb)
{
    const int law = m->law[ma * m->law_n + mb].law;
    if (!sx__law(law)->bonds)
        return sx__fail(m, SX_EINVAL,
                        "bond: materials '%s' and '%s' use the %s model (%s), which is not to be combined "
                        "with bonds (seed 4.3.3); use the linear model for bonded materials",
                        m->mats[ma].name, m->mats[mb].name, sx_law_name(law), sx_law_summary(law));
    const sx_bpm_def *pa = &m->mats[ma].bpm, *pb = &m->mats[mb].bpm;
    if (def->kind == SX_BOND_CONTACT) {
        if (!(param(def->normal_strength, pa->normal_strength, pb->normal_strength) > 0) ||
            !(param(def->shear_strength, pa->shear_strength, pb->shear_strength) > 0))
            return sx__fail(m, SX_EINVAL,
                            "bond: a contact bond between '%s' and '%s' needs normal_strength and shear_strength > 0 N "
                            "(from the call or the materials' bond parameters)",
                            m->mats[ma].name, m->mats[mb].name);
        return SX_OK;
    }
    const char *what = def->kind == SX_BOND_FLATJOINT ? "flat joint" : "parallel bond";
    if (!(param(def->radius_multiplier, pa->radius_multiplier, pb->radius_multiplier) > 0) ||
        !(param(def->modulus, pa->modulus, pb->modulus) > 0) ||
        !(param(def->stiffness_ratio, pa->stiffness_ratio, pb->stiffness_ratio) > 0) ||
        !(param(def->tensile_strength, pa->tensile_strength, pb->tensile_strength) > 0) ||
        !(param(def->cohesion, pa->cohesion, pb->cohesion) > 0))
        return sx__fail(m, SX_EINVAL,
                        "bond: a %s between '%s' and '%s' needs radius_multiplier, modulus, "
                        "stiffness_ratio, tensile_strength and cohesion > 0 (from the call or the materials' bond "
                        "parameters)",
                        what, m->mats[ma].name, m->mats[mb].name);
    return SX_OK;
}

/* x_b - x_a of pair c where its balls are now: a periodic ghost b is its
 * ball plus its shift (its slot is as the last contact pass copied it, a
 * step behind, unless m:bond's build with its gap made it anew: the
 * decision to bond and the bond's starting geometry must not depend on
 * which). */
static void pair_rel(const sx_model *m, int64_t c, double *rel)
{
    const int d = m->dim;
    const sx_balls *B = &m->balls;
    const int64_t i = m->bb.a[c];
    int64_t j = m->bb.b[c];
    double shift[3] = {0, 0, 0};
    if (m->cell) {
        const int64_t o = sx__cell_owner(m, j, shift);
        if (o >= 0) j = o;
        else shift[0] = shift[1] = shift[2] = 0;
    }
    for (int k = 0; k < d; k++) rel[k] = (B->x[j * d + k] + shift[k]) - B->x[i * d + k];
}

/* The gap d - RA - RB of pair c, and its unit normal from a to b in n. */
static double pair_gap(const sx_model *m, int64_t c, double *n)
{
    const int d = m->dim;
    const sx_balls *B = &m->balls;
    const int64_t i = m->bb.a[c], j = m->bb.b[c];
    double dist = 0;
    pair_rel(m, c, n);
    for (int k = 0; k < d; k++) dist += n[k] * n[k];
    dist = sqrt(dist);
    for (int k = 0; k < d; k++) n[k] /= dist;
    return dist - B->rad[i] - B->rad[j];
}

/* Whether pair c is to be bonded: its surfaces closer than gap, or than
 * touching. */
static bool within_gap(const sx_model *m, int64_t c, double *n, double gap)
{
    const double t = sx__touching(m->balls.rad[m->bb.a[c]], m->balls.rad[m->bb.b[c]]);
    return pair_gap(m, c, n) < (gap > t ? gap : t);
}

/* A value of the def, or the mean of the materials', or the default. */
static double param_or(double given, double a, double b, double fallback)
{
    const double v = param(given, a, b);
    return v > 0 ? v : fallback;
}

/* The flat joint of bond slot s on pair c (normal n from a to b, the
 * joint's orientation): its face (laws/flatjoint.h) from the pair's
 * current geometry, stress free, and its elements' states and strengths
 * drawn from rng in element order. */
static sx_status install_flat_joint(sx_model *m, const sx_bond_def *def, int32_t s, int64_t c, const double *n,
                                    uint64_t *rng)
{
    const int d = m->dim;
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    const int64_t i = p->a[c], j = p->b[c];
    const sx_bpm_def *pa = &m->mats[B->mat[i]].bpm, *pb = &m->mats[B->mat[j]].bpm;
    /* a count given as 0 is the material's, as a material's 0 is the default */
    const double ge = def->elements > 0 ? def->elements : NAN, gs = def->sectors > 0 ? def->sectors : NAN;
    const int nr = (int)param_or(ge, pa->elements, pb->elements, d == 2 ? 4 : 2);
    const int na = d == 2 ? 1 : (int)param_or(gs, pa->sectors, pb->sectors, 4);
    sx_fjels *E = &m->fjel;
    if (E->n + nr * na > INT32_MAX - 1 || fjels_reserve(m, E->n + nr * na))
        return sx__fail(m, SX_ENOMEM, "bond: out of memory");
    sx_bonds *b = &m->bonds;
    const double ri = B->rad[i], rj = B->rad[j];
    b->rbar[s] = param(def->radius_multiplier, pa->radius_multiplier, pb->radius_multiplier) * (ri < rj ? ri : rj);
    b->kn[s] = param(def->modulus, pa->modulus, pb->modulus) / (ri + rj);          /* 4-51 */
    b->ks[s] = b->kn[s] / param(def->stiffness_ratio, pa->stiffness_ratio, pb->stiffness_ratio); /* 4-52 */
    b->fj_mu[s] = param(def->friction, pa->friction, pb->friction);
    b->fj_tanphi[s] = tan(param(def->friction_angle, pa->friction_angle, pb->friction_angle) * SX_PI / 180);
    b->fj_first[s] = (int32_t)E->n;
    b->fj_nr[s] = (uint8_t)nr;
    b->fj_na[s] = (uint8_t)na;
    double rel[3], dist = 0;
    pair_rel(m, c, rel);
    for (int k = 0; k < d; k++) dist += rel[k] * rel[k];
    b->fj_d0[s] = sqrt(dist);
    for (int k = 0; k < d - 1; k++) b->fj_rot[s * (d - 1) + k] = 0;
    if (d == 3) { /* t1: the world axis least along n, made normal to n */
        int least = 0;
        for (int k = 1; k < 3; k++)
            if (fabs(n[k]) < fabs(n[least])) least = k;
        double *t = b->fj_axis + s * 3;
        for (int k = 0; k < 3; k++) t[k] = (k == least) - n[least] * n[k];
        const double len = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        for (int k = 0; k < 3; k++) t[k] /= len;
    }
    const double fraction = param(def->unbonded_fraction, pa->unbonded_fraction, pb->unbonded_fraction);
    /* a gapped face: its balls apart, every element open by their surface gap */
    const double surface = b->fj_d0[s] - ri - rj;
    const bool gapped = def->gapped && surface > sx__touching(ri, rj); /* touching balls: a closed face */
    const double gap0 = gapped ? surface : param(def->initial_gap, pa->initial_gap, pb->initial_gap);
    for (int e = 0; e < nr * na; e++) {
        const int64_t x = E->n++;
        const bool bonded = !gapped && !(fraction > 0 && uniform01(rng) < fraction);
        E->state[x] = (uint8_t)(bonded ? SX_FJ_BONDED : SX_FJ_UNBONDED);
        E->gap0[x] = bonded ? 0 : gap0;
        E->sigma_c[x] = draw_strength(rng, param(def->tensile_strength, pa->tensile_strength, pb->tensile_strength),
                                      param(def->tensile_strength_sd, pa->tensile_strength_sd, pb->tensile_strength_sd));
        E->coh[x] = draw_strength(rng, param(def->cohesion, pa->cohesion, pb->cohesion),
                                  param(def->cohesion_sd, pa->cohesion_sd, pb->cohesion_sd));
        E->fn[x] = 0;
        for (int k = 0; k < d - 1; k++) E->fs[x * (d - 1) + k] = 0;
    }
    for (int k = 0; k < d; k++) p->fs[c * d + k] = 0; /* the joint replaces the contact and its shear spring */
    return SX_OK;
}

sx_status sx_bond_install(sx_model *m, const sx_bond_def *def, int64_t *count)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "bond: the model is stepping");
    if (def->kind != SX_BOND_CONTACT && def->kind != SX_BOND_PARALLEL && def->kind != SX_BOND_FLATJOINT)
        return sx__fail(m, SX_EINVAL, "bond: kind must be contact, parallel or flatjoint");
    if (!(def->gap >= 0) || !isfinite(def->gap))
        return sx__fail(m, SX_EINVAL, "bond: gap must be >= 0 m (got %g)", def->gap);
    sx_status st = check_bpm(m, "bond", def, true);
    if (st) return st;
    if (def->material_a >= m->nmat || def->material_b >= m->nmat)
        return sx__fail(m, SX_ENOTFOUND, "bond: no material with index %d",
                        def->material_a >= m->nmat ? def->material_a : def->material_b);

    /* candidates within the gap: rebuild the broad phase with a skin at
     * least that wide, and at least the touching tolerance's (a gap of
     * 1e-18 m made the skin that, and pairs 2e-15 m apart went unlisted) */
    const double skin_user = m->skin_user;
    double rmax = 0;
    for (int64_t i = 0; i < m->balls.n; i++) rmax = fmax(rmax, m->balls.rad[i]);
    const double skin_gap = fmax(def->gap, 2 * sx__touching(rmax, rmax));
    if (def->gap > 0 && m->skin_user < skin_gap) m->skin_user = skin_gap;
    m->build_needed = true;
    st = sx__prepare(m);
    m->skin_user = skin_user;
    m->build_needed = true; /* back to the normal skin; bonded pairs are kept */
    if (st) return st;
    if ((st = sx__bonds_reserve_pairs(m))) return sx__fail(m, st, "bond: out of memory");

    const int d = m->dim;
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    /* every pair checked before any is bonded: a Ctrl-C stops the scan with no bond installed (the
     * installing pass that follows is as long as this one) */
    for (int64_t c = 0; c < p->n; c++) {
        if (c % 4096 == 0 && sx__interrupted(m))
            return sx__fail(m, SX_EINTERRUPT, "bond: interrupted (no bond installed)");
        const int ma = B->mat[p->a[c]], mb = B->mat[p->b[c]];
        double n[3];
        if (!pair_selected(def, ma, mb) || !within_gap(m, c, n, def->gap)) continue;
        if ((st = check_pair(m, def, ma, mb))) return st;
        /* a flat joint is its pair's contact: it takes no other bond */
        const unsigned has = p->bond[c] > 0 ? m->bonds.kind[p->bond[c] - 1] : 0;
        if (has && (has & SX_BOND_FLATJOINT) != (def->kind & SX_BOND_FLATJOINT))
            return sx__fail(m, SX_EINVAL,
                            "bond: balls %d and %d already have a %s; a flat joint replaces the contact and is not "
                            "combined with other bonds",
                            B->id[p->a[c]], B->id[p->b[c]], has & SX_BOND_FLATJOINT ? "flat joint" : "bond");
    }
    uint64_t rng = def->seed;
    int64_t installed = 0;
    for (int64_t c = 0; c < p->n; c++) {
        const int64_t i = p->a[c], j = p->b[c];
        const int ma = B->mat[i], mb = B->mat[j];
        if (!pair_selected(def, ma, mb)) continue;
        double n[3] = {0, 0, 0};
        if (!within_gap(m, c, n, def->gap)) continue;
        int32_t slot = p->bond[c] - 1;
        if (slot < 0) {
            if (bonds_reserve(m, m->bonds.n + 1)) return sx__fail(m, SX_ENOMEM, "bond: out of memory");
            slot = (int32_t)m->bonds.n++;
            sx_bonds *b = &m->bonds;
            b->kind[slot] = 0;
            b->ida[slot] = B->id[i];
            b->idb[slot] = B->id[j];
            b->fn[slot] = b->mn[slot] = 0;
            for (int k = 0; k < d; k++) b->fs[slot * d + k] = 0;
            for (int k = 0; k < m->rdim; k++) b->ms[slot * m->rdim + k] = 0;
            p->bond[c] = slot + 1;
        }
        sx_bonds *b = &m->bonds;
        if (b->kind[slot] & def->kind) continue; /* already bonded this way */
        const sx_bpm_def *pa = &m->mats[ma].bpm, *pb = &m->mats[mb].bpm;
        if (def->kind == SX_BOND_CONTACT) {
            b->cb_n[slot] = draw_strength(&rng, param(def->normal_strength, pa->normal_strength, pb->normal_strength),
                                          param(def->normal_strength_sd, pa->normal_strength_sd, pb->normal_strength_sd));
            b->cb_s[slot] = draw_strength(&rng, param(def->shear_strength, pa->shear_strength, pb->shear_strength),
                                          param(def->shear_strength_sd, pa->shear_strength_sd, pb->shear_strength_sd));
        } else if (def->kind == SX_BOND_FLATJOINT) {
            if ((st = install_flat_joint(m, def, slot, c, n, &rng))) return st;
            b = &m->bonds;
        } else {
            const double lambda = param(def->radius_multiplier, pa->radius_multiplier, pb->radius_multiplier);
            const double ec = param(def->modulus, pa->modulus, pb->modulus);
            const double ratio = param(def->stiffness_ratio, pa->stiffness_ratio, pb->stiffness_ratio);
            const double ri = B->rad[i], rj = B->rad[j];
            b->rbar[slot] = lambda * (ri < rj ? ri : rj);             /* 4-53 */
            b->kn[slot] = ec / (ri + rj);                             /* 4-51 */
            b->ks[slot] = b->kn[slot] / ratio;                        /* 4-52 */
            b->sigma_c[slot] = draw_strength(&rng, param(def->tensile_strength, pa->tensile_strength, pb->tensile_strength),
                                             param(def->tensile_strength_sd, pa->tensile_strength_sd, pb->tensile_strength_sd));
            b->tau_c[slot] = draw_strength(&rng, param(def->cohesion, pa->cohesion, pb->cohesion),
                                           param(def->cohesion_sd, pa->cohesion_sd, pb->cohesion_sd));
        }
        if (!b->kind[slot]) b->intact++;
        b->kind[slot] |= (uint8_t)def->kind;
        if (!p->touching[c]) { /* the bond starts from the current geometry: the relative position */
            pair_rel(m, c, p->geo + c * d);
            for (int k = 0; k < d; k++) p->fs[c * d + k] = 0;
            p->touching[c] = 1;
            if (p->cmodel) p->cmodel[c] = sx__cmodel_pick(m, i, j); /* a contact created: its row (cmodel.c) */
        }
        installed++;
    }
    m->dt_stale = true;
    m->guard_dirty = true; /* a bond across a gap starts in tension: the strain jumps (a new baseline) */
    if (count) *count = installed;
    return SX_OK;
}

/* --------------------------------------------------------- flat joints */

/* The flat-joint slot joining balls a and b (either order) and its pair,
 * or -1. */
static int32_t flat_joint_of(const sx_model *m, int64_t a, int64_t b, int64_t *pair)
{
    const sx_pairs *p = &m->bb;
    for (int64_t c = 0; p->bond && c < p->n; c++) {
        const int32_t s = p->bond[c] - 1;
        if (s < 0 || !(m->bonds.kind[s] & SX_BOND_FLATJOINT)) continue;
        const int32_t ia = m->bonds.ida[s], ib = m->bonds.idb[s];
        if ((ia == a && ib == b) || (ia == b && ib == a)) {
            *pair = c;
            return s;
        }
    }
    return -1;
}

int sx_flatjoint_get(const sx_model *m, int64_t a, int64_t b, int e, sx_fj_element *out)
{
    int64_t c;
    const int32_t s = flat_joint_of(m, a, b, &c);
    if (s < 0) return 0;
    const sx_bonds *k = &m->bonds;
    const int d = m->dim, nel = k->fj_nr[s] * k->fj_na[s];
    if (!out || e < 0 || e >= nel) return nel;
    /* the joint's normal and axes at the last evaluation (geo: x_b - x_a of the pair) */
    const double *rel = m->bb.geo + c * d;
    const double dist = sqrt(rel[0] * rel[0] + rel[1] * rel[1] + (d == 3 ? rel[2] * rel[2] : 0));
    const double sg = m->balls.id[m->bb.a[c]] == k->ida[s] ? 1 : -1;
    double n[3] = {0, 0, 0}, t1[3] = {0, 0, 0}, t2[3] = {0, 0, 0};
    for (int q = 0; q < d; q++) n[q] = sg * rel[q] / dist;
    if (d == 3) {
        for (int q = 0; q < 3; q++) t1[q] = k->fj_axis[s * 3 + q];
        t2[0] = n[1] * t1[2] - n[2] * t1[1], t2[1] = n[2] * t1[0] - n[0] * t1[2], t2[2] = n[0] * t1[1] - n[1] * t1[0];
    } else {
        t1[0] = -n[1], t1[1] = n[0];
    }
    const double ay = d == 3 ? -k->fj_rot[s * 2 + 1] : -k->fj_rot[s], az = d == 3 ? k->fj_rot[s * 2] : 0;
    sx_law_fj_geom g;
    sx_law_fj_element(d, k->rbar[s], k->fj_nr[s], k->fj_na[s], e, &g);
    const sx_fjels *E = &m->fjel;
    const int64_t x = k->fj_first[s] + e;
    const int64_t ia = sx__ball_index(m, k->ida[s]);
    memset(out, 0, sizeof *out);
    out->state = (sx_fj_state)E->state[x];
    out->area = g.area;
    /* the contact point of 4-4 from a's current centre, then the element's offset */
    const double ra = m->balls.rad[ia], rb = m->balls.rad[sx__ball_index(m, k->idb[s])];
    const double arm = ra - 0.5 * (ra + rb - dist);
    for (int q = 0; q < d; q++) out->centroid[q] = m->balls.x[ia * d + q] + arm * n[q] + g.y * t1[q] + g.z * t2[q];
    out->gap = E->gap0[x] + (dist - k->fj_d0[s]) + ay * g.y + az * g.z;
    out->fn = E->fn[x];
    double f2 = 0;
    for (int q = 0; q < d - 1; q++) f2 += E->fs[x * (d - 1) + q] * E->fs[x * (d - 1) + q];
    out->fs = sqrt(f2);
    out->tensile_strength = E->sigma_c[x];
    out->cohesion = E->coh[x];
    return nel;
}

sx_status sx_flatjoint_unbond(sx_model *m, int64_t a, int64_t b, int e)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "flatjoint_unbond: the model is stepping");
    int64_t c;
    const int32_t s = flat_joint_of(m, a, b, &c);
    if (s < 0)
        return sx__fail(m, SX_ENOTFOUND, "flatjoint_unbond: no flat joint between balls %lld and %lld", (long long)a,
                        (long long)b);
    const int nel = m->bonds.fj_nr[s] * m->bonds.fj_na[s];
    if (e < 0 || e >= nel)
        return sx__fail(m, SX_EINVAL, "flatjoint_unbond: element %d out of range 0 to %d (from 0)", e, nel - 1);
    uint8_t *st = &m->fjel.state[m->bonds.fj_first[s] + e];
    if (*st == SX_FJ_BONDED) *st = SX_FJ_UNBONDED;
    m->guard_dirty = true; /* the element's strain may go: a new baseline */
    return SX_OK;
}
