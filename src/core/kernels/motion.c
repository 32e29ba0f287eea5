/* Stage: the law of motion (entry point KERNEL(integrate)). Part of the
 * per-dimension unit kernels.c, which includes it; not compiled alone. */

/* --------------------------------------------------------- law of motion */


/* After a block's law of motion: when its check sum is not finite, the
 * first ball whose position, velocity or spin is not (-1: none, the sum
 * overflowed). */
static void blame_non_finite(const sx_model *m, sx_block *o, double check)
{
    const sx_balls *B = &m->balls;
    o->bad = -1;
    if (isfinite(check)) return;
    for (int64_t i = o->b0; i < o->b1 && o->bad < 0; i++) {
        bool ok = true;
        for (int k = 0; k < D; k++) ok &= isfinite(B->x[i * D + k]) && isfinite(B->v[i * D + k]);
        for (int k = 0; k < RD; k++) ok &= isfinite(B->w[i * RD + k]);
        if (!ok) o->bad = i;
    }
}

/* An energy term of the block's sum (k: 0 damping, 1 loads, 2 the
 * dashpots' share), or, decomposed in a block begun on a lower rank, of
 * the rank's tape (dd_energy.c). */
static inline void motion_energy(sx_model *m, const sx_block *o, int k, double *sum, double x)
{
    if (o->tape_k >= 0) sx__tape_add(&m->dd->tape, o->tape_k + k, x);
    else *sum += x;
}

/* 4-46 ... 4-48: central differences, velocities at half steps, for the
 * balls of one block; partial sums go to the block. With energy tracking,
 * the damping's and applied loads' work use the mean of the old and new
 * velocities, and so does the dashpots': the contact passes booked it at
 * the old velocity, this adds -dt/2 Fd . (v_new - v_old) per ball (the
 * dashpots' forces and moments on it, m->visc_f and visc_t; a pebble's
 * stays at the old velocity); a component held at its velocity books the
 * holder's work, -(F_contact + m g) v dt, with the loads'. A free, undamped component takes v += (F/m + g) dt, the
 * same lines in both instances: `plain` (a constant at each call site)
 * compiles a block without fixities, damping or tracking alone. */
static inline __attribute__((always_inline)) void motion_pass(sx_model *m, sx_block *o, const bool plain)
{
    sx_balls *B = &m->balls;
    const double dt = m->dt;
    /* the kick spans the time between the half-step velocities, t_{n+1/2} - t_{n-1/2} */
    const double dtv = m->dt_prev > 0 ? 0.5 * (m->dt_prev + m->dt) : m->dt;
    const double g[D] = {m->gravity[0], m->gravity[1]
#if D == 3
                         , m->gravity[2]
#endif
    };
    const bool track = !plain && m->track_energy;
    double *restrict xa = B->x, *restrict va = B->v, *restrict wa = B->w;
    const double *restrict fa = B->f, *restrict ta = B->t, *restrict xb = B->x_build;
    const double *restrict ima = B->inv_mass, *restrict iia = B->inv_inertia;
    const uint8_t *restrict fixa = B->fix;
    const int32_t *cl = B->clump;
    double worst = 0, damp_work = 0, load_work = 0, visc_work = 0;
    const double *restrict vf = track ? m->visc_f : NULL, *restrict vt = track ? m->visc_t : NULL;
    /* the displacements' squares (a non-finite velocity makes its position
     * so) and 0 x every spin: not finite once some value is not (or once
     * the squares overflow; the search below tells) */
    double check = 0;
    /* a deforming cell's work on the balls through their ghosts (ghosts.c, fold_ghosts) */
    const double *restrict shifted = track && m->cell && m->cell->controlled ? m->cell->shifted : NULL;
    for (int64_t i = o->b0; i < o->b1; i++) {
        if (shifted) {
            double w = 0;
            for (int k = 0; k < D; k++)
                for (int j = 0; j < D; j++) w += m->cell->hdot[k][j] * shifted[(i * D + k) * D + j];
            if (w != 0) motion_energy(m, o, 1, &load_work, -w * dt);
        }
        if (cl && cl[i]) continue; /* clumps: a pebble moves with its clump (clump_motion.c) */
        const unsigned fix = plain ? 0 : fixa[i];
        const double a = plain ? 0 : sx__ball_damping(m, i), im = ima[i], ii = iia[i];
        double *v = va + i * D, *x = xa + i * D;
        const double *f = fa + i * D;
        double disp2 = 0, visc = 0;
        for (int k = 0; k < D; k++) {
            if (!(fix & (SX_FIX_VX << k))) {
                const double vold = v[k];
                if (a == 0) {
                    v[k] += (f[k] * im + g[k]) * dtv; /* 4-46 with 4-40 */
                } else {
                    const double force = f[k] + g[k] / im; /* 4-40: the unbalanced force includes the weight */
                    const double fd = sx__damped(force, v[k], a);
                    v[k] += fd * im * dtv; /* 4-46 */
                    if (track) motion_energy(m, o, 0, &damp_work, (fd - force) * 0.5 * (vold + v[k]) * dt);
                }
                if (track && B->fapp)
                    motion_energy(m, o, 1, &load_work, B->fapp[i * D + k] * 0.5 * (vold + v[k]) * dt);
                if (track) visc += vf[i * D + k] * (v[k] - vold);
            } else if (track) { /* held at its velocity: the holder's work on the rest, -(contact force + weight) . v */
                const double fc = f[k] - (B->fapp ? B->fapp[i * D + k] : 0); /* a load on a held component does nothing */
                motion_energy(m, o, 1, &load_work, -(fc + g[k] / im) * v[k] * dt);
            }
            x[k] += v[k] * dt; /* 4-48 */
            const double u = x[k] - xb[i * D + k];
            disp2 += u * u;
        }
        check += disp2;
        double *w = wa + i * RD;
        const double *t = ta + i * RD;
        for (int k = 0; k < RD; k++) {
            if (!(fix & (SX_FIX_WX << k))) {
                const double wold = w[k];
                if (a == 0) {
                    w[k] += t[k] * ii * dtv; /* 4-47 */
                } else {
                    const double md = sx__damped(t[k], w[k], a);
                    w[k] += md * ii * dtv;
                    if (track) motion_energy(m, o, 0, &damp_work, (md - t[k]) * 0.5 * (wold + w[k]) * dt);
                }
                if (track && B->tapp)
                    motion_energy(m, o, 1, &load_work, B->tapp[i * RD + k] * 0.5 * (wold + w[k]) * dt);
                if (track) visc += vt[i * RD + k] * (w[k] - wold);
            } else if (track) { /* held at its spin: -(contact moment) . w */
                const double tc = t[k] - (B->tapp ? B->tapp[i * RD + k] : 0);
                motion_energy(m, o, 1, &load_work, -tc * w[k] * dt);
            }
            check += 0 * w[k];
        }
        if (visc != 0) motion_energy(m, o, 2, &visc_work, -0.5 * visc * dt);
        worst = disp2 > worst ? disp2 : worst;
    }
    o->worst = worst;
    o->damp_work = damp_work;
    o->load_work = load_work;
    o->visc_work = visc_work;
    blame_non_finite(m, o, check);
}

