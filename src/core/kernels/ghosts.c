/* Stage: periodic space's ghosts (model_internal.h, sx_cell): balls
 * wrapped into the cell and ghosts made at each build, the ghosts' pairs,
 * ghosts copied from their owners before each contact pass and their
 * forces added to the owners after it, and the cell's average stress.
 * Part of the per-dimension unit kernels.c, which includes it after the
 * broad phase; not compiled alone. */

/* ------------------------------------------------------------- periodic */

/* The shift of an image: the sum of the cell vectors (h: the cell's H or
 * its rate) it is moved by, in axis order, from zero. */
static inline void image_shift(const double (*h)[3], const int8_t *s, double *out)
{
    for (int i = 0; i < D; i++) out[i] = 0;
    for (int k = 0; k < D; k++)
        if (s[k])
            for (int i = 0; i < D; i++) out[i] += s[k] * h[k][i];
}

/* Brings every free ball into the cell (sx__cell_wrap); wrap (3 per
 * ball) records how many cell vectors each moved by, for the history of
 * the pairs, and the balls' unwrap adds the lengths they were moved by
 * (their unwrapped positions: displacements, the gravitational energy).
 * Pebbles move with their clump (clump_motion.c places them from its
 * centroid), so a clump is wrapped as a body. False when out of memory
 * for the unwrap. */
static bool wrap_balls(sx_model *m, int32_t *wrap)
{
    sx_balls *B = &m->balls;
    if (sx__balls_expand_unwrap(m)) return false;
    memset(wrap, 0, (size_t)(B->n * 3) * sizeof *wrap);
    for (int64_t i = 0; i < B->n; i++)
        if (!B->clump || !B->clump[i]) sx__cell_wrap(m->cell, D, B->x + i * D, wrap + i * 3);
    if (B->clump) sx__cell_wrap_clumps(m, wrap);
    for (int64_t i = 0; i < B->n; i++)
        for (int k = 0; k < D; k++)
            if (wrap[i * 3 + k])
                for (int q = 0; q < D; q++) B->unwrap[i * D + q] += wrap[i * 3 + k] * m->cell->h[k][q];
    return true;
}

/* The images a ball may have: every combination of -1, 0, 1 over the
 * periodic axes but all zeros, in a fixed order; returns their count. */
static int image_set(const sx_cell *c, int8_t (*set)[3])
{
    int n = 0;
    for (int z = -1; z <= 1; z++)
        for (int y = -1; y <= 1; y++)
            for (int x = -1; x <= 1; x++) {
                const int s[3] = {x, y, z};
                bool ok = x || y || z;
                for (int k = 0; k < 3; k++) ok &= s[k] == 0 || (k < D && c->axis[k]);
                if (!ok) continue;
                for (int k = 0; k < 3; k++) set[n][k] = (int8_t)s[k];
                n++;
            }
    return n;
}

/* Ghost g (slot base + g) from its owner: position and velocity through
 * its shift, spin; with all, the rest a contact reads. Its force starts at zero. */
static void ghost_copy(sx_model *m, int64_t g, bool all)
{
    const sx_cell *c = m->cell;
    sx_balls *B = &m->balls;
    const int64_t q = c->base + g, o = c->owner[g];
    if (o < 0) return; /* its owner was removed: no pair refers to it */
    const int8_t *s = c->image + g * 3;
    double dx[D], dv[D];
    image_shift(c->h, s, dx);
    image_shift(c->hdot, s, dv);
    for (int k = 0; k < D; k++) {
        B->x[q * D + k] = B->x[o * D + k] + dx[k];
        B->v[q * D + k] = B->v[o * D + k] + dv[k];
        B->f[q * D + k] = 0;
    }
    for (int k = 0; k < RD; k++) B->w[q * RD + k] = B->w[o * RD + k], B->t[q * RD + k] = 0;
    if (!all) return;
    for (int k = 0; k < D; k++) B->x_build[q * D + k] = B->x[q * D + k];
    B->rad[q] = B->rad[o];
    B->inv_mass[q] = B->inv_mass[o];
    B->inv_inertia[q] = B->inv_inertia[o];
    B->id[q] = B->id[o];
    B->mat[q] = B->mat[o];
    B->fix[q] = B->fix[o];
    if (B->alpha) B->alpha[q] = B->alpha[o];
    if (B->group) B->group[q] = B->group[o];
    if (B->clump) B->clump[q] = B->clump[o];
}

