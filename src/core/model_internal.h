/* The model's private layout, shared by the dimension-independent layer
 * (model.c, balls.c, walls.c, ...) and the kernels compiled once per
 * dimension (kernels.c with SEIXO_DIM = 2 and 3).
 *
 * Storage is a structure of arrays. A vector field holds `dim` components
 * per ball, a rotational field `rdim` (1 in 2D, 3 in 3D), so a 2D scene
 * never stores a third component. Ids are stable; dense indices change when
 * the broad phase re-sorts balls spatially.
 */
#pragma once

#include "alloc.h"
#include "seixo.h"

#include <math.h>
#include <signal.h>

#define SX_ERRLEN 1024

/* pi to double precision (M_PI is not C11) */
#define SX_PI 3.14159265358979323846
#define SX_SQRT2 1.41421356237309504880

#define SX_LAW_MAX 16 /* units of the law registry, at most */

typedef struct sx_material {
    char name[64];
    sx_material_def def;
    sx_bpm_def bpm;
    double derived[SX_LAW_MAX]; /* the registry units' constants of the material (sx__material_derive) */
} sx_material;

/* The element types of the stores' fields (sx_bond_field, sx_ball_field,
 * sx_pair_field). */
typedef enum sx_field_type { SX_FIELD_I32, SX_FIELD_F64, SX_FIELD_U8, SX_FIELD_U16 } sx_field_type;
/* Bytes of one element of a field. */
static inline size_t sx__field_size(sx_field_type t)
{
    return t == SX_FIELD_F64 ? sizeof(double) : t == SX_FIELD_I32 ? sizeof(int32_t) : t == SX_FIELD_U16 ? 2 : 1;
}
/* Resizes a store's field, `per` elements of type t a row, from `from`
 * rows to `to`; false (the array as it was) out of memory. */
static inline bool sx__field_resize(sx_alloc *a, void **data, int per, sx_field_type t, int64_t from, int64_t to)
{
    void *q = sx_alloc_resize(a, *data, (size_t)(from * per), (size_t)(to * per), sx__field_size(t));
    if (q) *data = q;
    return q != NULL;
}

/* Bonds live apart from pairs, so an unbonded scene stores none. A pair
 * refers to its bond by slot (pairs.bond, allocated with the first bond);
 * slots are never reused. Vectors are expressed for the pair's a -> b
 * orientation, like the pair's shear force. */
typedef struct sx_bonds {
    int64_t n, cap, intact;
    uint8_t *kind;          /* SX_BOND_* bits still intact */
    int32_t *ida, *idb;     /* the balls, by id (the pair may be re-sorted) */
    double *cb_n, *cb_s;    /* contact-bond strengths, N */
    double *rbar, *kn, *ks; /* parallel bond: radius (4-53), stiffnesses per area (4-51/4-52) */
    double *sigma_c, *tau_c;/* parallel-bond strengths, Pa */
    double *fn;             /* normal force, compression positive */
    double *fs;             /* shear force (dim) */
    double *mn;             /* twisting moment about n (3D only; scalar) */
    double *ms;             /* bending moment (3D: vector, 2D: scalar) */
    /* flat joint (laws/flatjoint.h), in the orientation ida -> idb as
     * installed (the pair may turn round; the joint does not): its face
     * radius, kn, ks are rbar, kn, ks above, and fn, fs, mn, ms its last
     * resultants on the pair's b (as the parallel bond's) */
    int32_t *fj_first;      /* its first element in m->fjel */
    uint8_t *fj_nr, *fj_na; /* rings (2D: elements) and sectors (3D; 2D: 1) */
    double *fj_mu, *fj_tanphi; /* friction of unbonded elements; tan phi-bar of bonded ones */
    double *fj_d0;          /* centre distance at installation */
    double *fj_rot;         /* relative bend rotation in the face's axes (3D: 2; 2D: 1) */
    double *fj_axis;        /* 3D: the face's first in-plane axis t1 (3), carried with the contact */
} sx_bonds;

/* The bond store's per-bond arrays, described once (sx__bond_fields):
 * resizing, freeing, a restart's allocation, turning a bond round, the
 * bytes and the ranks' digest iterate this table. (The files, the state
 * hash and the checks of a loaded state list theirs, as formats.) */
typedef struct sx_bond_field {
    void **data;           /* the array's address in the store */
    int per;               /* elements per bond */
    sx_field_type type;
    bool sign;             /* a vector on the pair's b: negated when the pair turns round */
    bool joint;            /* a flat joint's (laws/flatjoint.h) */
} sx_bond_field;
#define SX_BOND_FIELDS_MAX 24
/* The arrays of bond store b, into f; returns their count. */
int sx__bond_fields(const sx_model *m, sx_bonds *b, sx_bond_field *f);

/* Flat-joint elements: each joint owns fj_nr x fj_na consecutive ones. */
typedef struct sx_fjels {
    int64_t n, cap;
    uint8_t *state;         /* sx_fj_state */
    double *sigma_c, *coh;  /* Pa, drawn per element */
    double *gap0;           /* m, gap at installation (unbonded elements; 0 when bonded) */
    double *fs;             /* shear force in the face's axes (3D: 2; 2D: 1) */
    double *fn;             /* last normal force, compression positive */
} sx_fjels;

typedef struct sx_cracks {
    int64_t n, cap;
    sx_crack *ev;
} sx_cracks;

/* Balls: hot arrays first. */
typedef struct sx_balls {
    int64_t n, cap;
    double *x, *v, *w;     /* position (dim), velocity (dim), spin (rdim) */
    double *f, *t;         /* force (dim), moment (rdim) of the last step */
    double *x_build;       /* position at the last broad-phase build (dim) */
    double *rad, *inv_mass, *inv_inertia; /* radius, 1/m, 1/I */
    int32_t *id;           /* stable id of each dense index */
    uint16_t *mat;         /* material index */
    uint8_t *fix;          /* SX_FIX_* bits (2D: spin bit stored as SX_FIX_WX) */
    /* allocated once some ball needs them (sx__balls_expand_*): local damping,
     * NULL while every ball has its material's (sx__ball_damping); user
     * group number, NULL while every ball is in none (0) */
    double *alpha;
    int32_t *group;
    int32_t *clump;        /* clump id of each ball (0: a free ball); NULL while the model has no clumps */
    /* cold: applied loads, allocated on first use */
    double *fapp, *tapp;
    /* periodic space: how far each ball was moved back into the cell since
     * it was placed, the cell vectors of each wrap as they were then (dim a
     * ball; LAMMPS's image flags, kept as lengths so that a deforming cell
     * moves no ball's unwrapped position x + unwrap, which is where its
     * velocity took it; kept when the space becomes open or the cell is
     * made anew, where the balls stay: their unwrapped positions go on);
     * NULL until a periodic build wraps a ball */
    double *unwrap;
    /* id -> dense index (-1 when deleted); ids are 1..next_id-1 */
    int32_t *index_of;
    int64_t index_cap, next_id;
} sx_balls;

/* The ball store's per-ball arrays, described once: resizing, freeing,
 * moving, permuting, a periodic cell's ghost slots, the store's bytes and
 * the ranks' digest iterate this table (sx__ball_fields); an optional array
 * joins it once allocated. (The files and the state hash list theirs: a
 * file's columns and the hash's canonical order are a format.) */
typedef struct sx_ball_field {
    void **data;           /* the array's address in the store */
    int per;               /* elements per ball */
    sx_field_type type;
    bool ghost;            /* a periodic ghost slot carries it (applied loads: only real balls) */
} sx_ball_field;
#define SX_BALL_FIELDS_MAX 18 /* every optional array included */

/* A triangle mesh (mesh.c): its shape in its own frame, fixed at creation,
 * and its pose (the wall's point and an orientation); the world vertices
 * and facet normals follow the pose at every step. The facets' grid is in
 * the mesh's frame, so a moving mesh never rebuilds it: a ball is taken
 * into that frame to find its facets. */
