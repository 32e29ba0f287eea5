/* The model: owner of all storage, the material table and the step
 * pipeline. The pipeline is
 *     broad phase (when needed) -> timestep (auto) -> contact forces
 *     -> law of motion -> walls -> time, guard
 * with the dimension-specific stages in kernels.c. */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <stdatomic.h>
#include <math.h>
#include <stddef.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* How often the automatic timestep is re-estimated between builds, and how
 * often the energy guard looks at an unforced system. */
enum { DT_REFRESH_STEPS = 32, GUARD_STEPS = 64 };

/* The largest gravity component, as for a ball's fields: a step's velocity
 * g dt must square without overflowing, or the state cannot be saved and
 * loaded (a robustness tester's 1e308 did both, silently). */
#define SX_GRAVITY_MAX 1e100
/* An unforced system whose mechanical energy grows past this many times its
 * initial scale is numerically unstable. */
#define GUARD_ENERGY_FACTOR 100.0

sx_status sx__fail(sx_model *m, sx_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->err, sizeof m->err, fmt, ap);
    va_end(ap);
    return st;
}

static const sx_kernels *kernels(const sx_model *m) { return m->dim == 2 ? &sx_kernels_2d : &sx_kernels_3d; }

sx_model_def sx_model_default_def(void)
{
    sx_model_def d;
    memset(&d, 0, sizeof d);
    d.dim = 3;
    d.timestep_safety = 0.8;
    return d;
}

/* A user timestep: 0 (automatic), or from 1e-15 s (below, a step no
 * longer advances the time of a long run; a denormal is no timestep) to
 * 1 s (a DEM timestep is orders of magnitude below: a larger one is a
 * mistake of units). */
static bool timestep_ok(double dt) { return dt == 0 || (dt >= 1e-15 && dt <= 1); }

sx_model *sx_model_create(const sx_model_def *def, char *err, size_t errlen)
{
    const char *why = NULL;
    if (def->dim != 2 && def->dim != 3) why = "dim must be 2 or 3";
    else if (!timestep_ok(def->timestep)) why = "timestep must be 0 (automatic) or in [1e-15, 1] s";
    else if (!(def->timestep_safety > 0 && def->timestep_safety <= 1)) why = "timestep_safety must be in (0, 1]";
    else if (!(def->skin >= 0) || !isfinite(def->skin)) why = "skin must be >= 0 (0 = automatic)";
    for (int k = 0; k < 3 && !why; k++)
        if (!(fabs(def->gravity[k]) < SX_GRAVITY_MAX)) why = "gravity components must be finite and below 1e100 m/s^2";
    if (!why && def->dim == 2 && def->gravity[2] != 0) why = "a 2D model has no z gravity component";
    if (why) {
        if (err) snprintf(err, errlen, "model_create: %s", why);
        return NULL;
    }
    sx_model *m = calloc(1, sizeof *m);
    if (!m) {
        if (err) snprintf(err, errlen, "model_create: out of memory");
        return NULL;
    }
    m->dim = def->dim;
    m->rdim = def->dim == 3 ? 3 : 1;
    memcpy(m->gravity, def->gravity, sizeof m->gravity);
    m->dt_user = def->timestep;
    m->dt_safety = def->timestep_safety;
    m->skin_user = def->skin;
    m->dt_stale = true;
    m->build_needed = true;
    m->guard_dirty = true;
    m->threads = 1;
    return m;
}

void sx_model_destroy(sx_model *m)
{
    if (!m) return;
    sx__balls_free(m);
    sx__pairs_free(m, &m->bb);
    sx__pairs_free(m, &m->bw);
    sx__walls_free(m);
    sx__bonds_free(m);
    sx__clumps_free(m);
    sx__cell_free(m);
    sx__dd_free(m);
    sx__joints_free(m);
    for (int64_t c = 0; c < m->cap_chunk; c++) free(m->chunks[c].cracks);
    sx_alloc_free(&m->alloc, m->chunks, (size_t)m->cap_chunk, sizeof *m->chunks);
    sx_alloc_free(&m->alloc, m->blocks, m->blocks ? SX_MOTION_BLOCKS : 0, sizeof *m->blocks);
    sx_alloc_free(&m->alloc, m->wall_acc, (size_t)m->cap_wall_acc, sizeof *m->wall_acc);
    sx_alloc_free(&m->alloc, m->wlaw, (size_t)m->cap_wlaw, sizeof *m->wlaw);
    sx_alloc_free(&m->alloc, m->grid.start, (size_t)m->grid.cap_cells, sizeof(int32_t));
    sx_alloc_free(&m->alloc, m->law, (size_t)(m->law_n * m->law_n), sizeof *m->law);
    sx_alloc_free(&m->alloc, m->scratch, (size_t)m->scratch_cap, sizeof(double));
    sx_alloc_free(&m->alloc, m->dash_im, (size_t)m->cap_dash_im, sizeof(double));
    sx_alloc_free(&m->alloc, m->visc_f, (size_t)(m->cap_visc * m->dim), sizeof(double));
    sx_alloc_free(&m->alloc, m->visc_t, (size_t)(m->cap_visc * m->rdim), sizeof(double));
    sx_alloc_free(&m->alloc, m->mats, (size_t)m->cap_mat, sizeof *m->mats);
    sx_alloc_free(&m->alloc, m->cmodel, (size_t)m->cap_cmodel, sizeof *m->cmodel);
    free(m);
}

