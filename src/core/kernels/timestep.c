/* Stage: the critical timestep (entry point KERNEL(critical_dt)). Part of
 * the per-dimension unit kernels.c, which includes it; not compiled alone. */

/* -------------------------------------------------------------- timestep */

/* Hertz has no stiffness at zero overlap: a free Hertz ball is rated at the
 * tangent stiffness of this overlap, a fraction of its radius. */
#define HERTZ_REFERENCE_OVERLAP 0.01

/* PFC-style estimate: for each ball sqrt(m / k_tran) with k_tran the sum of
 * its contacts' (tangent) normal and shear stiffnesses, bonds included, and
 * sqrt(I / k_rot) with k_rot = sum ks l^2 plus the bonds' rotational
 * stiffness. A ball is never rated below its own stiffness (as if touching
 * one entity like itself), so the first impact is already resolved and the
 * timestep does not jump as contacts form. */
/* The overlap a ball of radius r, mass and speed is rated at under pair
 * law l: HERTZ_REFERENCE_OVERLAP of its radius or, if larger, the deepest
 * overlap of a head-on impact with its twin (reduced mass m/2, closing
 * speed 2v: m v^2 = the law's strain energy, strain x Fn(u) u). A law
 * whose stiffness grows with the overlap (Hertz) would otherwise rate a
 * fast ball as if it touched lightly: the timestep is rated again only
 * every few steps, and an impact lasting 4 of them went wrong (a Hertz
 * ball hitting a plane at 10 m/s came back at 11.55). For a law of constant
 * stiffness the overlap changes nothing. */
static double rating_overlap(const sx_pair_law *l, double r, double mass, double speed)
{
    const double u0 = HERTZ_REFERENCE_OVERLAP * r, energy = mass * speed * speed;
    if (!(energy > 0) || !isfinite(energy)) return u0; /* at rest, or fixed (no mass to stop) */
    if (!sx__law_stiffens(l->law)) return u0; /* a constant stiffness: the overlap changes nothing */
    const double strain = sx__law(l->law)->strain;
    double kn, ks;
    /* u = sqrt(energy / (strain kn(u))) with kn(u) = Fn(u) / u, by fixed
     * points: for Hertz they close in from both sides, a quarter of the gap
     * a step; the larger of the last two is the safe side */
    double u = u0, last = u0;
    for (int k = 0; k < 8; k++) {
        last = u;
        u = sqrt(energy / (strain * stiffness(l, r, r, r, u, &kn, &ks) / u));
    }
    return fmax(u0, fmax(u, last));
}

/* A ball's own rating under pair law l: its stiffnesses against an entity
 * of its own, at the overlap of rating_overlap. */
static void self_rating(const sx_pair_law *l, double r, double mass, double speed, double *kn, double *ks)
{
    stiffness(l, r, r, r, rating_overlap(l, r, mass, speed), kn, ks);
    const sx_law *own = sx__law(l->law);
    *kn *= own->tangent;
    if (own->series) *kn *= 2, *ks *= 2; /* undo the series combination with itself */
}

/* A law whose stiffness grows with the overlap (Hertz) rates a ball by the
 * impact it may meet: a candidate pair's part in its balls' own ratings.
 * Each may be struck by the other at their closing speed (struck: the
 * fastest partner; a resting ball hit by one at 50 m/s was rated at rest
 * and left 16 % fast), and is rated under the pair's law where that is not
 * its material's own (a soft ball against a stiff one: their Hertz law,
 * of the mean shear modulus, was 40 times the soft ball's, and a drop
 * onto a steel plane bounced 5 times as high; both a verification study's
 * findings). kself holds each ball's stiffest such rating, kn then ks. A
 * ghost's part goes to its owner. */
static void rate_against(const sx_model *m, const sx_pair_law *law, int64_t i, double partner_speed, double *struck,
                         double *kself)
{
    const sx_balls *B = &m->balls;
    struck[i] = fmax(struck[i], partner_speed);
    if (law == &m->law[B->mat[i] * m->law_n + B->mat[i]]) return; /* its own: the ball's rating takes it */
    const double speed = sqrt(dot(B->v + i * D, B->v + i * D)) + partner_speed;
    double kn, ks;
    self_rating(law, B->rad[i], 1.0 / B->inv_mass[i], speed, &kn, &ks);
    if (kn + ks > kself[i] + kself[B->n + i]) kself[i] = kn, kself[B->n + i] = ks;
}

