/* The decomposition's exchanges, shared by its files: decompose.c (the
 * plan and the cut, a cycle's start and end), dd_share.c (what moves
 * between ranks in a step and at a gather), dd_migrate.c (the build inside
 * a cycle and the migration after it), dd_agree.c (what the ranks of a
 * step agree on: to stop, and an error) and dd_energy.c (the energy sums
 * in the serial order). Internal to the core. */
#ifndef SX_DECOMPOSE_H
#define SX_DECOMPOSE_H

#include "model_internal.h"

/* Rows of per-entry arrays between ranks: field[k] has row[k] bytes an
 * entry, and the rows moved are base + list[e] for the entries e < n of
 * the buffer. Each rank packs the entries own[rank], they are shared
 * (need: nper spans per rank), and each rank unpacks those it needs. */
enum { ROWS_MAX = SX_PAIR_FIELDS_MAX };
typedef struct sx_rows {
    void *field[ROWS_MAX];
    size_t row[ROWS_MAX];
    int nf;
} sx_rows;

void sx__rows_add(sx_rows *f, void *field, size_t row); /* a field of row bytes an entry (0: none) */
/* [0, count) for every rank: what a gather needs (the plan's spans, reused) */
const sx_span *sx__dd_everything(sx_dd *d, int64_t count);
/* data's entries own[r] (size bytes each), rank r's, to the ranks whose
 * need spans (per a rank) hold them; counted into the profile's bytes */
bool sx__dd_share(sx_dd *d, void *data, size_t size, const sx_span *own, const sx_span *need, int per);
bool sx__dd_move_rows(sx_dd *d, const sx_rows *f, const int32_t *list, int64_t base, int64_t n, const sx_span *own,
                      const sx_span *need, int nper);
bool sx__dd_share_by_rank(sx_dd *d, void *data, size_t size); /* entry r, rank r's, to every rank */
/* An entry (a row index) to move from one rank to another. */
typedef struct sx_hop {
    int32_t item, from, to;
} sx_hop;
/* The route of the hops (model_internal.h, sx_route): their items by
 * source, then by destination, each (source, destination) in the hops'
 * order; rt's own and need have room for the ranks. False: out of memory. */
bool sx__dd_route(sx_dd *d, const sx_hop *hop, int64_t n, sx_route *rt);
int sx__dd_owner_of(const sx_dd *d, int64_t i, int64_t n);    /* the rank owning ball i of n */
sx_rows sx__dd_ball_motion(const sx_model *m, bool with_position);
/* the bonds' state a step changes (kinds_only: their kinds alone) */
sx_rows sx__dd_bond_rows(const sx_model *m, bool kinds_only);
/* the bonds' state of the slots list[e], each rank's entries own[r], to
 * every rank */
bool sx__dd_share_bonds(sx_model *m, const int32_t *list, int64_t n, const sx_span *own, bool kinds_only);
/* a flat joint's state of the slots slot[e], each rank's entries own[r],
 * to the ranks whose need spans (nper per rank) hold them */
bool sx__dd_share_fjoints(sx_model *m, const int32_t *slot, int64_t nb, const sx_span *own, const sx_span *need, int nper);
void sx__dd_count_intact(sx_model *m);
bool sx__dd_gather_cracks(sx_model *m);
bool sx__dd_share_pace(sx_model *m);

#endif