typedef struct sx_mesh {
    int64_t nv, nt;
    double *body;          /* vertices relative to the point, in the mesh's frame (3 nv) */
    int32_t *tri;          /* three vertex indices per facet (3 nt) */
    double q[4];           /* orientation: unit quaternion (w, x, y, z), body -> world */
    double rot[9];         /* its rotation matrix, row-major */
    double *x;             /* world vertices: point + rot body (3 nv) */
    double *nrm;           /* facets' unit normals (x1 - x0) x (x2 - x0), world (3 nt) */
    double reach;          /* the largest distance of a vertex from the point, m */
    /* the facets' grid (mesh frame): cells of side cell from lo, CSR lists */
    double lo[3], cell;
    int64_t nc[3];
    int32_t *start, *items;
    int64_t nitems;
    uint32_t *stamp;       /* per facet: the last query that met it (one query lists a facet once) */
    uint32_t query;
} sx_mesh;

typedef struct sx_wall {
    int64_t id;
    sx_wall_def def;       /* def.point moves with the wall */
    double u[3], v[3];     /* rect: unit edge directions; length in len_u, len_v */
    double len_u, len_v;
    double seg_len;        /* segment length */
    double force[3], moment[3];
    double load, kn_sum;   /* sum of normal contact forces and stiffnesses, last step */
    int64_t contacts;      /* its contacts in the last step */
    bool servo_on;
    sx_servo_def servo;
    double moved;          /* distance moved since the last broad-phase build */
    sx_mesh *mesh;         /* SX_WALL_MESH: its mesh (owned), else NULL */
} sx_wall;

/* Candidate pairs of the broad phase with their history, in one flat
 * structure of arrays. Ball-ball pairs: a < b as dense indices, grouped by a
 * (CSR) in cell order. Ball-wall pairs: a the ball, b the wall's index.
 * History: the shear force on b (dim) and the geometry of the last
 * evaluation (dim), whose normal the rotation 4-7/4-14 starts from.
 * touching = 0 means no history. */
typedef struct sx_pairs {
    int64_t n, cap;
    int32_t *a, *b;
    double *fs;            /* shear force (dim) */
    /* the last evaluation (dim): ball-ball, the relative position x_b - x_a,
     * whose direction is the previous normal (n = r / |r|, as the step
     * computes it, to the bit) and whose length gives the overlap; ball-wall,
     * the previous unit normal */
    double *geo;
    uint8_t *touching;     /* history is live (touching, or bonded) */
    int32_t *bond;         /* bond slot + 1, 0 = none; NULL while the model has no bonds */
    double *mr;            /* rolling moment on b (rdim, laws/rolling.h); NULL while no material rolls */
    double *us;            /* accumulated tangential displacement of b (dim, laws/total_shear.h); NULL
                            * while no material asks for the total form */
    int32_t *facet;        /* m->bw: a mesh wall's facet (0 for other walls); NULL until the model has a mesh */
    int32_t *cmodel;       /* m->bb, m->bw: the contact-model row the contact took (from 1; 0: its materials'
                            * law), cmodel.c; NULL while the table is empty */
    /* m->bb, smooth joints (laws/smoothjoint.h): NULL until the model has a joint */
    int32_t *joint;        /* the joint this contact crosses + 1 (0: none) */
    double *jnormal;       /* its normal from a's side to b's (dim) */
    double *jun;           /* the elastic normal overlap along it, m */
    /* the last force evaluation, for queries consistent with the balls' forces */
    double *un;            /* overlap (m->bw only: a ball-ball pair's follows from geo) */
    double *fn;            /* normal force incl. the normal dashpot, compression positive */
} sx_pairs;

/* The pair store's fields, described once: resizing, moving, flipping,
 * sorting and freeing a store, its bytes, a build's history transfer and
 * the files (src/io/snapshot.c) iterate this table (sx__pair_fields); a
 * law's history fields join it there. */
typedef struct sx_pair_field {
    void **data;           /* the array's address in the store */
    int per;               /* elements per pair */
    sx_field_type type;
    bool sign;             /* a vector of the pair's a -> b orientation: negated when it turns round */
    bool end;              /* a or b: listed by the broad phase, not carried as history */
    const char *name;      /* the files' dataset */
    const char *unit;      /* its unit (NULL: none) */
} sx_pair_field;
#define SX_PAIR_FIELDS_MAX 16
/* The fields store p has (bond slots only once the model has bonds, rolling
 * moments once a material rolls, the overlap only in the ball-wall store),
 * into f; returns their count. */
int sx__pair_fields(const sx_model *m, sx_pairs *p, sx_pair_field *f);
/* The arrays ball store b has, into f; returns their count. */
int sx__ball_fields(const sx_model *m, sx_balls *b, sx_ball_field *f);
/* Bytes of one ball's elements of a field. */
static inline size_t sx__ball_row(const sx_ball_field *f) { return (size_t)f->per * sx__field_size(f->type); }
/* Bytes of one element of a pair field. */
static inline size_t sx__pair_size(const sx_pair_field *f) { return sx__field_size(f->type); }

typedef struct sx_grid {
    /* lo, nc and a cell's coordinates are along the grid's axes: grid axis
     * k is the model's axis axis[k], the last one the slowest of the cell
     * order (broad_phase.c, grid_axes) */
    int axis[3];
    double lo[3], cell;
    int64_t nc[3], ncells, cap_cells;
    int32_t *start;        /* cells' start in sorted order (ncells + 1) */
} sx_grid;

/* The ball-ball pass runs in fixed chunks of pairs. Pairs are sorted by a
 * (a < b), so chunk c owns a contiguous range of balls: the a's of its
 * pairs. The plan makes every b of chunk c fall in its own range or the
 * next chunk's, so the even chunks write disjoint sets of balls, and so do
 * the odd ones: the even chunks run (in parallel), then the odd ones,
 * each adding its forces straight into the balls' arrays. An even chunk
 * first clears its range and the next chunk's. The chunking depends only
 * on the pair store, never on the thread count, so every ball receives
 * its contributions in the same order, and results are bit-identical for
 * any number of threads. */
typedef struct sx_chunk {
    int64_t first, last;   /* pair range [first, last) */
    int64_t own_lo, own_hi;/* balls [own_lo, own_hi): the a's of its pairs */
    int64_t clear_lo, clear_hi; /* balls whose forces it starts from the applied loads (or zero) */
    /* decomposed with energy tracking (dd_energy.c, sx__dd_energy): from
     * pair tape_at on (-1: never) the chunk's energy terms are this rank's
     * part of a chunk begun on a lower rank, and go to its tape (taping);
     * part: what this rank gives the chunk's energy sums (SX_DD_PART_*) */
    int64_t tape_at;
    bool taping;
    int8_t part;
    /* results of the last pass */
    double slip, viscous, released;
    int64_t lost_bonds;
    sx_crack *cracks;
    int64_t ncracks, capcracks;
    sx_status st;
    int64_t err_a, err_b;
    double err_un, err_r;
    bool err_break;        /* st is a bond broken with a non-finite force, not an overlap */
} sx_chunk;

/* The per-ball passes (wall contacts, then the law of motion) run in
 * fixed blocks of balls; each block keeps partial sums
 * (energies, wall resultants), added in block order. */
typedef struct sx_wall_acc {
    double force[3], moment[3], load, kn_sum;
    int64_t contacts;
} sx_wall_acc;

#define SX_MOTION_BLOCKS 64 /* at most this many blocks */
#define SX_CHUNKS_MAX 16    /* the ball-ball pass's chunks, at most */

typedef struct sx_block {
    int64_t b0, b1;        /* balls [b0, b1) */
    int64_t w0, w1;        /* their ball-wall pairs [w0, w1) */
    double worst, damp_work, load_work, visc_work, slip, viscous;
    /* decomposed with energy tracking: this rank's part of a block begun on
     * a lower rank puts its law of motion's energy terms on its tape at
     * tape_k (damping), tape_k + 1 (loads) and tape_k + 2 (the dashpots'
     * share, visc_work) (decompose.c); -1: in the sums */
    int64_t tape_k;
    int64_t bad;           /* first ball with a non-finite state, or -1 */
    sx_status st;          /* a wall contact's overlap error */
    int64_t err_ball, err_wall;
    double err_un, err_r;
} sx_block;

