/* The clumps' step, one form per dimension as every kernel: d and r below
 * are the unit's D and RD.
 *
 * After the balls' step. Translation is 4-46/4-48 with the resultant of
 * the pebbles' forces and the clump's weight, as for a ball. Rotation
 * integrates Euler's equations (4-42) written as
 *     dL/dt = M (space),   dL_b/dt = L_b x w_b + M_b (body, w_b,i = L_b,i / I_i),
 * which are 4-42 component by component in the principal frame. It is
 * leapfrog in the same arrangement as 4-46/4-47: L at half steps, the
 * orientation at whole steps.
 *   kick:  L(t + dt/2) = L(t - dt/2) + M(t) dt    (4-47 for L; exact for a
 *          moment held over the step, and in space the moment adds to L
 *          directly, whatever the inertia);
 *   drift: the torque-free body (4-42 with M = 0) over dt, split into its
 *          three principal parts T = sum L_b,i^2 / (2 I_i). The part T_i
 *          alone keeps L_b,i, so w_i, constant: its flow is the rotation of
 *          the body about its principal axis i by w_i dt, exact. The
 *          symmetric composition  i = 1 (dt/2), 2 (dt/2), 3 (dt), 2 (dt/2),
 *          1 (dt/2)  is second order, time-reversible and symplectic
 *          (Dullweber, Leimkuhler & McLachlan 1997). Axes ascend in I, so
 *          the major axis takes the middle, whole step: of the orders tried
 *          on a free asymmetric body this one had the smallest energy error
 *          (9 times below the reverse order), which scales as (w dt)^2
 *          (3e-5 at w dt = 0.1, 1.3e-6 at 0.02).
 * Why this scheme: each sub-rotation turns the body about a body axis and
 * so leaves L in space unchanged, so a torque-free clump keeps L (and |L|)
 * to round-off over any number of steps; as a symplectic map its energy
 * error stays bounded, O((w dt)^2), and does not drift, which is what long
 * DEM runs need. Fincham's leapfrog extrapolates the half-step orientation
 * and is not symplectic (its energy drifts slowly); Omelyan's leapfrog is
 * stable too but needs an implicit iteration per step. Here everything is
 * explicit: five rotations of a quaternion.
 * Local damping acts per component of the force (space axes, as for balls)
 * and of the moment in the principal frame, where each component drives
 * one w_i (4-42), opposing the sign of that component of the spin. In 2D
 * the rotation is about z with the scalar moment and Izz: 4-47 exactly.
 * After the step every pebble is placed from its body: x + R b, v + w x r,
 * spin w, so pebbles never drift from their clump. */
#include "clump_math.h"

/* Sets every pebble of clump c from its body: position x + R s b,
 * velocity v + w x r, spin w. Returns the largest squared displacement of
 * a pebble since the last broad-phase build. */
static double KERNEL(place_pebbles)(sx_model *m, int64_t c, const double *R)
{
    const int d = D, r = RD;
    sx_clumps *C = m->clumps;
    sx_balls *B = &m->balls;
    const sx_clump_tpl *t = &C->tpl[C->tpl_of[c]];
    const double s = C->scale[c], *xc = C->x + c * d, *vc = C->v + c * d, *wc = C->w + c * r;
    const double *body = C->tp_body + t->first * d;
    const int32_t *peb = C->pebble + C->first[c];
    double worst = 0;
    for (int64_t k = 0; k < t->n; k++) {
        const int64_t i = B->index_of[peb[k]];
        double b[3] = {0, 0, 0}, arm[3] = {0, 0, 0}, u[3];
        for (int j = 0; j < d; j++) b[j] = s * body[k * d + j];
        mat_vec(R, b, arm);
        spin_arm(d, wc, arm, u);
        double *x = B->x + i * d, *v = B->v + i * d, disp2 = 0;
        for (int j = 0; j < d; j++) {
            x[j] = xc[j] + arm[j];
            v[j] = vc[j] + u[j];
            const double e = x[j] - B->x_build[i * d + j];
            disp2 += e * e;
        }
        for (int j = 0; j < r; j++) B->w[i * r + j] = wc[j];
        if (disp2 > worst) worst = disp2;
    }
    return worst;
}

