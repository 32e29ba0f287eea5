/* What the clumps' files share inside the core (clumps.h describes the
 * store, clump_math.h has the rotations). The files, one job each:
 *   clumps.c            the bodies: add, remove, read and set
 *   clump_templates.c   the templates: define, find, read
 *   clump_mass.c        a template's mass properties
 *   clump_queries.c     what the other stages ask: energy, timestep, balance
 *   clump_store.c       the store's memory; a restore's sizes and checks; the hash
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

/* Lines per axis of a template's overlap integration (clump_mass.c): the
 * defaults, and the range a template may ask for. At most 16 times the
 * default's work in 3D (lines^2), 16 times its lines in 2D. */
enum { LINES_3D = 512, LINES_2D = 65536, LINES_MIN = 16, LINES_MAX_3D = 2048, LINES_MAX_2D = 1 << 20 };

/* The mass properties of template t from its pebbles (tp_pos, tp_rad),
 * the overlaps integrated on `lines` lines per axis (0: the default):
 * fills everything but the name and the pebble range, and the pebbles'
 * centres in the body frame (tp_body). SX_ENOMEM, SX_EINTERRUPT, or
 * SX_EINVAL when the properties are degenerate. */
sx_status sx__clump_mass_props(sx_model *m, sx_clump_tpl *t, int64_t lines);

/* Template t, or NULL with a message naming fn (SX_ENOTFOUND). */
const sx_clump_tpl *sx__clump_template_at(const sx_model *m, int t, const char *fn);
