/* The contact-law registry. Adding a law: its header under laws/ (see
 * law.h and docs/developer.md), included here, and its name appended to
 * SX_LAWS. The order numbers the laws (sx_material_def.model, the files'
 * `model` enum): append only. */
#pragma once

#include "hertz.h"
#include "linear.h"

#define SX_LAWS(X) X(linear) X(hertz)

#define SX_LAW_ID(name) SX_LAW_ID_##name
#define SX_LAW_ENUM_(name) SX_LAW_ID(name),
enum sx_law_id { SX_LAWS(SX_LAW_ENUM_) SX_LAW_COUNT };
#undef SX_LAW_ENUM_

/* The normal force and secant stiffnesses of pair law l at overlap un
 * (rbar: 4-27's 2 RA RB / (RA + RB); ball-wall R, 4-28), by its law. */
static inline double sx__law_force(const sx_pair_law *l, int dim, double ra, double rb, double rbar, double un,
                                   double *kn, double *ks)
{
    switch (l->law) {
#define SX_LAW_CASE_(name) \
    case SX_LAW_ID(name): return sx_law_##name##_force(l, dim, ra, rb, rbar, un, kn, ks);
        SX_LAWS(SX_LAW_CASE_)
#undef SX_LAW_CASE_
    }
    __builtin_unreachable(); /* l->law is checked when a material is set or loaded */
}
