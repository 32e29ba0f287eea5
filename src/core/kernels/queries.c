/* Queries: energies and the contact list (entry points KERNEL(energy),
 * KERNEL(each_contact), KERNEL(count_contacts)); they read the model and
 * change nothing: a pair's law is mixed from the materials as they are
 * (sx__pair_law), not read from the step's table, which may be stale. Part of the per-dimension unit kernels.c, which includes
 * it; not compiled alone. */

/* Geometry of a stored ball-ball pair: overlap and unit normal. */
static double pair_geometry(const sx_model *m, int64_t i, int64_t j, double *n)
{
    const sx_balls *B = &m->balls;
    /* a periodic ghost where its ball is now: its slot is as the last
     * contact pass copied it, a step behind (ghost_copy's sum) */
    double shift[D];
    int64_t o = sx__cell_owner(m, j, shift);
    if (o < 0) o = j; /* its ball was removed (no pair is left to it) */
    for (int k = 0; k < D; k++) n[k] = (B->x[o * D + k] + shift[k]) - B->x[i * D + k];
    const double d = sqrt(dot(n, n));
    for (int k = 0; k < D; k++) n[k] = d > 0 ? n[k] / d : 0;
    return B->rad[i] + B->rad[j] - d;
}

/* Normal force and stiffnesses of a stored ball-ball pair from its geometry. */
static double pair_force(const sx_model *m, int64_t c, double un, double *kn, double *ks)
{
    const sx_balls *B = &m->balls;
    const int64_t i = m->bb.a[c], j = m->bb.b[c];
    sx_pair_law buf;
    const sx_pair_law *law = sx__bb_law(m, c, i, j, &buf);
    const int32_t slot = m->bb.bond ? m->bb.bond[c] - 1 : -1;
    const unsigned bonds = slot >= 0 ? m->bonds.kind[slot] : 0;
    const bool active = !(bonds & SX_BOND_FLATJOINT) && (un > 0 || (bonds & SX_BOND_CONTACT));
    const double rsum = B->rad[i] + B->rad[j];
    const double fn = stiffness(law, B->rad[i], B->rad[j], 2 * B->rad[i] * B->rad[j] / rsum, un, kn, ks);
    return active ? fn : 0;
}

/* The shear stiffness of a touching ball-ball pair at the overlap its last
 * force pass saw (rel: the relative position the pass kept), where its
 * shear force was made; a linear law's, which does not depend on it, is ks. */
static double pass_ks(const sx_model *m, const sx_pair_law *law, int64_t i, int64_t j, const double *rel, double ks)
{
    if (!sx__law_stiffens(law->law)) return ks;
    const sx_balls *B = &m->balls;
    const double rsum = B->rad[i] + B->rad[j], un = rsum - sqrt(dot(rel, rel));
    double kn, ks_pass;
    stiffness(law, B->rad[i], B->rad[j], 2 * B->rad[i] * B->rad[j] / rsum, un, &kn, &ks_pass);
    return ks_pass;
}

/* The rolling spring's energy of a touching pair whose law rolls. */
static double rolling_strain(const sx_pair_law *l, const sx_pairs *p, int64_t c, double ks, double rbar)
{
    return l->mu_r > 0 && p->touching[c] ? sx_law_rolling_strain(D, p->mr + c * RD, ks, rbar) : 0;
}

/* The kinetic and gravitational energy of balls [i0, i1) added to e[0], e[1]. */
static void energy_balls(const sx_model *m, int64_t i0, int64_t i1, double *e)
{
    const sx_balls *B = &m->balls;
    const double half = sx__half_step(m);
    for (int64_t i = i0; i < i1; i++) {
        if (B->clump && B->clump[i]) continue; /* clumps: a body's energy is counted once (clump_queries.c) */
        const double *v = B->v + i * D, *w = B->w + i * RD;
        double ww = 0;
        for (int k = 0; k < RD; k++) ww += w[k] * w[k];
        e[0] += 0.5 * dot(v, v) / B->inv_mass[i] + 0.5 * ww / B->inv_inertia[i];
        /* unwrapped (a crossing of a periodic face along gravity is no
         * jump), at the time of the velocities, half a step before the
         * positions: -m g.(x - v dt/2), whose change a step's kick matches
         * exactly (at x, a fall gained g^2 dt^2 / 2 a step: first order) */
        double x[D];
        sx__ball_unwrapped(m, i, x);
        for (int k = 0; k < D; k++) x[k] -= half * v[k];
        e[1] -= dot(m->gravity, x) / B->inv_mass[i];
    }
}

