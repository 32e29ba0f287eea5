/* The bond-law interface (issue 12): a bond kind is one header under laws/
 * (contact_bond.h, parallel_bond.h, flatjoint.h) that declares
 *   - its name (m:bond's `kind`, the crack log's) and its kind bit,
 *   - its micro-parameters with their units and valid ranges: each a field
 *     of a material's sx_bpm_def (its `bond` table, the files' bond_*
 *     columns) and of an installing call's sx_bond_def (m:bond's keys);
 *     Lua and the HDF5 layer read and write them from this table,
 *   - its force and moment, its strength test, its stiffness for the
 *     critical timestep and its strain energy, as static inline functions
 *     of the dimension (the passes call them with their constant D).
 * SX_BONDS below lists the kinds; a parameter several kinds share (the
 * flat joint's radius_multiplier, modulus, ... are the parallel bond's) is
 * declared by each and appears once in the union (sx_bond_key_*). */
#pragma once

#include "../model_internal.h"

#include <math.h>
#include <stddef.h>

/* A bond micro-parameter: a double of sx_bpm_def and of sx_bond_def alike. */
typedef struct sx_bond_param {
    const char *name;     /* the key (m:bond, a material's bond table) and, after bond_, the files' column */
    const char *unit;
    size_t material;      /* offsetof(sx_bpm_def, ...) */
    size_t call;          /* offsetof(sx_bond_def, ...) */
    double lo, hi;        /* valid range: lo <= x, x < hi (x <= hi when hi_closed); lo is 0 for all */
    bool hi_closed;
    bool whole;           /* a count: a whole number */
} sx_bond_param;

#define SX_BOND_PARAM(field, unit, hi, hi_closed) \
    {#field, unit, offsetof(sx_bpm_def, field), offsetof(sx_bond_def, field), 0, hi, hi_closed, false}
/* A count in [0, hi]. */
#define SX_BOND_COUNT(field, hi) {#field, "1", offsetof(sx_bpm_def, field), offsetof(sx_bond_def, field), 0, hi, true, true}

typedef struct sx_bond_law {
    const char *name;
    sx_bond_kind kind;
    const char *summary;
    const sx_bond_param *params;
    int nparams;
} sx_bond_law;

/* The cement face's micro-parameters, the parallel bond's (4-35, 4-38) and
 * the flat joint's alike: one list for both kinds' tables. */
#define SX_BOND_FACE_PARAMS                                                                                            \
    SX_BOND_PARAM(radius_multiplier, "1", INFINITY, false), SX_BOND_PARAM(modulus, "Pa", INFINITY, false),             \
        SX_BOND_PARAM(stiffness_ratio, "1", INFINITY, false), SX_BOND_PARAM(tensile_strength, "Pa", INFINITY, false), \
        SX_BOND_PARAM(tensile_strength_sd, "Pa", INFINITY, false), SX_BOND_PARAM(cohesion, "Pa", INFINITY, false),    \
        SX_BOND_PARAM(cohesion_sd, "Pa", INFINITY, false)

/* The sum of a[k] b[k] from zero, as the passes' dot() (the same bits). */
static inline double sx_bond_dot(int dim, const double *a, const double *b)
{
    double s = 0;
    for (int k = 0; k < dim; k++) s += a[k] * b[k];
    return s;
}

/* The first micro-parameter of d (a material's, or with call an installing
 * call's sx_bond_def) out of its range, described into why, or NULL. */
const char *sx__bond_params_invalid(const void *d, bool call, char *why, size_t len);
