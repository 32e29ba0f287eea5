/* Stage: the ball-ball contacts (entry point KERNEL(contacts); the
 * chunk plan KERNEL(plan)). Part of the per-dimension unit kernels.c,
 * which includes it; not compiled alone. */

/* ------------------------------------------------------- contact forces */

/* The rotation carried by a contact from one step to the next: into the new
 * contact plane (4-13/4-14, c = n_old x n) and about the normal by the mean
 * spin of the two entities (4-8/4-9/4-15). Applied to the shear force and to
 * the parallel bond's shear force and bending moment. */
typedef struct carry {
    double c[D == 3 ? 3 : 1];
    double wdt[D == 3 ? 3 : 1];
} carry;

static inline void carry_make(carry *r, const double *nold, const double *n, const double *wa, const double *wb,
                              double dt)
{
#if D == 3
    r->c[0] = nold[1] * n[2] - nold[2] * n[1];
    r->c[1] = nold[2] * n[0] - nold[0] * n[2];
    r->c[2] = nold[0] * n[1] - nold[1] * n[0];
    /* 4-9: the mean spin projected on the normal (a wall does not spin) */
    double ws[3];
    for (int k = 0; k < 3; k++) ws[k] = wa ? wa[k] + wb[k] : wb[k];
    const double wbar = 0.5 * dot(ws, n);
    for (int k = 0; k < 3; k++) r->wdt[k] = wbar * n[k] * dt;
#else
    /* in 2D c is along z, and the spins are normal to n, so 4-15 is the identity */
    (void)wa, (void)wb, (void)dt;
    r->c[0] = nold[0] * n[1] - nold[1] * n[0];
    r->wdt[0] = 0;
#endif
}

static inline void carry_apply(const carry *r, double *v)
{
#if D == 3
    double t[3];
    spin_cross(r->c, v, t); /* 4-14: F + c x F */
    for (int k = 0; k < 3; k++) v[k] += t[k];
    spin_cross(r->wdt, v, t); /* 4-15: F + (w dt) x F */
    for (int k = 0; k < 3; k++) v[k] += t[k];
#else
    const double v0 = v[0];
    v[0] -= r->c[0] * v[1];
    v[1] += r->c[0] * v0;
#endif
}

/* Normal and shear stiffness of a contact by its law (laws/registry.h).
 * rbar is 4-27's 2RARB/(RA+RB) (ball-wall: R, 4-28). Returns the normal force. */
static inline double stiffness(const sx_pair_law *l, double ra, double rb, double rbar, double un, double *kn,
                               double *ks)
{
    return sx__law_force(l, D, ra, rb, rbar, un, kn, ks);
}

/* Strain energy of a contact spring: its law's factor times Fn Un (linear
 * 1/2, Hertz 2/5), plus the shear spring's 1/2 |Fs|^2 / ks. */
static inline double contact_strain(const sx_pair_law *l, double fn, double un, const double *fs, double ks)
{
    const double normal = sx__law(l->law)->strain * fn * un;
    return normal + (ks > 0 ? 0.5 * dot(fs, fs) / ks : 0);
}

/* The flat joint of bond s (laws/flatjoint.h): its face axes t1, t2 for
 * the joint's normal n (3D: t1 as carried; 2D: n turned by +90 deg, t2 = z). */
static inline void fj_axes(const sx_bonds *b, int32_t s, const double *n, double *t1, double *t2)
{
#if D == 3
    for (int k = 0; k < 3; k++) t1[k] = b->fj_axis[s * 3 + k];
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
#else
    (void)b, (void)s;
    t1[0] = -n[1], t1[1] = n[0];
    t2[0] = t2[1] = 0;
#endif
}

/* The gap gradient (ay, az) = (-theta2, theta1) of flat joint s's bend rotation. */
static inline void fj_gradient(const sx_bonds *b, int32_t s, double *ay, double *az)
{
#if D == 3
    *ay = -b->fj_rot[s * 2 + 1], *az = b->fj_rot[s * 2];
#else
    *ay = -b->fj_rot[s], *az = 0;
#endif
}

/* Shear spring energy of a flat-joint element: |Fs|^2 / (2 ks A). */
static inline double fj_shear_energy(const double *fs, double ks, double area)
{
    double f2 = 0;
    for (int k = 0; k < D - 1; k++) f2 += fs[k] * fs[k];
    return 0.5 * f2 / (ks * area);
}

/* Strain energy of flat joint s at centre distance d (its last evaluation's). */
static double fj_strain(const sx_model *m, int32_t s, double d)
{
    const sx_bonds *b = &m->bonds;
    const sx_fjels *E = &m->fjel;
    double ay, az;
    fj_gradient(b, s, &ay, &az);
    const double delta = d - b->fj_d0[s];
    const int nel = b->fj_nr[s] * b->fj_na[s];
    double e = 0;
    for (int el = 0; el < nel; el++) {
        const int64_t x = b->fj_first[s] + el;
        sx_law_fj_geom g;
        sx_law_fj_element(D, b->rbar[s], b->fj_nr[s], b->fj_na[s], el, &g);
        const double gc = E->gap0[x] + delta + ay * g.y + az * g.z;
        e += sx_law_fj_load_of(D, &g, E->state[x] == SX_FJ_BONDED, b->kn[s], gc, ay, az).energy;
        e += fj_shear_energy(E->fs + x * (D - 1), b->ks[s], g.area);
    }
    return e;
}

static double KERNEL(estimate_dt)(sx_model *m);

/* 4-16 ... 4-20: the velocity v_{n-1/2} moved the entities from x_{n-1} to
 * x_n during the previous step, so displacement increments use its length. */
static inline double motion_dt(const sx_model *m) { return m->dt_prev > 0 ? m->dt_prev : m->dt; }

/* what_a, what_b: "ball", "ball" or "ball", "wall" (sx__unstable_fail). */
static sx_status overlap_error(sx_model *m, const char *what_a, const char *what_b, int64_t ida, int64_t idb,
                               double un, double r)
{
    sx_unstable u = {.kind = SX_UNSTABLE_OVERLAP, .a = ida, .b = idb, .step = m->step, .un = un, .r = r, .dt = m->dt};
    strncpy(u.what_a, what_a, sizeof u.what_a - 1);
    strncpy(u.what_b, what_b, sizeof u.what_b - 1);
    return sx__unstable_fail(m, &u, KERNEL(estimate_dt)(m));
}

/* A chunk's error: an overlap deeper than a radius, or a bond broken with
 * a non-finite force. */
