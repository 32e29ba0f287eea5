/* The step's kernels, compiled once per dimension (SEIXO_DIM = 2 or 3) so
 * that every vector loop has a constant trip count and a 2D scene never
 * touches a third component. The dimension-independent layer (cycle.c)
 * calls them through sx_kernels_2d / sx_kernels_3d.
 *
 * Broad phase: a uniform grid of cells at least one diameter plus the skin
 * wide; balls are sorted by cell at every build (cache locality and a
 * deterministic pair order); a forward half stencil gives each pair once
 * with a < b. History (shear force and the last evaluation's geometry) is
 * carried across builds from each new pair's old one, found through the
 * sort's permutation among the old pairs of its lower ball (transfer).
 *
 * Contacts and the law of motion have batched forms for the common cases,
 * four pairs, wall contacts or balls at a time in vector lanes (GCC
 * vector extensions), beside the full scalar forms; both give the same
 * bits (tests/test_determinism.c).
 */
#include "joints.h"
#include "laws/bonds.h"
#include "laws/flatjoint.h"
#include "laws/registry.h"
#include "model_internal.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#if SEIXO_DIM == 2
#define D 2
#define RD 1
#define KERNEL(name) name##_2d
#elif SEIXO_DIM == 3
#define D 3
#define RD 3
#define KERNEL(name) name##_3d
#else
#error "SEIXO_DIM must be 2 or 3"
#endif

/* The stages, in the order the step runs them; one translation unit per
 * dimension, so every helper stays static and inlined as one file had it. */
#include "kernels/vec.h"

#include "kernels/facets.c"
#include "kernels/broad_phase.c"
#include "kernels/pair_contacts.c"
#include "kernels/ghosts.c"
#include "kernels/wall_contacts.c"
#include "kernels/motion.c"
#include "kernels/timestep.c"
#include "kernels/clump_motion.c"
#include "kernels/queries.c"

const sx_kernels KERNEL(sx_kernels) = {
    .build = KERNEL(build),
    .contacts = KERNEL(contacts),
    .walls = KERNEL(walls),
    .integrate = KERNEL(integrate),
    .critical_dt = KERNEL(critical_dt),
    .own_dt = KERNEL(own_dt),
    .clumps_step = KERNEL(clumps_step),
    .place_pebbles = KERNEL(place_pebbles),
    .energy = KERNEL(energy),
    .each_contact = KERNEL(each_contact),
    .count_contacts = KERNEL(count_contacts),
    .plan = plan_chunks,
    .ghosts_refresh = KERNEL(ghosts_refresh),
    .cell_stress = KERNEL(cell_stress),
};
