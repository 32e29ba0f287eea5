/* The stability guard: an unforced system (no moving wall, no applied
 * load, no component moving at an imposed velocity) cannot gain
 * mechanical energy, so a growth by orders of magnitude is an instability,
 * reported with the ball that carries the most energy. */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* An unforced system whose mechanical energy grows past this many times its
 * initial scale is numerically unstable. */
#define GUARD_ENERGY_FACTOR 100.0

/* ------------------------------------------------------- instabilities */

/* An overlap: a timestep within the critical one is not the cause, the
 * overlap came from before this step (a robustness tester followed "use
 * the automatic one" and got the same error, the model still holding the
 * blown-up state), or grew over many steps under contacts too soft for
 * their load (a newcomer's 2D bed with kn = 1e3 was told only of the first
 * two causes). */
static sx_status unstable_message(sx_model *m, const sx_unstable *u, double crit)
{
    const long long step = (long long)u->step, a = (long long)u->a, b = (long long)u->b;
    switch (u->kind) {
    case SX_UNSTABLE_OVERLAP:
        if (u->dt <= crit)
            return sx__fail(m, SX_EUNSTABLE,
                            "unstable at step %lld: %s %lld and %s %lld overlap by %g m, more than the radius %g m, "
                            "with a timestep (%g s) within the critical one (%g s): the overlap came from before this "
                            "step (bodies placed overlapping, a wall moved or set through them, or an earlier unstable "
                            "run whose state the model still holds: move them apart, or load a save), a body moved "
                            "more than a radius in one step (slow it down), or contacts too soft for the load they "
                            "carry let the overlap grow step by step (raise kn, or the modulus, for the weight or the "
                            "walls' push)",
                            step, u->what_a, a, u->what_b, b, u->un, u->r, u->dt, crit);
        return sx__fail(m, SX_EUNSTABLE,
                        "unstable at step %lld: %s %lld and %s %lld overlap by %g m, more than the radius %g m; "
                        "the timestep %g s is too large for the contact stiffness (critical estimate %g s): "
                        "lower the timestep or use the automatic one, from a save (the model keeps the state this step "
                        "found)",
                        step, u->what_a, a, u->what_b, b, u->un, u->r, u->dt, crit);
    case SX_UNSTABLE_BOND:
        return sx__fail(m, SX_EUNSTABLE,
                        "unstable at step %lld: the bond of balls %lld and %lld broke with a force or moment that is "
                        "not finite; the timestep %g s is too large for its stiffness (critical estimate %g s): "
                        "lower the timestep or use the automatic one, from a save (the model keeps the state this "
                        "step found)",
                        step, a, b, u->dt, crit);
    default:
        return sx__fail(m, SX_EUNSTABLE,
                        "unstable at step %lld: %s %lld has a non-finite position, velocity or spin; "
                        "the timestep %g s is likely too large (critical estimate %g s)",
                        step, u->what_a, a, u->dt, crit);
    }
}

sx_status sx__unstable_fail(sx_model *m, const sx_unstable *u, double crit)
{
    const sx_status st = unstable_message(m, u, crit);
    m->unstable = *u;
    return st;
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
    /* an applied load does work; one set back to zero does none (the array,
     * once a load was set, stays: a bonded pair whose load was removed ran
     * unguarded at 5 times the critical timestep to 1.9e6 m/s) */
    const sx_balls *B = &m->balls;
    for (int64_t i = 0; B->fapp && i < B->n * m->dim; i++)
        if (B->fapp[i] != 0) return false;
    for (int64_t i = 0; B->tapp && i < B->n * m->rdim; i++)
        if (B->tapp[i] != 0) return false;
    if (m->cell && m->cell->controlled) return false; /* the deforming cell does work on the balls */
    /* gravity along a periodic cell vector has no bounded potential (a
     * chute: the balls gain kinetic energy without end, against a growing
     * scale the guard's hundredfold would not catch) */
    for (int k = 0; m->cell && k < m->dim; k++) {
        double gh = 0;
        for (int q = 0; q < m->dim; q++) gh += m->gravity[q] * m->cell->h[k][q];
        if (m->cell->axis[k] && gh != 0) return false;
    }
    /* a fixed component moving at its imposed velocity does work; one held
     * at rest does none (a ball fixed as an obstacle or a rough floor), so
     * the guard stays on for it (a physics check: a bonded pair with one
     * ball fixed at rest, at 5 times the critical timestep, left at 2.8e11
     * m/s with the guard off) */
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

sx_status sx__guard_start(sx_model *m, bool stepped)
{
    m->guard_on = unforced(m);
    if (!m->guard_on) return SX_OK;
    sx_energy e;
    /* decomposed, after a step or gone on from a scattered state: the
     * ghosts where the last step left their owners, as guard_check reads them */
    const bool refresh = m->dd && m->dd->active && (stepped || m->dd->scattered);
    if ((refresh && !sx__dd_refresh(m)) || !sx__kernels(m)->energy(m, &e)) return sx__fail(m, SX_EINVAL, "%s", NO_EXCHANGE);
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

sx_status sx__guard_check(sx_model *m)
{
    if (!m->guard_on || m->guard_scale <= 0) return SX_OK;
    sx_energy e;
    /* decomposed: the ghosts where the step left their owners, for the pairs' strain */
    if ((m->dd && m->dd->active && !sx__dd_refresh(m)) || !sx__kernels(m)->energy(m, &e))
        return sx__fail(m, SX_EINVAL, "%s", NO_EXCHANGE);
    const double gain = mechanical(&e) - m->guard_e0;
    if (!(gain > GUARD_ENERGY_FACTOR * m->guard_scale)) return SX_OK;
    int64_t fastest;
    double crit;
    if (!most_energetic_ball(m, &fastest) || !sx__critical(m, &crit)) return sx__fail(m, SX_EINVAL, "%s", NO_EXCHANGE);
    /* within the estimate, the timestep may still be the cause (the
     * estimate is the balls' translational one) or a force may feed energy */
    const bool large = m->dt > crit;
    return sx__fail(m, SX_EUNSTABLE,
                    "unstable at step %lld: the mechanical energy of an unforced system grew by %g J "
                    "(%.3g times its initial scale %g J; fastest ball %lld); the timestep %g s is %s "
                    "(critical estimate %g s)%s",
                    (long long)m->step, gain, gain / m->guard_scale, m->guard_scale, (long long)fastest, m->dt,
                    large ? "too large" : "within the estimate", crit,
                    large ? "" : ": lower it (m:set_timestep) to see whether it is the cause, or look for a force "
                                 "that feeds energy");
}