static sx_status chunk_error(sx_model *m, const sx_chunk *o)
{
    if (o->err_break) {
        const sx_unstable u = {.kind = SX_UNSTABLE_BOND, .a = o->err_a, .b = o->err_b, .step = m->step, .dt = m->dt};
        return sx__unstable_fail(m, &u, KERNEL(estimate_dt)(m));
    }
    return overlap_error(m, "ball", "ball", o->err_a, o->err_b, o->err_un, o->err_r);
}

static void log_crack(sx_model *m, sx_chunk *o, const double *xc, sx_crack_mode mode, sx_bond_kind kind, int element,
                      int64_t i, int64_t j, double fn, double fs, double mn, double ms)
{
    sx_crack c;
    memset(&c, 0, sizeof c);
    c.time = m->time;
    c.step = m->step;
    for (int k = 0; k < D; k++) c.pos[k] = xc[k];
    c.mode = mode;
    c.kind = kind;
    c.a = m->balls.id[i];
    c.b = m->balls.id[j];
    c.fn = fn, c.fs = fs, c.mn = mn, c.ms = ms;
    c.element = element;
    /* a force no finite stiffness and step can make: the step is unstable
     * (a stiffness far above what the timestep was computed for), not a crack */
    if (!isfinite(fn) || !isfinite(fs) || !isfinite(mn) || !isfinite(ms)) {
        if (!o->st) o->st = SX_EUNSTABLE, o->err_break = true, o->err_a = c.a, o->err_b = c.b;
        return;
    }
    /* kept with the chunk, merged into the model's log in chunk order */
    if (o->ncracks == o->capcracks) {
        const int64_t cap = o->capcracks ? 2 * o->capcracks : 16;
        sx_crack *q = realloc(o->cracks, (size_t)cap * sizeof *q);
        if (!q) return; /* out of memory: the event is dropped, the bond still breaks */
        o->cracks = q;
        o->capcracks = cap;
    }
    o->cracks[o->ncracks++] = c;
}

/* An energy term of the chunk's current pair: to the chunk's sum k, or,
 * decomposed past its tape_at, to the rank's tape (dd_energy.c). A zero
 * changes no sum (a sum from +0 never reaches -0), so it is not kept. */
enum { E_SLIP, E_VISCOUS, E_RELEASED };
static inline void chunk_energy(sx_model *m, sx_chunk *o, int k, double x)
{
    if (x == 0) return;
    if (o->taping) sx__tape_add(&m->dd->tape, 3 * (o - m->chunks) + k, x);
    else if (k == E_SLIP) o->slip += x;
    else if (k == E_VISCOUS) o->viscous += x;
    else o->released += x;
}

/* The parallel bond of pair (i, j) (laws/parallel_bond.h): carried with
 * the contact (4-13 ... 4-15), then stepped and tested by its law. Adds its
 * force to F (on j) and its moment to mb (on j). Returns false when it
 * broke (logged, its energy released). */
static bool parallel_bond(sx_model *m, sx_chunk *o, int32_t s, const carry *rot, const double *n, double vn,
                          const double *vs, const double *dtheta, const double *xc, int64_t i, int64_t j, double *F,
                          double *mb)
{
    sx_bonds *b = &m->bonds;
    carry_apply(rot, b->fs + s * D);
#if D == 3
    carry_apply(rot, b->ms + s * RD);
#endif
    sx_bond_break br;
    if (sx_bond_parallel_step(D, b, s, n, vn, vs, dtheta, motion_dt(m), &br)) {
        log_crack(m, o, xc, br.mode, SX_BOND_PARALLEL, -1, i, j, b->fn[s], br.fsn, br.mnn, br.msn);
        if (m->track_energy) chunk_energy(m, o, E_RELEASED, sx_bond_parallel_strain(D, b, s));
        return false;
    }
    sx_bond_parallel_add(D, b, s, n, F, mb);
    return true;
}

/* The flat joint of pair (i, j) in place of its contact law (laws/flatjoint.h):
 * its axes carried, its bend rotation and its elements' shear forces
 * incremented, each element loaded from the gap field and checked against
 * its strengths (a break goes to the crack log with its element), friction
 * capping the unbonded ones. The face is evaluated in the joint's own
 * orientation (as installed); its resultants are turned to the pair's:
 * the force on j added to F, its moment about the contact point to mb, and
 * both kept in the bond's fn, fs, mn, ms (as the parallel bond's). Returns
 * false when the joint is gone: no element bonded and none in contact (a
 * gapped face: and its balls apart by more than twice its gap; a face on
 * overlapping balls: and the balls apart). */
