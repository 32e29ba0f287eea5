/* What the other stages ask of the clumps (the hooks in model_internal.h):
 * their energy, their critical timestep, whether some is fixed, their
 * unbalanced force, a pebble's body. Queries: they change nothing. */
#include "clump_math.h"
#include "clumps_internal.h"

#include <math.h>

void sx__clumps_energy(const sx_model *m, sx_energy *e)
{
    const sx_clumps *C = m->clumps;
    const int d = m->dim, r = m->rdim;
    const double half = sx__half_step(m);
    for (int64_t c = 0; c < C->n; c++) {
        const double *v = C->v + c * d, *x = C->x + c * d, *I = C->inertia + c * r, mass = C->mass[c];
        double v2 = 0, gx = 0, rot = 0, s[3]; /* s: unwrapped, as its pebbles (wrapped with it) */
        sx__ball_wraps(m, m->balls.index_of[C->pebble[C->first[c]]], s);
        for (int k = 0; k < d; k++) /* at the velocities' time, as a ball's (kernels/queries.c) */
            v2 += v[k] * v[k], gx += m->gravity[k] * (x[k] + s[k] - half * v[k]);
        if (d == 3) { /* 1/2 w^T I w = sum L_b,i^2 / (2 I_i) in the principal frame */
            double R[9], Lb[3];
            body_rotation(m, c, R);
            mat_tvec(R, C->L + c * 3, Lb);
            for (int k = 0; k < 3; k++) rot += 0.5 * Lb[k] * Lb[k] / I[k];
        } else {
            rot = 0.5 * I[0] * C->w[c] * C->w[c];
        }
        e->kinetic += 0.5 * mass * v2 + rot;
        e->gravitational -= mass * gx;
    }
}

/* A clump's rating. Translation: its mass against the sum of its pebbles'
 * contact stiffnesses kt (and dashpots ct), as a ball's. Rotation about a
 * principal axis i, for a pebble whose centre is at distance h from it:
 * normal springs act through the pebble centre (lever <= h), shear springs
 * at its surface (lever <= h + R), and bonds' rotational springs directly.
 * critical_dt's sums are kt = normal + shear stiffness and kr = shear
 * stiffness R^2 + rotational springs, so the stiffness about i is at most
 *     K_i = sum over pebbles of kt h^2 + kr (1 + 2 h / R)
 * (the shear part's (h + R)^2 - h^2 = R^2 (1 + 2 h / R) is charged to kr),
 * which is exact for a pebble on the axis (h = 0: kr). The largest
 * rotational frequency, the largest eigenvalue of I^-1 K, is at most its
 * trace, w^2 <= sum_i K_i / I_i (the body frame diagonalises I). The
 * dashpots enter likewise, with the largest damping ratio of the axes. */
static double clump_rating(const sx_model *m, int64_t c, const double *kt, const double *kr, const double *ct,
                           const double *cr)
{
    const sx_clumps *C = m->clumps;
    const sx_balls *B = &m->balls;
    const int d = m->dim, r = m->rdim;
    double best = INFINITY;
    const sx_clump_tpl *t = &C->tpl[C->tpl_of[c]];
    const double s = C->scale[c], *body = C->tp_body + t->first * d, *I = C->inertia + c * r;
    double Kt = 0, Ct = 0, Kr[3] = {0, 0, 0}, Cr[3] = {0, 0, 0};
    for (int64_t k = 0; k < t->n; k++) {
        const int64_t i = B->index_of[C->pebble[C->first[c] + k]];
        Kt += kt[i];
        Ct += ct[i];
        for (int a = 0; a < r; a++) {
            /* the pebble centre's distance from principal axis a (2D: from z) */
            double h2 = 0;
            for (int j = 0; j < d; j++)
                if (d == 2 || j != a) h2 += s * body[k * d + j] * s * body[k * d + j];
            const double lever = 1 + 2 * sqrt(h2) / B->rad[i];
            Kr[a] += kr[i] * lever + kt[i] * h2;
            Cr[a] += cr[i] * lever + ct[i] * h2;
        }
    }
    const double mass = C->mass[c], amp = 1 + C->alpha[c];
    if (Kt > 0) {
        const double z = amp * Ct / (2 * sqrt(Kt * mass));
        best = fmin(best, sqrt(mass / Kt) * (sqrt(1 + z * z) - z));
    }
    double w2 = 0, z = 0;
    for (int a = 0; a < r; a++) {
        w2 += Kr[a] / I[a];
        if (Kr[a] > 0) z = fmax(z, amp * Cr[a] / (2 * sqrt(Kr[a] * I[a])));
    }
    if (w2 > 0) best = fmin(best, (sqrt(1 + z * z) - z) / sqrt(w2));
    return best;
}

/* Decomposed inside a cycle, a rank rates its own clumps (decompose.c):
 * the ranks' minimum is the serial one. */
double sx__clumps_critical_dt(const sx_model *m, const double *kt, const double *kr, const double *ct,
                              const double *cr)
{
    const sx_dd *dd = m->dd && m->dd->active ? m->dd : NULL;
    double best = INFINITY;
    if (dd)
        for (int64_t e = dd->cl_own[dd->x.rank].lo; e < dd->cl_own[dd->x.rank].hi; e++)
            best = fmin(best, clump_rating(m, dd->cl[e], kt, kr, ct, cr));
    else
        for (int64_t c = 0; c < m->clumps->n; c++) best = fmin(best, clump_rating(m, c, kt, kr, ct, cr));
    return best;
}

bool sx__clumps_forced(const sx_model *m)
{
    const sx_clumps *C = m->clumps;
    for (int64_t c = 0; c < C->n; c++)
        if (C->fix[c]) return true;
    return false;
}

void sx__clumps_unbalanced(const sx_model *m, double *sum, int64_t *bodies)
{
    const sx_clumps *C = m->clumps;
    const int d = m->dim;
    for (int64_t c = 0; c < C->n; c++) {
        double s2 = 0;
        for (int k = 0; k < d; k++) {
            if (C->fix[c] & (SX_FIX_VX << k)) continue; /* balanced by its fixity */
            const double f = C->f[c * d + k] + m->gravity[k] * C->mass[c];
            s2 += f * f;
        }
        *sum += sqrt(s2);
        *bodies += 1 - C->tpl[C->tpl_of[c]].n; /* one body, not its pebbles */
    }
}

void sx__pebble_body(const sx_model *m, int64_t i, double centre[3], double *volume)
{
    const sx_clumps *C = m->clumps;
    const int d = m->dim;
    const int64_t c = C->index_of[m->balls.clump[i]];
    const sx_clump_tpl *t = &C->tpl[C->tpl_of[c]];
    centre[0] = centre[1] = centre[2] = 0;
    for (int k = 0; k < d; k++) centre[k] = C->x[c * d + k];
    const double s = C->scale[c], u = m->balls.rad[i] / s;
    *volume = t->volume * (d == 3 ? s * s * s * u * u * u : s * s * u * u) / t->power_sum;
}
