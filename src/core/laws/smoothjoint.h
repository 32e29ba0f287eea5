/* The smooth joint (Mas Ivars et al. 2011; PFC's `smoothjoint`): a planar
 * discontinuity -- a joint of the model, given by a point and a unit normal
 * Nj -- through an assembly of balls. A contact (or a bond) between two
 * balls whose centres lie on opposite sides of the plane takes this law in
 * place of its contact law (and of its bond): its directions are fixed by
 * the joint, not by the balls' centre line, so the two sides slide along
 * the plane whatever the balls' arrangement.
 *
 * Per contact: N, the joint's normal oriented from a's side to b's (fixed
 * at the contact's creation), the elastic normal overlap Un along N
 * (history) and the shear force Fs in the plane (history). The interface
 * is a notional disk (3D, area A = pi R^2) or segment of unit thickness
 * (2D, A = 2R), R = lambda min(RA, RB). Each step, with v the velocity of
 * b relative to a at the contact point (4-16):
 *     dUn = -(v . N) dt                  (closing positive)
 *     dUs = (v - (v . N) N) dt           (in the plane)
 *     Un <- Un + dUn,  Fn = kn A Un     (compression positive)
 *     Fs <- Fs - ks A dUs
 * kn, ks are stiffnesses per unit area (Pa/m). The force on b is
 * Fn N + Fs, on a the opposite; it acts at the contact point on the
 * centre line (4-4), so it turns the balls as a contact force does (4-21).
 *
 * Bonded (the joint has a tensile strength sigma_c and a cohesion c), the
 * contact carries tension and breaks
 *     in tension when -Fn / A >= sigma_c,
 *     in shear   when |Fs| / A >= c + (Fn / A) tan(phi_b),
 * and from then on is unbonded (a crack in the log, kind smooth joint).
 * Unbonded, the joint carries no force while open (Un <= 0: Fn = Fs = 0)
 * and slips by Coulomb's rule |Fs| <= mu Fn. A slip of length
 * ds = (|Fs*| - mu Fn) / (ks A) (|Fs*| the trial force) dilates the joint:
 *     Un <- Un + ds tan(psi)
 * so that under a constant normal load the joint opens by ds tan(psi)
 * (psi the dilation angle). A new unbonded contact starts with Fs = 0 and
 * Un = (RA + RB - d) |n . N|, the balls' overlap along the joint normal.
 *
 * Energy: the joint stores Fn^2 / (2 kn A) + |Fs|^2 / (2 ks A). Coulomb
 * slip dissipates its plastic work (sx__law_cap); a dilation's rise of the
 * normal strain energy is drawn from that work (it is counted against the
 * slip energy), since it is done by the shear force; a break releases the
 * energy the bond loses (bond_released).
 */
#pragma once

#include "law.h"

#include <math.h>
#include <stdbool.h>

/* A joint's constants as the pass uses them. */
typedef struct sx_law_sj {
    double kn, ks;           /* Pa/m */
    double mu, tanpsi;       /* friction; tangent of the dilation angle */
    double sigma_c, coh;     /* Pa (0 and 0: unbonded) */
    double tanphi;           /* tangent of the bond's friction angle */
    double lambda;           /* radius multiplier */
} sx_law_sj;

/* The interface's area for balls of radii ra, rb. */
static inline double sx_law_sj_area(int dim, const sx_law_sj *j, double ra, double rb)
{
    const double r = j->lambda * (ra < rb ? ra : rb);
    return dim == 3 ? 3.14159265358979323846 * r * r : 2 * r;
}

/* Strain energy of a joint contact with overlap un and shear force fs (n components). */
static inline double sx_law_sj_strain(int n, const sx_law_sj *j, double area, double un, const double *fs)
{
    double f2 = 0;
    for (int k = 0; k < n; k++) f2 += fs[k] * fs[k];
    return 0.5 * j->kn * area * un * un + 0.5 * f2 / (j->ks * area);
}

/* How a bonded contact fails, or 0: 1 tension, 2 shear (the crack modes'
 * order in seixo.h). */
static inline int sx_law_sj_breaks(const sx_law_sj *j, double area, double fn, double fsn)
{
    if (-fn / area >= j->sigma_c) return 1;
    if (fsn / area >= j->coh + (fn / area) * j->tanphi) return 2;
    return 0;
}

/* The unbonded law after the elastic increments: open (no force), or
 * Coulomb slip with dilation. un and fs (n components, fs0 before this
 * step's increment) are updated in place; the slip's plastic work is added
 * to work[0] and the dilation's strain energy taken from work[1] (two
 * terms of the caller's sum, in that order; work may be NULL). Returns Fn. */
static inline double sx_law_sj_unbonded(int n, const sx_law_sj *j, double area, double *un, double *fs,
                                        const double *fs0, double *work)
{
    if (*un <= 0) {
        for (int k = 0; k < n; k++) fs[k] = 0;
        return 0;
    }
    const double kna = j->kn * area, ksa = j->ks * area, fn = kna * *un;
    double f2 = 0;
    for (int k = 0; k < n; k++) f2 += fs[k] * fs[k];
    double sc;
    const double trial = sqrt(f2);
    if (!sx__law_cap(n, fs, fs0, f2, j->mu * fn, ksa, work, &sc)) return fn;
    if (j->tanpsi == 0) return fn;
    const double slip = (trial - j->mu * fn) / ksa;
    *un += slip * j->tanpsi;
    const double fn1 = kna * *un;
    if (work) work[1] -= 0.5 * (fn1 * fn1 - fn * fn) / kna;
    return fn1;
}