static bool flat_joint(sx_model *m, sx_chunk *o, int32_t s, const carry *rot, const double *np, double d,
                       const double *vsp, const double *dthp, const double *xc, int64_t i, int64_t j, double *F,
                       double *mb)
{
    sx_bonds *b = &m->bonds;
    sx_fjels *E = &m->fjel;
    const double sg = m->balls.id[i] == b->ida[s] ? 1 : -1; /* the pair's orientation against the joint's */
    const double dt = motion_dt(m), kn = b->kn[s], ks = b->ks[s], r = b->rbar[s];
    const bool track = m->track_energy;
    double n[D], vs[D], dth[RD], t1[D], t2[D];
    for (int k = 0; k < D; k++) n[k] = sg * np[k], vs[k] = sg * vsp[k];
    for (int k = 0; k < RD; k++) dth[k] = sg * dthp[k];
#if D == 3
    /* t1 turns with the contact (4-14/4-15), then is made normal to n again */
    double *axis = b->fj_axis + s * 3;
    carry_apply(rot, axis);
    const double an = dot(axis, n);
    for (int k = 0; k < 3; k++) axis[k] -= an * n[k];
    const double inv = 1.0 / sqrt(dot(axis, axis));
    for (int k = 0; k < 3; k++) axis[k] *= inv;
    fj_axes(b, s, n, t1, t2);
    b->fj_rot[s * 2] += dot(dth, t1);
    b->fj_rot[s * 2 + 1] += dot(dth, t2);
    const double twist = dot(dth, n);
    const double dus[2] = {dot(vs, t1) * dt, dot(vs, t2) * dt};
#else
    (void)rot;
    fj_axes(b, s, n, t1, t2);
    b->fj_rot[s] += dth[0];
    const double twist = 0, dus[1] = {dot(vs, t1) * dt};
#endif
    double ay, az;
    fj_gradient(b, s, &ay, &az);
    const double delta = d - b->fj_d0[s], tanphi = b->fj_tanphi[s], mu = b->fj_mu[s];
    const int nr = b->fj_nr[s], na = b->fj_na[s];
    double fn_sum = 0, fs_sum[2] = {0, 0}, m1 = 0, m2 = 0, mt = 0;
    bool alive = false, gapped = true;
    for (int el = 0; el < nr * na; el++) {
        const int64_t x = b->fj_first[s] + el;
        sx_law_fj_geom g;
        sx_law_fj_element(D, r, nr, na, el, &g);
        double *fs = E->fs + x * (D - 1);
        /* the shear displacement of the element's centroid: the contact point's
         * (4-17 ... 4-20) plus the twist's dtheta_n n x re = (-z, y) dtheta_n */
        const double ksa = ks * g.area;
        double f0[2]; /* before the increment, for the slip work */
        for (int k = 0; k < D - 1; k++) f0[k] = fs[k];
        fs[0] -= ksa * (dus[0] - twist * g.z);
        if (D == 3) fs[D - 2] -= ksa * (dus[D - 2] + twist * g.y);
        const double gc = E->gap0[x] + delta + ay * g.y + az * g.z;
        bool bonded = E->state[x] == SX_FJ_BONDED;
        sx_law_fj_load l = sx_law_fj_load_of(D, &g, bonded, kn, gc, ay, az);
        double fsn = 0;
        for (int k = 0; k < D - 1; k++) fsn += fs[k] * fs[k];
        fsn = sqrt(fsn);
        double released = 0;
        if (bonded) {
            const double sigma = -l.fn / g.area, tau = fsn / g.area;
            const int mode = sigma >= E->sigma_c[x]                ? SX_CRACK_TENSION
                             : tau >= E->coh[x] - sigma * tanphi ? SX_CRACK_SHEAR
                                                                 : 0;
            if (mode) {
                double pos[D];
                for (int k = 0; k < D; k++) pos[k] = xc[k] + g.y * t1[k] + (D == 3 ? g.z * t2[k] : 0);
                log_crack(m, o, pos, (sx_crack_mode)mode, SX_BOND_FLATJOINT, el, i, j, l.fn, fsn, 0, 0);
                E->state[x] = (uint8_t)(mode == SX_CRACK_TENSION ? SX_FJ_TENSION : SX_FJ_SHEAR);
                released = l.energy + fj_shear_energy(fs, ks, g.area);
                l = sx_law_fj_contact(D, &g, kn, gc, ay, az);
                bonded = false;
            }
        }
        if (!bonded) { /* compression and Coulomb friction only; a break's drop is released, not slip */
            double sc, work = 0;
            sx__law_cap(D - 1, fs, f0, fsn * fsn, mu * (l.fn > 0 ? l.fn : 0), ksa, track && !released ? &work : NULL,
                        &sc);
            if (track) chunk_energy(m, o, E_SLIP, work);
            if (released) released -= l.energy + fj_shear_energy(fs, ks, g.area);
        }
        if (track) chunk_energy(m, o, E_RELEASED, released);
        E->fn[x] = l.fn;
        alive = alive || bonded || l.fn > 0;
        gapped = gapped && E->gap0[x] > 0;
        /* the element's moment about the contact point: re x (Fn n + Fs) + its own */
        fn_sum += l.fn;
        fs_sum[0] += fs[0];
        m1 += l.m1 + l.fn * g.z;
        m2 += l.m2 - l.fn * g.y;
#if D == 3
        fs_sum[1] += fs[1];
        mt += g.y * fs[1] - g.z * fs[0];
#endif
    }
    /* a gapped face (every element installed open: Potyondy's gapped grains)
     * waits for its balls to close while they have not opened by more than
     * its gap again */
    if (!alive && gapped) alive = delta < E->gap0[b->fj_first[s]];
    /* a face installed on overlapping balls opens (delta > 0) before they
     * part: it stays, carrying nothing, until they part, so the contact
     * law takes over at zero overlap rather than with a force kn u0 out
     * of nowhere (an energy jump); "part" as m:bond saw them touching, so
     * a face installed on balls just touching, every element unbonded,
     * is not dropped at its first step */
    if (!alive && !gapped) {
        const double ri = m->balls.rad[i], rj = m->balls.rad[j];
        alive = d - (ri + rj) < sx__touching(ri, rj);
    }
    /* resultants, turned to the pair's orientation (sg) */
    double *bfs = b->fs + s * D, *bms = b->ms + s * RD;
    b->fn[s] = fn_sum;
    b->mn[s] = D == 3 ? mt : 0; /* sg mt n_joint = mt n */
    for (int k = 0; k < D; k++) {
        bfs[k] = sg * (fs_sum[0] * t1[k] + (D == 3 ? fs_sum[1] * t2[k] : 0));
        F[k] += fn_sum * np[k] + bfs[k];
    }
#if D == 3
    for (int k = 0; k < 3; k++) {
        bms[k] = sg * (m1 * t1[k] + m2 * t2[k]);
        mb[k] += b->mn[s] * np[k] + bms[k];
    }
#else
    (void)m1, (void)mt;
    bms[0] = sg * m2;
    mb[0] += bms[0];
#endif
    return alive;
}

/* 4-21 and 4-39: F on j and -F on i at the contact point, whose arms la n
 * from i and -lb n from j both lie along n (so both moments are multiples
 * of n x F), plus a moment mb on j and -mb on i (a bond's; NULL: none) and
 * the rolling moment mroll alike. */
static inline void pair_apply(double *f, double *t, int64_t i, int64_t j, const double *n, double la, double lb,
                              const double *F, const double *mb, const double *mroll)
{
    double nf[RD];
    moment_of(n, F, nf);
    double *fi = f + i * D, *ti = t + i * RD, *fj = f + j * D, *tj = t + j * RD;
    for (int k = 0; k < D; k++) {
        fi[k] -= F[k];
        fj[k] += F[k];
    }
    for (int k = 0; k < RD; k++) {
        double ma = la * nf[k], mj = -lb * nf[k];
        if (mb) ma += mb[k], mj += mb[k];
        ma += mroll[k], mj += mroll[k];
        ti[k] -= ma;
        tj[k] += mj;
    }
}

/* The smooth joint of pair c (laws/smoothjoint.h) in place of its contact
 * law and bond: its overlap along the joint normal and its shear force in
 * the plane incremented from vc, the contact point's relative velocity
 * (4-16); a bonded joint (bit SX_BOND_SMOOTHJOINT of *bonds) checked
 * against its strengths (a break cleared from *bonds, logged at xc); an
 * unbonded one open, or slipping with dilation. The force on j to F. */
