/* The parallel bond (Potyondy & Cundall's bonded-particle model, 4-32 ...
 * 4-39; PFC's linear parallel bond): a cement of radius R-bar =
 * lambda-bar min(RA, RB) (4-53) beside the contact, a disk in 3D (a beam of
 * unit thickness and width 2 R-bar in 2D), with stiffnesses per area
 * kn-bar = Ec-bar / (RA + RB), ks-bar = kn-bar / (kn/ks ratio) (4-51/4-52).
 * Carried with the contact (the passes rotate its shear force and bending
 * moment with the contact plane, 4-13 ... 4-15), it is incremented from the
 * relative motion:
 *   Fn += kn-bar A dUn, Fs -= ks-bar A dUs (4-33),
 *   Mt -= ks-bar J dtheta_n, Mb -= kn-bar I dtheta_s (4-34; no twist in 2D),
 * and adds Fn n + Fs to b and Mt n + Mb to b's moment (4-32, 4-39). It breaks
 * when the largest tensile stress -Fn/A + |Mb| R-bar / I reaches sigma-bar_c
 * or the largest shear stress |Fs|/A + |Mt| R-bar / J reaches tau-bar_c
 * (4-38 as corrected: magnitudes, the twist only in 3D), in the mode whose
 * ratio to its strength is the larger; the energy it held is released. */
#pragma once

#include "bond.h"

/* Section of a parallel bond: area, moment of inertia, polar moment (4-35;
 * 2D: a beam of unit thickness, A = 2R, I = 2/3 R^3, no twist). */
static inline void sx_bond_parallel_section(int dim, double r, double *area, double *inertia, double *polar)
{
    if (dim == 3) {
        *area = SX_PI * r * r;
        *inertia = 0.25 * SX_PI * r * r * r * r;
        *polar = 0.5 * SX_PI * r * r * r * r;
    } else {
        *area = 2 * r;
        *inertia = 2.0 / 3.0 * r * r * r;
        *polar = 0;
    }
}

/* The strain energy of bond s: its springs' (1/2) F^2 / k each. */
static inline double sx_bond_parallel_strain(int dim, const sx_bonds *b, int64_t s)
{
    const int rdim = dim == 3 ? 3 : 1;
    double area, inertia, polar;
    sx_bond_parallel_section(dim, b->rbar[s], &area, &inertia, &polar);
    const double *fs = b->fs + s * dim, *ms = b->ms + s * rdim;
    double e = 0.5 * b->fn[s] * b->fn[s] / (b->kn[s] * area) + 0.5 * sx_bond_dot(dim, fs, fs) / (b->ks[s] * area);
    double m2 = 0;
    for (int k = 0; k < rdim; k++) m2 += ms[k] * ms[k];
    e += 0.5 * m2 / (b->kn[s] * inertia);
    if (dim == 3) e += 0.5 * b->mn[s] * b->mn[s] / (b->ks[s] * polar);
    return e;
}

/* What a parallel bond broke with: its mode and the magnitudes for the crack log. */
typedef struct sx_bond_break {
    sx_crack_mode mode;
    double fsn, mnn, msn;
} sx_bond_break;

/* One step of bond s (its shear force and bending moment already carried
 * with the contact plane): the increments of 4-33/4-34 from the normal n,
 * the normal velocity vn of b's centre relative to a's, the shear velocity
 * vs and the relative rotation dtheta, then the strength test (4-38). vn
 * is along the step's mid normal (the bisector of the last evaluation's
 * normal and this one's), not this step's: the half-step velocity dotted
 * with the step's normal is off by w^2 d dt^2 / 2 a step on a pair turning
 * at w, a stretch a tumbling bonded pair would gather without end (pi w dt
 * of strain a turn), where along the mid normal a rigid turn gives none.
 * A jump of a ball (b.pos) is no velocity: a bond does not see it, as in
 * PFC. True when it broke (*out says how). */