/* The strain of ball-ball pairs [c0, c1) added to e[0], their bonds' to e[1]. */
static void energy_pairs(const sx_model *m, int64_t c0, int64_t c1, double *e)
{
    const sx_balls *B = &m->balls;
    /* every overlap stores normal strain, even one no step has seen yet;
     * the shear spring only once the contact has history */
    const double zero[D] = {0};
    for (int64_t c = c0; c < c1; c++) {
        double n[D], kn, ks;
        const int64_t i = m->bb.a[c], j = m->bb.b[c];
        const double un = pair_geometry(m, i, j, n);
        const double fn = pair_force(m, c, un, &kn, &ks);
        sx_pair_law buf;
        const sx_pair_law *law = sx__bb_law(m, c, i, j, &buf);
        if (m->bb.joint && m->bb.joint[c] && m->bb.touching[c]) { /* a smooth joint (laws/smoothjoint.h) */
            const sx_law_sj *L = &m->joints[m->bb.joint[c] - 1].law;
            const int32_t slot = m->bb.bond ? m->bb.bond[c] - 1 : -1;
            const bool bonded = slot >= 0 && (m->bonds.kind[slot] & SX_BOND_SMOOTHJOINT);
            const double ju = bonded || m->bb.jun[c] > 0 ? m->bb.jun[c] : 0;
            const double s = sx_law_sj_strain(D, L, sx_law_sj_area(D, L, B->rad[i], B->rad[j]), ju, m->bb.fs + c * D);
            if (bonded) e[1] += s;
            else e[0] += s;
            continue;
        }
        /* the shear and rolling springs' energy at the stiffness of the pass
         * that made their forces (a Hertz ks from the overlap now: near
         * separation it goes to 0 and 1/2 |Fs|^2 / ks without bound) */
        const double ks_pass = m->bb.touching[c] ? pass_ks(m, law, i, j, m->bb.geo + c * D, ks) : ks;
        e[0] += contact_strain(law, fn, un, m->bb.touching[c] ? m->bb.fs + c * D : zero, ks_pass);
        e[0] += rolling_strain(law, &m->bb, c, ks_pass, B->rad[i] * B->rad[j] / (B->rad[i] + B->rad[j]));
        const int32_t slot = m->bb.bond ? m->bb.bond[c] - 1 : -1;
        if (slot >= 0 && (m->bonds.kind[slot] & SX_BOND_PARALLEL)) e[1] += sx_bond_parallel_strain(D, &m->bonds, slot);
        if (slot >= 0 && (m->bonds.kind[slot] & SX_BOND_FLATJOINT)) /* at its last evaluation's distance */
            e[1] += fj_strain(m, slot, sqrt(dot(m->bb.geo + c * D, m->bb.geo + c * D)));
    }
}