static void smooth_joint(sx_model *m, sx_chunk *o, int64_t c, int32_t slot, unsigned *bonds, const double *vc,
                         const double *xc, int64_t i, int64_t j, double *F)
{
    sx_pairs *p = &m->bb;
    const sx_law_sj *L = &m->joints[p->joint[c] - 1].law;
    const double *N = p->jnormal + c * D;
    double *fs = p->fs + c * D, *un = p->jun + c;
    const double dt = motion_dt(m), area = sx_law_sj_area(D, L, m->balls.rad[i], m->balls.rad[j]);
    const bool track = m->track_energy;
    const double vn = dot(vc, N);
    double fs0[D];
    for (int k = 0; k < D; k++) fs0[k] = fs[k];
    *un -= vn * dt;
    for (int k = 0; k < D; k++) fs[k] -= L->ks * area * (vc[k] - vn * N[k]) * dt;
    double fn = L->kn * area * *un;
    bool bonded = *bonds & SX_BOND_SMOOTHJOINT;
    double before = 0; /* a break releases the energy the bond loses */
    if (bonded) {
        const double fsn = sqrt(dot(fs, fs));
        const int mode = sx_law_sj_breaks(L, area, fn, fsn);
        if (mode) {
            log_crack(m, o, xc, (sx_crack_mode)mode, SX_BOND_SMOOTHJOINT, -1, i, j, fn, fsn, 0, 0);
            *bonds &= ~(unsigned)SX_BOND_SMOOTHJOINT;
            bonded = false;
            before = sx_law_sj_strain(D, L, area, *un, fs);
        }
    }
    if (!bonded) {
        if (track && *un <= 0 && !before) /* opening releases the shear spring */
            chunk_energy(m, o, E_SLIP, sx_law_sj_strain(D, L, area, 0, fs));
        double work[2] = {0, 0};
        fn = sx_law_sj_unbonded(D, L, area, un, fs, fs0, track && !before ? work : NULL);
        if (track) chunk_energy(m, o, E_SLIP, work[0]), chunk_energy(m, o, E_SLIP, work[1]);
        if (track && before)
            chunk_energy(m, o, E_RELEASED, before - sx_law_sj_strain(D, L, area, *un > 0 ? *un : 0, fs));
    }
    for (int k = 0; k < D; k++) F[k] = fn * N[k] + fs[k];
    p->fn[c] = fn;
    if (slot >= 0 && bonded) { /* the bond's resultants, as a parallel bond's */
        m->bonds.fn[slot] = fn;
        for (int k = 0; k < D; k++) m->bonds.fs[slot * D + k] = fs[k];
    }
}

/* A chunk's results start empty; the balls it clears start from their
 * applied loads (or nothing). */
static void chunk_start(sx_model *m, sx_chunk *o)
{
    sx_balls *B = &m->balls;
    const size_t nf = (size_t)((o->clear_hi - o->clear_lo) * D), nt = (size_t)((o->clear_hi - o->clear_lo) * RD);
    if (B->fapp) {
        memcpy(B->f + o->clear_lo * D, B->fapp + o->clear_lo * D, nf * sizeof(double));
        memcpy(B->t + o->clear_lo * RD, B->tapp + o->clear_lo * RD, nt * sizeof(double));
    } else {
        memset(B->f + o->clear_lo * D, 0, nf * sizeof(double));
        memset(B->t + o->clear_lo * RD, 0, nt * sizeof(double));
    }
    o->slip = o->viscous = o->released = 0;
    o->taping = false;
    o->lost_bonds = 0;
    o->ncracks = 0;
    o->st = SX_OK;
    o->err_break = false;
}

/* Ball slots: the balls, then the periodic ghosts past them. */
static inline int64_t ball_slots(const sx_model *m) { return m->cell ? m->cell->base + m->cell->n : m->balls.n; }

/* The inverse masses a contact's dashpot takes its reduced mass from
 * (m->dash_im): a ball whose velocity is fixed on every axis moves as it
 * is told whatever the forces, so its mass is a wall's, infinite, and a
 * free ball striking it rebounds at the restitution asked for (with its
 * own mass in the reduced mass, at 0.616 for 0.5 against a fixed twin; as
 * LAMMPS takes a frozen atom's). B->inv_mass itself while no ball is so
 * fixed (NULL with no ball); false when out of memory. A periodic ghost
 * is as its owner. */
static bool dashpot_inverse_mass(sx_model *m, const double **im)
{
    const sx_balls *B = &m->balls;
    const unsigned all = D == 3 ? SX_FIX_VEL : SX_FIX_VX | SX_FIX_VY;
    uint8_t any = 0; /* (no early exit: the loop vectorizes, a step's cost stays out of sight) */
    const uint8_t vel = (uint8_t)all;
    for (int64_t i = 0; i < B->n; i++) any |= (uint8_t)((B->fix[i] & vel) == vel);
    *im = B->inv_mass;
    if (!any) return true;
    const int64_t slots = ball_slots(m);
    if (slots > m->cap_dash_im) {
        double *q = sx_alloc_resize(&m->alloc, m->dash_im, (size_t)m->cap_dash_im, (size_t)slots, sizeof *q);
        if (!q) return false;
        m->dash_im = q, m->cap_dash_im = slots;
    }
    for (int64_t k = 0; k < slots; k++) {
        const int64_t o = k < B->n ? k : m->cell->owner[k - m->cell->base];
        m->dash_im[k] = o >= 0 && (B->fix[o] & all) == all ? 0 : B->inv_mass[k];
    }
    *im = m->dash_im;
    return true;
}

/* With energy tracking: the step's dashpot forces and moments per ball
 * slot (m->visc_f, m->visc_t), cleared. The contact passes book a
 * dashpot's work at the velocity the force was computed from, half a
 * step old; the law of motion adds the other half, the work at the mean
 * of the old and new velocities (motion.c), which is the kinetic energy's
 * change: at the automatic timestep the old velocity alone booked 17 %
 * of a bounce's energy more than was lost at beta = 0.5, 26 % at 0.7.
 * False: out of memory. */
