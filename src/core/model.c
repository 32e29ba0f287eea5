/* The model: its creation and destruction (the owner of all storage),
 * its settings (gravity, threads), the interrupt and the scratch array.
 * The rest of what a model does lives beside it, one job a file:
 *     material.c        the material table and the pair laws it mixes
 *     prepare.c         what a cycle needs first (laws, skin, broad phase)
 *                       and the timestep
 *     cycle.c           the step pipeline: broad phase (when needed) ->
 *                       timestep -> contact forces -> law of motion ->
 *                       walls and the periodic cell -> time, guard, with
 *                       the dimension-specific stages in kernels.c
 *     guard.c           the stability guard of an unforced system
 *     profile.c         the time per stage
 *     model_queries.c   energies, contacts and the unbalanced-force ratio */
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


sx_status sx__fail(sx_model *m, sx_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->err, sizeof m->err, fmt, ap);
    va_end(ap);
    m->unstable.kind = SX_UNSTABLE_NONE; /* an instability's message sets it after (sx__unstable_fail) */
    return st;
}


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

sx_model *sx_model_create(const sx_model_def *def, char *err, size_t errlen)
{
    const char *why = NULL;
    if (def->dim != 2 && def->dim != 3) why = "dim must be 2 or 3";
    else if (!sx__timestep_ok(def->timestep)) why = "timestep must be 0 (automatic) or in [1e-15, 1] s";
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
    r.bonds = sx__bonds_bytes(m);
    r.work = r.total - r.balls - r.contacts - r.bonds;
    r.ball_count = m->balls.n;
    r.pair_count = m->bb.n + m->bw.n;
    r.contact_count = sx__kernels(m)->count_contacts(m);
    r.bytes_per_ball = r.ball_count ? (double)r.balls / (double)r.ball_count : 0;
    r.bytes_per_contact = r.contact_count ? (double)r.contacts / (double)r.contact_count : 0;
    return r;
}
/* A signal handler sets it, the core's long loops read it: lock-free. And
 * for decomposed cycles, which stop alike on every rank (sx__dd_stop), the
 * requests numbered: the process's count; the number of the last one
 * answered here (cleared: by a run not decomposed, or after a stop); the
 * number of the last one a decomposed stop answered (the largest any rank
 * had: another rank's copy of a signal up to there, come late, is not a
 * new one); and the stops. */
static atomic_int interrupt_requested;
static atomic_uint requests, answered_here, answered_level, stops;

void sx_model_interrupt(sx_model *m)
{
    m->interrupt = 1;
    if (m->dd) atomic_fetch_add(&requests, 1); /* a decomposed cycle stops on the ranks' requests alone */
}

void sx_interrupt_request(void)
{
    atomic_store(&interrupt_requested, 1);
    atomic_fetch_add(&requests, 1);
}

int sx_interrupt_pending(void) { return atomic_load(&interrupt_requested); }

void sx_interrupt_clear(void)
{
    atomic_store(&interrupt_requested, 0);
    atomic_store(&answered_here, atomic_load(&requests));
}

unsigned sx__interrupts_unanswered(void)
{
    const unsigned n = atomic_load(&requests), here = atomic_load(&answered_here),
                   level = atomic_load(&answered_level);
    return n > here && n > level ? n : 0;
}

unsigned sx__interrupts_level(void) { return atomic_load(&answered_level); }

void sx__interrupts_stopped(unsigned level)
{
    unsigned old = atomic_load(&answered_level);
    while (level > old && !atomic_compare_exchange_weak(&answered_level, &old, level)) {}
    atomic_fetch_add(&stops, 1);
    if (atomic_load(&requests) <= level) atomic_store(&interrupt_requested, 0); /* every one here answered */
}

unsigned sx_interrupts_agreed(void) { return atomic_load(&stops); }

bool sx__speed_rated(const sx_model *m)
{
    if (m->dt_user > 0) return false;
    for (int k = 0; k < m->law_n; k++)
        if (sx__law_stiffens(m->law[k * m->law_n + k].law)) return true;
    for (int row = 0; row < m->ncmodel; row++)
        if (sx__law_stiffens(m->cmodel[row].law.law)) return true;
    return false;
}

/* a model's own flag only while it cycles: it stays set after the cycle it
 * stopped. Decomposed, never: a signal reaches each rank at its own time,
 * and one rank stopping alone would leave the ranks out of step (a cycle
 * stops on the ranks' agreement, sx__dd_stop; the loops outside cycles
 * run to their end). */
bool sx__interrupted(const sx_model *m)
{
    if (m->dd) return false;
    return (m->locked && m->interrupt) || atomic_load(&interrupt_requested);
}

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