static inline bool sx_bond_parallel_step(int dim, sx_bonds *b, int64_t s, const double *n, double vn,
                                         const double *vs, const double *dtheta, double dt, sx_bond_break *out)
{
    const int rdim = dim == 3 ? 3 : 1;
    const double rbar = b->rbar[s];
    double area, inertia, polar;
    sx_bond_parallel_section(dim, rbar, &area, &inertia, &polar);
    double *fs = b->fs + s * dim, *ms = b->ms + s * rdim;
    b->fn[s] += b->kn[s] * area * (-vn * dt); /* 4-33, compression positive */
    for (int k = 0; k < dim; k++) fs[k] -= b->ks[s] * area * vs[k] * dt; /* 4-33 with dUs (seed typo corrected) */
    if (dim == 3) {
        const double twist = sx_bond_dot(3, dtheta, n);
        b->mn[s] -= b->ks[s] * polar * twist; /* 4-34 */
        for (int k = 0; k < 3; k++) ms[k] -= b->kn[s] * inertia * (dtheta[k] - twist * n[k]);
    } else {
        ms[0] -= b->kn[s] * inertia * dtheta[0];
    }
    double ms2 = 0;
    for (int k = 0; k < rdim; k++) ms2 += ms[k] * ms[k];
    const double msn = sqrt(ms2), fsn = sqrt(sx_bond_dot(dim, fs, fs)), mnn = fabs(b->mn[s]);
    /* 4-38 as corrected: magnitudes, the twist only in 3D */
    const double sigma = -b->fn[s] / area + msn * rbar / inertia;
    const double tau = fsn / area + (dim == 3 ? mnn * rbar / polar : 0);
    if (sigma >= b->sigma_c[s] || tau >= b->tau_c[s]) {
        out->mode = sigma / b->sigma_c[s] >= tau / b->tau_c[s] ? SX_CRACK_TENSION : SX_CRACK_SHEAR;
        out->fsn = fsn, out->mnn = mnn, out->msn = msn;
        return true;
    }
    return false;
}

/* An intact bond's force on b added to F and its moment on b to mb (4-32, 4-39). */
static inline void sx_bond_parallel_add(int dim, const sx_bonds *b, int64_t s, const double *n, double *F, double *mb)
{
    const double *fs = b->fs + s * dim;
    for (int k = 0; k < dim; k++) F[k] += b->fn[s] * n[k] + fs[k]; /* 4-32 */
    if (dim == 3) {
        const double *ms = b->ms + s * 3;
        for (int k = 0; k < 3; k++) mb[k] += b->mn[s] * n[k] + ms[k];
    } else {
        mb[0] += b->ms[s];
    }
}

/* The bond's stiffnesses for the critical timestep: translational (kn-bar +
 * ks-bar) A into *kt, rotational kn-bar I + ks-bar J plus the shear spring
 * at each arm into *kra, *krb (ra, rb the balls' radii). The flat joint's
 * face is rated the same way. */
static inline void sx_bond_parallel_stiffness(int dim, const sx_bonds *b, int64_t s, double ra, double rb, double *kt,
                                              double *kra, double *krb)
{
    double area, inertia, polar;
    sx_bond_parallel_section(dim, b->rbar[s], &area, &inertia, &polar);
    *kt += (b->kn[s] + b->ks[s]) * area;
    const double kr = b->kn[s] * inertia + b->ks[s] * polar;
    *kra += kr + b->ks[s] * area * ra * ra;
    *krb += kr + b->ks[s] * area * rb * rb;
}

static inline const sx_bond_law *sx_bond_parallel_bond(void)
{
    static const sx_bond_param params[] = {
        SX_BOND_FACE_PARAMS,
    };
    static const sx_bond_law law = {
        .name = "parallel",
        .kind = SX_BOND_PARALLEL,
        .summary = "parallel bond: a cement disk (2D beam) with its own springs and strengths (4-32 ... 4-39)",
        .params = params,
        .nparams = 7,
    };
    return &law;
}