static bool visc_clear(sx_model *m)
{
    const int64_t slots = ball_slots(m);
    if (slots == 0) return true;
    if (slots > m->cap_visc) {
        double *f = sx_alloc_resize(&m->alloc, m->visc_f, (size_t)(m->cap_visc * D), (size_t)(slots * D), sizeof *f);
        if (f) m->visc_f = f;
        double *t = sx_alloc_resize(&m->alloc, m->visc_t, (size_t)(m->cap_visc * RD), (size_t)(slots * RD), sizeof *t);
        if (t) m->visc_t = t;
        if (!f || !t) { /* the one that grew is freed, the other kept at the old size */
            if (f) m->visc_f = sx_alloc_resize(&m->alloc, f, (size_t)(slots * D), (size_t)(m->cap_visc * D), sizeof *f);
            if (t) m->visc_t = sx_alloc_resize(&m->alloc, t, (size_t)(slots * RD), (size_t)(m->cap_visc * RD), sizeof *t);
            return false;
        }
        m->cap_visc = slots;
    }
    memset(m->visc_f, 0, (size_t)(slots * D) * sizeof(double));
    memset(m->visc_t, 0, (size_t)(slots * RD) * sizeof(double));
    return true;
}

/* Ball-ball contacts of one chunk, every model: 4-1 ... 4-21 with the
 * contact models of 4.3.3 - 4.3.5. The total force F acts on b and -F on
 * a; energies, cracks and errors go to the chunk. */