/* A plain block (no fixities, damping, tracking or pebbles) four balls at
 * a time: motion_pass's arithmetic in vector lanes (four balls' components
 * are adjacent in memory, moved by shuffles), the largest displacement per
 * lane and then over the lanes (a maximum, in any order the same), the
 * last balls one by one. */
static inline __attribute__((always_inline)) void motion_lanes(sx_model *m, sx_block *o)
{
    sx_balls *B = &m->balls;
    const double dt = m->dt;
    const double dtv = m->dt_prev > 0 ? 0.5 * (m->dt_prev + m->dt) : m->dt; /* as in motion_pass */
    double *restrict xa = B->x, *restrict va = B->v, *restrict wa = B->w;
    const double *restrict fa = B->f, *restrict ta = B->t, *restrict xb = B->x_build;
    const double *restrict ima = B->inv_mass, *restrict iia = B->inv_inertia;
    vd worst = VZERO, check = VZERO;
    int64_t i = o->b0;
    for (; i + LANES <= o->b1; i += LANES) {
        vd x[D], v[D], f[D], x0[D], im, ii;
        load_lanes(xa + i * D, x);
        load_lanes(va + i * D, v);
        load_lanes(fa + i * D, f);
        load_lanes(xb + i * D, x0);
        memcpy(&im, ima + i, sizeof im);
        memcpy(&ii, iia + i, sizeof ii);
        vd disp2 = VZERO;
        for (int k = 0; k < D; k++) {
            v[k] += (f[k] * im + m->gravity[k]) * dtv; /* 4-46 with 4-40 */
            x[k] += v[k] * dt;                         /* 4-48 */
            const vd u = x[k] - x0[k];
            disp2 += u * u;
        }
        store_lanes(xa + i * D, x);
        store_lanes(va + i * D, v);
        check += disp2;
        worst = VSEL(disp2 > worst, disp2, worst);
#if D == 3
        vd w[3], t[3];
        load_lanes(wa + i * 3, w);
        load_lanes(ta + i * 3, t);
        for (int k = 0; k < 3; k++) {
            w[k] += t[k] * ii * dtv; /* 4-47 */
            check += 0 * w[k];
        }
        store_lanes(wa + i * 3, w);
#else
        vd w, t;
        memcpy(&w, wa + i, sizeof w);
        memcpy(&t, ta + i, sizeof t);
        w += t * ii * dtv; /* 4-47 */
        check += 0 * w;
        memcpy(wa + i, &w, sizeof w);
#endif
    }
    double most = 0, sum = check[0] + check[1] + check[2] + check[3];
    for (int q = 0; q < LANES; q++) most = worst[q] > most ? worst[q] : most;
    for (; i < o->b1; i++) {
        const double im = ima[i], ii = iia[i];
        double disp2 = 0;
        for (int k = 0; k < D; k++) {
            va[i * D + k] += (fa[i * D + k] * im + m->gravity[k]) * dtv;
            xa[i * D + k] += va[i * D + k] * dt;
            const double u = xa[i * D + k] - xb[i * D + k];
            disp2 += u * u;
        }
        sum += disp2;
        for (int k = 0; k < RD; k++) {
            wa[i * RD + k] += ta[i * RD + k] * ii * dtv;
            sum += 0 * wa[i * RD + k];
        }
        most = disp2 > most ? disp2 : most;
    }
    o->worst = most;
    o->damp_work = o->load_work = o->visc_work = 0;
    blame_non_finite(m, o, sum);
}

