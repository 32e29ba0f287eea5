/* The complete state of a model as plain arrays, for the I/O layer.
 *
 * src/io (snapshots and restarts) is part of libseixo's implementation, not
 * a user of its public API: a bit-for-bit restart needs every array the
 * step reads, so it includes model_internal.h and reads the stores
 * directly. What is delicate is done here instead, next to the stores:
 * sizing every array of an empty model for a given number of balls,
 * pairs, bonds, ... with the model's tracked allocator, and, once the I/O
 * layer has filled them, rebuilding what is derived (the id -> index map,
 * the intact-bond count) and checking every cross reference, so a damaged
 * file can never leave a model that crashes the step.
 *
 * What a continuing run reads and what is derived:
 *   saved    balls (all arrays, dense order, incl. x_build and applied
 *            loads), next ball id, both pair stores with their history,
 *            bonds, crack log, walls (definition incl. a cylinder's radius,
 *            height and radial velocity, frame, force, moment, the last
 *            step's load, stiffness sum and contact count, servo settings,
 *            distance moved; a mesh's vertices in its frame, triangles and
 *            orientation), materials with BPM parameters, the contact-model
 *            table's rows (their match, name and law; cmodel.c), and every
 *            scalar of sx_model below `dim` (timestep state, skin, time,
 *            step, builds, build flag, guard, energy tracking);
 *   derived  id -> index map, intact bonds (here), pair laws (refreshed by
 *            every cycle; a contact-model row's when restored), the grid and scratch (rebuilt by every build).
 * Clumps (clumps.h) are sized and checked by their own module: the I/O
 * layer calls sx__clumps_alloc after sx__state_alloc, and sx__state_finish
 * calls sx__clumps_finish, which also rebuilds the balls' clump ids.
 */
#pragma once

#include "model_internal.h"

/// How many entries each store holds.
typedef struct sx_state_sizes {
    int64_t balls;        ///< balls (dense)
    int64_t next_ball_id; ///< ids in use are 1 .. next_ball_id - 1
    bool applied;         ///< the applied force / moment arrays exist
    bool unwrap;          ///< the balls' periodic wraps exist
    int64_t bb, bw;       ///< ball-ball and ball-wall candidate pairs
    bool bw_facets;       ///< the ball-wall store carries mesh facets
    bool bb_bonds;        ///< the ball-ball store carries bond slots
    bool rolling;         ///< both pair stores carry rolling moments (laws/rolling.h)
    bool total_shear;     ///< both pair stores carry shear displacements (laws/total_shear.h)
    int64_t bonds;        ///< bond slots (intact or broken)
    int64_t fj_elements;  ///< flat-joint elements
    int64_t joints;       ///< smooth joints (the ball-ball store carries their fields when > 0)
    int64_t cracks;       ///< entries of the crack log
    int64_t walls;
    int materials;
    int cmodels;          ///< rows of the contact-model table (cmodel.c)
    bool bb_cmodel;       ///< the ball-ball store carries each contact's row (a ball-ball row exists)
    bool bw_cmodel;       ///< the ball-wall store carries each contact's row (a wall row exists)
} sx_state_sizes;


/// Every one of the n values is finite (a restored array's check).
bool sx__state_finite(const double *v, int64_t n);
/// A digest of the whole state in dense order, for ranks that must hold
/// the same bytes (decompose.c): much faster than sx_model_state_hash, but
/// not canonical (a re-sort changes it).
uint64_t sx__state_digest(const sx_model *m);
/// The digest of what every rank holds whole while the balls are
/// scattered (the scalars, the materials and the walls): what a cycle
/// that goes on from a scattered state compares (decompose.c).
uint64_t sx__replicated_digest(const sx_model *m);
/// The vector's squared length is finite: every component is, and none is
/// so large (1e300) that a length, or a product of two, overflows (a
/// restored vector's check: a finite spin of 1e300 broke a bond into NaN).
bool sx__state_length_finite(const double *v, int64_t n);

/// Sizes every store of m, a model just made by sx_model_create and never
/// used, to hold exactly s (arrays zeroed, counts set). SX_EINVAL when m is
/// not empty or a size is out of range, SX_ENOMEM; the message is in m.
sx_status sx__state_alloc(sx_model *m, const sx_state_sizes *s);

/// A mesh for a wall being restored: nv vertices and nt triangles, its
/// arrays zeroed for the I/O layer to fill (body, tri, q) before
/// sx__state_finish derives the rest; NULL when out of memory.
sx_mesh *sx__mesh_alloc(sx_model *m, int64_t nv, int64_t nt);

/// After the arrays are filled: rebuilds the id -> index map and the
/// intact-bond count and checks every index, id, kind and material
/// reference. SX_EINVAL with a message naming the first inconsistency.
sx_status sx__state_finish(sx_model *m);
/// A restore's check of dense row i's stable id in a store (`kind` names
/// it in the message: "ball", "clump"): within 1 .. next_id - 1 and not met
/// before in index_of (every entry -1 at the start); then mapped to i.
sx_status sx__state_map_id(sx_model *m, const char *kind, int32_t *index_of, int64_t next_id, int64_t i, int64_t id);
