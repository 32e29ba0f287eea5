/* Smooth joints (joints.c; the law in laws/smoothjoint.h): the model's
 * joint planes and what the other stages ask of them. */
#pragma once

#include "laws/smoothjoint.h"
#include "model_internal.h"

typedef struct sx_joint {
    sx_joint_def def;      /* as given, the normal made unit */
    sx_law_sj law;         /* its constants for the pass */
} sx_joint;

/* The first joint (in order) whose plane separates the centres xa and xb
 * (dim components) and, for a joint of finite radius, whose disk (2D:
 * segment) the centre line crosses: its number + 1, and its unit normal
 * from a's side to b's in nrm; 0 when none does. A centre on the plane
 * counts as on the normal's side. */
static inline int32_t sx__joint_crossed(const sx_model *m, int dim, const double *xa, const double *xb, double *nrm)
{
    for (int64_t k = 0; k < m->njoint; k++) {
        const sx_joint_def *j = &m->joints[k].def;
        double sa = 0, sb = 0;
        for (int q = 0; q < dim; q++) {
            sa += (xa[q] - j->point[q]) * j->normal[q];
            sb += (xb[q] - j->point[q]) * j->normal[q];
        }
        if ((sa >= 0) == (sb >= 0)) continue;
        if (j->radius > 0) { /* where the centre line meets the plane, against the disk */
            const double t = sa / (sa - sb);
            double r2 = 0;
            for (int q = 0; q < dim; q++) {
                const double c = xa[q] + t * (xb[q] - xa[q]) - j->point[q];
                r2 += c * c;
            }
            if (r2 > j->radius * j->radius) continue;
        }
        const double s = sb >= 0 ? 1 : -1;
        for (int q = 0; q < dim; q++) nrm[q] = s * j->normal[q];
        return (int32_t)(k + 1);
    }
    return 0;
}

/* Restores the joints of a file (its n definitions): checked as sx_joint_add
 * checks them, installed on nothing (the pairs come with their state). */
sx_status sx__joints_restore(sx_model *m, const sx_joint_def *defs, int64_t n);
/* The pair store's joint arrays (both NULL or all there). */
sx_status sx__joints_reserve_pairs(sx_model *m);
uint64_t sx__joints_hash(const sx_model *m, uint64_t h);
size_t sx__joints_bytes(const sx_model *m);
void sx__joints_free(sx_model *m);