/* Contact parameters of a pair of materials, or of a material and a wall
 * (4-22, 4-23, 4-27/4-28, 4-30, 4-49/4-50). */
typedef struct sx_pair_law {
    double kn, ks, mu;      /* springs in series, smaller friction */
    double beta_n, beta_s;  /* critical-damping ratios (mean of the two) */
    double mu_r;            /* rolling friction (laws/rolling.h; 0: no rolling resistance) */
    bool total_shear;       /* Mindlin's total tangential form (laws/total_shear.h) */
    bool unloading;         /* Mindlin-Deresiewicz unloading (laws/mindlin_unloading.h) */
    double dash_n;          /* 4 beta_n^2 kn: the normal dashpot is sqrt(dash_n m*) (linear, not per radius) */
    uint8_t law;            /* its number in the registry (laws/registry.h) */
    bool plain;             /* the batched passes' case: linear, not per radius (laws/linear.h) */
    double g, nu;           /* Hertz-Mindlin's G and nu (laws/hertz.h) */
    bool wall, rigid;       /* a ball against a wall (R-bar = R, 4-28); the wall rigid (sx_wall_def) */
    /* BPM modulus mode (4-49/4-50): a side with ec > 0 has kn = 4 R ec (3D)
     * or 2 ec (2D) and ks = kn / ratio, put in series per contact; a side
     * with ec = 0 keeps its kn, ks. */
    bool per_radius;
    double kn_a, ks_a, ec_a, ratio_a, kn_b, ks_b, ec_b, ratio_b;
} sx_pair_law;

/* A row of the contact-model table (cmodel.c): its match, its law read as
 * a material (name, definition, derived constants) and the contact it
 * makes, mixed once (rows never change). */
typedef struct sx_cmodel_row {
    sx_cmodel_def def;
    sx_material mat;
    sx_pair_law law;   /* a ball-ball row's: two balls of its material */
    sx_pair_law wlaw;  /* a wall row's: a ball and a wall of its material */
} sx_cmodel_row;

/* Periodic space (periodic.c; kernels/ghosts.c). The cell is lo + H f,
 * f in [0, 1) on the periodic axes, H upper triangular with columns
 * h[k] (h[k][i] = 0 for i > k; a non-periodic axis keeps h[k] = e_k).
 *
 * Ghosts are the images of balls near a face, shifted by cell vectors, that
 * the contact passes see like any other ball: they live in the ball arrays
 * past the real balls, in slots [base, base + n), copied from their owners
 * at every step (position + the shift, velocity + the shift's rate, spin)
 * and made afresh at every build. A contact through the boundary is one
 * pair (real ball, ghost), kept once by the owner rule: the real end has
 * the smaller id. The ghost's force is added to its owner after the pass,
 * in ghost order, so every ball's force is summed in a fixed order. (The
 * MPI decomposition does not use them: each rank holds the whole model and
 * works on its slab's range of the dense order, decompose.c.) */
typedef struct sx_cell {
    bool axis[3];
    double lo[3];
    double h[3][3];         /* h[k]: the k-th cell vector, m */
    double hdot[3][3];      /* its rate, m/s, set by the control each step */
    sx_cell_control ctl;
    bool controlled;        /* some component not fixed */
    double moved;           /* how far an image may have moved against its owner since the last build, m */
    int64_t n, cap, base;   /* ghosts in ball slots [base, base + n) */
    int32_t *owner;         /* the real ball (dense index) each ghost images; -1 after its removal */
    int8_t *image;          /* the cell vectors it is shifted by, 3 per ghost (-1, 0, 1) */
    /* with energy tracking in a deforming cell: per real ball, the sum over
     * its ghosts of s (x) f (dim x dim: the cell vectors shifting a ghost,
     * the force it felt this step), from which the law of motion books the
     * cell's work on the ball, -(hdot : that) dt (kernels/ghosts.c) */
    double *shifted;
    int64_t cap_shifted;
} sx_cell;

/* Domain decomposition (decompose.c; docs/developer.md). Between cycles
 * every rank holds the whole model, identical; inside a cycle rank r
 * integrates the balls own[r] (dense indices: slabs of the cell order),
 * keeps the balls need[4r ... 4r + 3] current as ghosts (below and above
 * them, and in periodic space the far ends of the cell), evaluates the
 * ball-ball pairs pairs[r] that reach its balls (in the serial order;
 * in periodic space also xpair, those through the boundary whose image
 * of the far end is of its own balls) and completes the wall
 * blocks wblk[r]. Every ball's sums thus run in the serial run's order. */
/* The spans of ghosts a rank keeps: near below, near above, far below, far above. */
enum { SX_DD_NEED = 4 };
/* Decomposed with energy tracking: the energy terms of a rank's part of
 * a chunk or block begun on a lower rank, in the order the step makes
 * them, each with the index of its sum (dd_energy.c, sx__dd_energy). */
typedef struct sx_tape {
    struct sx_tape_term {
        double v;
        int64_t k;
    } *e;
    int64_t n, cap;
    bool lost; /* out of memory */
} sx_tape;

/* What a rank gives a chunk's energy sums: nothing (none of its pairs),
 * the sums of the chunk's first pairs (the chunk begins among its own), or
 * its tape's terms, folded into the lower ranks' sums. */
enum { SX_DD_PART_NONE, SX_DD_PART_START, SX_DD_PART_TAPE };

/* Entries (ball indices) moved between ranks, grouped by the rank they
 * come from (a run each, own[src]) and within it by the rank they go to
 * (need[dst * ranks + src]). */
typedef struct sx_route {
    int32_t *item;
    int64_t n, cap;
    sx_span *own, *need;
} sx_route;