static void ball_chunk_pass(sx_model *m, sx_chunk *o)
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    const double *restrict x = B->x, *restrict v = B->v, *restrict w = B->w, *restrict rad = B->rad;
    const double *restrict im = m->dash_im_now; /* the dashpots' (dashpot_inverse_mass) */
    const uint16_t *restrict mat = B->mat;
    const int32_t *restrict pa = p->a, *restrict pb = p->b;
    const int32_t *restrict bond = p->bond;
    int32_t *restrict cmodel = p->cmodel; /* the contact-model table's rows (cmodel.c); NULL: none */
    double *restrict fs_all = p->fs, *restrict geo_all = p->geo, *restrict fn_all = p->fn;
    uint8_t *restrict touching = p->touching;
    double *restrict f = B->f, *restrict t = B->t;
    const sx_pair_law *laws = m->law;
    chunk_start(m, o);
    const double dt = motion_dt(m);
    const int nlaw = m->law_n;
    const bool track = m->track_energy;
    for (int64_t c = o->first; c < o->last; c++) {
        const int64_t i = pa[c], j = pb[c];
        const int32_t slot = bond ? bond[c] - 1 : -1;
        if (c == o->tape_at) o->taping = true; /* decomposed: the rank's own pairs of a chunk begun below them */
        double dx[D];
        for (int k = 0; k < D; k++) dx[k] = x[j * D + k] - x[i * D + k];
        const double d2 = dot(dx, dx), ri = rad[i], rj = rad[j], rsum = ri + rj;
        const sx_pair_law *law = &laws[mat[i] * nlaw + mat[j]];
        if (cmodel) { /* a contact takes its row when it is created and keeps it */
            if (!touching[c]) cmodel[c] = sx__cmodel_pick(m, i, j);
            if (cmodel[c]) law = &m->cmodel[cmodel[c] - 1].law;
        }
        double *restrict fs = fs_all + c * D, *restrict rel = geo_all + c * D;
        if (d2 >= rsum * rsum && slot < 0) {
            if (track && touching[c]) { /* the shear spring's energy is released as the contact opens */
                double kn, ks;
                stiffness(law, ri, rj, 2 * ri * rj / rsum, 0, &kn, &ks);
                if (ks > 0) chunk_energy(m, o, E_SLIP, 0.5 * dot(fs, fs) / ks);
                if (law->mu_r > 0)
                    chunk_energy(m, o, E_SLIP, sx_law_rolling_strain(D, p->mr + c * RD, ks, ri * rj / rsum));
                if (p->joint && p->joint[c]) { /* a smooth joint's springs instead */
                    const sx_law_sj *L = &m->joints[p->joint[c] - 1].law;
                    chunk_energy(m, o, E_SLIP,
                                 sx_law_sj_strain(D, L, sx_law_sj_area(D, L, ri, rj), fmax(p->jun[c], 0), fs) -
                                     (ks > 0 ? 0.5 * dot(fs, fs) / ks : 0));
                }
            }
            touching[c] = 0;
            fn_all[c] = 0; /* its last evaluation: no force */
            continue;
        }
        /* 4-1 ... 4-4 */
        const double d = sqrt(d2), inv_d = 1.0 / d;
        double n[D];
        for (int k = 0; k < D; k++) n[k] = dx[k] * inv_d;
        const double un = rsum - d;
        const double rmin = ri < rj ? ri : rj;
        /* a smooth joint's contact may overlap deeply: its balls slide past each other along the plane */
        if (un > rmin && !(p->joint && p->joint[c] && touching[c])) {
            o->st = SX_EUNSTABLE;
            o->err_a = B->id[i], o->err_b = B->id[j], o->err_un = un, o->err_r = rmin;
            return;
        }
        const double la = ri - 0.5 * un, lb = rj - 0.5 * un;
        /* 4-16 with the arms la n from a and -lb n from b: the contact-point
         * velocity of b relative to a is vb - va - (la wa + lb wb) x n */
        const double *wi = w + i * RD, *wj = w + j * RD;
        double ws[RD], wn[D], vc[D];
        for (int k = 0; k < RD; k++) ws[k] = la * wi[k] + lb * wj[k];
        spin_cross(ws, n, wn);
        for (int k = 0; k < D; k++) vc[k] = (v[j * D + k] - v[i * D + k]) - wn[k];
        const double vn = dot(vc, n);
        double vs[D];
        for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k]; /* 4-17 */

        if (p->joint) { /* a smooth joint: a new contact across a joint plane takes it */
            int32_t *jk = p->joint + c;
            double *jn = p->jnormal + c * D;
            if (!touching[c] && (*jk = sx__joint_crossed(m, D, x + i * D, x + j * D, jn))) {
                p->jun[c] = un * fabs(dot(n, jn));
                for (int k = 0; k < D; k++) fs[k] = 0;
                if (p->mr) /* no rolling moment: an old contact's would be released when this one ends */
                    for (int k = 0; k < RD; k++) p->mr[c * RD + k] = 0;
            }
            if (*jk) {
                double xc[D], F[D];
                for (int k = 0; k < D; k++) xc[k] = x[i * D + k] + la * n[k];
                unsigned bonds = slot >= 0 ? m->bonds.kind[slot] : 0;
                smooth_joint(m, o, c, slot, &bonds, vc, xc, i, j, F);
                if (slot >= 0 && !bonds) {
                    m->bonds.kind[slot] = 0;
                    p->bond[c] = 0;
                    o->lost_bonds++;
                }
                for (int k = 0; k < D; k++) rel[k] = dx[k];
                touching[c] = 1;
                const double none[RD] = {0};
                pair_apply(f, t, i, j, n, la, lb, F, NULL, none);
                continue;
            }
        }
        /* the previous normal, from the last evaluation's relative position as n
         * was computed from dx (the same bits); none for a new contact */
        double nold[D];
        if (touching[c]) {
            const double inv_r = 1.0 / sqrt(dot(rel, rel));
            for (int k = 0; k < D; k++) nold[k] = rel[k] * inv_r;
        } else {
            for (int k = 0; k < D; k++) fs[k] = 0, nold[k] = n[k];
        }
        carry rot;
        carry_make(&rot, nold, n, wi, wj, dt);
        unsigned bonds = slot >= 0 ? m->bonds.kind[slot] : 0;
        const unsigned bonds_before = bonds;
        double xc[D]; /* the contact point (4-4), for the crack log */
        if (slot >= 0)
            for (int k = 0; k < D; k++) xc[k] = x[i * D + k] + la * n[k];

        double kn, ks, fn = 0, F[D], mb[RD], mroll[RD] = {0};
        bool bond_moment = false;
        /* a contact bond carries tension; a flat joint replaces the contact law */
        const bool active = !(bonds & SX_BOND_FLATJOINT) && (un > 0 || (bonds & SX_BOND_CONTACT));
        bool slip = false;
        if (active) {
            fn = stiffness(law, ri, rj, 2 * ri * rj / rsum, un, &kn, &ks);
            carry_apply(&rot, fs);
            if (law->unloading && touching[c] && un > 0) { /* laws/mindlin_unloading.h: from the last evaluation's overlap */
                double kn0, ks0;
                stiffness(law, ri, rj, 2 * ri * rj / rsum, rsum - sqrt(dot(rel, rel)), &kn0, &ks0);
                const double e = sx_law_mindlin_unloading_scale(D, fs, ks, ks0);
                if (track) chunk_energy(m, o, E_SLIP, e);
            }
            double f0[D]; /* the shear force before this step's increment, for the slip energy */
            for (int k = 0; k < D; k++) f0[k] = fs[k];
            const double ksdt = ks * dt;
            for (int k = 0; k < D; k++) fs[k] -= ksdt * vs[k]; /* 4-18 ... 4-20 */
            double *us = law->total_shear ? p->us + c * D : NULL; /* Mindlin's total form (laws/total_shear.h) */
            if (us) {
                if (!touching[c])
                    for (int k = 0; k < D; k++) us[k] = 0;
                carry_apply(&rot, us);
                sx_law_total_shear_force(D, us, fs, vs, ks, dt);
            }
            if (bonds & SX_BOND_CONTACT) { /* laws/contact_bond.h */
                const double fsn = sqrt(dot(fs, fs));
                const int mode = sx_bond_contact_test(fn, fsn, m->bonds.cb_n[slot], m->bonds.cb_s[slot]);
                if (mode) {
                    log_crack(m, o, xc, (sx_crack_mode)mode, SX_BOND_CONTACT, -1, i, j, fn, fsn, 0, 0);
                    bonds &= ~(unsigned)SX_BOND_CONTACT;
                }
                if (mode == SX_CRACK_TENSION) { /* both components vanish; in shear, slip takes over */
                    if (track) chunk_energy(m, o, E_RELEASED, sx_bond_contact_released(fn, un, fsn, ks));
                    fn = 0;
                    for (int k = 0; k < D; k++) fs[k] = 0;
                    if (us) sx_law_total_shear_slip(D, us, 0);
                }
            }
            if (!(bonds & SX_BOND_CONTACT)) {
                if (un <= 0) { /* unbonded and open: no contact force */
                    /* a contact bond that failed in shear while in tension releases both springs */
                    if (track)
                        chunk_energy(m, o, E_RELEASED, 0.5 * fn * un + (ks > 0 ? 0.5 * dot(fs, fs) / ks : 0));
                    fn = 0;
                    for (int k = 0; k < D; k++) fs[k] = 0;
                    if (us) sx_law_total_shear_slip(D, us, 0);
                }
                /* 4-30/4-31: Coulomb slip with the smaller friction */
                const double fmax = law->mu * (fn > 0 ? fn : 0);
                double sc, work = 0;
                slip = sx__law_cap(D, fs, f0, dot(fs, fs), fmax, ks, track ? &work : NULL, &sc);
                if (track) chunk_energy(m, o, E_SLIP, work);
                if (slip && us) sx_law_total_shear_slip(D, us, sc);
            }
            if (law->mu_r > 0) { /* rolling resistance (laws/rolling.h) */
                double *mr = p->mr + c * RD, dtheta[RD];
                if (!touching[c])
                    for (int k = 0; k < RD; k++) mr[k] = 0;
#if D == 3
                carry_apply(&rot, mr);
#endif
                for (int k = 0; k < RD; k++) dtheta[k] = (wj[k] - wi[k]) * dt;
                const double e = sx_law_rolling_moment(law, D, mr, dtheta, n, ks, ri * rj / rsum, un > 0 ? fn : 0);
                if (track) chunk_energy(m, o, E_SLIP, e);
                for (int k = 0; k < RD; k++) mroll[k] = mr[k];
            }
            double fd = fn, fdn = 0, dsh[D] = {0}; /* dsh set when shear_dashpot; zeroed for the compiler's flow analysis */
            bool shear_dashpot = false;
            if ((law->beta_n > 0 || law->beta_s > 0) && un > 0) {
                /* viscous dashpots at the critical-damping ratios on the reduced mass
                 * m* = 1 / (1/ma + 1/mb): c = 2 beta sqrt(m* k), a per-law factor when k is */
                const double sum_im = im[i] + im[j]; /* 0: both balls fixed, no dashpot between them */
                const double cn = !(sum_im > 0) ? 0
                                  : !law->plain ? 2 * law->beta_n * sqrt(kn / sum_im)
                                                : sqrt(law->dash_n / sum_im);
                fdn = -cn * vn;
                fd += fdn;
                double work = fdn * vn;
                if (!slip && law->beta_s > 0 && sum_im > 0) {
                    const double cs = 2 * law->beta_s * sqrt(ks / sum_im);
                    for (int k = 0; k < D; k++) dsh[k] = -cs * vs[k];
                    work += dot(dsh, vs);
                    shear_dashpot = true;
                }
                if (track) chunk_energy(m, o, E_VISCOUS, -(work * dt));
            }
            for (int k = 0; k < D; k++) F[k] = fd * n[k] + fs[k]; /* 4-5 */
            if (shear_dashpot)
                for (int k = 0; k < D; k++) F[k] += dsh[k];
            if (track && (fdn != 0 || shear_dashpot)) { /* the dashpots' forces: the law of motion's share of their work */
                double Fd[D];
                const double none[RD] = {0};
                for (int k = 0; k < D; k++) Fd[k] = fdn * n[k] + dsh[k];
                pair_apply(m->visc_f, m->visc_t, i, j, n, la, lb, Fd, NULL, none);
            }
            fn_all[c] = fd;
        } else {
            if (track && touching[c]) { /* a parallel-bonded pair's contact opened: its shear spring is released */
                double kn0, ks0;
                stiffness(law, ri, rj, 2 * ri * rj / rsum, 0, &kn0, &ks0);
                if (ks0 > 0) chunk_energy(m, o, E_SLIP, 0.5 * dot(fs, fs) / ks0);
            }
            for (int k = 0; k < D; k++) F[k] = fs[k] = 0;
            fn_all[c] = 0;
        }
        if (bonds & SX_BOND_PARALLEL) {
            double dtheta[RD];
            for (int k = 0; k < RD; k++) dtheta[k] = (wj[k] - wi[k]) * dt;
            for (int k = 0; k < RD; k++) mb[k] = 0;
            /* the normal stretch at the step's mid normal, from the centres'
             * velocities (laws/parallel_bond.h) */
            double nm[D], vm[D];
            for (int k = 0; k < D; k++) nm[k] = nold[k] + n[k], vm[k] = v[j * D + k] - v[i * D + k];
            const double vn_mid = dot(vm, nm) / sqrt(dot(nm, nm));
            if (parallel_bond(m, o, slot, &rot, n, vn_mid, vs, dtheta, xc, i, j, F, mb)) bond_moment = true;
            else bonds &= ~(unsigned)SX_BOND_PARALLEL;
        }
        if (bonds & SX_BOND_FLATJOINT) {
            double dtheta[RD];
            for (int k = 0; k < RD; k++) dtheta[k] = (wj[k] - wi[k]) * dt, mb[k] = 0;
            bond_moment = true;
            if (!flat_joint(m, o, slot, &rot, n, d, vs, dtheta, xc, i, j, F, mb)) bonds &= ~(unsigned)SX_BOND_FLATJOINT;
        }
        if (bonds != bonds_before) { /* only this pair touches its bond slot */
            m->bonds.kind[slot] = (uint8_t)bonds;
            if (!bonds) {
                p->bond[c] = 0;
                o->lost_bonds++;
            }
        }
        for (int k = 0; k < D; k++) rel[k] = dx[k];
        touching[c] = active || bonds;
        pair_apply(f, t, i, j, n, la, lb, F, bond_moment ? mb : NULL, mroll);
    }
}