const char *sx_model_error(const sx_model *m) { return m->err; }
int sx_model_dim(const sx_model *m) { return m->dim; }
double sx_model_time(const sx_model *m) { return m->time; }
int64_t sx_model_step_count(const sx_model *m) { return m->step; }
size_t sx_model_bytes(const sx_model *m) { return m->alloc.bytes; }

sx_memory sx_model_memory(const sx_model *m)
{
    sx_memory r;
    memset(&r, 0, sizeof r);
    r.total = m->alloc.bytes;
    r.peak = m->alloc.peak;
    r.balls = sx__balls_bytes(m);
    r.contacts = sx__pairs_bytes(m, &m->bb) + sx__pairs_bytes(m, &m->bw) + sx__cell_bytes(m) + sx__joints_bytes(m);
    const sx_bonds *k = &m->bonds;
    const size_t d = (size_t)m->dim;
    const size_t per_bond = 3 + 3 * sizeof(int32_t) +
                            (12 + d + (size_t)m->rdim + (d - 1) + (d == 3 ? 3 : 0)) * sizeof(double);
    const size_t per_element = 1 + (4 + (d - 1)) * sizeof(double);
    r.bonds = (size_t)k->cap * per_bond + (size_t)m->fjel.cap * per_element + (size_t)m->cracks.cap * sizeof(sx_crack);
    r.work = r.total - r.balls - r.contacts - r.bonds;
    r.ball_count = m->balls.n;
    r.pair_count = m->bb.n + m->bw.n;
    r.contact_count = kernels(m)->count_contacts(m);
    r.bytes_per_ball = r.ball_count ? (double)r.balls / (double)r.ball_count : 0;
    r.bytes_per_contact = r.contact_count ? (double)r.contacts / (double)r.contact_count : 0;
    return r;
}
void sx_model_interrupt(sx_model *m) { m->interrupt = 1; }

/* A signal handler sets it, the core's long loops read it: lock-free */
static atomic_int interrupt_requested;

void sx_interrupt_request(void) { atomic_store(&interrupt_requested, 1); }

int sx_interrupt_pending(void) { return atomic_load(&interrupt_requested); }

void sx_interrupt_clear(void) { atomic_store(&interrupt_requested, 0); }

bool sx__speed_rated(const sx_model *m)
{
    if (m->dt_user > 0) return false;
    for (int k = 0; k < m->law_n; k++)
        if (sx__law_stiffens(m->law[k * m->law_n + k].law)) return true;
    for (int row = 0; row < m->ncmodel; row++)
        if (sx__law_stiffens(m->cmodel[row].law.law)) return true;
    return false;
}

/* a model's own flag only while it cycles: it stays set after the cycle it stopped */
bool sx__interrupted(const sx_model *m) { return (m->locked && m->interrupt) || atomic_load(&interrupt_requested); }

sx_status sx_model_set_threads(sx_model *m, int threads)
{
    if (threads < 1 || threads > 1024)
        return sx__fail(m, SX_EINVAL, "set_threads: the thread count must be in 1..1024 (got %d)", threads);
    m->threads = threads;
    return SX_OK;
}

int sx_model_threads(const sx_model *m) { return m->threads; }

void sx_model_gravity(const sx_model *m, double out[3]) { memcpy(out, m->gravity, sizeof m->gravity); }

sx_status sx_model_set_gravity(sx_model *m, const double g[3])
{
    for (int k = 0; k < m->dim; k++)
        if (!(fabs(g[k]) < SX_GRAVITY_MAX))
            return sx__fail(m, SX_EINVAL, "set_gravity: components must be finite and below 1e100 m/s^2 (got %g)", g[k]);
    for (int k = 0; k < m->dim; k++) m->gravity[k] = g[k];
    m->guard_dirty = true;
    return SX_OK;
}

void sx__scratch_release(sx_model *m)
{
    sx_alloc_free(&m->alloc, m->scratch, (size_t)m->scratch_cap, sizeof *m->scratch);
    m->scratch = NULL;
    m->scratch_cap = 0;
}