static void KERNEL(ghosts_refresh)(sx_model *m, bool all)
{
    for (int64_t g = 0; g < m->cell->n; g++) ghost_copy(m, g, all);
}

/* Appends ghost (owner o, image s); false when out of memory. */
static bool ghost_add(sx_model *m, int64_t o, const int8_t *s)
{
    sx_cell *c = m->cell;
    if (sx__cell_reserve(m, c->base, c->n + 1)) return false;
    c->owner[c->n] = (int32_t)o;
    for (int k = 0; k < 3; k++) c->image[c->n * 3 + k] = s[k];
    ghost_copy(m, c->n++, true);
    return true;
}

/* The ghosts of a build: an image of each ball near a face, within the
 * contact reach of the cell across every axis it is shifted along. */
static bool make_ghosts(sx_model *m)
{
    sx_cell *c = m->cell;
    const sx_balls *B = &m->balls;
    double rmax = 0;
    for (int64_t i = 0; i < B->n; i++)
        if (B->rad[i] > rmax) rmax = B->rad[i];
    double near[D]; /* the reach in fractional units of each axis */
    for (int k = 0; k < D; k++) near[k] = c->axis[k] ? (2 * rmax + m->skin) / sx__cell_thickness(c, D, k) : 0;
    int8_t set[26][3];
    const int ns = image_set(c, set);
    c->n = 0;
    c->base = B->n;
    c->moved = 0;
    for (int pass = 0; pass < 2; pass++) { /* count, then fill the slots */
        int64_t count = 0;
        for (int64_t i = 0; i < B->n; i++) {
            double f[3];
            sx__cell_frac(c, D, B->x + i * D, f);
            for (int e = 0; e < ns; e++) {
                bool in = true;
                for (int k = 0; k < D; k++)
                    if (set[e][k]) in &= set[e][k] > 0 ? f[k] < near[k] : f[k] >= 1 - near[k];
                if (!in) continue;
                if (pass == 1) {
                    c->owner[count] = (int32_t)i;
                    memcpy(c->image + count * 3, set[e], 3);
                }
                count++;
            }
        }
        if (pass == 0 && sx__cell_reserve(m, B->n, count)) return false;
        c->n = count;
    }
    for (int64_t g = 0; g < c->n; g++) ghost_copy(m, g, true);
    return true;
}

/* Pairs of ghosts with real balls, ghost by ghost: the real balls of the
 * cells around the ghost's (a ghost outside the grid is counted in its
 * nearest cell, whose neighbours then hold every ball within its reach).
 * The owner rule keeps one of the two images of a contact: the real end
 * has the smaller id. */
static void build_ghost_pairs(sx_model *m, transfer *tr, cursor *to)
{
    const sx_cell *c = m->cell;
    const sx_grid *g = &m->grid;
    const sx_balls *b = &m->balls;
    for (int64_t e = 0; e < c->n; e++) {
        const int32_t q = (int32_t)(c->base + e);
        const double *xq = b->x + (int64_t)q * D;
        const int32_t idq = b->id[q];
        int64_t cc[3] = {0, 0, 0};
        cell_coords(g, xq, cc);
        for (int64_t z = cc[2] - (D == 3); z <= cc[2] + (D == 3); z++)
            for (int64_t y = cc[1] - 1; y <= cc[1] + 1; y++)
                for (int64_t x = cc[0] - 1; x <= cc[0] + 1; x++) {
                    if (x < 0 || x >= g->nc[0] || y < 0 || y >= g->nc[1] || z < 0 || z >= g->nc[2]) continue;
                    const int64_t cell = x + g->nc[0] * (y + g->nc[1] * z);
                    for (int32_t j = g->start[cell]; j < g->start[cell + 1]; j++) {
                        if (b->id[j] >= idq) continue;
                        double dx[D];
                        for (int k = 0; k < D; k++) dx[k] = xq[k] - b->x[(int64_t)j * D + k];
                        const double reach = b->rad[q] + b->rad[j] + m->skin;
                        if (dot(dx, dx) < reach * reach) candidate(m, tr, j, q, to);
                    }
                }
    }
}