#include "lanes.h"

#define LISTED 0
#include "pair_lanes.c"
#undef LISTED
#define LISTED 1
#include "pair_lanes.c"
#undef LISTED

static inline bool chunk_plain(const sx_model *m)
{
    return m->law_plain && !m->bb.bond && !m->bb.cmodel && !m->bb.joint && !m->track_energy;
}

static void ball_chunk(sx_model *m, sx_chunk *o)
{
    if (chunk_plain(m)) ball_chunk_batched(m, o);
    else ball_chunk_pass(m, o);
}

/* Decomposed: chunk o started anew (over its clear range) with the pairs
 * list[e0, e1) (in pair order): the batched pass takes them four at a
 * time, the scalar one in runs of consecutive pairs (each starting o
 * again). Leaves o's pair range changed. */
static void ball_chunk_list(sx_model *m, sx_chunk *o, const int32_t *list, int64_t e0, int64_t e1)
{
    if (chunk_plain(m)) {
        o->first = e0, o->last = e1;
        ball_chunk_listed(m, o, list);
        return;
    }
    for (int64_t e = e0; e < e1 && !o->st;) {
        o->first = list[e];
        while (++e < e1 && list[e] == list[e - 1] + 1) {}
        o->last = list[e - 1] + 1;
        ball_chunk_pass(m, o);
    }
}

/* Decomposed: chunk o, whose first pairs lie below the rank's own (their
 * a is a ghost). Of these it evaluates only those that reach its balls,
 * the list inpair (decompose.c, plan_inpairs): the others add only to
 * ghosts, whose sums are their owners'. Each ball's contributions keep
 * their order, so its sums their bits. The chunk's balls are cleared
 * once, first; the start of its own pairs then resets only what the pairs
 * below leave that is not this rank's (their cracks, bonds lost and energy
 * terms: see plan_inpairs). */
static void ball_chunk_below(sx_model *m, sx_chunk *o)
{
    const sx_dd *d = m->dd;
    const int64_t first = o->first, last = o->last, mine = d->bb_own[d->x.rank].lo, split = last < mine ? last : mine;
    const int64_t clear_hi = o->clear_hi;
    chunk_start(m, o);
    o->clear_hi = o->clear_lo; /* cleared */
    ball_chunk_list(m, o, d->inpair, sx__first_at(d->inpair, d->ninpair, first),
                    sx__first_at(d->inpair, d->ninpair, split));
    o->first = split, o->last = last; /* its own pairs */
    if (!o->st && last > split) ball_chunk(m, o);
    o->first = first, o->clear_hi = clear_hi;
}

/* Chunks of the ball-ball pass and blocks of the per-ball passes, planned
 * after each build (and on a restore) from the stores alone. A power of
 * two of chunks (so that each phase splits evenly over 2, 4, ... threads)
 * of at least CHUNK_PAIRS pairs, at most MAX_CHUNKS; MAX_CHUNKS / 2 bounds
 * the useful thread count of that pass, MOTION_BLOCKS that of the per-ball
 * passes. */
enum { CHUNK_PAIRS = 1024, MAX_CHUNKS = SX_CHUNKS_MAX, MOTION_BLOCKS = SX_MOTION_BLOCKS, MOTION_MIN = 256 };

