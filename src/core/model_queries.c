/* Queries of a model's state: its energies, its contacts and the
 * unbalanced-force ratio. */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sx_energy sx_model_energy(sx_model *m)
{
    sx_energy e;
    memset(&e, 0, sizeof e);
    /* materials or positions may have changed since the last cycle: the
     * broad phase the next cycle would build anyway sees every overlap */
    if (sx__prepare(m)) { /* no energy rather than a silent zero */
        double *t = (double *)&e;
        for (size_t k = 0; k < sizeof e / sizeof(double); k++) t[k] = NAN;
        return e;
    }
    sx__kernels(m)->energy(m, &e); /* between cycles: the serial sums, which cannot fail */
    return e;
}

void sx_model_track_energy(sx_model *m, bool on)
{
    m->track_energy = on;
    memset(&m->acc, 0, sizeof m->acc);
}

int64_t sx_contact_count(const sx_model *m) { return sx__kernels(m)->count_contacts(m); }

bool sx_contact_each(const sx_model *m, bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    return sx__kernels(m)->each_contact(m, fn, ud);
}

/* A contact's force: its law's and its bond's (a parallel bond's or a flat
 * joint's face), as PFC counts a bonded contact's force. Without the
 * bond's, a structure that bonds alone carry (a bonded beam, balls bonded
 * across a gap) had no contact force and a ratio that never settled. */
static bool add_contact_force(const sx_contact_info *ci, void *ud)
{
    double *acc = ud;
    const double fn = ci->fn + ci->pb_fn;
    double s2 = fn * fn;
    for (int k = 0; k < 3; k++) s2 += (ci->shear[k] + ci->pb_fs[k]) * (ci->shear[k] + ci->pb_fs[k]);
    acc[0] += sqrt(s2);
    acc[1] += 1;
    return true;
}

/* Something moves: a ball, a wall or the periodic cell. */
static bool anything_moves(const sx_model *m)
{
    const sx_balls *b = &m->balls;
    for (int64_t i = 0; i < b->n * m->dim; i++)
        if (b->v[i] != 0) return true;
    for (int64_t i = 0; i < b->n * m->rdim; i++)
        if (b->w[i] != 0) return true;
    for (int64_t i = 0; i < m->nwall; i++) {
        const sx_wall *w = &m->walls[i];
        if (w->servo_on || w->def.radial_vel != 0) return true;
        for (int k = 0; k < 3; k++)
            if (w->def.vel[k] != 0 || w->def.spin[k] != 0) return true;
    }
    return m->cell && m->cell->controlled;
}

double sx_model_unbalanced_ratio(const sx_model *m)
{
    const sx_balls *b = &m->balls;
    const int d = m->dim;
    double unbalanced = 0;
    int64_t bodies = b->n;
    for (int64_t i = 0; i < b->n; i++) {
        if (b->clump && b->clump[i]) continue; /* a pebble is balanced with its clump, below */
        double s2 = 0;
        for (int k = 0; k < d; k++) {
            if (b->fix[i] & (SX_FIX_VX << k)) continue; /* a fixed component is balanced by its fixity */
            const double f = b->f[i * d + k] + m->gravity[k] / b->inv_mass[i];
            s2 += f * f;
        }
        unbalanced += sqrt(s2);
    }
    if (m->clumps) sx__clumps_unbalanced(m, &unbalanced, &bodies);
    double acc[2] = {0, 0};
    sx_contact_each(m, add_contact_force, acc);
    if (bodies == 0) return 0;
    /* no contact force to compare with: settled only when nothing moves (a
     * cloud of balls a servo is closing on is not; issue: m:solve{ratio}
     * stopped at once there) */
    if (acc[1] == 0 || acc[0] == 0) return unbalanced > 0 || anything_moves(m) ? INFINITY : 0;
    return (unbalanced / (double)bodies) / (acc[0] / acc[1]);
}
