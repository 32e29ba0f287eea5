/* The linear law: Fn = kn Un (4-6) with the two balls' springs in series
 * (4-22/4-23), or, in the BPM modulus mode, each side's stiffness from its
 * contact modulus and radius (4-49/4-50) put in series per contact; a
 * rigid wall adds no spring (the ball's own kn, ks). The
 * shear spring is incremental (4-18 ... 4-20). Its common case (no
 * modulus) is `plain`: the batched passes run it four pairs at a time. */
#pragma once

#include "law.h"

static inline double sx_law_linear_force(const sx_pair_law *l, int dim, double ra, double rb, double rbar,
                                         double un, double *kn, double *ks)
{
    (void)rbar;
    if (l->per_radius) {
        const double kna = l->ec_a > 0 ? (dim == 3 ? 4 * ra * l->ec_a : 2 * l->ec_a) : l->kn_a; /* 4-49 */
        const double ksa = l->ec_a > 0 ? kna / l->ratio_a : l->ks_a;                             /* 4-50 */
        if (l->rigid) { /* a rigid wall: in series with an infinite spring */
            *kn = kna, *ks = ksa;
            return *kn * un;
        }
        const double knb = l->ec_b > 0 ? (dim == 3 ? 4 * rb * l->ec_b : 2 * l->ec_b) : l->kn_b;
        const double ksb = l->ec_b > 0 ? knb / l->ratio_b : l->ks_b;
        *kn = kna * knb / (kna + knb);
        *ks = ksa + ksb > 0 ? ksa * ksb / (ksa + ksb) : 0;
    } else {
        *kn = l->kn;
        *ks = l->ks;
    }
    return *kn * un; /* 4-6 */
}

static inline void sx_law_linear_mix(sx_pair_law *l, const sx_material *a, const sx_material *b,
                                     int self)
{
    (void)a, (void)b, (void)self;
    l->plain = !l->per_radius;
}

static inline const sx_law *sx_law_linear(void)
{
    static const sx_law law = {
        .name = "linear",
        .kind = SX_LAW_MODEL,
        .summary = "linear springs kn, ks in series (4-22/4-23), or from the BPM modulus (4-49/4-50)",
        .mix = sx_law_linear_mix,
        .strain = 0.5,
        .tangent = 1,
        .series = true,
        .bonds = true,
    };
    return &law;
}