static void rate_candidate(const sx_model *m, int64_t c, double *struck, double *kself)
{
    const sx_balls *B = &m->balls;
    const sx_pairs *p = &m->bb;
    const int64_t n = B->n, i = p->a[c], j = p->b[c];
    const int64_t jo = j < n ? j : m->cell->owner[j - m->cell->base];
    const sx_pair_law *law = sx__bb_step_law(m, c, i, jo);
    if (!sx__law_stiffens(law->law)) return; /* a constant stiffness: counted once the pair touches */
    const double vi = sqrt(dot(B->v + i * D, B->v + i * D)), vj = sqrt(dot(B->v + jo * D, B->v + jo * D));
    rate_against(m, law, i, vj, struck, kself);
    rate_against(m, law, jo, vi, struck, kself);
}

/* Adds ball-ball pair c's stiffness and dashpot to its balls' sums kt,
 * kr, ct, cr (n each, from kt); a ghost's go to its owner. im: the
 * dashpots' inverse masses (dashpot_inverse_mass). */
static inline void rate_pair(const sx_model *m, int64_t c, const double *im, double *kt)
{
    const sx_balls *B = &m->balls;
    const sx_pairs *p = &m->bb;
    const int64_t n = B->n;
    double *kr = kt + n, *ct = kt + 2 * n, *cr = kt + 3 * n;
    const int64_t i = p->a[c], j = p->b[c];
    const int64_t jo = j < n ? j : m->cell->owner[j - m->cell->base]; /* a ghost's sums are its owner's */
    const int32_t slot = p->bond ? p->bond[c] - 1 : -1;
    double dx[D];
    for (int k = 0; k < D; k++) dx[k] = B->x[j * D + k] - B->x[i * D + k];
    const double rsum = B->rad[i] + B->rad[j], d = sqrt(dot(dx, dx)), un = rsum - d;
    const sx_pair_law *law = sx__bb_step_law(m, c, i, j);
    double ktr = 0, krot_i = 0, krot_j = 0;
    const unsigned bonds = slot >= 0 ? m->bonds.kind[slot] : 0;
    if (p->joint && p->joint[c] && p->touching[c]) { /* a smooth joint's springs (laws/smoothjoint.h) */
        const sx_law_sj *L = &m->joints[p->joint[c] - 1].law;
        const double area = sx_law_sj_area(D, L, B->rad[i], B->rad[j]);
        ktr = (L->kn + L->ks) * area;
        krot_i = L->ks * area * B->rad[i] * B->rad[i];
        krot_j = L->ks * area * B->rad[j] * B->rad[j];
    } else if (!(bonds & SX_BOND_FLATJOINT) && (un > 0 || (bonds & SX_BOND_CONTACT))) {
        double kn, ks;
        stiffness(law, B->rad[i], B->rad[j], 2 * B->rad[i] * B->rad[j] / rsum, un, &kn, &ks);
        if (un > 0 && (law->beta_n > 0 || law->beta_s > 0)) { /* the dashpots of ball_contacts */
            const double sum_im = im[i] + im[j], mstar = sum_im > 0 ? 1.0 / sum_im : 0; /* 0: both fixed */
            const double cn = 2 * law->beta_n * sqrt(mstar * kn), cs = 2 * law->beta_s * sqrt(mstar * ks);
            ct[i] += cn + cs, ct[jo] += cn + cs;
            cr[i] += cs * B->rad[i] * B->rad[i], cr[jo] += cs * B->rad[j] * B->rad[j];
        }
        kn *= sx__law(law->law)->tangent; /* 4-29 */
        ktr = kn + ks;
        krot_i = ks * B->rad[i] * B->rad[i];
        krot_j = ks * B->rad[j] * B->rad[j];
        if (law->mu_r > 0) { /* the rolling spring kr = ks R-bar^2 (laws/rolling.h) */
            const double rbar = B->rad[i] * B->rad[j] / rsum;
            krot_i += ks * rbar * rbar, krot_j += ks * rbar * rbar;
        }
    }
    if (bonds & (SX_BOND_PARALLEL | SX_BOND_FLATJOINT)) /* a flat joint's face: the section of 4-35 */
        sx_bond_parallel_stiffness(D, &m->bonds, slot, B->rad[i], B->rad[j], &ktr, &krot_i, &krot_j);
    kt[i] += ktr;
    kt[jo] += ktr;
    kr[i] += krot_i;
    kr[jo] += krot_j;
}

/* ranks: whether a decomposed rank may exchange with the others (the
 * clumps' pebble sums go to their owners); not from an error found on one
 * rank, whose partners are elsewhere in the step. */
