/* What the clumps' files share, inside the core (clumps.h describes the
 * store; clump_math.h has the rotations):
 *   clump_store.c           the store's memory; a restore's sizes and checks; the hash
 *   clumps.c                the bodies: add, remove, read and set
 * and the step, once per dimension, in kernels/clump_motion.c. */
#pragma once

#include "clumps.h"

/* Doubles per clump orientation: 3D a quaternion, 2D an angle. */
static inline int qdim(const sx_model *m) { return m->dim == 3 ? 4 : 1; }

/* Room for one more template of n pebbles, the store made with the first
 * (SX_ENOMEM). */
sx_status sx__clump_template_reserve(sx_model *m, int64_t n);
/* Room for one more clump of n pebbles: its row, its pebbles, its id, and
 * n more balls with their clump ids (SX_ENOMEM). The store exists. */
sx_status sx__clump_reserve(sx_model *m, int64_t n);
