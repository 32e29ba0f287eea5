/* The contact bond (seed 4.3.5; PFC's contact bond): a glue of no size at
 * the contact point, holding the contact law's springs in tension as well
 * as compression. It adds no force of its own: while it is intact the
 * contact's normal spring acts whatever the sign of the overlap and the
 * shear force is not capped by friction. It breaks
 *   in tension  when the tensile normal force -Fn reaches its normal
 *               strength: both forces vanish, and the released energy is
 *               the two springs' (1/2 Fn Un + |Fs|^2 / (2 ks));
 *   in shear    when |Fs| reaches its shear strength: Coulomb slip takes
 *               over from that step.
 * Strengths are drawn per bond at installation (normal distribution of the
 * given mean and standard deviation, truncated at zero). Its stiffness for
 * the critical timestep and its strain energy are the contact's. */
#pragma once

#include "bond.h"

/* The test of an intact contact bond: the crack mode it breaks in, or 0. */
static inline int sx_bond_contact_test(double fn, double fsn, double normal_strength, double shear_strength)
{
    if (-fn >= normal_strength) return SX_CRACK_TENSION;
    if (fsn >= shear_strength) return SX_CRACK_SHEAR;
    return 0;
}

/* The energy a break releases: the normal and shear springs' (fsn = |Fs|). */
static inline double sx_bond_contact_released(double fn, double un, double fsn, double ks)
{
    return 0.5 * fn * un + (ks > 0 ? 0.5 * fsn * fsn / ks : 0);
}

static inline const sx_bond_law *sx_bond_contact_bond(void)
{
    static const sx_bond_param params[] = {
        SX_BOND_PARAM(normal_strength, "N", INFINITY, false),
        SX_BOND_PARAM(normal_strength_sd, "N", INFINITY, false),
        SX_BOND_PARAM(shear_strength, "N", INFINITY, false),
        SX_BOND_PARAM(shear_strength_sd, "N", INFINITY, false),
    };
    static const sx_bond_law law = {
        .name = "contact",
        .kind = SX_BOND_CONTACT,
        .summary = "contact bond: the contact's springs hold tension until the normal or shear strength (4.3.5)",
        .params = params,
        .nparams = 4,
    };
    return &law;
}