typedef struct sx_dd {
    sx_exchange x;
    bool active;            /* inside a decomposed cycle: the plan below holds */
    bool walls_stale;       /* the walls' resultants lag their blocks' sums (sx__dd_walls) */
    bool lazy;              /* a cycle leaves the state scattered (sx_model_gather_lazily) */
    bool scattered;         /* each rank's own balls, pairs and bonds current, the rest as a gather left it */
    int fetched;            /* scattered: the balls' rows fetched since the cycle's end (sx_ball_fetch), */
    bool motion_whole;      /* and whether every ball's motion has been shared since */
    bool cracks_merged;     /* scattered: the ranks' crack logs merged since the cycle's end (sx_model_share_cracks) */
    bool failed;            /* this rank met an error in its own part of this step: it moves nothing more */
    int64_t fail_order;     /* its error's place in the serial order where that is not the ranks' (a clump's index) */
    bool own_error;         /* its error is of its own part of the step, met after the part's exchanges (a
                             * mesh too fine for a ball), to be agreed on as an instability (cycle.c go_on) */
    bool agreed;            /* the cycle ended on an error every rank agreed on (sx__dd_agree_failure) */
    sx_span *own, *need, *pairs, *wblk, *wrun, *bb_own, *bw_own, *all; /* per rank (need: SX_DD_NEED per rank) */
    /* periodic space: this rank's pairs outside pairs[rank] whose b is a
     * ghost of one of its balls, in pair order (the first nxlow below
     * pairs[rank], the rest above it), and the chunk that runs them */
    int32_t *xpair;
    int64_t nxpair, nxlow, cap_xpair;
    sx_chunk xchunk;
    /* the pairs of pairs[rank] below its own (their a a ghost) that reach
     * its balls, in pair order: the others, between two ghosts, it skips */
    int32_t *inpair;
    int64_t ninpair, cap_inpair;
    /* periodic space: the ghosts grouped by their owner's rank (each
     * rank's a run, gho_own), what a gather takes from each */
    int32_t *gho;
    int64_t ngho, cap_gho;
    sx_span *gho_own;
    /* bonds: the slots of the bonded pairs in pair order, as planned, and
     * each rank's entries (its own pairs'); scratch spans for a gather */
    int32_t *bslot;
    int64_t nbslot, cap_bslot;
    sx_span *bs_own, *scratch;
    sx_span *by_rank;       /* rank r's entry r, {r, r + 1}: the spans of sx__dd_share_by_rank, which so leaves scratch alone */
    int64_t crack0;         /* the crack log's entries every rank holds alike */
    /* clumps: each clump's owner (cown: the rank owning its pebble
     * nearest its centroid), the clumps by owner, each rank's in clump
     * order a run (cl, cl_own; cl_at: a clump's entry), and the pebbles
     * whose owner is not their clump's, routed to (fwd) and from (back)
     * the clump's owner */
    int32_t *cown, *cl, *cl_at;
    int64_t ncl, cap_cl;
    sx_span *cl_own;
    sx_route fwd, back;
    /* energy tracking: every clump's terms at its entry, then the blocks'
     * sums (sx__dd_clump_terms), kept from step to step */
    double *cterm;
    int64_t cap_cterm;
    sx_span *cterm_need; /* which terms each rank takes from each (r per rank) */
    sx_tape tape; /* energy tracking: this step's terms (sx__dd_energy) */
    /* the cut (decompose.c, cut_by_work): per ball the lowest first ball of
     * a pair reaching it, the pairs crossing it (first ball below it,
     * second ball it or above), and the work of the balls before it */
    int32_t *low_a, *cross;
    int64_t *work, cap_cut;
    /* the cut's balance by measured pace (dd_share.c, sx__dd_share_pace): per
     * rank its seconds of computing per unit of the cut's work, smoothed
     * (0: not measured yet), and the ranks' last samples (2 per rank);
     * this rank's computing seconds and planned work since its last
     * sample, and its planned work per step (the cut's) */
    double *pace, *sample;
    double *stopping; /* sx__dd_stop's exchange: per rank its last unanswered interrupt and answered level */
    uint64_t *sums;   /* sx__dd_sum's exchange: SX_DD_SUM_MAX a rank */
    char *rowbuf;     /* sx__dd_move_rows' packed rows, kept */
    size_t cap_rowbuf;
    double busy, busy_work;
    int64_t planned;
    /* a build inside a cycle from what each rank holds current (sx__dd_build,
     * sx__dd_migrate): the last plan's owner of each ball by its id (was),
     * of each bond slot (slot_was; -1: in no pair of the plan) and its
     * pair stores' owner spans (bb_was, bw_was); the build's old pair of
     * each new pair (src_bb, src_bw: + 1, negated when turned round, 0
     * none), kept from its transfer while migrating */
    bool migrating;
    int64_t *received; /* the model's profile's count of the bytes this rank received */
    int32_t *was, *slot_was, *src_bb, *src_bw;
    int64_t cap_was, cap_slot_was, nsrc_bb, nsrc_bw, cap_src_bb, cap_src_bw;
    sx_span *bb_was, *bw_was;
} sx_dd;

/* An instability a contact pass or the law of motion meets on its own
 * balls: what its message says but the critical estimate, which a
 * decomposed step knows whole only once the ranks agree on the error
 * (sx__dd_agree_failure renders the message again from this; the
 * estimate decides an overlap's wording: the timestep, or an overlap from
 * before the step). */
typedef enum { SX_UNSTABLE_NONE, SX_UNSTABLE_OVERLAP, SX_UNSTABLE_BOND, SX_UNSTABLE_NONFINITE } sx_unstable_kind;
typedef struct sx_unstable {
    sx_unstable_kind kind;
    char what_a[8], what_b[8]; /* "ball", "wall", "clump" */
    int64_t a, b, step;        /* the ids (b: none for a non-finite state) */
    double un, r, dt;          /* an overlap's depth and the radius it passed; the timestep */
} sx_unstable;
/* Fails m with u's message at the critical estimate crit (s); keeps u. */
sx_status sx__unstable_fail(sx_model *m, const sx_unstable *u, double crit);

struct sx_model {
    int dim, rdim;
    double gravity[3];
    double dt_user;          /* 0 = automatic */
    double dt;               /* the timestep in use */
    double dt_prev;          /* the timestep of the last step taken (0 before the first) */
    double dt_safety;
    double skin, skin_user;
    double time;
    int64_t step;
    bool dt_stale;           /* recompute the automatic timestep before the next step */
    double dt_wall_speed;    /* the fastest wall speed the timestep was rated at (kernels/timestep.c) */
    bool build_needed;       /* broad phase must be rebuilt before the next step */
    bool locked;             /* stepping */
    volatile sig_atomic_t interrupt;

    sx_alloc alloc;
    char err[SX_ERRLEN];
    sx_unstable unstable;    /* the instability behind err, if one is (kind SX_UNSTABLE_NONE: none) */

    sx_material *mats;
    int nmat, cap_mat;

    sx_balls balls;

    sx_wall *walls;
    int64_t nwall, cap_wall, next_wall_id;
    bool mesh_pairs;        /* the ball-wall store carries facets (bw.facet): the model has had a mesh */

    sx_pairs bb, bw;        /* ball-ball and ball-wall candidate pairs */
    sx_chunk *chunks;       /* the ball-ball pass's chunks, planned at each build */
    int64_t nchunk, cap_chunk;
    sx_block *blocks;       /* the per-ball passes' blocks (room for SX_MOTION_BLOCKS) */
    int64_t nblock;
    sx_wall_acc *wall_acc;  /* nblock x nwall partial wall resultants */
    int64_t cap_wall_acc;
    int threads;            /* OpenMP threads for the step (results do not depend on it) */
    sx_pair_law *law;       /* nmat x nmat contact parameters, refreshed each cycle */
    int law_n;
    bool law_plain;         /* every law linear, not per radius, without a shear dashpot */
    sx_pair_law *wlaw;      /* nmat x nwall laws of the ball-wall contacts, refreshed each step */
    int64_t cap_wlaw;
    double *scratch;        /* scratch of one operation (sorting, timestep sums), released after it */
    int64_t scratch_cap;
    /* per ball slot (periodic ghosts included), the inverse mass a contact's
     * dashpot sees: 0 for a ball whose velocity is fixed on every axis,
     * which moves as it is told whatever the forces (a wall's infinite
     * mass), else its own; filled for each pass that needs it, only while
     * some ball is so fixed (pair_contacts.c, dashpot_inverse_mass) */
    double *dash_im;
    int64_t cap_dash_im;
    const double *dash_im_now; /* the contact pass's: dash_im or balls.inv_mass */
    /* with energy tracking, per ball slot (periodic ghosts included): the
     * step's dashpot forces (dim) and their moments (rdim) on the ball, for
     * the law of motion's share of the viscous work (motion.c); cap in slots */
    double *visc_f, *visc_t;
    int64_t cap_visc;
    sx_grid grid;
    int64_t builds;         /* number of broad-phase builds so far */

    sx_bonds bonds;
    sx_fjels fjel;
    sx_cracks cracks;
    bool track_energy;
    sx_energy acc;          /* accumulated energy terms (slip, damping, work, ...) */

    sx_profile prof;         /* stage timers of sx_model_cycle */

    /* stability guard: mechanical energy at the start of the current cycle */
    double guard_e0, guard_scale;
    bool guard_on;
    bool guard_dirty;        /* the system was changed by the user: take a new energy baseline */

    sx_cmodel_row *cmodel;   /* the contact-model table (cmodel.c); NULL while it is empty */
    int ncmodel, cap_cmodel;
    struct sx_clumps *clumps; /* templates and clumps (clumps.h); NULL while the model has none */
    sx_cell *cell;            /* periodic space (periodic.c); NULL while the space is not periodic */
    sx_dd *dd;                /* domain decomposition (decompose.c); NULL in a serial run */
    struct sx_joint *joints;  /* smooth joints (joints.c), in the order added */
    int64_t njoint, cap_joint;
};

/* The volume of a ball of radius r: a sphere's, or a disk's of unit
 * thickness in 2D. */
