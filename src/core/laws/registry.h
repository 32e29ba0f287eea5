/* The contact-law registry. Adding a law: its header under laws/ (see
 * law.h and docs/developer.md), included here, and its name appended to
 * SX_LAWS (a contact's normal law, a material's `model`) or SX_PARTS (a
 * part every contact runs beside its law). The order numbers them
 * (sx_material_def.model, the files' `model` enum): append only. */
#pragma once

#include "hertz.h"
#include "hertz_mixing.h"
#include "linear.h"
#include "mindlin_unloading.h"
#include "restitution.h"
#include "rolling.h"
#include "total_shear.h"

#define SX_LAWS(X) X(linear) X(hertz)
#define SX_PARTS(X) X(restitution) X(rolling) X(total_shear) X(hertz_mixing) X(mindlin_unloading)

#define SX_LAW_ID(name) SX_LAW_ID_##name
#define SX_LAW_ENUM_(name) SX_LAW_ID(name),
enum sx_law_id { SX_LAWS(SX_LAW_ENUM_) SX_PARTS(SX_LAW_ENUM_) SX_LAW_COUNT };
#undef SX_LAW_ENUM_
#define SX_LAW_ONE_(name) +1
enum { SX_MODEL_COUNT = 0 SX_LAWS(SX_LAW_ONE_) }; /* the normal laws: numbers 0 .. SX_MODEL_COUNT - 1 */
#undef SX_LAW_ONE_
_Static_assert(SX_LAW_COUNT <= SX_LAW_MAX, "raise SX_LAW_MAX");

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
