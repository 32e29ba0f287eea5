/* What a cycle needs before its first step (the laws refreshed, the models
 * checked, the skin, a broad-phase build when one is due) and the
 * timestep: the user's, or the automatic one from the critical estimate,
 * re-estimated every DT_REFRESH_STEPS steps. Queries that need a prepared
 * model (the timestep, the energy) call sx__prepare too. */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* How often the automatic timestep is re-estimated between builds. */
enum { DT_REFRESH_STEPS = 32 };

/* ------------------------------------------------------------- timestep */

/* A user's skin so wide that nearly every pair of balls is a candidate
 * (skin = 1e3 m, or m:bond's gap over a large assembly) would build for
 * minutes, uninterruptibly, and exhaust memory: refused before the build,
 * from the pairs a uniform spread of the balls over their bounding box
 * would give (cubes of the reach's width: an overestimate). */
sx_status sx__check_skin(sx_model *m)
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
sx_status sx__build_failed(sx_model *m, sx_status st)
{
    if (st == SX_EINTERRUPT)
        return sx__fail(m, st, "interrupted in the broad phase at step %lld (the model is as it was)", (long long)m->step);
    return sx__fail(m, SX_ENOMEM, "broad phase: out of memory");
}

/* Broad phase and laws up to date, so timestep queries see current contacts. */
sx_status sx__prepare_laws(sx_model *m)
{
    sx_status st = sx__refresh_laws(m);
    if (!st) st = sx__check_models(m);
    if (!st && m->ncmodel) st = sx__cmodel_prepare(m);
    return st;
}

sx_status sx__prepare(sx_model *m)
{
    sx_status st = sx__prepare_laws(m);
    if (!st && m->build_needed) st = sx__check_skin(m);
    if (st) return st;
    if (m->build_needed && m->cell && (st = sx__cell_check(m))) return st;
    if (m->build_needed && (st = sx__kernels(m)->build(m))) return sx__build_failed(m, st);
    return SX_OK;
}

/* The critical timestep; decomposed, each rank rates its own balls: the
 * smallest of all (exact). False: the ranks could not exchange. */
bool sx__critical(sx_model *m, double *crit)
{
    *crit = sx__kernels(m)->critical_dt(m);
    if (!m->dd || !m->dd->active) return true;
    *crit = -*crit;
    if (!m->dd->x.max(m->dd->x.ud, crit)) return false;
    *crit = -*crit;
    return true;
}

/* The timestep the next step takes: the user's, the automatic one in use,
 * or, when that is stale or due for a refresh, safety x critical. */
sx_status sx__next_timestep(sx_model *m, double *dt)
{
    *dt = m->dt;
    if (m->dt_user > 0) {
        *dt = m->dt_user;
    } else if (m->dt_stale || m->step % DT_REFRESH_STEPS == 0 || !(m->dt > 0)) {
        /* decomposed: the ghosts where the last step left them, as the serial run reads them */
        if (m->dd && m->dd->active && !sx__dd_halo(m))
            return sx__fail(m, SX_EINVAL, "timestep: the ranks could not exchange ghosts");
        double crit;
        if (!sx__critical(m, &crit))
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

sx_status sx__update_timestep(sx_model *m)
{
    const sx_status st = sx__next_timestep(m, &m->dt);
    if (!st) m->dt_stale = false;
    return st;
}

sx_status sx__prepare_query(sx_model *m, bool *split)
{
    const sx_status st = sx_model_scattered(m) ? sx__prepare_scattered(m) : sx__prepare(m);
    *split = !st && m->dd && m->dd->active;
    return st;
}

double sx_model_critical_timestep(sx_model *m)
{
    bool split;
    double crit = NAN;
    /* scattered: each rank rates its own balls, the ghosts where their owners left them */
    if (!sx__prepare_query(m, &split) && ((split && !sx__dd_halo(m)) || !sx__critical(m, &crit))) {
        sx__fail(m, SX_EINVAL, "critical timestep: the ranks could not exchange");
        crit = NAN;
    }
    if (split) m->dd->active = false;
    return crit;
}

/* A query: the timestep is computed, not stored, so that asking for it
 * leaves the state (and its hash) as it was. */
double sx_model_timestep(sx_model *m)
{
    if (m->dt_user > 0) return m->dt_user;
    double dt = NAN;
    bool split; /* scattered (a lazy cycle's): rated rank by rank, as at a resumed cycle's start */
    sx_status st = sx__prepare_query(m, &split);
    if (!st) st = sx__next_timestep(m, &dt);
    if (split) m->dd->active = false;
    return st ? NAN : dt;
}

double sx_model_fixed_timestep(const sx_model *m) { return m->dt_user; }

double sx_model_critical_timestep_bound(sx_model *m)
{
    if (sx__prepare_laws(m)) return NAN;
    return sx__kernels(m)->own_dt(m);
}

sx_status sx_model_set_timestep(sx_model *m, double dt)
{
    if (!sx__timestep_ok(dt))
        return sx__fail(m, SX_EINVAL, "set_timestep: the timestep must be in [1e-15, 1] s, or 0 for automatic (got %g)",
                        dt);
    m->dt_user = dt;
    m->dt_stale = true;
    return SX_OK;
}