static double KERNEL(rate_dt)(sx_model *m, bool ranks)
{
    sx_balls *B = &m->balls;
    const int64_t n = B->n;
    if (n == 0) return INFINITY;
    double *kt = sx__scratch(m, 7 * n + m->nwall);
    if (!kt) return INFINITY;
    double *kr = kt + n, *ct = kt + 2 * n, *cr = kt + 3 * n; /* stiffness and dashpot sums */
    /* the fastest wall or ball each ball has a candidate pair with, its
     * stiffest rating under a candidate's law (rate_candidate: kn, then ks,
     * n each), and each wall's speed (sx__wall_speed: how fast its surface
     * may close on a ball) */
    double *struck = kt + 4 * n, *kself = kt + 5 * n, *wall_speed = kt + 7 * n;
    memset(kt, 0, (size_t)(7 * n) * sizeof(double));
    double vwall = 0;
    for (int64_t w = 0; w < m->nwall; w++) vwall = fmax(vwall, wall_speed[w] = sx__wall_speed(m, &m->walls[w]));
    m->dt_wall_speed = vwall; /* a wall set faster than a quarter more rates it again (walls.c) */
    /* decomposed: this rank's balls, summed over their pairs in the serial
     * order (decompose.c): those of pairs[rank] that reach them (inpair,
     * then its own), and in periodic space the pairs through the boundary
     * that reach them from elsewhere (xpair: the first nxlow before
     * pairs[rank], the rest after it); a ghost's sums are its owner's */
    const sx_dd *dd = m->dd && m->dd->active ? m->dd : NULL;
    const sx_pairs *p = &m->bb;
    const double *im;
    if (!dashpot_inverse_mass(m, &im)) return INFINITY; /* out of memory, as the scratch's above */
    if (!dd) {
        for (int64_t c = 0; c < p->n; c++) rate_pair(m, c, im, kt), rate_candidate(m, c, struck, kself);
    } else {
        const sx_span mine = dd->bb_own[dd->x.rank];
        for (int64_t e = 0; e < dd->nxlow; e++) rate_pair(m, dd->xpair[e], im, kt);
        for (int64_t e = 0; e < dd->ninpair; e++) rate_pair(m, dd->inpair[e], im, kt);
        for (int64_t c = mine.lo; c < mine.hi; c++) rate_pair(m, c, im, kt);
        for (int64_t e = dd->nxlow; e < dd->nxpair; e++) rate_pair(m, dd->xpair[e], im, kt);
        /* maxima: in any order (every candidate pair of an own ball is among these) */
        for (int64_t e = 0; e < dd->nxpair; e++) rate_candidate(m, dd->xpair[e], struck, kself);
        for (int64_t e = 0; e < dd->ninpair; e++) rate_candidate(m, dd->inpair[e], struck, kself);
        for (int64_t c = mine.lo; c < mine.hi; c++) rate_candidate(m, c, struck, kself);
    }
    p = &m->bw;
    const int64_t w0 = dd ? dd->bw_own[dd->x.rank].lo : 0, w1 = dd ? dd->bw_own[dd->x.rank].hi : p->n;
    for (int64_t c = w0; c < w1; c++) {
        const int64_t i = p->a[c];
        struck[i] = fmax(struck[i], wall_speed[p->b[c]]);
        double nrm[D];
        /* a mesh's contacts as the last step kept them (a shadowed facet adds no stiffness) */
        const bool mesh = m->walls[p->b[c]].mesh != NULL;
        const double un = mesh ? (p->touching[c] ? p->un[c] : 0)
                               : B->rad[i] - wall_distance(&m->walls[p->b[c]], B->x + i * D, nrm);
        const sx_pair_law law = sx__bw_law(m, c); /* its contact-model row's, or its ball's and wall's */
        if (sx__law_stiffens(law.law)) rate_against(m, &law, i, wall_speed[p->b[c]], struck, kself);
        if (un <= 0) continue;
        double kn, ks;
        stiffness(&law, B->rad[i], 0, B->rad[i], un, &kn, &ks);
        if (law.beta_n > 0 || law.beta_s > 0) {
            const double mass = 1.0 / B->inv_mass[i];
            const double cs = 2 * law.beta_s * sqrt(mass * ks);
            ct[i] += 2 * law.beta_n * sqrt(mass * kn) + cs;
            cr[i] += cs * B->rad[i] * B->rad[i];
        }
        kn *= sx__law(law.law)->tangent;
        kt[i] += kn + ks;
        kr[i] += ks * B->rad[i] * B->rad[i] * (law.mu_r > 0 ? 2 : 1); /* with the rolling spring ks R^2 */
    }
    double best = INFINITY;
    const int64_t i0 = dd ? dd->own[dd->x.rank].lo : 0, i1 = dd ? dd->own[dd->x.rank].hi : n;
    for (int64_t i = i0; i < i1; i++) {
        /* the ball's own rating: a contact with an entity of its own stiffness */
        const double r = B->rad[i], mass = 1.0 / B->inv_mass[i], own = sqrt(dot(B->v + i * D, B->v + i * D));
        /* a ball may be struck by a wall or a ball it has a candidate pair
         * with at its own speed plus theirs, and is rated as if it moved at
         * that closing speed (as a ball flying at a resting plane is); a
         * resting Hertz ball hit by a plane at 5 m/s was rated at rest and
         * left at 0.955 of 10 m/s. A wall or a ball coming from farther is
         * listed at a build, which rates the timestep again. */
        const double speed = own + struck[i];
        double kn, ks;
        self_rating(&m->law[B->mat[i] * m->law_n + B->mat[i]], r, mass, speed, &kn, &ks);
        for (int row = 0; row < m->ncmodel; row++) { /* and not below a contact-model row's (cmodel.c) */
            double knr, ksr;
            self_rating(&m->cmodel[row].law, r, mass, speed, &knr, &ksr);
            if (knr + ksr > kn + ks) kn = knr, ks = ksr;
        }
        if (kself[i] + kself[n + i] > kn + ks) kn = kself[i], ks = kself[n + i]; /* a candidate's law */
        for (int64_t q = 0; q < m->njoint; q++) { /* a smooth joint's contact may form at any step */
            const sx_law_sj *L = &m->joints[q].law;
            const double area = sx_law_sj_area(D, L, r, r);
            if ((L->kn + L->ks) * area > kn + ks) kn = L->kn * area, ks = L->ks * area;
        }
        const double ktr = kt[i] > kn + ks ? kt[i] : kn + ks;
        const double krot = kr[i] > ks * r * r ? kr[i] : ks * r * r;
        if (B->clump && B->clump[i]) { /* clumps: the body is rated from its pebbles' sums (clump_queries.c) */
            kt[i] = ktr, kr[i] = krot;
            continue;
        }
        /* Contact dashpots lower the stable timestep of the central differences: for
         * m x'' + c x' + k x = 0 with x' taken at the half step, stability needs
         * (w dt)^2 + 4 z (w dt) < 4, i.e. dt < (2/w)(sqrt(1 + z^2) - z), z = c / (2 sqrt(k m));
         * local damping scales a decelerating force by up to (1 + alpha), so z is scaled too. */
        const double amp = 1 + sx__ball_damping(m, i);
        const double zt = amp * ct[i] / (2 * sqrt(ktr / B->inv_mass[i]));
        const double dtt = sqrt(1.0 / (B->inv_mass[i] * ktr)) * (sqrt(1 + zt * zt) - zt);
        if (dtt < best) best = dtt;
        if (krot > 0) {
            const double zr = amp * cr[i] / (2 * sqrt(krot / B->inv_inertia[i]));
            const double dtr = sqrt(1.0 / (B->inv_inertia[i] * krot)) * (sqrt(1 + zr * zr) - zr);
            if (dtr < best) best = dtr;
        }
    }
    /* decomposed: a clump's owner rates it, from its pebbles' sums made by their owners */
    if (m->clumps && dd && ranks && !sx__dd_pebbles(m, kt, n)) best = NAN;
    else if (m->clumps) best = fmin(best, sx__clumps_critical_dt(m, kt, kr, ct, cr)); /* reads the sums above */
    sx__scratch_release(m);
    return best;
}

