/* Rolling resistance: the rolling-resistance linear model of PFC. A
 * material's `rolling_friction` mu_r (>= 0; a contact takes the smaller
 * of its two, as friction, 4-30; against a wall the ball's own) switches
 * it on. The contact carries a rolling moment Mr (history; 3D a vector in
 * the contact plane, 2D a scalar), incremented by a rolling spring from
 * the relative rotation of the two bodies and capped by a plastic limit:
 *   kr = ks R-bar^2,          R-bar = RA RB / (RA + RB) (ball-wall: R),
 *   Mr <- Mr - kr d(theta)_b,  d(theta)_b = (w_B - w_A) dt less its
 *                             component along n (3D: the twist is free),
 *   |Mr| <= mu_r R-bar Fn     (Fn the normal spring's force, >= 0),
 * Mr acting on B and -Mr on A. In 3D the moment is carried with the
 * contact plane as the shear force is (4-14/4-15). Energy: the spring
 * holds |Mr|^2 / (2 kr); a capped step dissipates the mean moment times
 * the plastic rotation, as Coulomb slip does (kernels: slip energy). */
#pragma once

#include "law.h"

#include <math.h>

static inline void sx_law_rolling_mix(sx_pair_law *l, const sx_material *a, const sx_material *b, int self)
{
    (void)self;
    const double ma = a->def.rolling_friction, mb = b ? b->def.rolling_friction : ma;
    l->mu_r = ma < mb ? ma : mb;
    if (l->mu_r > 0) l->plain = false; /* the batched passes carry no rolling moment */
}

/* Advances the rolling moment mr (rdim components, carried into the
 * current contact plane already) by the relative rotation dtheta (rdim)
 * about unit normal n (dim), with shear stiffness ks, R-bar rbar and
 * normal spring force fn; returns the energy the cap dissipated. */
static inline double sx_law_rolling_moment(const sx_pair_law *l, int dim, double *mr, const double *dtheta,
                                           const double *n, double ks, double rbar, double fn)
{
    const int rd = dim == 3 ? 3 : 1;
    const double kr = ks * rbar * rbar;
    double twist = 0, m0[3], m2 = 0;
    if (dim == 3) { /* the bending part alone: the moment kept in the plane, the twist left free */
        twist = dtheta[0] * n[0] + dtheta[1] * n[1] + dtheta[2] * n[2];
        const double along = mr[0] * n[0] + mr[1] * n[1] + mr[2] * n[2];
        for (int k = 0; k < 3; k++) mr[k] -= along * n[k];
    }
    for (int k = 0; k < rd; k++) {
        m0[k] = mr[k];
        mr[k] -= kr * (dtheta[k] - (dim == 3 ? twist * n[k] : 0));
        m2 += mr[k] * mr[k];
    }
    double work = 0, sc;
    sx__law_cap(rd, mr, m0, m2, l->mu_r * rbar * (fn > 0 ? fn : 0), kr, &work, &sc);
    return work;
}

/* The rolling spring's energy |Mr|^2 / (2 kr), kr = ks R-bar^2. */
static inline double sx_law_rolling_strain(int dim, const double *mr, double ks, double rbar)
{
    double m2 = 0;
    for (int k = 0; k < (dim == 3 ? 3 : 1); k++) m2 += mr[k] * mr[k];
    return ks > 0 ? 0.5 * m2 / (ks * rbar * rbar) : 0;
}

static inline const sx_law *sx_law_rolling(void)
{
    static const sx_law_param params[] = {
        {"rolling_friction", "1", offsetof(sx_material_def, rolling_friction), 0, INFINITY, true, false,
         "rolling_friction must be >= 0"},
    };
    static const sx_law law = {
        .name = "rolling",
        .kind = SX_LAW_PART,
        .summary = "rolling resistance (PFC's linear model): kr = ks R^2, |Mr| <= rolling_friction R Fn",
        .params = params,
        .nparams = 1,
        .mix = sx_law_rolling_mix,
    };
    return &law;
}
