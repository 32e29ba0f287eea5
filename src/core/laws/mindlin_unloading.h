/* Mindlin & Deresiewicz's unloading, beside the seed's incremental shear
 * force (4-18 ... 4-20): a material's `mindlin_unloading` = 1 asks for it
 * (a contact uses it when both of its materials do; against a wall the
 * ball's choice). While the overlap grows, new contact area is laid down
 * free of traction and the incremental form is already theirs (the
 * increment at the current, larger ks); while it shrinks, the shear
 * force also shrinks with the stiffness, which is the contact radius for
 * Hertz-Mindlin (ks = 8 G* a, 4-26; Thornton's form of their rule,
 * T' = ks u + T a'/a; LAMMPS's mindlin_rescale/force):
 *   Fs <- Fs ks(Un) / ks(Un_before)   when ks(Un) < ks(Un_before),
 * before the step's increment. Without it a Hertz contact sheared while
 * loaded gives its shear force back in full as it unloads, at a smaller
 * stiffness: the elastic energy of the incremental form grows, and a
 * sphere thrown at a plane at a small angle leaves with 1.35 % more
 * tangential speed than it came with (docs/lua-api.md, oblique impacts).
 * With a constant ks (the linear law) it changes nothing. The total form
 * (total_shear) scales the force with ks always: the two are exclusive. */
#pragma once

#include "law.h"

static inline void sx_law_mindlin_unloading_mix(sx_pair_law *l, const sx_material *a, const sx_material *b, int self)
{
    (void)self;
    /* a constant-stiffness law (tangent 1: linear) has nothing to scale,
     * and keeps the batched passes */
    l->unloading = a->def.mindlin_unloading == 1 && (!b || b->def.mindlin_unloading == 1) && sx__law_stiffens(l->law);
    if (l->unloading) l->plain = false; /* the batched passes do not scale */
}

static inline const char *sx_law_mindlin_unloading_check(const sx_material_def *d)
{
    if (d->mindlin_unloading != 0 && d->mindlin_unloading != 1)
        return "mindlin_unloading must be 0 (none) or 1 (the shear force shrinks with ks as the overlap does)";
    if (d->mindlin_unloading == 1 && d->total_shear == 1)
        return "mindlin_unloading applies to the incremental shear force: total_shear = 1 scales the force with ks "
               "always; ask for one of them";
    return NULL;
}

/* Scales the shear force fs (dim components, carried into the current
 * contact plane) from the stiffness before, ks0, to the current ks when
 * it fell; returns the strain energy the spring gave up: fs^2 / (2 ks0)
 * as the last step left it, less (ratio fs)^2 / (2 ks) now, which is
 * (1 - ratio) of it (the tangential displacement fs / ks0 is kept); the
 * micro-slip of the shrinking contact's rim dissipates it. */
static inline double sx_law_mindlin_unloading_scale(int dim, double *fs, double ks, double ks0)
{
    if (!(ks < ks0) || !(ks > 0)) return 0;
    const double ratio = ks / ks0;
    double f2 = 0;
    for (int k = 0; k < dim; k++) f2 += fs[k] * fs[k], fs[k] *= ratio;
    return 0.5 * f2 * (1 - ratio) / ks0;
}

static inline const sx_law *sx_law_mindlin_unloading(void)
{
    static const sx_law_param params[] = {
        {"mindlin_unloading", "1", offsetof(sx_material_def, mindlin_unloading), 0, 1, true, true,
         "mindlin_unloading must be 0 (none) or 1 (the shear force shrinks with ks as the overlap does)"},
    };
    static const sx_law law = {
        .name = "mindlin_unloading",
        .kind = SX_LAW_PART,
        .summary = "Mindlin-Deresiewicz unloading: as the overlap shrinks, Fs shrinks with ks (Hertz: the contact radius)",
        .params = params,
        .nparams = 1,
        .mix = sx_law_mindlin_unloading_mix,
        .check = sx_law_mindlin_unloading_check,
    };
    return &law;
}