/* A term of the clump step's energy sums: onto the block's sum *work, or,
 * decomposed, into slot k of the clump's terms (dd_energy.c sums them in
 * the serial order). The serial step passes terms NULL: inlined, the
 * branch goes. */
static inline __attribute__((always_inline)) void energy_term(double *work, double *terms, int k, double v)
{
    if (terms) terms[k] = v;
    else *work += v;
}

/* What every clump's step reads of the model, read once per run of
 * clumps (the stores through the clumps' arrays could alias it). */
typedef struct step_env {
    sx_clumps *C;
    sx_balls *B;
    double dt, dtv;
    const double *g;
    bool track;
} step_env;

static step_env step_env_of(sx_model *m)
{
    /* the kick spans the time between the half-step velocities, as for balls */
    return (step_env){m->clumps, &m->balls, m->dt, m->dt_prev > 0 ? 0.5 * (m->dt_prev + m->dt) : m->dt, m->gravity,
                      m->track_energy};
}

/* Steps clump c: its resultant, translation, rotation, and its pebbles
 * placed. *worst takes the largest squared pebble displacement, work[0]
 * and work[1] the damping and load terms (or terms, decomposed: the
 * damping's d + r slots, then the loads' d + 1). False: a non-finite
 * state. */
static inline __attribute__((always_inline)) bool step_clump(sx_model *m, const step_env *env, int64_t c,
                                                             double *worst, double *work, double *terms)
{
    const int d = D, r = RD, nd = D + RD;
    sx_clumps *C = env->C;
    sx_balls *B = env->B;
    const double dt = env->dt, dtv = env->dtv, *g = env->g;
    const bool track = env->track;
    const sx_clump_tpl *t = &C->tpl[C->tpl_of[c]];
    const int32_t *peb = C->pebble + C->first[c];
    double *x = C->x + c * d, *v = C->v + c * d, *w = C->w + c * r;
    /* the resultant of the pebbles' forces, and its moment about the centroid:
     * each pebble's own moment plus (x_pebble - x) x F (4-21 carried to the body) */
    double F[3] = {0, 0, 0}, T[3] = {0, 0, 0}, Fa[3] = {0, 0, 0}, Ta[3] = {0, 0, 0};
    for (int64_t k = 0; k < t->n; k++) {
        const int64_t i = B->index_of[peb[k]];
        double arm[3] = {0, 0, 0}, mo[3];
        for (int j = 0; j < d; j++) arm[j] = B->x[i * d + j] - x[j];
        moment_arm(d, arm, B->f + i * d, mo);
        for (int j = 0; j < d; j++) F[j] += B->f[i * d + j];
        for (int j = 0; j < r; j++) T[j] += B->t[i * r + j] + mo[j];
        if (track && B->fapp) {
            moment_arm(d, arm, B->fapp + i * d, mo);
            for (int j = 0; j < d; j++) Fa[j] += B->fapp[i * d + j];
            for (int j = 0; j < r; j++) Ta[j] += B->tapp[i * r + j] + mo[j];
        }
    }
    memcpy(C->f + c * d, F, (size_t)d * sizeof(double));
    memcpy(C->t + c * r, T, (size_t)r * sizeof(double));
    const double mass = C->mass[c], a = C->alpha[c], *I = C->inertia + c * r;
    const unsigned fix = C->fix[c];
    /* translation: 4-46, 4-48 */
    for (int k = 0; k < d; k++) {
        if (!(fix & (SX_FIX_VX << k))) {
            const double force = F[k] + g[k] * mass; /* 4-40: the weight acts at the centroid */
            const double fd = sx__damped(force, v[k], a);
            const double vold = v[k];
            v[k] += fd / mass * dtv;
            if (track) {
                energy_term(&work[0], terms, k, (fd - force) * 0.5 * (vold + v[k]) * dt);
                energy_term(&work[1], terms, nd + k, Fa[k] * 0.5 * (vold + v[k]) * dt);
            }
        } else if (track) { /* held at its velocity: the holder's work, as a ball's (motion.c) */
            energy_term(&work[1], terms, nd + k, -(F[k] - Fa[k] + g[k] * mass) * v[k] * dt);
        }
        x[k] += v[k] * dt;
    }
    /* rotation: 4-42 */
    if (d == 3) {
        double *q = C->q + c * 4, *L = C->L + c * 3, R[9];
        qmatrix(q, R);
        if ((fix & SX_FIX_SPIN) == SX_FIX_SPIN) {
            if (track) /* held at its spin: the holder's work, -(contact moment) . w */
                energy_term(&work[1], terms, nd + d,
                            -((T[0] - Ta[0]) * w[0] + (T[1] - Ta[1]) * w[1] + (T[2] - Ta[2]) * w[2]) * dt);
            imposed_rotation(q, w, dt);
            qmatrix(q, R);
            momentum_of(R, I, w, L);
        } else {
            /* the kick, with local damping per principal component */
            double Tb[3], Lb[3], Md[3], dL[3];
            mat_tvec(R, T, Tb);
            mat_tvec(R, L, Lb);
            for (int k = 0; k < 3; k++) Md[k] = sx__damped(Tb[k], Lb[k] / I[k], a);
            mat_vec(R, Md, dL);
            for (int k = 0; k < 3; k++) L[k] += dL[k] * dtv;
            if (track) { /* work at the mean of the old and new spins, as for balls */
                double Ln[3], wm[3];
                mat_tvec(R, L, Ln);
                for (int k = 0; k < 3; k++) {
                    const double wold = Lb[k] / I[k], wnew = Ln[k] / I[k];
                    energy_term(&work[0], terms, d + k, (Md[k] - Tb[k]) * 0.5 * (wold + wnew) * dt);
                    wm[k] = 0.5 * (wold + wnew);
                }
                double ws[3];
                mat_vec(R, wm, ws);
                energy_term(&work[1], terms, nd + d, (Ta[0] * ws[0] + Ta[1] * ws[1] + Ta[2] * ws[2]) * dt);
            }
            free_rotor(q, R, L, I, dt); /* the drift */
            qmatrix(q, R);
            spin_of(R, I, L, w);
        }
        *worst = fmax(*worst, KERNEL(place_pebbles)(m, c, R));
    } else {
        if (!(fix & SX_FIX_WX)) {
            const double md = sx__damped(T[0], w[0], a), wold = w[0];
            w[0] += md / I[0] * dtv; /* 4-47 about z */
            if (track) {
                energy_term(&work[0], terms, d, (md - T[0]) * 0.5 * (wold + w[0]) * dt);
                energy_term(&work[1], terms, nd + d, Ta[0] * 0.5 * (wold + w[0]) * dt);
            }
        } else if (track) {
            energy_term(&work[1], terms, nd + d, -(T[0] - Ta[0]) * w[0] * dt);
        }
        C->q[c] += w[0] * dt;
        double R[9];
        body_rotation(m, c, R);
        *worst = fmax(*worst, KERNEL(place_pebbles)(m, c, R));
    }
    bool ok = isfinite(C->q[c * (d == 3 ? 4 : 1)]);
    for (int k = 0; k < d; k++) ok &= isfinite(x[k]) && isfinite(v[k]);
    for (int k = 0; k < r; k++) ok &= isfinite(w[k]);
    return ok;
}