/* The strain of ball-wall pairs [c0, c1) added to *e. */
static void energy_walls(const sx_model *m, int64_t c0, int64_t c1, double *e)
{
    const sx_balls *B = &m->balls;
    const double zero[D] = {0};
    /* the law of each material against each wall, mixed once here rather
     * than for every contact (the energy guard runs this every 64 steps);
     * a model with contact-model rows for walls asks each contact its row */
    const int64_t nw = m->nwall, nlaw = m->bw.cmodel || c1 <= c0 ? 0 : m->nmat * nw;
    sx_pair_law *wall_laws = nlaw > 0 && nlaw <= 4096 ? malloc((size_t)nlaw * sizeof *wall_laws) : NULL;
    for (int64_t k = 0; wall_laws && k < nlaw; k++) wall_laws[k] = sx__wall_law(m, (int)(k / nw), &m->walls[k % nw]);
    for (int64_t c = c0; c < c1; c++) {
        double n[D], kn, ks;
        const int64_t i = m->bw.a[c];
        const sx_wall *wl = &m->walls[m->bw.b[c]];
        /* a mesh's contacts as the last step kept them (a shadowed facet stores nothing) */
        const double un = wl->mesh ? (m->bw.touching[c] ? m->bw.un[c] : 0) : B->rad[i] - wall_distance(wl, B->x + i * D, n);
        if (un <= 0) continue;
        const sx_pair_law law = wall_laws ? wall_laws[B->mat[i] * nw + m->bw.b[c]] : sx__bw_law(m, c);
        const double fn = stiffness(&law, B->rad[i], 0, B->rad[i], un, &kn, &ks);
        double kn_pass, ks_pass = ks; /* the shear spring's at its pass's overlap, as for a ball pair */
        if (m->bw.touching[c] && sx__law_stiffens(law.law)) stiffness(&law, B->rad[i], 0, B->rad[i], m->bw.un[c], &kn_pass, &ks_pass);
        *e += contact_strain(&law, fn, un, m->bw.touching[c] ? m->bw.fs + c * D : zero, ks_pass);
        *e += rolling_strain(&law, &m->bw, c, ks_pass, B->rad[i]);
    }
    free(wall_laws);
}

/* Rank r's terms of the energy's chained sums (dd_energy.c, sx__dd_chain):
 * its own balls' kinetic and gravitational energy and its own pairs'
 * strains (acc: kinetic, gravitational, strain, bond strain); then, the
 * pairs' strain summed, its own ball-wall pairs' (acc: strain). */
static void energy_own(const sx_model *m, int r, double *acc)
{
    energy_balls(m, m->dd->own[r].lo, m->dd->own[r].hi, acc);
    energy_pairs(m, m->dd->bb_own[r].lo, m->dd->bb_own[r].hi, acc + 2);
}

static void energy_own_walls(const sx_model *m, int r, double *acc)
{
    energy_walls(m, m->dd->bw_own[r].lo, m->dd->bw_own[r].hi, acc);
}

/* The serial sums: balls in dense order (then the clumps), pairs in pair
 * order, then ball-wall pairs in order. Decomposed inside a cycle (the
 * energy guard), the same sums run as chains over the ranks' own balls and
 * pairs (the ghosts current: guard.c refreshes them), every rank adding
 * the clumps alike (guard.c first takes their state from their owners). */
static bool KERNEL(energy)(const sx_model *m, sx_energy *e)
{
    *e = m->acc;
    double s[4] = {0, 0, 0, 0}; /* kinetic, gravitational, strain, bond strain */
    const bool dd = m->dd && m->dd->active;
    if (dd && !sx__dd_chain(m, s, 4, energy_own)) return false;
    if (!dd) {
        energy_balls(m, 0, m->balls.n, s);
        energy_pairs(m, 0, m->bb.n, s + 2);
    }
    e->kinetic = s[0], e->gravitational = s[1], e->strain = s[2], e->bond_strain = s[3];
    if (m->clumps) sx__clumps_energy(m, e);
    if (dd) return sx__dd_chain(m, &e->strain, 1, energy_own_walls);
    energy_walls(m, 0, m->bw.n, &e->strain);
    return true;
}

/* Contacts are reported as the last force evaluation left them (the forces
 * the balls felt): normal, overlap (a ball-ball one from the evaluation's
 * centre distance and the current radii), normal force (with its dashpot),
 * the elastic shear force and the bonds; the point is placed from ball a's
 * current centre. */