static double KERNEL(critical_dt)(sx_model *m) { return KERNEL(rate_dt)(m, true); }

/* An upper bound of critical_dt from each ball's own rating alone (a
 * contact with a ball like itself, at rest): no contact sums, so no
 * memory, and only what every rank holds alike (radii, masses, materials).
 * critical_dt takes at least that stiffness (more with its contacts, its
 * speed and a wall's, a contact-model row, a joint; a dashpot lowers it
 * further), and its rotation's rating is the lower. */
static double KERNEL(own_dt)(const sx_model *m)
{
    const sx_balls *B = &m->balls;
    double best = INFINITY;
    for (int64_t i = 0; i < B->n; i++) {
        const double mass = 1.0 / B->inv_mass[i];
        double kn, ks;
        self_rating(&m->law[B->mat[i] * m->law_n + B->mat[i]], B->rad[i], mass, 0, &kn, &ks);
        if (kn + ks > 0) best = fmin(best, sqrt(mass / (kn + ks)));
    }
    return best;
}

/* The critical estimate an instability message gives where it is met.
 * Decomposed, it is the failing rank's own (its balls, and its clumps from
 * the pebble sums it holds), at least the serial one: the rank rates it
 * where it fails, with no exchange the others would have to meet; where
 * the ranks agree on the error at the step's end, the message is made
 * again at the ranks' least (dd_agree.c). */
static double KERNEL(estimate_dt)(sx_model *m) { return KERNEL(rate_dt)(m, false); }