/* A bonded pair the grid did not find (its gap beyond the skin): through
 * the nearest image of b seen from a, its real end the ball of smaller id
 * (the owner rule), the ghost added if the build made none. Returns the
 * pair's ends in *ra, *rb; false when out of memory. */
static bool bonded_ends(sx_model *m, int32_t a, int32_t b, int32_t *ra, int32_t *rb)
{
    sx_cell *c = m->cell;
    const sx_balls *B = &m->balls;
    double fa[3], fb[3];
    sx__cell_frac(c, D, B->x + (int64_t)a * D, fa);
    sx__cell_frac(c, D, B->x + (int64_t)b * D, fb);
    int8_t s[3] = {0, 0, 0};
    bool shifted = false;
    for (int k = 0; k < D; k++) {
        s[k] = (int8_t)(c->axis[k] ? nearbyint(fa[k] - fb[k]) : 0);
        shifted |= s[k] != 0;
    }
    if (!shifted) {
        *ra = a < b ? a : b, *rb = a < b ? b : a;
        return true;
    }
    if (B->id[a] > B->id[b]) { /* seen from b: a's image at -s */
        const int32_t t = a;
        a = b, b = t;
        for (int k = 0; k < 3; k++) s[k] = (int8_t)-s[k];
    }
    *ra = a;
    for (int64_t g = 0; g < c->n; g++)
        if (c->owner[g] == b && !memcmp(c->image + g * 3, s, 3)) {
            *rb = (int32_t)(c->base + g);
            return true;
        }
    if (!ghost_add(m, b, s)) return false;
    *rb = (int32_t)(c->base + c->n - 1);
    return true;
}

/* ------------------------------------------------------------ the pass */

/* With energy tracking in a deforming cell: the balls' shifted ghost
 * forces (sx_cell), cleared; NULL otherwise, or out of memory (*ok). */
static double *shifted_clear(sx_model *m, bool *ok)
{
    sx_cell *c = m->cell;
    const int64_t n = m->balls.n * D * D;
    *ok = true;
    if (!m->track_energy || !c->controlled || n == 0) return NULL;
    if (n > c->cap_shifted) {
        double *p = sx_alloc_resize(&m->alloc, c->shifted, (size_t)c->cap_shifted, (size_t)n, sizeof *p);
        if (!p) return *ok = false, NULL;
        c->shifted = p, c->cap_shifted = n;
    }
    memset(c->shifted, 0, (size_t)n * sizeof *c->shifted);
    return c->shifted;
}

/* After the ball-ball pass: each ghost's force and moment added to its
 * owner's, in ghost order. A deforming cell moves a ghost against its
 * owner by s dH, and so does work on the pair the ghost's force does not
 * pay for from the owner's motion: -f . (s dH) (the wall work's image:
 * wall_contacts.c); the owner keeps s (x) f for the law of motion, which
 * books it with the step's rate (sx__cell_rate, after this pass). False:
 * out of memory for that. */
static bool fold_ghosts(sx_model *m)
{
    const sx_cell *c = m->cell;
    sx_balls *B = &m->balls;
    bool ok;
    double *G = shifted_clear(m, &ok);
    for (int64_t g = 0; g < c->n; g++) {
        const int64_t q = c->base + g, o = c->owner[g];
        if (o < 0) continue;
        for (int k = 0; k < D && G; k++)
            for (int i = 0; i < D && c->image[g * 3 + k]; i++) G[(o * D + k) * D + i] += c->image[g * 3 + k] * B->f[q * D + i];
        for (int k = 0; k < D; k++) B->f[o * D + k] += B->f[q * D + k];
        for (int k = 0; k < RD; k++) B->t[o * RD + k] += B->t[q * RD + k];
        if (m->track_energy) { /* the dashpots' share too (motion.c) */
            for (int k = 0; k < D; k++) m->visc_f[o * D + k] += m->visc_f[q * D + k];
            for (int k = 0; k < RD; k++) m->visc_t[o * RD + k] += m->visc_t[q * RD + k];
        }
    }
    return ok;
}