double *sx__scratch(sx_model *m, int64_t n)
{
    if (n > m->scratch_cap) {
        double *q = sx_alloc_resize(&m->alloc, m->scratch, (size_t)m->scratch_cap, (size_t)n, sizeof *q);
        if (!q) return NULL;
        m->scratch = q;
        m->scratch_cap = n;
    }
    return m->scratch;
}

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

static sx_status refresh_laws(sx_model *m)
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
static sx_status check_models(sx_model *m)
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

/* ------------------------------------------------------------- timestep */

/* A user's skin so wide that nearly every pair of balls is a candidate
 * (skin = 1e3 m, or m:bond's gap over a large assembly) would build for
 * minutes, uninterruptibly, and exhaust memory: refused before the build,
 * from the pairs a uniform spread of the balls over their bounding box
 * would give (cubes of the reach's width: an overestimate). */
static sx_status check_skin(sx_model *m)
{
    const sx_balls *b = &m->balls;
    if (m->skin_user <= 0 || b->n < 2) return SX_OK;
    const int d = m->dim;
    double lo[3], hi[3], rmax = 0;
    for (int k = 0; k < d; k++) lo[k] = hi[k] = b->x[k];
    for (int64_t i = 0; i < b->n; i++) {
        for (int k = 0; k < d; k++) {
            lo[k] = fmin(lo[k], b->x[i * d + k]);
            hi[k] = fmax(hi[k], b->x[i * d + k]);
        }
        rmax = fmax(rmax, b->rad[i]);
    }
    const double reach = 2 * rmax + m->skin_user;
    double share = 1;
    for (int k = 0; k < d; k++) share *= fmin(1, 2 * reach / fmax(hi[k] - lo[k], DBL_MIN));
    const double pairs = 0.5 * (double)b->n * (double)(b->n - 1) * share, most = 200.0 * (double)b->n + 1e6;
    if (pairs > most)
        return sx__fail(m, SX_EINVAL,
                        "broad phase: a skin of %g m makes about %.3g candidate pairs of %lld balls (more than %.3g): "
                        "lower the skin (m:bond's gap widens it)",
                        m->skin_user, pairs, (long long)b->n, most);
    return SX_OK;
}

/* A build that did not finish left the model as it was before it. */
static sx_status build_failed(sx_model *m, sx_status st)
{
    if (st == SX_EINTERRUPT)
        return sx__fail(m, st, "interrupted in the broad phase at step %lld (the model is as it was)", (long long)m->step);
    return sx__fail(m, SX_ENOMEM, "broad phase: out of memory");
}

/* Broad phase and laws up to date, so timestep queries see current contacts. */
sx_status sx__prepare(sx_model *m)
{
    sx_status st = refresh_laws(m);
    if (!st) st = check_models(m);
    if (!st && m->ncmodel) st = sx__cmodel_prepare(m);
    if (!st && m->build_needed) st = check_skin(m);
    if (st) return st;
    if (m->build_needed && m->cell && (st = sx__cell_check(m))) return st;
    if (m->build_needed && (st = kernels(m)->build(m))) return build_failed(m, st);
    return SX_OK;
}

/* The critical timestep; decomposed, each rank rates its own balls: the
 * smallest of all (exact). False: the ranks could not exchange. */
static bool critical(sx_model *m, double *crit)
{
    *crit = kernels(m)->critical_dt(m);
    if (!m->dd || !m->dd->active) return true;
    *crit = -*crit;
    if (!m->dd->x.max(m->dd->x.ud, crit)) return false;
    *crit = -*crit;
    return true;
}

/* The timestep the next step takes: the user's, the automatic one in use,
 * or, when that is stale or due for a refresh, safety x critical. */
static sx_status next_timestep(sx_model *m, double *dt)
{
    *dt = m->dt;
    if (m->dt_user > 0) {
        *dt = m->dt_user;
    } else if (m->dt_stale || m->step % DT_REFRESH_STEPS == 0 || !(m->dt > 0)) {
        /* decomposed: the ghosts where the last step left them, as the serial run reads them */
        if (m->dd && m->dd->active && !sx__dd_halo(m))
            return sx__fail(m, SX_EINVAL, "timestep: the ranks could not exchange ghosts");
        double crit;
        if (!critical(m, &crit))
            return sx__fail(m, SX_EINVAL, "timestep: the ranks could not exchange their estimates");
        if (!isfinite(crit))
            return sx__fail(m, SX_EINVAL,
                            "timestep: no ball to estimate the automatic timestep from; add balls or set a timestep");
        *dt = m->dt_safety * crit;
        /* the user's timestep has the same floor: below it the steps no
         * longer advance the time (a stiffness of 1e300 N/m gave 0 s, and
         * cycles that counted steps at a standstill) */
        if (!(*dt >= 1e-15))
            return sx__fail(m, SX_EINVAL,
                            "timestep: the automatic timestep is %g s, below 1e-15 s: a stiffness far too large for "
                            "the masses (see m:materials() and the walls' kn)", *dt);
    }
    return SX_OK;
}