static bool plan_chunks(sx_model *m)
{
    /* ownership needs the pairs grouped by a: bonded pairs appended by a
     * build, or a store patched by a removal, are put in order (stably, so
     * each ball's contacts keep their order) */
    if (!sx__pairs_sort(m, &m->bb) || !sx__pairs_sort(m, &m->bw)) return false;
    const sx_pairs *p = &m->bb;
    const int64_t n = m->balls.n;
    int64_t k = 1;
    /* periodic space: a ghost may be the b of pairs in any chunk, so the
     * pass is one chunk (ghosts' forces are added to their owners after it) */
    const bool ghosts = m->cell && m->cell->n > 0;
    while (!ghosts && 2 * k <= MAX_CHUNKS && 2 * k * CHUNK_PAIRS <= p->n) k *= 2;
    if (k > m->cap_chunk) {
        sx_chunk *q = sx_alloc_resize(&m->alloc, m->chunks, (size_t)m->cap_chunk, (size_t)k, sizeof *q);
        if (!q) return false;
        m->chunks = q;
        m->cap_chunk = k;
    }
    m->nchunk = k;
    /* chunk c starts at the ball of pair p->n c / k, and at least where the
     * chunk two before it reaches (its largest b), so that a chunk's b's
     * fall in its own range or the next one's */
    int64_t lo[MAX_CHUNKS + 1];
    for (int64_t c = 0; c < k; c++) {
        const int64_t q = p->n * c / k;
        lo[c] = c == 0 ? 0 : q < p->n ? p->a[q] : n;
    }
    lo[k] = n;
    for (int64_t c = 0; c < k; c++) {
        if (c > 0 && lo[c] < lo[c - 1]) lo[c] = lo[c - 1];
        sx_chunk *o = &m->chunks[c];
        o->own_lo = lo[c];
        o->first = sx__first_at(p->a, p->n, lo[c]);
        o->tape_at = -1; /* decomposed: decompose.c plans its energy's part */
        if (c >= 2) { /* chunk c - 2 is complete once chunk c - 1 starts */
            const sx_chunk *e = &m->chunks[c - 2];
            int64_t reach = lo[c - 1];
            for (int64_t q = e->first; q < m->chunks[c - 1].first; q++)
                if (p->b[q] + 1 > reach) reach = p->b[q] + 1;
            if (reach > lo[c]) {
                lo[c] = reach;
                o->own_lo = reach;
                o->first = sx__first_at(p->a, p->n, reach);
            }
        }
    }
    for (int64_t c = 0; c < k; c++) {
        sx_chunk *o = &m->chunks[c];
        o->own_hi = c + 1 < k ? m->chunks[c + 1].own_lo : n;
        o->last = c + 1 < k ? m->chunks[c + 1].first : p->n;
        /* the first phase clears the forces of every ball before either phase adds to them */
        o->clear_lo = c % 2 == 0 ? o->own_lo : 0;
        o->clear_hi = c % 2 == 0 ? (c + 2 < k ? m->chunks[c + 2].own_lo : n) : 0;
        for (int64_t q = o->first; q < o->last; q++) /* what the two phases rely on */
            assert(p->a[q] >= o->own_lo && p->a[q] < o->own_hi && (c + 2 >= k || p->b[q] < m->chunks[c + 2].own_lo));
    }
    /* blocks of at least MOTION_MIN balls, at most MOTION_BLOCKS of them */
    if (!m->blocks) {
        m->blocks = sx_alloc_resize(&m->alloc, NULL, 0, MOTION_BLOCKS, sizeof *m->blocks);
        if (!m->blocks) return false;
    }
    int64_t nb = (n + MOTION_MIN - 1) / MOTION_MIN;
    if (nb > MOTION_BLOCKS) nb = MOTION_BLOCKS;
    const int64_t size = nb ? (n + nb - 1) / nb : 0;
    m->nblock = nb;
    for (int64_t b = 0; b < nb; b++) {
        sx_block *o = &m->blocks[b];
        o->b0 = b * size;
        o->b1 = (b + 1) * size < n ? (b + 1) * size : n;
        o->w0 = sx__first_at(m->bw.a, m->bw.n, o->b0);
        o->w1 = sx__first_at(m->bw.a, m->bw.n, o->b1);
        o->tape_k = -1;
    }
    return true;
}

/* Decomposed in periodic space: the pairs xpair[e0, e1) (decompose.c,
 * plan_far), for their ghosts' forces (the forces on their first balls,
 * another rank's, and their cracks are that rank's to keep). Their errors
 * are that rank's too, which runs them in its chunks: reported here, one
 * would come before this rank's own pairs', against the serial order in
 * which the ranks agree on an error (dd_agree.c). */
static void far_pairs(sx_model *m, int64_t e0, int64_t e1)
{
    sx_dd *d = m->dd;
    sx_chunk *o = &d->xchunk;
    o->clear_lo = o->clear_hi = 0;
    ball_chunk_list(m, o, d->xpair, e0, e1);
}

/* Runs the even chunks, then the odd ones (each phase in parallel), then
 * merges energies, cracks and errors in chunk order. */
static void KERNEL(ghosts_refresh)(sx_model *m, bool all);
static bool fold_ghosts(sx_model *m);

static sx_status KERNEL(contacts)(sx_model *m)
{
    const int64_t nchunk = m->nchunk;
    /* decomposed in periodic space: the ghosts' pairs outside this rank's
     * chunk, before and after it, so that each ghost's force adds up in
     * pair order (a ghost is only ever a pair's b; one chunk) */
    sx_dd *dd = m->dd && m->dd->active && m->dd->nxpair ? m->dd : NULL;
    if (m->cell) KERNEL(ghosts_refresh)(m, false); /* the ghosts where their owners are now */
    if (!dashpot_inverse_mass(m, &m->dash_im_now) || (m->track_energy && !visc_clear(m)))
        return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    if (dd) far_pairs(m, 0, dd->nxlow);
#pragma omp parallel num_threads(m->threads) if (nchunk > 2)
    for (int64_t phase = 0; phase < 2; phase++) {
#pragma omp for schedule(static)
        for (int64_t c = phase; c < nchunk; c += 2) {
            sx_chunk *o = &m->chunks[c];
            if (m->dd && m->dd->active && o->first < m->dd->bb_own[m->dd->x.rank].lo) ball_chunk_below(m, o);
            else ball_chunk(m, o);
        }
    }
    if (dd) far_pairs(m, dd->nxlow, dd->nxpair);
    if (m->cell && !fold_ghosts(m)) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    /* decomposed: the energy sums are the ranks' to chain (dd_energy.c, sx__dd_energy) */
    const bool sums = !m->dd || !m->dd->active;
    for (int64_t c = 0; c < nchunk; c++) {
        sx_chunk *o = &m->chunks[c];
        if (o->st) return chunk_error(m, o);
        if (sums) {
            m->acc.slip += o->slip;
            m->acc.viscous += o->viscous;
            m->acc.bond_released += o->released;
        }
        m->bonds.intact -= o->lost_bonds;
        for (int64_t e = 0; e < o->ncracks; e++) sx__crack_log(m, &o->cracks[e]);
    }
    return SX_OK;
}
