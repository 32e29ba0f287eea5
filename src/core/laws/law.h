/* The contact-law interface (issue 12; in the manner of LAMMPS's granular
 * sub-models): a law is one header under laws/ that declares
 *   - its name and a one-line summary (Lua's `model` key, the files' enum),
 *   - its material parameters with their units and valid ranges (checked
 *     when a material is set or loaded, read by Lua and written by the
 *     HDF5 layer from this table, not from hand-written lists),
 *   - how two materials (or a material and a wall) mix into a pair's law,
 *   - its force: the normal force and the secant stiffnesses kn, ks at an
 *     overlap (static inline, so the scalar passes dispatch on the law's
 *     number through a switch the compiler inlines),
 *   - its strain-energy factor and its tangent-over-secant stiffness ratio
 *     for the critical timestep (4-29),
 *   - whether bonds may join its materials (seed 4.3.3).
 * registry.h lists the laws; their order numbers them. */
#pragma once

#include "../model_internal.h"

#include <math.h>
#include <stddef.h>

/* A material parameter of a law: a double of sx_material_def. */
typedef struct sx_law_param {
    const char *name;     /* the material key (Lua) and dataset name (HDF5) */
    const char *unit;
    size_t offset;        /* offsetof(sx_material_def, ...) */
    double lo, hi;        /* valid range: lo < x < hi, with <= on a closed end */
    bool lo_closed, hi_closed;
    const char *what;     /* for the error message */
} sx_law_param;

/* What a unit of the registry is: a normal law (a material's `model`,
 * one per contact) or a part every contact runs beside it, switched on by
 * its parameters (rolling resistance, damping by restitution). */
typedef enum sx_law_kind { SX_LAW_MODEL, SX_LAW_PART } sx_law_kind;

typedef struct sx_law {
    const char *name;
    const char *summary;
    sx_law_kind kind;
    const sx_law_param *params;
    int nparams;
    /* Completes the pair law l (its springs in series, friction and
     * dashpot ratios already mixed by the model, 4-22/4-23/4-30; a part
     * after the contact's law) for materials a and b; b is NULL for a
     * ball against a wall. */
    void (*mix)(sx_pair_law *l, const sx_material *a, const sx_material *b, int self); /* self: its number */
    /* A material's constant of this unit, derived once when it is set or
     * loaded (into sx_material.derived[its number]); NULL: none. */
    double (*derive)(const sx_material_def *d);
    /* Why the parameters do not go together, or NULL; NULL: no such rule. */
    const char *(*check)(const sx_material_def *d);
    double strain;        /* a law: the normal spring's strain energy is strain x Fn Un */
    double tangent;       /* a law: tangent / secant normal stiffness, for the critical timestep */
    bool series;          /* a law: a pair's springs are its two sides' in series (a ball's own is
                           * twice its contact with itself) */
    bool bonds;           /* a law: bonds may join materials of this law */
} sx_law;

/* The law or part numbered id, or NULL (laws.c). */
const sx_law *sx__law(int id);
/* Whether law id's stiffness grows with the overlap (Hertz: its tangent
 * stiffness is not its secant): the timestep's rating by speed and
 * Mindlin & Deresiewicz's unloading apply to it, not to a constant one. */
static inline bool sx__law_stiffens(int id) { return sx__law(id)->tangent != 1; }
/* Mixes every part into l (after its law's mix). */
void sx__law_parts_mix(sx_pair_law *l, const sx_material *a, const sx_material *b);
/* A material's parameter of a law. */
static inline double *sx__law_value(sx_material_def *d, const sx_law_param *p)
{
    return (double *)((char *)d + p->offset);
}

/* The cap of a spring force (Coulomb slip 4-30/4-31, the rolling limit):
 * when |v|^2 = v2 exceeds limit^2, scales v (n components) to the limit,
 * adds to *work (if not NULL) the plastic work, the mean of the force
 * before the step (v0) and after it along the plastic displacement
 * (trial - final) / k, and gives the scale in *scale; false within it. */
static inline bool sx__law_cap(int n, double *v, const double *v0, double v2, double limit, double k, double *work,
                               double *scale)
{
    if (!(v2 > limit * limit)) return false;
    const double sc = limit / sqrt(v2);
    if (work && k > 0) {
        double e = 0;
        for (int i = 0; i < n; i++) e += (v0[i] + sc * v[i]) * (1 - sc) * v[i];
        *work += 0.5 * e / k;
    }
    for (int i = 0; i < n; i++) v[i] *= sc;
    *scale = sc;
    return true;
}