static sx_status update_timestep(sx_model *m)
{
    const sx_status st = next_timestep(m, &m->dt);
    if (!st) m->dt_stale = false;
    return st;
}

double sx_model_critical_timestep(sx_model *m)
{
    if (sx__prepare(m)) return NAN;
    return kernels(m)->critical_dt(m);
}

/* A query: the timestep is computed, not stored, so that asking for it
 * leaves the state (and its hash) as it was. */
double sx_model_timestep(sx_model *m)
{
    if (m->dt_user > 0) return m->dt_user;
    double dt = NAN;
    if (sx__prepare(m) || next_timestep(m, &dt)) return NAN;
    return dt;
}

sx_status sx_model_set_timestep(sx_model *m, double dt)
{
    if (!timestep_ok(dt))
        return sx__fail(m, SX_EINVAL, "set_timestep: the timestep must be in [1e-15, 1] s, or 0 for automatic (got %g)",
                        dt);
    m->dt_user = dt;
    m->dt_stale = true;
    return SX_OK;
}

/* ---------------------------------------------------------------- guard */

/* An unforced system (no moving wall, no applied load, no fixed velocity
 * that could inject energy) cannot gain mechanical energy: if it does by
 * orders of magnitude, the integration is unstable. */
static bool unforced(const sx_model *m)
{
    for (int64_t w = 0; w < m->nwall; w++) {
        /* a servo sets its wall moving, and a cylinder's radius moves at radial_vel */
        if (m->walls[w].servo_on || m->walls[w].def.radial_vel != 0) return false;
        for (int k = 0; k < m->dim; k++)
            if (m->walls[w].def.vel[k] != 0 || m->walls[w].def.spin[k] != 0) return false;
    }
    if (m->balls.fapp) return false;
    if (m->cell && m->cell->controlled) return false; /* the deforming cell does work on the balls */
    /* a fixed component moving at its imposed velocity does work; one held
     * at rest does none (a ball fixed as an obstacle or a rough floor), so
     * the guard stays on for it (a physics check: a bonded pair with one
     * ball fixed at rest, at 5 times the critical timestep, left at 2.8e11
     * m/s with the guard off) */
    const sx_balls *B = &m->balls;
    for (int64_t i = 0; i < B->n; i++) {
        if (!B->fix[i]) continue;
        for (int k = 0; k < m->dim; k++)
            if ((B->fix[i] & (SX_FIX_VX << k)) && B->v[i * m->dim + k] != 0) return false;
        for (int k = 0; k < m->rdim; k++)
            if ((B->fix[i] & (SX_FIX_WX << k)) && B->w[i * m->rdim + k] != 0) return false;
    }
    if (m->clumps && sx__clumps_forced(m)) return false;
    return true;
}

/* Kinetic, potential and the strain stored in contacts and bonds: a bonded
 * specimen under load holds much of its energy in the bonds. */
static double mechanical(const sx_energy *e) { return e->kinetic + e->gravitational + e->strain + e->bond_strain; }

static const char *const NO_EXCHANGE = "cycle: the ranks could not exchange the state";

/* Decomposed, inside a cycle: the ghosts, and the clumps' state, where
 * the last step left their owners, for an energy sum. False: the ranks
 * could not exchange. */
static bool refresh_ghosts(sx_model *m) { return sx__dd_halo(m) && (!m->clumps || sx__dd_clumps(m)); }

static sx_status guard_start(sx_model *m)
{
    m->guard_on = unforced(m);
    if (!m->guard_on) return SX_OK;
    sx_energy e;
    /* decomposed and gone on from a scattered state: the ghosts where the
     * last step left their owners, as guard_check reads them */
    const bool resumed = m->dd && m->dd->active && m->dd->scattered;
    if ((resumed && !refresh_ghosts(m)) || !kernels(m)->energy(m, &e)) return sx__fail(m, SX_EINVAL, "%s", NO_EXCHANGE);
    m->guard_e0 = mechanical(&e);
    /* the scale: the energy in play, with a floor of each ball's weight over its radius */
    double floor_e = 0, g = 0;
    for (int k = 0; k < m->dim; k++) g += m->gravity[k] * m->gravity[k];
    g = sqrt(g);
    for (int64_t i = 0; i < m->balls.n; i++) floor_e += g * m->balls.rad[i] / m->balls.inv_mass[i];
    m->guard_scale = e.kinetic + e.strain + e.bond_strain + floor_e;
    return SX_OK;
}

/* The ball with the largest translational kinetic energy, the first in
 * dense order on a tie: the one to name (-1: none). Decomposed, each rank
 * its own balls', then the largest of all and, among the ranks that hold
 * it, the lowest index (maxima: exact). False: the ranks could not
 * exchange. */