static bool report(const sx_model *m, const sx_pairs *p, int64_t c, bool is_wall,
                   bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    const sx_balls *B = &m->balls;
    const int64_t i = p->a[c];
    double n[D], un;
    if (is_wall) {
        for (int k = 0; k < D; k++) n[k] = p->geo[c * D + k];
        un = p->un[c];
    } else { /* the normal and overlap of the relative position, as the step computed them */
        /* coincident centres (only a damaged file's) have no normal, as in pair_geometry */
        const double *rel = p->geo + c * D, d = sqrt(dot(rel, rel)), inv_d = d > 0 ? 1.0 / d : 0;
        for (int k = 0; k < D; k++) n[k] = rel[k] * inv_d;
        un = B->rad[i] + B->rad[p->b[c]] - d;
    }
    sx_contact_info ci;
    memset(&ci, 0, sizeof ci);
    sx_pair_law buf;
    const sx_pair_law *law = is_wall ? (buf = sx__bw_law(m, c), &buf) : sx__bb_law(m, c, i, p->b[c], &buf);
    const double rj = is_wall ? B->rad[i] : B->rad[p->b[c]];
    stiffness(law, B->rad[i], rj, is_wall ? B->rad[i] : 2 * B->rad[i] * rj / (B->rad[i] + rj), un, &ci.kn, &ci.ks);
    /* ball-wall normals point from the wall to the ball, so the point lies behind the centre */
    const double arm = is_wall ? -(B->rad[i] - 0.5 * un) : B->rad[i] - 0.5 * un;
    for (int k = 0; k < D; k++) {
        ci.normal[k] = n[k];
        ci.point[k] = B->x[i * D + k] + arm * n[k];
        ci.shear[k] = p->fs[c * D + k];
    }
    ci.overlap = un;
    ci.fn = p->fn[c];
    ci.a = B->id[i];
    ci.b = is_wall ? m->walls[p->b[c]].id : B->id[p->b[c]];
    ci.is_wall = is_wall;
    ci.cmodel = p->cmodel && p->touching[c] ? p->cmodel[c] : 0;
    if (!is_wall && m->cell) sx__cell_owner(m, p->b[c], ci.shift); /* through the boundary */
    if (!is_wall && p->joint && p->joint[c]) { /* a smooth joint: its normal and stiffnesses */
        const sx_law_sj *L = &m->joints[p->joint[c] - 1].law;
        const double area = sx_law_sj_area(D, L, B->rad[i], B->rad[p->b[c]]);
        for (int k = 0; k < D; k++) ci.normal[k] = p->jnormal[c * D + k];
        ci.kn = L->kn * area, ci.ks = L->ks * area;
        ci.joint = p->joint[c];
    }
    const int32_t slot = !is_wall && p->bond ? p->bond[c] - 1 : -1;
    if (slot >= 0) {
        const sx_bonds *b = &m->bonds;
        ci.bond = b->kind[slot];
        if (b->kind[slot] & (SX_BOND_PARALLEL | SX_BOND_FLATJOINT)) { /* a flat joint's resultants alike */
            ci.pb_fn = b->fn[slot];
            ci.pb_radius = b->rbar[slot];
            for (int k = 0; k < D; k++) ci.pb_fs[k] = b->fs[slot * D + k];
#if D == 3
            for (int k = 0; k < 3; k++) ci.pb_moment[k] = b->mn[slot] * n[k] + b->ms[slot * 3 + k];
#else
            ci.pb_moment[0] = b->ms[slot];
#endif
        }
    }
    return fn(&ci, ud);
}

static bool KERNEL(each_contact)(const sx_model *m, bool walls, int64_t lo, int64_t hi,
                                 bool (*fn)(const sx_contact_info *, void *), void *ud)
{
    const sx_pairs *p = walls ? &m->bw : &m->bb;
    for (int64_t c = lo; c < hi; c++)
        if (p->touching[c] && !report(m, p, c, walls, fn, ud)) return false;
    return true;
}

static int64_t KERNEL(count_contacts)(const sx_model *m)
{
    int64_t n = 0;
    for (int64_t c = 0; c < m->bb.n; c++) n += m->bb.touching[c];
    for (int64_t c = 0; c < m->bw.n; c++) n += m->bw.touching[c];
    return n;
}