/* The step of clumps [c0, c1): partial sums of one block. Each clump
 * writes only itself and its own pebbles, so blocks run in parallel. */
typedef struct clump_block {
    double worst, damp_work, load_work; /* largest squared pebble displacement; energy terms */
    int64_t bad;                        /* first clump with a non-finite state, or -1 */
} clump_block;

static void step_block(sx_model *m, int64_t c0, int64_t c1, clump_block *o)
{
    const step_env env = step_env_of(m);
    double worst = 0, work[2] = {0, 0};
    o->bad = -1;
    for (int64_t c = c0; c < c1; c++)
        if (!step_clump(m, &env, c, &worst, work, NULL) && o->bad < 0) o->bad = c;
    o->worst = worst, o->damp_work = work[0], o->load_work = work[1];
}

/* In fixed blocks of clumps whose partial sums are added in block order:
 * the same bits for any thread count (as the balls' law of motion). */
enum { CLUMP_BLOCK = 512, CLUMP_BLOCKS = 64 };

/* Decomposed: this rank steps its own clumps (decompose.c), from their
 * pebbles' forces (those of other ranks' pebbles sent by their owners);
 * with energy tracking each clump's terms go to the serial sums
 * (sx__dd_clump_energy), in the serial step's blocks. A rank that failed
 * earlier in the step moves no clump but still takes part in that
 * exchange; one that fails here names its first bad clump in clump order,
 * whose index places its error among the ranks' (dd_agree.c). */
