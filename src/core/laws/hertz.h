/* The Hertz-Mindlin law (4-25 ... 4-29): from the shear modulus G and
 * Poisson's ratio nu, Fn = kn Un with the secant stiffness
 * kn = 2 G sqrt(2 R-bar) / (3 (1 - nu)) sqrt(Un) (4-25) and the shear
 * stiffness ks = 2 (G^2 3 (1 - nu) R-bar)^(1/3) / (2 - nu) Fn^(1/3)
 * (4-26); the tangent normal stiffness is 3/2 kn (4-29). Two materials mix
 * by the means of G and nu (4-27); against a wall a ball uses its own
 * (4-28, R-bar = R); a wall of a material mixes with the ball's by 4-27,
 * with R-bar = R. Not to be bonded (seed 4.3.3).
 *
 * In the literature's terms (Johnson's Fn = 4/3 E* sqrt(R*) Un^(3/2),
 * Mindlin's ks = 8 G* a, a = sqrt(R* Un)) 4-25/4-26 are
 *   E* = s G / (1 - nu),  G* = s G / (2 (2 - nu)),  s = sqrt(R-bar / (2 R*)):
 * two balls of one material (R-bar = 2 R*, s = 1) are exactly the
 * literature's pair, E* = E / (2 (1 - nu^2)), G* = G / (2 (2 - nu)). Both
 * stiffnesses scale with G sqrt(R-bar) at a given nu, so a pair law whose
 * G is scaled by c is the same law at R-bar c^2: sx_law_hertz_literature
 * sets the G and nu that give any E*, G* at the R-bar the passes use. A
 * rigid plane (E* = E / (1 - nu^2) = 2 G / (1 - nu), G* = G / (2 - nu),
 * R* = R) is 4-25/4-26 at R-bar = 8 R: the wall pass's R-bar = R with G
 * scaled by sqrt(8). */
#pragma once

#include "law.h"

#include <math.h>

static inline double sx_law_hertz_force(const sx_pair_law *l, int dim, double ra, double rb, double rbar,
                                        double un, double *kn, double *ks)
{
    (void)dim, (void)ra, (void)rb;
    const double u = un > 0 ? un : 0;
    *kn = 2 * l->g * sqrt(2 * rbar) / (3 * (1 - l->nu)) * sqrt(u);                  /* 4-25 */
    const double fn = *kn * u;
    *ks = 2 * cbrt(l->g * l->g * 3 * (1 - l->nu) * rbar) / (2 - l->nu) * cbrt(fn); /* 4-26 */
    return fn;
}

static inline void sx_law_hertz_mix(sx_pair_law *l, const sx_material *a, const sx_material *b,
                                    int self)
{
    (void)self;
    l->g = b ? 0.5 * (a->def.shear_modulus + b->def.shear_modulus) : a->def.shear_modulus; /* 4-27, 4-28 */
    l->nu = b ? 0.5 * (a->def.poisson + b->def.poisson) : a->def.poisson;
    if (l->rigid) l->g *= 2 * SX_SQRT2; /* the rigid plane: R-bar = 8 R (above) */
}

/* The G and nu that make 4-25/4-26 the literature's contact of effective
 * moduli es (E*) and gs (G*) at the R-bar the passes use (a wall: R,
 * R* = R, s = 1/sqrt(2); two balls: 2 R*, s = 1): G/(1 - nu) = E* / s and
 * G/(2 (2 - nu)) = G* / s give nu = (4 G* - E*)/(2 G* - E*), in [0, 0.5)
 * for any two materials of nu in [0, 0.5) (E* / G* is then in [4, 6)). */
static inline void sx_law_hertz_literature(sx_pair_law *l, double es, double gs)
{
    const double s = l->wall ? 1 / SX_SQRT2 : 1, e = es / s, g = gs / s;
    l->nu = (4 * g - e) / (2 * g - e);
    l->g = e * (1 - l->nu);
}

static inline const sx_law *sx_law_hertz(void)
{
    static const sx_law_param params[] = {
        {"shear_modulus", "Pa", offsetof(sx_material_def, shear_modulus), 0, INFINITY, false, false,
         "the Hertz shear modulus must be > 0 Pa"},
        {"poisson", "1", offsetof(sx_material_def, poisson), 0, 0.5, true, false,
         "the Hertz Poisson's ratio must be in [0, 0.5)"},
    };
    static const sx_law law = {
        .name = "hertz",
        .kind = SX_LAW_MODEL,
        .summary = "Hertz-Mindlin from shear_modulus and poisson (4-25 ... 4-29)",
        .params = params,
        .nparams = 2,
        .mix = sx_law_hertz_mix,
        .strain = 0.4,
        .tangent = 1.5, /* 4-29 */
        .series = false,
        .bonds = false,
    };
    return &law;
}