/* -------------------------------------------------------------- stress */

/* The terms of the cell's stress of pairs [c0, c1), added to acc: the sum
 * of F (x) l over the ball-ball pairs that carry a force (acc[3 i + j]),
 * F the force on b and l = x_b - x_a the branch vector of the last
 * evaluation (through the boundary for a ghost), and the servo's K per
 * component (acc[9 + k], sx_cell_control) with stiff (the step's laws:
 * the servo's, inside a cycle). */
static void stress_terms(const sx_model *m, int64_t c0, int64_t c1, double *acc, bool stiff)
{
    const sx_pairs *p = &m->bb;
    const sx_balls *B = &m->balls;
    const sx_bonds *bs = &m->bonds;
    double *k6 = acc + 9;
    for (int64_t c = c0; c < c1; c++) {
        if (!p->touching[c]) continue;
        const double *l = p->geo + c * D, d = sqrt(dot(l, l));
        /* the forces as the step applied them (as the contacts' reports
         * give them, queries.c): a smooth joint's normal force along its
         * joint's normal, a flat joint's face resultants as a parallel
         * bond's (its contact law off); the centre line took both, and a
         * flat-jointed cell read no stress */
        const double *nc = p->joint && p->joint[c] ? p->jnormal + c * D : NULL;
        double n[D], F[D];
        for (int k = 0; k < D; k++) n[k] = l[k] / d, F[k] = p->fn[c] * (nc ? nc[k] : n[k]) + p->fs[c * D + k];
        const int32_t slot = p->bond ? p->bond[c] - 1 : -1;
        if (slot >= 0 && (bs->kind[slot] & (SX_BOND_PARALLEL | SX_BOND_FLATJOINT)))
            for (int k = 0; k < D; k++) F[k] += bs->fn[slot] * n[k] + bs->fs[slot * D + k];
        for (int i = 0; i < D; i++)
            for (int j = 0; j < D; j++) acc[3 * i + j] += F[i] * l[j];
        if (!stiff) continue;
        const int64_t a = p->a[c], b = p->b[c];
        const double ra = B->rad[a], rb = B->rad[b];
        const sx_pair_law *law = sx__bb_step_law(m, c, a, b);
        double kn, ks;
        stiffness(law, ra, rb, 2 * ra * rb / (ra + rb), ra + rb - d, &kn, &ks);
        for (int k = 0; k < D; k++) k6[k] += kn * l[k] * l[k];
        k6[SX_CELL_XY] += ks * l[1] * l[1];
#if D == 3
        k6[SX_CELL_XZ] += ks * l[2] * l[2];
        k6[SX_CELL_YZ] += ks * l[2] * l[2];
#endif
    }
}

/* stress_terms with the servo's K of rank r's own pairs, for a sum over the ranks. */
static void KERNEL(stress_terms_stiff)(const sx_model *m, int r, double *acc)
{
    stress_terms(m, m->dd->bb_own[r].lo, m->dd->bb_own[r].hi, acc, true);
}

/* The cell's average stress, (1/V) sum F (x) l (stress_terms), compression
 * positive; with stiff, the servo's K per component. Decomposed (inside a
 * cycle, the servo's; or of a state a lazy cycle left scattered, each rank
 * its own pairs current), the sum runs over the ranks in pair order
 * (sx__dd_chain), the serial bits. False: the ranks could not exchange. */
static bool KERNEL(cell_stress)(const sx_model *m, double stress[3][3], double stiff[6])
{
    double acc[9 + 6] = {0};
    if (m->dd && (m->dd->active || m->dd->scattered)) {
        if (!sx__dd_chain(m, acc, 9 + 6, KERNEL(stress_terms_stiff))) return false;
    } else {
        stress_terms(m, 0, m->bb.n, acc, stiff != NULL);
    }
    double vol = 1;
    for (int k = 0; k < D; k++) vol *= m->cell->h[k][k];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) stress[i][j] = i < D && j < D ? acc[3 * i + j] / vol : 0;
    if (stiff)
        for (int k = 0; k < 6; k++) stiff[k] = acc[9 + k] / vol;
    return true;
}
