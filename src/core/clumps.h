/* The clump store (clumps.c), private to the core and to the I/O layer
 * (which saves every array below for bit-for-bit restarts).
 *
 * Templates are cold data, never removed: their pebbles live in shared
 * arrays (tp_*), each template owning a contiguous range. Clumps are a
 * structure of arrays indexed densely, with stable ids; their pebbles are
 * balls, listed by ball id in `pebble`, each clump owning the contiguous
 * range first[c] .. first[c] + (its template's pebble count). Pebble k of
 * a clump is pebble k of its template.
 *
 * Frames: a template gives pebble centres in its own frame. Its body frame
 * is the principal frame about the centroid (3D: the eigenvectors of the
 * inertia tensor, a rotation `frame` of the template frame; 2D: the
 * template frame itself), where a pebble sits at tp_body. A clump's state
 * is its centroid x and velocity v, its orientation q (3D: the unit
 * quaternion from the body frame to space; 2D: the angle), its angular
 * momentum L in space (3D) and spin w in space, velocities and L at half
 * steps, positions and orientation at whole steps (4-44 ... 4-48). */
#pragma once

#include "model_internal.h"

typedef struct sx_clump_tpl {
    char name[64];
    int64_t first, n;       /* its pebbles in the tp_* arrays */
    int64_t lines;          /* lines per axis of the overlap integration (0: exact, no overlaps) */
    double volume;          /* of the union at scale 1: m^3 (2D: m^2) */
    double centroid[3];     /* template frame */
    double inertia[9];      /* per unit density about the centroid, template frame, row-major 3x3 (2D: [0] = Izz) */
    double principal[3];    /* principal moments per unit density, ascending (2D: [0] = Izz) */
    double frame[4];        /* quaternion of the principal axes in the template frame (2D: identity) */
    double error;           /* estimated relative error of the integration (0: exact) */
    double power_sum;       /* sum of r^dim over its pebbles: a pebble's share of the volume is r^dim / power_sum */
} sx_clump_tpl;

typedef struct sx_clumps {
    /* templates */
    int ntpl, cap_tpl;
    sx_clump_tpl *tpl;
    int64_t tp_n, tp_cap;
    double *tp_pos;         /* pebble centres, template frame (dim per pebble) */
    double *tp_rad;         /* radii */
    double *tp_body;        /* centres in the body frame relative to the centroid (dim per pebble) */

    /* clumps, dense */
    int64_t n, cap;
    int32_t *id, *tpl_of;
    uint16_t *mat;
    uint8_t *fix;           /* SX_FIX_* bits as balls store them (2D spin: SX_FIX_WX) */
    double *scale;
    double *x, *v;          /* centroid, velocity (dim) */
    double *q;              /* 3D: quaternion (4), 2D: angle (1) */
    double *L;              /* 3D: angular momentum in space (3); NULL in 2D (L = I w) */
    double *w;              /* spin in space (rdim) */
    double *f, *t;          /* resultant force (dim) and moment about the centroid (rdim), last step */
    double *alpha;          /* local damping */
    double *mass;           /* kg */
    double *inertia;        /* principal moments, kg m^2 (rdim, ascending) */
    int64_t *first;         /* first pebble in `pebble` */

    /* pebbles of the clumps (ball ids) */
    int64_t pn, pcap;
    int32_t *pebble;

    /* id -> dense index (-1 when removed); ids are 1 .. next_id - 1 */
    int32_t *index_of;
    int64_t index_cap, next_id;
} sx_clumps;

/* Restores (the I/O layer fills the arrays in between; see state.h). */
typedef struct sx_clump_sizes {
    int templates;
    int64_t template_pebbles, clumps, pebbles, next_id;
} sx_clump_sizes;

/* Sizes the clump store of a model being restored (its balls already
 * sized) to exactly s; nothing is allocated when s is all zero. */
sx_status sx__clumps_alloc(sx_model *m, const sx_clump_sizes *s);
/* After the arrays are filled (and the balls checked): rebuilds the id
 * map and the balls' clump ids and checks every reference. */
sx_status sx__clumps_finish(sx_model *m);