static bool most_energetic_ball(const sx_model *m, int64_t *id)
{
    const sx_balls *b = &m->balls;
    const sx_dd *dd = m->dd && m->dd->active ? m->dd : NULL;
    const int64_t i0 = dd ? dd->own[dd->x.rank].lo : 0, i1 = dd ? dd->own[dd->x.rank].hi : b->n;
    int64_t best = -1;
    double top = -1;
    for (int64_t i = i0; i < i1; i++) {
        double v2 = 0;
        for (int k = 0; k < m->dim; k++) v2 += b->v[i * m->dim + k] * b->v[i * m->dim + k];
        const double ke = 0.5 * v2 / b->inv_mass[i];
        if (ke > top) top = ke, best = i;
    }
    if (dd) {
        double all = top;
        if (!dd->x.max(dd->x.ud, &all)) return false;
        double lowest = best >= 0 && top == all ? -(double)best : -INFINITY; /* an index is exact in a double */
        if (!dd->x.max(dd->x.ud, &lowest)) return false;
        best = all >= 0 ? (int64_t)-lowest : -1;
    }
    *id = best >= 0 ? b->id[best] : -1;
    return true;
}

static sx_status guard_check(sx_model *m)
{
    if (!m->guard_on || m->guard_scale <= 0) return SX_OK;
    sx_energy e;
    /* decomposed: the ghosts where the step left their owners, for the pairs' strain */
    if ((m->dd && m->dd->active && !refresh_ghosts(m)) || !kernels(m)->energy(m, &e))
        return sx__fail(m, SX_EINVAL, "%s", NO_EXCHANGE);
    const double gain = mechanical(&e) - m->guard_e0;
    if (!(gain > GUARD_ENERGY_FACTOR * m->guard_scale)) return SX_OK;
    int64_t fastest;
    double crit;
    if (!most_energetic_ball(m, &fastest) || !critical(m, &crit)) return sx__fail(m, SX_EINVAL, "%s", NO_EXCHANGE);
    return sx__fail(m, SX_EUNSTABLE,
                    "unstable at step %lld: the mechanical energy of an unforced system grew by %g J "
                    "(%.3g times its initial scale %g J; fastest ball %lld); the timestep %g s is too large "
                    "(critical estimate %g s)",
                    (long long)m->step, gain, gain / m->guard_scale, m->guard_scale, (long long)fastest, m->dt,
                    crit);
}

/* ---------------------------------------------------------------- cycle */

/* A cylinder whose radius its radial velocity would take to 0 or below
 * within the step: an error before the step moves anything (the radius ran
 * through 0 unseen, and the model then saved could not be loaded). */
static sx_status check_radii(sx_model *m)
{
    for (int64_t i = 0; i < m->nwall; i++) {
        const sx_wall *w = &m->walls[i];
        if (w->def.kind != SX_WALL_CYLINDER || w->def.radial_vel >= 0) continue;
        if (!(w->def.radius + w->def.radial_vel * m->dt > 0))
            return sx__fail(m, SX_EINVAL,
                            "cylinder %lld: its radius %g m would reach %g m at step %lld (radial velocity %g m/s); a "
                            "radius must stay > 0: stop it first (w:set_radial_vel(0))",
                            (long long)w->id, w->def.radius, w->def.radius + w->def.radial_vel * m->dt,
                            (long long)m->step + 1, w->def.radial_vel);
    }
    return SX_OK;
}

static void move_walls(sx_model *m, double *max_wall)
{
    *max_wall = 0;
    for (int64_t i = 0; i < m->nwall; i++) {
        sx_wall *w = &m->walls[i];
        double s = 0;
        for (int k = 0; k < m->dim; k++) {
            w->def.point[k] += w->def.vel[k] * m->dt;
            s += w->def.vel[k] * w->def.vel[k];
        }
        w->moved += sqrt(s) * m->dt;
        if (w->def.kind == SX_WALL_CYLINDER) {
            w->def.radius += w->def.radial_vel * m->dt;
            w->moved += fabs(w->def.radial_vel) * m->dt;
        }
        if (w->mesh) { /* a moving mesh: the turn about its point, then its vertices */
            const double turned = sx__mesh_turn(w, m->dt);
            w->moved += turned;
            if (turned > 0 || s > 0) sx__mesh_pose(w);
        }
        if (w->moved > *max_wall) *max_wall = w->moved;
    }
}

double sx__now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Closes a stage that began at t0; returns the time, the next stage's start. */
static double stage_end(sx_model *m, sx_stage s, double t0)
{
    const double t = sx__now();
    m->prof.seconds[s] += t - t0;
    m->prof.calls[s]++;
    return t;
}

