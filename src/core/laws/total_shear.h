/* Mindlin's no-slip total tangential form, beside the seed's incremental
 * one (4-18 ... 4-20, the default). A material's `total_shear` = 1 asks
 * for it (a contact uses it when both of its materials do; against a wall
 * the ball's choice). The contact carries its accumulated tangential
 * displacement Us (history, dim components), rotated with the contact
 * plane as the shear force is (4-14/4-15) and incremented by the relative
 * tangential velocity (4-17):
 *   Us <- Us + vs dt,   Fs = -ks Us   (ks the current stiffness, 4-26),
 * capped by Coulomb (4-30/4-31), and on slip Us follows the capped force
 * (Us = -Fs / ks), so the spring unloads from the slip surface. With a
 * constant ks (the linear law) both forms give the same force; with
 * Hertz-Mindlin's ks, which grows with the normal force, the incremental
 * form keeps the force the tangential motion built at the stiffness of
 * its time, and the total form rescales it to the current one. */
#pragma once

#include "law.h"

static inline void sx_law_total_shear_mix(sx_pair_law *l, const sx_material *a, const sx_material *b, int self)
{
    (void)self;
    l->total_shear = a->def.total_shear == 1 && (!b || b->def.total_shear == 1);
    if (l->total_shear) l->plain = false; /* the batched passes are incremental */
}

static inline const char *sx_law_total_shear_check(const sx_material_def *d)
{
    return d->total_shear == 0 || d->total_shear == 1
               ? NULL
               : "total_shear must be 0 (the incremental shear force, 4-20) or 1 (Mindlin's total form)";
}

/* The total form after the incremental step computed fs: Us advanced by vs dt
 * (us carried into the current contact plane already) and fs = -ks Us. */
static inline void sx_law_total_shear_force(int dim, double *us, double *fs, const double *vs, double ks, double dt)
{
    for (int k = 0; k < dim; k++) {
        us[k] += vs[k] * dt;
        fs[k] = -ks * us[k];
    }
}

/* After a Coulomb cap scaled fs by sc: the displacement follows. */
static inline void sx_law_total_shear_slip(int dim, double *us, double sc)
{
    for (int k = 0; k < dim; k++) us[k] *= sc;
}

static inline const sx_law *sx_law_total_shear(void)
{
    static const sx_law_param params[] = {
        {"total_shear", "1", offsetof(sx_material_def, total_shear), 0, 1, true, true,
         "total_shear must be 0 (the incremental shear force, 4-20) or 1 (Mindlin's total form)"},
    };
    static const sx_law law = {
        .name = "total_shear",
        .kind = SX_LAW_PART,
        .summary = "Mindlin's total tangential form: Fs = -ks Us from the accumulated displacement, Coulomb-capped",
        .params = params,
        .nparams = 1,
        .mix = sx_law_total_shear_mix,
        .check = sx_law_total_shear_check,
    };
    return &law;
}