static sx_status KERNEL(clumps_step_own)(sx_model *m, double *max_disp, int64_t size)
{
    sx_dd *d = m->dd;
    const int W = 2 * D + RD + 1; /* the damping's D + RD terms, the loads' D + 1 */
    const sx_span own = d->cl_own[d->x.rank];
    const bool track = m->track_energy && m->clumps->n; /* (no clump left: no energy block) */
    double *terms = track ? sx__dd_clump_terms(m, W, size) : NULL;
    if (track && !terms) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    const step_env env = step_env_of(m);
    double worst = *max_disp * *max_disp, work[2] = {0, 0};
    int64_t bad = -1;
    for (int64_t e = own.lo; e < own.hi && !d->failed; e++)
        if (!step_clump(m, &env, d->cl[e], &worst, work, terms ? terms + (e - own.lo) * W : NULL) && bad < 0) bad = d->cl[e];
    *max_disp = sqrt(worst);
    const bool ok = !terms || sx__dd_clump_energy(m, W, D + RD, size);
    if (bad >= 0) {
        d->fail_order = bad;
        return KERNEL(nonfinite)(m, "clump", m->clumps->id[bad]);
    }
    return ok ? SX_OK : sx__fail(m, SX_EINVAL, "cycle: the ranks could not sum the clumps' energies");
}

static sx_status KERNEL(clumps_step)(sx_model *m, double *max_disp)
{
    const sx_clumps *C = m->clumps;
    const int64_t n = C->n;
    clump_block part[CLUMP_BLOCKS];
    int64_t size = (n + CLUMP_BLOCKS - 1) / CLUMP_BLOCKS;
    if (size < CLUMP_BLOCK) size = CLUMP_BLOCK;
    if (m->dd && m->dd->active) return KERNEL(clumps_step_own)(m, max_disp, size);
    const int64_t nblk = (n + size - 1) / size;
#pragma omp parallel for schedule(static) num_threads(m->threads) if (nblk > 1)
    for (int64_t k = 0; k < nblk; k++) step_block(m, k * size, (k + 1) * size < n ? (k + 1) * size : n, &part[k]);
    double worst = *max_disp * *max_disp;
    for (int64_t k = 0; k < nblk; k++) {
        if (part[k].bad >= 0) return KERNEL(nonfinite)(m, "clump", C->id[part[k].bad]);
        worst = fmax(worst, part[k].worst);
        if (m->track_energy) {
            m->acc.local_damping -= part[k].damp_work;
            m->acc.boundary_work += part[k].load_work;
        }
    }
    *max_disp = sqrt(worst);
    return SX_OK;
}