bool sx_model_time_reached(const sx_model *m, double t_end, int64_t since)
{
    /* each sum of a timestep in the run rounds by at most half an ulp of
     * the time (an ulp <= eps |t|), one more for t_end itself */
    const double sums = m->step > since ? (double)(m->step - since) : 0;
    const double rounding = (sums + 1) * DBL_EPSILON * fmax(fabs(m->time), fabs(t_end));
    return m->time >= t_end - fmin(rounding, 0.5 * m->dt_prev);
}

/* What a decomposed cycle cannot go on to from the state the last one
 * left scattered, each rank's own balls current: a build, which lists
 * from every ball; and the check of bonded pairs' contact-model rows
 * (sx__cmodel_prepare), which reads every pair. */
static bool whole_needed(const sx_model *m)
{
    return m->build_needed || (m->ncmodel && m->bb.bond && m->bb.cmodel);
}

sx_status sx_model_gather(sx_model *m)
{
    if (!m->dd || !m->dd->scattered) return SX_OK;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "gather: the model is stepping");
    return sx__dd_whole(m, kernels(m)->plan);
}

static sx_status cycle_steps(sx_model *m, int64_t n, double t_end, int64_t since)
{
    double t = sx__now();
    const int64_t builds = m->builds;
    sx_status st = SX_OK;
    /* decomposed and scattered: the ranks agree on what they hold whole
     * before any of them gathers (a wall moved on one rank alone would
     * otherwise leave it gathering while the others resume) */
    if (m->dd && m->dd->scattered && !(st = sx__dd_agree_replicated(m)) && whole_needed(m)) st = sx_model_gather(m);
    /* the last cycle's plan goes on (nothing but the walls and settings
     * changed since: a caller that changes more gathers first) */
    const bool resume = m->dd && m->dd->scattered;
    if (!st) st = sx__prepare(m);
    if (m->builds != builds) t = stage_end(m, SX_STAGE_BROAD_PHASE, t);
    if (st) return st;
    if (resume) m->dd->active = true, m->prof.resumed++; /* the timestep is then rated rank by rank */
    if ((st = update_timestep(m))) {
        if (resume) m->dd->active = false;
        return st;
    }
    const sx_kernels *k = kernels(m);
    if (m->dd && !resume && (st = sx__dd_begin(m))) return st; /* decomposed: each rank its slab (decompose.c) */
    sx_dd *dd = m->dd;
    m->locked = true;
    /* the energy baseline is taken when the user has changed the system, not
     * at every call: a script cycling one step at a time is guarded too */
    if (m->guard_dirty && (st = guard_start(m))) {
        m->locked = false;
        if (dd) dd->active = false;
        return st;
    }
    m->guard_dirty = false;
    double other = sx__now() - t; /* the stages outside the four of the step, summed over the steps */
    for (int64_t s = 0; s < n; s++) {
        if (sx_model_time_reached(m, t_end, since)) break; /* the time is global: every rank stops here */
        t = sx__now();
        if (sx__interrupted(m)) {
            st = sx__fail(m, SX_EINTERRUPT, "interrupted at step %lld", (long long)m->step);
            break;
        }
        if ((st = check_radii(m))) break;
        if (m->build_needed) {
            if (m->cell && (st = sx__cell_check(m))) break; /* the cell may have shrunk */
            if (dd && !sx__dd_gather(m)) { /* the serial build, on every rank, from the whole state */
                st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the state");
                break;
            }
            if ((st = check_skin(m))) break; /* as at a cycle's start, however the run is cut */
            st = k->build(m);
            if (!st && dd && !sx__dd_plan(m)) st = SX_ENOMEM; /* the new slabs: balls migrate */
            t = stage_end(m, SX_STAGE_BROAD_PHASE, t);
            if (st) {
                st = build_failed(m, st);
                break;
            }
        }
        st = update_timestep(m);
        double t1 = sx__now();
        other += t1 - t;
        if (st) break;
        if (dd && !sx__dd_halo(m)) {
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange ghosts");
            break;
        }
        const double t_own = dd ? sx__now() : 0; /* decomposed: this rank's computing, for its pace */
        st = k->contacts(m);
        t1 = stage_end(m, SX_STAGE_BALL_CONTACTS, t1);
        if (st) break;
        st = k->walls(m);
        t1 = stage_end(m, SX_STAGE_WALL_CONTACTS, t1);
        if (st) break;
        double max_disp, max_wall;
        st = k->integrate(m, &max_disp);
        if (dd) dd->busy += sx__now() - t_own, dd->busy_work += (double)dd->planned;
        if (!st && dd && m->track_energy && !sx__dd_energy(m)) /* the step's energy sums, in the serial order */
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not sum the step's energies (out of memory?)");
        if (!st && m->clumps && dd && !sx__dd_pebbles(m, NULL, 0)) /* to the clumps' owners, who step them */
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the pebbles' forces");
        if (!st && m->clumps) st = k->clumps_step(m, &max_disp); /* kernels/clump_motion.c: the bodies move their pebbles */
        if (!st && m->clumps && dd && !sx__dd_placed(m)) /* the placed pebbles to their owners */
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the pebbles' places");
        /* every rank decides the same rebuild (the largest of the ranks' own balls' and pebbles' moves) */
        if (!st && dd && !dd->x.max(dd->x.ud, &max_disp))
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange their displacements");
        t = stage_end(m, SX_STAGE_INTEGRATION, t1);
        if (st) break;
        sx__walls_servo(m);
        move_walls(m, &max_wall);
        if (m->cell && (st = sx__cell_step(m))) break; /* periodic space: the cell deforms */
        m->time += m->dt;
        m->dt_prev = m->dt;
        m->step++;
        m->prof.steps++;
        m->prof.calls[SX_STAGE_OTHER]++;
        /* Verlet criterion: two balls may close the gap by twice the largest
         * displacement, a ball and a wall by both of their displacements. */
        if (2 * max_disp > m->skin || max_disp + max_wall > m->skin) m->build_needed = true;
        /* a ghost moves with its owner and with the cell vectors that shift it */
        if (m->cell && 2 * max_disp + m->cell->moved > m->skin) m->build_needed = true;
        if (m->step % GUARD_STEPS == 0) st = guard_check(m); /* decomposed: chained sums (kernels/queries.c) */
        other += sx__now() - t;
        if (st) break;
    }
    m->prof.seconds[SX_STAGE_OTHER] += other;
    m->locked = false;
    /* the whole state on every rank again, or lazily not (after an error
     * the ranks are out of step, the state mixed: the caller stops them) */
    if (dd && !st) st = sx__dd_end(m, k->plan);
    if (dd) dd->active = false;
    if (dd && st) dd->scattered = true;
    return st;
}

