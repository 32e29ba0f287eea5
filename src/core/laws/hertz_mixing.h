/* How two Hertz materials mix: the seed's means of G and nu (4-27, the
 * default) or the literature's effective moduli (Johnson's, with
 * Mindlin's tangential one), a material's `hertz_mixing` = 1 asks for the
 * latter (a contact uses it when both of its materials do, a ball and a
 * wall of a material likewise):
 *   1/E* = (1 - nuA^2)/EA + (1 - nuB^2)/EB = (1 - nuA)/(2 GA) + (1 - nuB)/(2 GB),
 *   1/G* = (2 - nuA)/GA + (2 - nuB)/GB,
 * (E = 2 G (1 + nu)), R* = RA RB / (RA + RB) (a wall: R), so that
 * Fn = 4/3 E* sqrt(R*) Un^(3/2) and ks = 8 G* sqrt(R* Un). laws/hertz.h
 * turns E*, G* into the G and nu its formulas take. Two balls of one
 * material give the same law either way (4-27's means are then the
 * material's own), so they keep 4-27's bits. A wall with no material of
 * its own is not mixed (4-28, or the rigid plane). */
#pragma once

#include "hertz.h"

static inline void sx_law_hertz_mixing_mix(sx_pair_law *l, const sx_material *a, const sx_material *b, int self)
{
    (void)self;
    if (l->law != SX_MODEL_HERTZ || !b || a->def.hertz_mixing != 1 || b->def.hertz_mixing != 1) return;
    const sx_material_def *p = &a->def, *q = &b->def;
    if (!l->wall && p->shear_modulus == q->shear_modulus && p->poisson == q->poisson) return;
    const double es = 1 / ((1 - p->poisson) / (2 * p->shear_modulus) + (1 - q->poisson) / (2 * q->shear_modulus));
    const double gs = 1 / ((2 - p->poisson) / p->shear_modulus + (2 - q->poisson) / q->shear_modulus);
    sx_law_hertz_literature(l, es, gs);
}

static inline const char *sx_law_hertz_mixing_check(const sx_material_def *d)
{
    return d->hertz_mixing == 0 || d->hertz_mixing == 1
               ? NULL
               : "hertz_mixing must be 0 (the means of G and nu, 4-27) or 1 (the literature's 1/E* and 1/G* sums)";
}

static inline const sx_law *sx_law_hertz_mixing(void)
{
    static const sx_law_param params[] = {
        {"hertz_mixing", "1", offsetof(sx_material_def, hertz_mixing), 0, 1, true, true,
         "hertz_mixing must be 0 (the means of G and nu, 4-27) or 1 (the literature's 1/E* and 1/G* sums)"},
    };
    static const sx_law law = {
        .name = "hertz_mixing",
        .kind = SX_LAW_PART,
        .summary = "two Hertz materials mix by the literature's 1/E* = sum (1 - nu^2)/E, 1/G* = sum (2 - nu)/G",
        .params = params,
        .nparams = 1,
        .mix = sx_law_hertz_mixing_mix,
        .check = sx_law_hertz_mixing_check,
    };
    return &law;
}