SX_VECTOR_CLONES static void integrate_block(sx_model *m, sx_block *o)
{
    const sx_balls *B = &m->balls;
    /* undamped: no ball has its own damping and no material has any (no per-ball test needed) */
    bool plain = !m->track_energy, undamped = !B->alpha;
    for (int k = 0; k < m->nmat && undamped; k++) undamped = m->mats[k].def.damping == 0;
    for (int64_t i = o->b0; i < o->b1 && plain; i++) plain = !B->fix[i] && (undamped || sx__ball_damping(m, i) == 0);
    if (plain && !B->clump) motion_lanes(m, o);
    else if (plain) motion_pass(m, o, true);
    else motion_pass(m, o, false);
}

/* A ball's or clump's state became non-finite (what: "ball" or "clump"). */
static sx_status KERNEL(nonfinite)(sx_model *m, const char *what, int64_t id)
{
    sx_unstable u = {.kind = SX_UNSTABLE_NONFINITE, .a = id, .step = m->step, .dt = m->dt};
    strncpy(u.what_a, what, sizeof u.what_a - 1);
    return sx__unstable_fail(m, &u, KERNEL(estimate_dt)(m));
}

/* The law of motion in fixed blocks of balls whose partial sums are added
 * in block order (the same bits for any thread count). Returns the largest
 * displacement since the last build in *max_disp. */
static sx_status KERNEL(integrate)(sx_model *m, double *max_disp)
{
    const int64_t nb = m->nblock;
    const bool dd = m->dd && m->dd->active;
    if (dd) { /* decomposed: this rank's own balls of each block */
        const sx_span own = m->dd->own[m->dd->x.rank];
        /* energy tracking: the terms of a block begun on a lower rank go to
         * the tape, after the chunks' sums (3 a chunk) and the wall blocks' (2 a block),
         * 3 a block */
        const int64_t tape0 = 3 * m->nchunk + 2 * nb;
#pragma omp parallel for schedule(static) num_threads(m->threads) if (nb > 1)
        for (int64_t b = 0; b < nb; b++) {
            sx_block *o = &m->blocks[b], part = *o;
            part.b0 = o->b0 > own.lo ? o->b0 : own.lo;
            part.b1 = o->b1 < own.hi ? o->b1 : own.hi;
            part.worst = 0, part.bad = -1, part.damp_work = part.load_work = part.visc_work = 0;
            part.tape_k = o->b0 < own.lo ? tape0 + 3 * b : -1;
            if (part.b1 > part.b0) integrate_block(m, &part);
            o->worst = part.worst, o->bad = part.bad, o->damp_work = part.damp_work, o->load_work = part.load_work;
            o->visc_work = part.visc_work;
        }
    } else {
#pragma omp parallel for schedule(static) num_threads(m->threads) if (nb > 1)
        for (int64_t b = 0; b < nb; b++) integrate_block(m, &m->blocks[b]);
    }
    double worst = 0;
    for (int64_t b = 0; b < nb; b++) {
        const sx_block *o = &m->blocks[b];
        if (o->bad >= 0)
            return KERNEL(nonfinite)(m, "ball", m->balls.id[o->bad]);
        if (o->worst > worst) worst = o->worst;
        if (m->track_energy && !dd) { /* decomposed: the ranks' to chain (dd_energy.c, sx__dd_energy) */
            m->acc.local_damping -= o->damp_work;
            m->acc.boundary_work += o->load_work;
            m->acc.viscous += o->visc_work;
        }
    }
    *max_disp = sqrt(worst);
    return SX_OK;
}