sx_status sx_model_cycle(sx_model *m, int64_t n) { return sx_model_cycle_until(m, n, INFINITY, m->step); }

sx_status sx_model_cycle_until(sx_model *m, int64_t n, double t_end, int64_t since)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "cycle: the model is already stepping");
    if (n < 0) return sx__fail(m, SX_EINVAL, "cycle: the number of steps must be >= 0 (got %lld)", (long long)n);
    if (isnan(t_end)) return sx__fail(m, SX_EINVAL, "cycle: the time to stop at is not a number");
    m->err[0] = 0;
    m->interrupt = 0;
    const double t0 = sx__now();
    const sx_status st = cycle_steps(m, n, t_end, since);
    m->prof.cycle_seconds += sx__now() - t0;
    m->prof.cycles++;
    return st;
}

/* ------------------------------------------------------------- profile */

sx_profile sx_model_profile(const sx_model *m) { return m->prof; }

void sx_model_profile_reset(sx_model *m) { memset(&m->prof, 0, sizeof m->prof); }

void sx_model_profile_add(sx_model *m, sx_stage stage, double seconds)
{
    if ((unsigned)stage >= SX_STAGE_COUNT || !(seconds >= 0)) return;
    m->prof.seconds[stage] += seconds;
    m->prof.calls[stage]++;
}

const char *sx_stage_name(sx_stage stage)
{
    static const char *const names[SX_STAGE_COUNT] = {"broad phase", "ball contacts", "wall contacts",
                                                      "integration", "callbacks",     "other"};
    return (unsigned)stage < SX_STAGE_COUNT ? names[stage] : NULL;
}

/* snprintf at offset *used of buf[len], counting what it needed in *need. */
static void appendf(char *buf, size_t len, int *need, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static void appendf(char *buf, size_t len, int *need, const char *fmt, ...)
{
    char none[1];
    const size_t used = (size_t)*need;
    va_list ap;
    va_start(ap, fmt);
    const int w = buf && used < len ? vsnprintf(buf + used, len - used, fmt, ap) : vsnprintf(none, sizeof none, fmt, ap);
    va_end(ap);
    if (w > 0) *need += w;
}

int sx_profile_format(const sx_profile *p, int64_t balls, char *buf, size_t len)
{
    double total = 0;
    for (int s = 0; s < SX_STAGE_COUNT; s++) total += p->seconds[s];
    int need = 0;
#define OUT(...) appendf(buf, len, &need, __VA_ARGS__)
    OUT("%-14s %10s %7s %10s %12s\n", "stage", "seconds", "share", "calls", "us/call");
    for (int s = 0; s < SX_STAGE_COUNT; s++) {
        const double sec = p->seconds[s];
        OUT("%-14s %10.4f %6.1f%% %10lld %12.2f\n", sx_stage_name((sx_stage)s), sec, total > 0 ? 100 * sec / total : 0.0,
            (long long)p->calls[s], p->calls[s] ? 1e6 * sec / (double)p->calls[s] : 0.0);
    }
    OUT("%-14s %10.4f %6.1f%% %10lld steps in %lld cycles (%.4f s inside cycles)\n", "total", total, 100.0,
        (long long)p->steps, (long long)p->cycles, p->cycle_seconds);
    if (balls > 0 && p->cycle_seconds > 0 && p->steps > 0)
        OUT("%lld balls: %.3g particle-steps per second inside cycles\n", (long long)balls,
            (double)balls * (double)p->steps / p->cycle_seconds);
    if (p->resumed > 0)
        OUT("%lld of the cycles went on from the last one's scattered state, without a gather\n",
            (long long)p->resumed);
#undef OUT
    return need;
}

/* ---------------------------------------------------------------- state */

uint64_t sx__fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) h = (h ^ p[i]) * 0x100000001b3ULL;
    return h;
}