/* The surface gap below which two balls of radii ri, rj count as
 * touching: a part in a billion of their sum (the neighbours of a
 * generated lattice, which rounding puts a few ulps apart either way: with
 * gap 0 a third of them were bonded). Bonds install on it (bonds.c), and a
 * flat joint's closed face stays while its balls are within it. */
static inline double sx__touching(double ri, double rj) { return 1e-9 * (ri + rj); }

/* The volume (2D: area) of the ball of radius r at x inside the region
 * (region_cut.c). */
double sx__region_cut(const sx_region *region, int dim, const double *x, double r);

static inline double sx__ball_volume(int dim, double r) { return dim == 3 ? 4.0 / 3.0 * SX_PI * r * r * r : SX_PI * r * r; }

/* Ball i's local damping: its own, or its material's. */
static inline double sx__ball_damping(const sx_model *m, int64_t i)
{
    return m->balls.alpha ? m->balls.alpha[i] : m->mats[m->balls.mat[i]].def.damping;
}

/* Local (non-viscous) damping, -alpha |F| sign(v) per component (DESIGN 1):
 * the balls' law of motion (kernels.c) and the clumps' (kernels/clump_motion.c). */
static inline double sx__damped(double force, double vel, double alpha)
{
    if (alpha == 0 || vel == 0) return force;
    return force - alpha * fabs(force) * (vel > 0 ? 1.0 : -1.0);
}

/* The contact-model table (cmodel.c). The row (from 1) a contact between
 * dense balls i and j takes if created now, 0 for none. */
int32_t sx__cmodel_pick(const sx_model *m, int64_t i, int64_t j);
/* The law of ball-ball pair c (balls i, j) for the step: the row it took
 * (touching) or would take now, else its materials' in the step's table. */
static inline const sx_pair_law *sx__bb_step_law(const sx_model *m, int64_t c, int64_t i, int64_t j)
{
    const sx_pair_law *l = &m->law[m->balls.mat[i] * m->law_n + m->balls.mat[j]];
    if (!m->bb.cmodel) return l;
    const int32_t r = m->bb.touching[c] ? m->bb.cmodel[c] : sx__cmodel_pick(m, i, j);
    return r ? &m->cmodel[r - 1].law : l;
}
/* The row (from 1) a contact between dense ball i and wall index w takes
 * if created now, 0 for none (the WALL kinds of rows alone). */
int32_t sx__cmodel_pick_wall(const sx_model *m, int64_t i, int64_t w);
/* The row of ball-wall pair c for the step: the one it took (touching) or
 * would take now; 0 for its ball's and wall's law (m->wlaw). */
static inline int32_t sx__bw_row(const sx_model *m, int64_t c)
{
    if (!m->bw.cmodel) return 0;
    return m->bw.touching[c] ? m->bw.cmodel[c] : sx__cmodel_pick_wall(m, m->bw.a[c], m->bw.b[c]);
}
/* Law of a ball of material `mat` against a wall (wall stiffness in series;
 * material.c), and of a ball of material ball against a wall of definition w
 * and material wm (NULL: none), the same rules. */
sx_pair_law sx__wall_law(const sx_model *m, int mat, const sx_wall *w);
sx_pair_law sx__wall_law_of(const sx_material *ball, const sx_material *wm, const sx_wall_def *w);
/* The law of ball-wall pair c for queries: its row's, or its ball's and wall's. */
static inline sx_pair_law sx__bw_law(const sx_model *m, int64_t c)
{
    const int32_t r = sx__bw_row(m, c);
    return r ? m->cmodel[r - 1].wlaw : sx__wall_law(m, m->balls.mat[m->bw.a[c]], &m->walls[m->bw.b[c]]);
}
/* Rows' laws that need history the stores lack (rolling, total form):
 * expands the stores; and bonded contacts under a row whose law takes no
 * bonds are refused (seed 4.3.3). */
sx_status sx__cmodel_prepare(sx_model *m);
/* Why def cannot be a row of m (written into why[len]), or NULL. */
const char *sx__cmodel_invalid(const sx_model *m, const sx_cmodel_def *def, char *why, size_t len);
/* Gives store p its array of rows (zeroed), false when out of memory. */
bool sx__cmodel_store(sx_model *m, sx_pairs *p);
/* Whether a row of the table matches ball-wall contacts (walls), or ball-ball ones. */
bool sx__cmodel_any(const sx_model *m, bool walls);
/* A row's derived constants and its contact's law (on adding it, on a restore). */
void sx__cmodel_derive(sx_cmodel_row *r);
/* The mixed pair law of two materials (material.c). */
sx_pair_law sx__pair_law_of(const sx_material *ma, const sx_material *mb);
/* The law of ball-ball pair c for queries: its row's, or mixed from the
 * materials as they are (into *buf); a pointer, as queries run it for every
 * contact and the law is a few hundred bytes. */
static inline const sx_pair_law *sx__bb_law(const sx_model *m, int64_t c, int64_t i, int64_t j, sx_pair_law *buf)
{
    const int32_t r = !m->bb.cmodel ? 0 : m->bb.touching[c] ? m->bb.cmodel[c] : sx__cmodel_pick(m, i, j);
    if (r) return &m->cmodel[r - 1].law;
    const int a = m->balls.mat[i], b = m->balls.mat[j];
    /* While the model steps (the energy guard), the step's table is the same
     * mix (refresh_laws, before the cycle; materials cannot change while it
     * steps): read it rather than mix the two materials for every contact. */
    if (m->locked && m->law_n == m->nmat) return &m->law[a * m->law_n + b];
    *buf = sx__pair_law_of(&m->mats[a], &m->mats[b]);
    return buf;
}

/* First index c of the sorted a[0..n) with a[c] >= key (a pair store's
 * column a is sorted after a build). */