uint64_t sx__fnv_doubles(uint64_t h, const double *v, int64_t n, double sign)
{
    for (int64_t i = 0; i < n; i++) {
        const double x = v ? sign * v[i] : 0;
        const double c = x == 0 ? 0.0 : x; /* -0 as +0: the states continue alike */
        h = sx__fnv(h, &c, sizeof c);
    }
    return h;
}

sx_energy sx_model_energy(sx_model *m)
{
    sx_energy e;
    memset(&e, 0, sizeof e);
    /* materials or positions may have changed since the last cycle: the
     * broad phase the next cycle would build anyway sees every overlap */
    if (sx__prepare(m)) { /* no energy rather than a silent zero */
        double *t = (double *)&e;
        for (size_t k = 0; k < sizeof e / sizeof(double); k++) t[k] = NAN;
        return e;
    }
    kernels(m)->energy(m, &e); /* between cycles: the serial sums, which cannot fail */
    return e;
}

void sx_model_track_energy(sx_model *m, bool on)
{
    m->track_energy = on;
    memset(&m->acc, 0, sizeof m->acc);
}

int64_t sx_contact_count(const sx_model *m) { return kernels(m)->count_contacts(m); }

bool sx_contact_each(const sx_model *m, bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    return kernels(m)->each_contact(m, fn, ud);
}

/* A contact's force: its law's and its bond's (a parallel bond's or a flat
 * joint's face), as PFC counts a bonded contact's force. Without the
 * bond's, a structure that bonds alone carry (a bonded beam, balls bonded
 * across a gap) had no contact force and a ratio that never settled. */
static bool add_contact_force(const sx_contact_info *ci, void *ud)
{
    double *acc = ud;
    const double fn = ci->fn + ci->pb_fn;
    double s2 = fn * fn;
    for (int k = 0; k < 3; k++) s2 += (ci->shear[k] + ci->pb_fs[k]) * (ci->shear[k] + ci->pb_fs[k]);
    acc[0] += sqrt(s2);
    acc[1] += 1;
    return true;
}

/* Something moves: a ball, a wall or the periodic cell. */
static bool anything_moves(const sx_model *m)
{
    const sx_balls *b = &m->balls;
    for (int64_t i = 0; i < b->n * m->dim; i++)
        if (b->v[i] != 0) return true;
    for (int64_t i = 0; i < b->n * m->rdim; i++)
        if (b->w[i] != 0) return true;
    for (int64_t i = 0; i < m->nwall; i++) {
        const sx_wall *w = &m->walls[i];
        if (w->servo_on || w->def.radial_vel != 0) return true;
        for (int k = 0; k < 3; k++)
            if (w->def.vel[k] != 0 || w->def.spin[k] != 0) return true;
    }
    return m->cell && m->cell->controlled;
}

double sx_model_unbalanced_ratio(const sx_model *m)
{
    const sx_balls *b = &m->balls;
    const int d = m->dim;
    double unbalanced = 0;
    int64_t bodies = b->n;
    for (int64_t i = 0; i < b->n; i++) {
        if (b->clump && b->clump[i]) continue; /* a pebble is balanced with its clump, below */
        double s2 = 0;
        for (int k = 0; k < d; k++) {
            if (b->fix[i] & (SX_FIX_VX << k)) continue; /* a fixed component is balanced by its fixity */
            const double f = b->f[i * d + k] + m->gravity[k] / b->inv_mass[i];
            s2 += f * f;
        }
        unbalanced += sqrt(s2);
    }
    if (m->clumps) sx__clumps_unbalanced(m, &unbalanced, &bodies);
    double acc[2] = {0, 0};
    sx_contact_each(m, add_contact_force, acc);
    if (bodies == 0) return 0;
    /* no contact force to compare with: settled only when nothing moves (a
     * cloud of balls a servo is closing on is not; issue: m:solve{ratio}
     * stopped at once there) */
    if (acc[1] == 0 || acc[0] == 0) return unbalanced > 0 || anything_moves(m) ? INFINITY : 0;
    return (unbalanced / (double)bodies) / (acc[0] / acc[1]);
}