static inline int64_t sx__first_at(const int32_t *a, int64_t n, int64_t key)
{
    int64_t lo = 0, hi = n;
    while (lo < hi) {
        const int64_t mid = lo + (hi - lo) / 2;
        if (a[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* The first rule d breaks (its value in *bad), or NULL (material.c). */
const char *sx__material_invalid(const sx_material_def *d, char *why, size_t len);

/* error helper: formats into m->err and returns status */
sx_status sx__fail(sx_model *m, sx_status st, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* A Ctrl-C for the core's long loops to stop at (sx_interrupt_request, or
 * the model's sx_model_interrupt while it cycles) (model.c). */
bool sx__interrupted(const sx_model *m);
/* Decomposed cycles' interrupts (model.c, sx__dd_stop): the number of the
 * process's last request if neither answered here (sx_interrupt_clear) nor
 * by a stop (the level), else 0; the level; a stop that answered every
 * request up to level. */
unsigned sx__interrupts_unanswered(void);
unsigned sx__interrupts_level(void);
void sx__interrupts_stopped(unsigned level);
/* Whether the automatic timestep rates a ball by its speed: some material's
 * own law or a contact-model row stiffens with the overlap (Hertz: its
 * tangent stiffness is not its secant; kernels/timestep.c). A velocity set
 * by hand then rates the timestep again at the next step. */
bool sx__speed_rated(const sx_model *m);
/* The fastest speed at which wall w's surface may close on a ball
 * (walls.c), and what a change of it does to the timestep's rating. */
double sx__wall_speed(const sx_model *m, const sx_wall *w);
void sx__wall_speed_changed(sx_model *m, const sx_wall *w);
/* The fastest speed of a vertex of mesh s turning at spin about point (mesh.c). */
double sx__mesh_spin_speed(const sx_mesh *s, const double *point, const double *spin);

/* Dimension kernels (kernels.c, one instance per dimension). */
typedef struct sx_kernels {
    sx_status (*build)(sx_model *m);             /* broad phase + history transfer: SX_ENOMEM, SX_EINTERRUPT */
    sx_status (*contacts)(sx_model *m);          /* ball-ball forces (the balls' forces start here) */
    sx_status (*walls)(sx_model *m);             /* ball-wall forces */
    sx_status (*integrate)(sx_model *m, double *max_disp); /* law of motion */
    double (*critical_dt)(sx_model *m);          /* min sqrt(m/k) over balls */
    double (*own_dt)(const sx_model *m);         /* an upper bound of it from the balls' own ratings alone */
    /* the clumps after the balls' law of motion (kernels/clump_motion.c): sums
     * the pebbles' forces, integrates (4-42 ... 4-48), places the pebbles;
     * raises *max_disp to the largest pebble move since the last build */
    sx_status (*clumps_step)(sx_model *m, double *max_disp);
    /* clump c's pebbles placed from its body at rotation R; their largest squared move since the build */
    double (*place_pebbles)(sx_model *m, int64_t c, const double *R);
    /* decomposed inside a cycle: own balls and pairs summed in a chain (the
     * ghosts current); false: the ranks could not exchange */
    bool (*energy)(const sx_model *m, sx_energy *e);
    /* the contacts of the pairs [lo, hi) of the ball-ball or (walls) the ball-wall store, in order */
    bool (*each_contact)(const sx_model *m, bool walls, int64_t lo, int64_t hi, bool (*fn)(const sx_contact_info *, void *),
                         void *ud);
    int64_t (*count_contacts)(const sx_model *m);
    bool (*plan)(sx_model *m);                  /* chunks of the ball-ball pass for the pair store as it is (a restore) */
    /* periodic space: the ghosts' positions, velocities and spins from their owners (a restore) */
    void (*ghosts_refresh)(sx_model *m, bool all);
    /* the cell's average stress (compression positive) and the servo's
     * stiffnesses K per component (sx_cell_control) from the pair store */
    bool (*cell_stress)(const sx_model *m, double stress[3][3], double stiff[6]);
} sx_kernels;

extern const sx_kernels sx_kernels_2d, sx_kernels_3d;
/* The kernels of m's dimension. */
static inline const sx_kernels *sx__kernels(const sx_model *m) { return m->dim == 2 ? &sx_kernels_2d : &sx_kernels_3d; }

/* storage helpers (balls.c, walls.c) */
sx_status sx__balls_reserve(sx_model *m, int64_t cap);
void sx__balls_free(sx_model *m);
/* new index i <- old index order[i]; scratch holds n * dim doubles */
void sx__balls_permute(sx_model *m, const int32_t *order, double *scratch);
void sx__ball_update_mass(sx_model *m, int64_t i);
/* Allocate the per-ball damping (filled from the materials) or group (0)
 * array if absent; SX_ENOMEM. Compact frees each again when it holds only
 * what the materials or the default would (a loaded state, say). */
sx_status sx__balls_expand_damping(sx_model *m);
sx_status sx__balls_expand_groups(sx_model *m);
sx_status sx__balls_expand_unwrap(sx_model *m);
/* How far the velocities' time is behind the positions' (central
 * differences): half the last step's timestep, or, before the first step,
 * of the one it will take, which the first kick takes the given
 * velocities to be half a step old by (the user's, or the automatic one
 * in use: sx_model_energy rates it first). */
static inline double sx__half_step(const sx_model *m)
{
    return 0.5 * (m->dt_prev > 0 ? m->dt_prev : m->dt_user > 0 ? m->dt_user : m->dt);
}

/* Ball i placed anew (added, or its position or its clump's set): its
 * wraps start again, so that it is unwrapped where it was placed. */
void sx__ball_placed(sx_model *m, int64_t i);
/* Ball i's wraps, how far it was moved back into the periodic cell since
 * it was placed (zero outside periodic space), and its unwrapped position
 * x + that. */
void sx__ball_wraps(const sx_model *m, int64_t i, double *s);
void sx__ball_unwrapped(const sx_model *m, int64_t i, double *x);
void sx__balls_compact(sx_model *m);
sx_status sx__pairs_reserve(sx_model *m, sx_pairs *p, int64_t cap);
/* Gives both pair stores the history array at byte offset `field` of
 * sx_pairs (per components a pair, zero) if absent; SX_ENOMEM. */
sx_status sx__pairs_expand(sx_model *m, size_t field, int per);
void sx__pairs_free(sx_model *m, sx_pairs *p);
void sx__pair_move(sx_model *m, sx_pairs *p, int64_t to, int64_t from);
void sx__pair_flip(sx_model *m, sx_pairs *p, int64_t k); /* swap a and b, re-express the history */
/* Bytes of the ball arrays (with the id map and the grid's per-ball cells), of a pair store. */
size_t sx__balls_bytes(const sx_model *m);
size_t sx__pairs_bytes(const sx_model *m, const sx_pairs *p);
/* The bond store's bytes: the bonds, the flat joints' elements and the crack log. */
size_t sx__bonds_bytes(const sx_model *m);
/* Sorts the store by a, stably (a no-op when it is); false when out of memory. */
bool sx__pairs_sort(sx_model *m, sx_pairs *p);
void sx__walls_free(sx_model *m);
/* sx_wall_add, with the mesh (owned from then on) of a mesh wall. */
sx_status sx__wall_add(sx_model *m, const sx_wall_def *def, sx_mesh *mesh, int64_t *id);
/* Meshes (mesh.c). */
void sx__mesh_free(sx_model *m, sx_mesh *mesh);
/* World vertices and normals from the wall's point and the mesh's orientation. */
void sx__mesh_pose(const sx_wall *w);
/* Turns the mesh by its spin over dt (about the wall's point, which the
 * caller moves); returns the largest vertex displacement of the turn. */
double sx__mesh_turn(sx_wall *w, double dt);
/* A mesh from its frame's vertices and triangles as stored (a restore):
 * derived arrays and the grid; false when out of memory. */
bool sx__mesh_derive(sx_model *m, sx_mesh *mesh);
/* A restored mesh welded as sx_wall_add_mesh welds (files from before the
 * welding); false: out of memory. */
bool sx__mesh_weld_restored(sx_model *m, sx_mesh *mesh);
/* Sets m->mesh_pairs, with m->bw.facet (zeros) at the store's size; SX_ENOMEM. */
sx_status sx__pairs_expand_facets(sx_model *m);
/* Calls fn on each facet of mesh whose box in the mesh's frame meets the
 * cube of half-side h about body-frame point xb, each once, in cell order. */
void sx__mesh_query(sx_mesh *mesh, const double xb[3], double h, void (*fn)(int32_t facet, void *ud), void *ud);
void sx__walls_servo(sx_model *m); /* servo velocities from the step's wall loads */
/* The walls' resultants, the blocks' partial sums (m->wall_acc) in block
 * order; whether a step reads them (a servo, energy tracking's boundary
 * work) or only a query after the cycle does. */
void sx__walls_sum(sx_model *m);
bool sx__walls_read_in_step(const sx_model *m);
int64_t sx__ball_index(const sx_model *m, int64_t id); /* -1 if none */
int64_t sx__wall_index(const sx_model *m, int64_t id);
double *sx__scratch(sx_model *m, int64_t n); /* NULL on failure */
void sx__scratch_release(sx_model *m);      /* gives the scratch back (it is not kept between uses) */
/* Records a broken bond; false when out of memory (the event is dropped). */
bool sx__crack_log(sx_model *m, const sx_crack *c);
/* Drops kind bits from a bond; the bond's slot stays, and intact counts follow. */
void sx__bond_break(sx_model *m, int32_t slot, unsigned kind);
sx_status sx__bonds_reserve_pairs(sx_model *m); /* allocates pairs.bond when bonds appear */
/* Re-expresses a bond's vectors for the reversed pair orientation (b -> a). */
void sx__bond_flip(sx_model *m, int32_t slot);
void sx__bonds_free(sx_model *m);
/* The monotonic clock, in seconds (cycle.c): the profile's stages, a
 * decomposed rank's pace. */
double sx__now(void);
/* domain decomposition (decompose.c): the checks and plan of a cycle's
 * start (sx__dd_agree_replicated: of one that starts scattered),
 * the plan after a build, the ghosts' refresh, the whole state on every
 * rank (false: the exchange failed), the walls' resultants from every
 * rank's blocks (sx__walls_sum), and the end of a cycle (the whole state,
 * then replan: the serial chunk plan; lazily, the state left scattered),
 * and the whole state of a scattered model (sx__dd_whole, then replan) */
void sx__dd_free(sx_model *m);
sx_status sx__dd_begin(sx_model *m);
sx_status sx__dd_agree_replicated(sx_model *m);
sx_status sx__dd_whole(sx_model *m, bool (*replan)(sx_model *));
bool sx__dd_plan(sx_model *m);
bool sx__dd_halo(sx_model *m);
bool sx__dd_gather(sx_model *m);
/* The ghosts' motion and every clump's state where the last step left
 * their owners: what a sum over a rank's own rows reads of the others
 * (the energy guard's, an energy query's). False: the ranks could not
 * exchange. */
bool sx__dd_refresh(sx_model *m);
/* The motion of ball i (position, velocity, spin, force, moment) from the
 * rank that owns it in the last plan to every rank; of every ball when i
 * is negative. False: the ranks could not exchange. */
bool sx__dd_fetch_ball(sx_model *m, int64_t i);
/* A build inside a decomposed cycle without the whole state: before it,
 * sx__dd_build shares what every rank's build reads (the positions, the
 * pairs' contact flags and bond links, the bonds' kinds, the cracks, the
 * clumps; periodic space too); the build keeps each new
 * pair's old one (sx__dd_keep_sources); after the plan, sx__dd_migrate
 * moves to the ranks that now step them the balls, pairs and bonds the
 * cut gave another rank. False: the exchange failed, or out of memory. */
bool sx__dd_build(sx_model *m);
bool sx__dd_keep_sources(sx_model *m, bool walls, const int32_t *src, int64_t n);
/* The kept sources follow their store's sort (pos: each pair's new place;
 * sx__pairs_sort, after the build). False: out of memory. */
bool sx__dd_sources_sort(sx_model *m, bool walls, const int32_t *pos, int64_t n);
bool sx__dd_migrate(sx_model *m);
/* Decomposed: whether the ranks stop the cycle at this step for an
 * interrupt (*stop), the same on every rank. False: the exchange failed. */
bool sx__dd_stop(sx_model *m, bool *stop);
/* the parts of a step whose errors the ranks agree on, in the step's order
 * (sx__dd_agree_failure: the earliest part's, then the lowest order's
 * (a clump's index; else 0), then the lowest rank's, is every rank's; a
 * rank without one passes SX_OK) */
typedef enum {
    SX_FAIL_CONTACTS = 1,
    SX_FAIL_WALLS,
    SX_FAIL_RADII,
    SX_FAIL_CELL,
    SX_FAIL_MOTION,
    SX_FAIL_CLUMPS,
    SX_FAIL_GUARD
} sx_fail_part;
/* A rank's error in a step (st SX_OK: none; all zero then): its part, its
 * place in the part's serial order where that is not the ranks' (a
 * clump's index; else 0), its message. */
typedef struct sx_step_error {
    sx_status st;
    sx_fail_part part;
    int64_t order;
    char err[SX_ERRLEN];
    sx_unstable unstable;  /* an instability's, to render at the ranks' estimate */
} sx_step_error;
sx_status sx__dd_agree_failure(sx_model *m, const sx_step_error *mine);
/* Decomposed: st, an error of a check that every rank makes alike from
 * what all hold alike (before a cycle's steps: the laws, the timestep's
 * estimate once the ranks have shared it; at a build: the cell, the
 * skin), so that each meets it at the same place: the ranks compare it
 * (status and message), and when all met it, it is agreed
 * (sx_model_error_agreed: they stop in step, and a script catches it on
 * every rank as serially; any other error stops every rank). Running out
 * of memory is a rank's own, never compared. Not decomposed, or SX_OK: st. */
sx_status sx__dd_agree_alike(sx_model *m, sx_status st);
bool sx__dd_walls(sx_model *m, bool in_step);
/* Clumps, decomposed: each stepped by its owner. The pebbles' forces and
 * moments (before the step), or the timestep's sums (kt, kr, ct, cr, n
 * each, from sums), from the pebbles' owners to their clumps' owners; the
 * placed pebbles (position, velocity, spin) from the clumps' owners to the
 * pebbles' owners; the clumps' energy terms (w a clump, the first nd its
 * damping's, at the clump's entry cl_at, written by the owner where
 * sx__dd_clump_terms says), summed in blocks of `size`
 * clumps in the serial order and added to m->acc. */
bool sx__dd_pebbles(sx_model *m, double *sums, int64_t n);
bool sx__dd_placed(sx_model *m);
double *sx__dd_clump_terms(sx_model *m, int w, int64_t size); /* this rank's clumps' terms, zeroed; NULL: no memory */
bool sx__dd_clump_energy(sx_model *m, int w, int nd, int64_t size);
/* The clumps' state from their owners to every rank (the energy guard). */
bool sx__dd_clumps(sx_model *m);
bool sx__dd_chain(const sx_model *m, double *acc, int len, void (*part)(const sx_model *m, int rank, double *acc));
/* A list made in parts, one a rank (a decomposed build's pairs): this
 * rank's `count` entries go to *mine of the whole (*total long, the parts
 * in rank order); once each rank has put its part there, sx__dd_join gives
 * every rank the whole, an array of `size`-byte entries at a time, from
 * the parts sx__dd_parts left in the plan's scratch spans (no other
 * exchange between the two). */
bool sx__dd_parts(sx_model *m, int64_t count, sx_span *mine, int64_t *total);
bool sx__dd_join(sx_model *m, void *data, size_t size, int64_t total);
sx_status sx__dd_end(sx_model *m, bool (*replan)(sx_model *));
/* Energy tracking: term v of the sum k on the rank's tape; after the law
 * of motion, every chunk's and block's energy sums of the step, the serial
 * ones, added to m->acc in the serial order. */
void sx__tape_add(sx_tape *t, int64_t k, double v);
bool sx__dd_energy(sx_model *m);
/* Laws refreshed and broad phase built if needed (before queries and
 * cycles); sx__prepare_laws: the laws alone (a decomposed cycle that goes
 * on from a scattered state builds inside the cycle). */
sx_status sx__prepare(sx_model *m);
sx_status sx__prepare_laws(sx_model *m);
/* The same of a model a lazy cycle left scattered (cycle.c), as a cycle
 * that goes on from it prepares it: the ranks agree on what they hold
 * whole; the whole state gathered if a check must read every pair (then
 * sx__prepare); else the laws, and a build when one is due, from the
 * ranks' own state, the last plan active. On SX_OK with the state still
 * scattered it leaves the plan active (the caller ends it): each rank
 * then rates its own rows, and the kernels chain or reduce the ranks'
 * parts in the serial order, as inside a cycle. A collective call. */
sx_status sx__prepare_scattered(sx_model *m);
/* A query's start (energy, timestep, critical timestep): sx__prepare, or
 * of a scattered model sx__prepare_scattered; *split: the last plan is
 * left active, which the caller ends (m->dd->active = false). */
sx_status sx__prepare_query(sx_model *m, bool *split);
/* material.c: the pair laws from the materials (before a cycle), and the
 * check that the pairs' models agree. */
sx_status sx__refresh_laws(sx_model *m);
sx_status sx__check_models(sx_model *m);
/* prepare.c: the skin against the cell and the balls, a failed build's
 * status, the critical timestep (every rank's minimum under MPI; false
 * when the ranks fail) and the timestep a cycle's next step takes. */
sx_status sx__check_skin(sx_model *m);
sx_status sx__build_failed(sx_model *m, sx_status st);
bool sx__critical(sx_model *m, double *crit);
/* The timestep the next step takes (the user's, or rated), not stored. */
sx_status sx__next_timestep(sx_model *m, double *dt);
sx_status sx__update_timestep(sx_model *m);
/* guard.c: the stability guard's baseline (stepped: after a step of the
 * cycle, its ghosts refreshed as for a check), and its check. */
sx_status sx__guard_start(sx_model *m, bool stepped);
sx_status sx__guard_check(sx_model *m);
/* The largest gravity component, as for a ball's fields: a step's velocity
 * g dt must square without overflowing, or the state cannot be saved and
 * loaded (a robustness tester's 1e308 did both, silently). A file of an
 * older version may hold more: its cycles refuse it (cycle.c). */
#define SX_GRAVITY_MAX 1e100
/* A timestep the user may set: 0 (automatic) or in [1e-15, 1] s. */
static inline bool sx__timestep_ok(double dt) { return dt == 0 || (dt >= 1e-15 && dt <= 1); }
/* Law of a contact of materials ma and mb, from the materials as they are
 * (the step reads the table m->law, refreshed before each cycle). */
sx_pair_law sx__pair_law(const sx_model *m, int ma, int mb);
/* NULL when material d's law and its parameters are valid, else why not
 * (written into why[len]; laws.c). */
const char *sx__law_check(const sx_material_def *d, char *why, size_t len);
/* Derives the registry units' constants of material t from its definition (laws.c). */
void sx__material_derive(sx_material *t);
/* An order-free sum of digests (state.c: the state hash's balls, pairs,
 * bonds, cracks and clumps): their count and two sums of the mixed
 * digests, so that rows hash in any order, and in parts on the ranks that
 * hold them, then added. */
typedef struct sx_hash_bag {
    uint64_t n, sum[2];
} sx_hash_bag;
void sx__hash_bag_add(sx_hash_bag *b, uint64_t h);
/* The rows a rank counts in a sum over the model (the state hash, the
 * bond and crack counts): all of them, or, of a decomposed model left
 * scattered by a lazy cycle, those it holds current (sx__dd_rows_held):
 * its own balls, their pairs, the bonds of its pairs, the cracks it logged
 * of its balls since the last merge and the clumps it owns; rank 0 (first)
 * also what every rank holds alike (the bonds out of the plan, the merged
 * cracks). */
typedef struct sx_rows_held {
    bool all, first;
    sx_span balls, bb, bw;
    int64_t crack0;             /* the crack log's merged entries */
    uint8_t *bond;              /* per slot: 1 if this rank's to hash (freed by the caller) */
    const int32_t *clump_owner; /* per clump: its rank */
    int rank;
} sx_rows_held;
bool sx__dd_rows_held(const sx_model *m, sx_rows_held *part); /* false: out of memory */
bool sx__holds_crack(const sx_model *m, const sx_rows_held *part, int64_t i); /* crack log entry i (state.c) */
/* each v[k], k < n <= SX_DD_SUM_MAX, summed over the ranks (mod 2^64) */
#define SX_DD_SUM_MAX 24
bool sx__dd_sum(const sx_model *m, uint64_t *v, int n);
/* every rank's n <= SX_DD_SUM_MAX words v, rank r's at [r * n], in a kept
 * buffer (nothing to allocate, nothing to fail alone) valid until the next
 * exchange; NULL when the ranks could not exchange */
const uint64_t *sx__dd_words(const sx_model *m, const uint64_t *v, int n);
/* whether ok on every rank (false too when the ranks could not exchange):
 * before an exchange that a rank could not take part in (a buffer it
 * could not allocate), so that every rank stops, not that one alone */
bool sx__dd_all_ok(const sx_model *m, bool ok);
void sx__clumps_bag(const sx_model *m, const sx_rows_held *part, sx_hash_bag *out); /* each clump's digest */
/* FNV-1a over n bytes, continuing h (the state hash), from SX_FNV_BASIS. */
#define SX_FNV_BASIS 0xcbf29ce484222325ULL
uint64_t sx__fnv(uint64_t h, const void *data, size_t n);
/* The same over n doubles times sign (zeros when v is NULL), -0 hashed as +0. */
uint64_t sx__fnv_doubles(uint64_t h, const double *v, int64_t n, double sign);

/* Periodic space (periodic.c): hooks of the other stages; callers test
 * m->cell, so a scene without periodic space pays nothing. */
/* The ghost block of ball slots moves to start at slot `to` (a ball added
 * at the old base, balls removed below it); with rename, the pair ends in
 * it follow (a removal renames them through sx__cell_ghosts_remap). */
void sx__cell_ghosts_move(sx_model *m, int64_t to, bool rename);
/* Extends remap (old dense index -> new or -1, base + n entries) over the
 * ghost slots for a removal that keeps `keep` balls; owners follow. */
void sx__cell_ghosts_remap(sx_model *m, int32_t *remap, int64_t keep);
/* Ball or ghost j: its real ball (dense index; -1 for a ghost whose owner
 * was removed) and the shift (m, dim) it is seen through. */
int64_t sx__cell_owner(const sx_model *m, int64_t j, double *shift);
/* Fractional coordinates f (3) of x in the cell on its periodic axes (0 on the others). */
void sx__cell_frac(const sx_cell *c, int dim, const double *x, double *f);
/* Moves x into the cell by whole cell vectors, n (3) of each; exact
 * whenever the cell's numbers and x allow it (the same binade). */
void sx__cell_wrap(const sx_cell *c, int dim, double *x, int32_t *n);
/* The clumps' centroids wrapped, their pebbles moved with them (wrap per ball). */
void sx__cell_wrap_clumps(sx_model *m, int32_t *wrap);
/* The distance between the cell's two faces across periodic axis k, m. */
double sx__cell_thickness(const sx_cell *c, int dim, int k);
/* SX_EINVAL when the cell is too thin for the balls' contact reach. */
sx_status sx__cell_check(sx_model *m);
/* Before the bodies move: sets the cell's rates for the step (a servo from
 * the stress); an error, the cell left as it was and nothing moved yet,
 * when the move would flatten the cell or turn it inside out. */
sx_status sx__cell_rate(sx_model *m);
/* After the bodies: the cell moves at its rates. */
void sx__cell_move(sx_model *m);
uint64_t sx__cell_hash(const sx_model *m, uint64_t h);
size_t sx__cell_bytes(const sx_model *m);
/* Room for n ghosts in the table and in the ball slots past base; SX_ENOMEM. */
sx_status sx__cell_reserve(sx_model *m, int64_t base, int64_t n);
void sx__cell_free(sx_model *m);
/* A restore (the I/O layer): the cell as saved (its scalars; n ghosts),
 * room for the ghosts made, then, once their table is filled,
 * sx__cell_finish checks it and fills the ghosts' ball slots. */
sx_status sx__cell_restore(sx_model *m, const sx_cell *saved);
sx_status sx__cell_finish(sx_model *m);

/* Clumps (clump_queries.c, clump_store.c, clumps.c): the hooks of the
 * other stages, all no-ops while m->clumps is NULL (callers test it, so an
 * unclumped scene pays nothing). */
/* Adds the clumps' kinetic (once per body) and gravitational energy. */
void sx__clumps_energy(const sx_model *m, sx_energy *e);
/* The smallest critical timestep of the clumps, from their pebbles' sums of
 * contact stiffness kt, kr and dashpot ct, cr (per ball, as critical_dt has them). */
double sx__clumps_critical_dt(const sx_model *m, const double *kt, const double *kr, const double *ct,
                              const double *cr);
uint64_t sx__clumps_hash(const sx_model *m, uint64_t h);
/* Some clump has a fixed component (energy may be injected). */
bool sx__clumps_forced(const sx_model *m);
/* Adds each clump's |F + M g| (free components) to *sum; *bodies counts a clump once, not its pebbles. */
void sx__clumps_unbalanced(const sx_model *m, double *sum, int64_t *bodies);
/* A material was redefined: the mass and inertia (density changed) or
 * the local damping (damping changed) of its clumps follow, as its balls'. */
void sx__clumps_material_changed(sx_model *m, int material, bool density, bool damping);
/* Ball i is a pebble: the reference point of its body (the clump's centroid)
 * and its share of the body's volume, for measurements. */
void sx__pebble_body(const sx_model *m, int64_t i, double centre[3], double *volume);
void sx__clumps_free(sx_model *m);
