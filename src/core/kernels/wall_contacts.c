/* Stage: the ball-wall contacts (entry point KERNEL(walls)). Part of the
 * per-dimension unit kernels.c, which includes it; not compiled alone. */

/* The wall pass of one block: the block's ball-wall contacts, after the
 * ball-ball pass. The wall is entity A (phi1 of 4-10), the ball B; n
 * points from the wall to the ball. Wall resultants go to the block's
 * partial sums acc (one per wall). */

/* The dashpot factor of the last contact that needed one (balls of one
 * size and material share it). */
typedef struct dash_memo {
    double dash, im, cn;
} dash_memo;

/* Contact c ended (or gave way to another): the energy its shear spring
 * held is counted as slip, as for ball-ball contacts. */
static void wall_release(sx_model *m, sx_block *o, int64_t c)
{
    sx_pairs *p = &m->bw;
    const int64_t i = p->a[c];
    if (p->touching[c] && m->track_energy) { /* a Hertz spring holds nothing at zero overlap: ks = 0 */
        const int32_t row = sx__bw_row(m, c);
        const sx_pair_law *law = row ? &m->cmodel[row - 1].wlaw : &m->wlaw[m->balls.mat[i] * m->nwall + p->b[c]];
        const double r = m->balls.rad[i];
        double kn, ks;
        stiffness(law, r, 0, r, 0, &kn, &ks);
        if (ks > 0) o->slip += 0.5 * dot(p->fs + c * D, p->fs + c * D) / ks;
        if (law->mu_r > 0) o->slip += sx_law_rolling_strain(D, p->mr + c * RD, ks, r); /* and the rolling spring's */
    }
    p->touching[c] = 0;
}

/* The force of ball-wall contact c at distance dist < r along unit normal
 * n (from the wall to the ball), every law and wall kind; false on an
 * overlap error. */
static inline __attribute__((always_inline)) bool wall_force(sx_model *m, sx_block *o, sx_wall_acc *acc, int64_t c, dash_memo *memo, double dist, const double *n)
{
    sx_balls *B = &m->balls;
    double *restrict f = B->f, *restrict t = B->t;
    sx_pairs *p = &m->bw;
    const double dt = motion_dt(m);
    const bool track = m->track_energy;
    const int64_t i = p->a[c];
    const sx_wall *wl = &m->walls[p->b[c]];
    sx_wall_acc *wa = &acc[p->b[c]];
    const double *xi = B->x + i * D, r = B->rad[i];
    double *fs = p->fs + c * D;
    /* the contact-model row it took, or takes if new (cmodel.c); else its ball's and wall's law */
    const int32_t row = sx__bw_row(m, c);
    const sx_pair_law *law = row ? &m->cmodel[row - 1].wlaw : &m->wlaw[B->mat[i] * m->nwall + p->b[c]];
    const double un = r - dist; /* 4-3 */
    if (un > r) {
        o->st = SX_EUNSTABLE;
        o->err_ball = B->id[i], o->err_wall = wl->id, o->err_un = un, o->err_r = r;
        return false;
    }
    const double lb = r - 0.5 * un;
    double xc[D];
    for (int k = 0; k < D; k++) xc[k] = xi[k] - lb * n[k]; /* 4-4 */
    /* the contact point's velocity: the ball's, with its arm -lb n, less the
     * wall's surface velocity (its translation, a cylinder's radial motion
     * along -n, a mesh's spin about its point) */
    double wn[D], vc[D], ws[D];
    spin_cross(B->w + i * RD, n, wn);
    for (int k = 0; k < D; k++) ws[k] = wl->def.vel[k] - wl->def.radial_vel * n[k];
#if D == 3
    if (wl->mesh) {
        double arm0[3], turn[3];
        for (int k = 0; k < 3; k++) arm0[k] = xc[k] - wl->def.point[k];
        spin_cross(wl->def.spin, arm0, turn);
        for (int k = 0; k < 3; k++) ws[k] += turn[k];
    }
#endif
    for (int k = 0; k < D; k++) vc[k] = (B->v[i * D + k] - lb * wn[k]) - ws[k];
    const double vn = dot(vc, n);
    double vs[D];
    for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k];

    double kn, ks;
    const double fn = stiffness(law, r, 0, r, un, &kn, &ks);
    if (!p->touching[c])
        for (int k = 0; k < D; k++) fs[k] = 0, p->geo[c * D + k] = n[k];
    /* the wall is entity A of 4-8/4-9: only a mesh spins */
    const double *wspin = NULL;
#if D == 3
    if (wl->mesh) wspin = wl->def.spin;
#endif
    carry rot;
    carry_make(&rot, p->geo + c * D, n, wspin, B->w + i * RD, dt);
    carry_apply(&rot, fs);
    if (law->unloading && p->touching[c] && p->un[c] > 0) { /* laws/mindlin_unloading.h: from the last step's overlap */
        double kn0, ks0;
        stiffness(law, r, 0, r, p->un[c], &kn0, &ks0);
        const double e = sx_law_mindlin_unloading_scale(D, fs, ks, ks0);
        if (track) o->slip += e;
    }
    double f0[D];
    for (int k = 0; k < D; k++) f0[k] = fs[k];
    const double ksdt = ks * dt;
    for (int k = 0; k < D; k++) fs[k] -= ksdt * vs[k];
    double *us = law->total_shear ? p->us + c * D : NULL; /* Mindlin's total form (laws/total_shear.h) */
    if (us) {
        if (!p->touching[c])
            for (int k = 0; k < D; k++) us[k] = 0;
        carry_apply(&rot, us);
        sx_law_total_shear_force(D, us, fs, vs, ks, dt);
    }
    double sc;
    const bool slip = sx__law_cap(D, fs, f0, dot(fs, fs), law->mu * fn, ks, track ? &o->slip : NULL, &sc);
    if (slip && us) sx_law_total_shear_slip(D, us, sc);
    double mroll[RD] = {0};
    if (law->mu_r > 0) { /* rolling resistance (laws/rolling.h): the ball's turn relative to the wall's */
        double *mr = p->mr + c * RD, dtheta[RD];
        if (!p->touching[c])
            for (int k = 0; k < RD; k++) mr[k] = 0;
#if D == 3
        carry_apply(&rot, mr);
#endif
        for (int k = 0; k < RD; k++) dtheta[k] = (B->w[i * RD + k] - (wspin ? wspin[k] : 0)) * dt;
        const double e = sx_law_rolling_moment(law, D, mr, dtheta, n, ks, r, fn);
        if (track) o->slip += e;
        for (int k = 0; k < RD; k++) mroll[k] = mr[k];
    }
    for (int k = 0; k < D; k++) p->geo[c * D + k] = n[k];
    if (p->cmodel) p->cmodel[c] = row;
    p->touching[c] = 1;

    double fd = fn, fdn = 0, dsh[D] = {0}, F[D];
    bool shear_dashpot = false;
    if (law->beta_n > 0 || law->beta_s > 0) {
        /* the ball's full mass: c = 2 beta sqrt(m k); balls of one size and material share it */
        double cn;
        if (!law->plain) {
            cn = 2 * law->beta_n * sqrt(kn / B->inv_mass[i]);
        } else if (law->dash_n == memo->dash && B->inv_mass[i] == memo->im) {
            cn = memo->cn;
        } else {
            cn = sqrt(law->dash_n / B->inv_mass[i]);
            memo->dash = law->dash_n, memo->im = B->inv_mass[i], memo->cn = cn;
        }
        fdn = -cn * vn;
        fd += fdn;
        double work = fdn * vn;
        if (!slip && law->beta_s > 0) {
            const double cs = 2 * law->beta_s * sqrt(ks / B->inv_mass[i]);
            for (int k = 0; k < D; k++) dsh[k] = -cs * vs[k];
            work += dot(dsh, vs);
            shear_dashpot = true;
        }
        if (track) o->viscous -= work * dt;
    }
    for (int k = 0; k < D; k++) F[k] = fd * n[k] + fs[k];
    if (shear_dashpot)
        for (int k = 0; k < D; k++) F[k] += dsh[k];
    p->un[c] = un;
    p->fn[c] = fd;
    wa->load += fd;
    wa->kn_sum += kn;
    wa->contacts++;
    /* 4-21: the ball's arm is -lb n */
    double nf[RD], mw[RD], arm[D];
    moment_of(n, F, nf);
    if (track && (fdn != 0 || shear_dashpot)) { /* the dashpots' force on the ball: the law of motion's share of its work */
        double Fd[D], nd[RD];
        for (int k = 0; k < D; k++) Fd[k] = fdn * n[k] + dsh[k];
        moment_of(n, Fd, nd);
        for (int k = 0; k < D; k++) m->visc_f[i * D + k] += Fd[k];
        for (int k = 0; k < RD; k++) m->visc_t[i * RD + k] -= lb * nd[k];
    }
    for (int k = 0; k < D; k++) {
        f[i * D + k] += F[k];
        wa->force[k] -= F[k];
        arm[k] = xc[k] - wl->def.point[k];
    }
#if D == 3
    if (wl->def.kind == SX_WALL_RECT)
        for (int k = 0; k < D; k++) arm[k] -= 0.5 * (wl->def.edge1[k] + wl->def.edge2[k]);
#endif
    moment_of(arm, F, mw);
    for (int k = 0; k < RD; k++) {
        t[i * RD + k] += mroll[k] - lb * nf[k];
        wa->moment[k] -= mw[k] + mroll[k];
    }
    return true;
}

/* One ball-wall contact c of a wall that is not a mesh. */
static inline __attribute__((always_inline)) bool wall_contact(sx_model *m, sx_block *o, sx_wall_acc *acc, int64_t c, dash_memo *memo)
{
    const int64_t i = m->bw.a[c];
    double n[D];
    const double dist = wall_distance(&m->walls[m->bw.b[c]], m->balls.x + i * D, n);
    if (dist >= m->balls.rad[i]) {
        wall_release(m, o, c);
        return true;
    }
    return wall_force(m, o, acc, c, memo, dist, n);
}

/* The most candidate facets one ball may have on one mesh. */
#define MESH_ROWS_MAX 256

#if D == 3

/* Whether facet t has vertex v among its corners. */
static bool facet_has(const sx_mesh *s, int32_t t, int32_t v)
{
    const int32_t *tv = s->tri + 3 * (int64_t)t;
    return tv[0] == v || tv[1] == v || tv[2] == v;
}

/* Faces of one mesh whose normals differ by at most 20 degrees (and a
 * hair: this is the cosine of 20.5, so that a drum of 18 strips, 20
 * degrees to the crease, is not split by rounding), sharing a corner, are
 * one smooth surface: a curve tessellated (a drum of 18 strips or more, a
 * shallow bowl) gives one contact there, at the nearest face's overlap,
 * along the faces' normals weighted by their overlaps (mesh_rows), as on
 * the surface it stands for; each was counted before, six times the force
 * in a bowl of six facets sinking 0.5 degrees. Sharper creases are
 * corners, with a contact per face. */
#define MESH_SMOOTH_COS 0.93667199738904622

/* Whether the faces of facets a and b, their normals na and nb toward the
 * ball, are one smooth surface (MESH_SMOOTH_COS, a corner in common). */
static bool smooth_faces(const sx_mesh *s, int32_t a, int32_t b, const double *na, const double *nb)
{
    if (dot(na, nb) < MESH_SMOOTH_COS) return false;
    const int32_t *ta = s->tri + 3 * (int64_t)a;
    return facet_has(s, b, ta[0]) || facet_has(s, b, ta[1]) || facet_has(s, b, ta[2]);
}

/* Whether touching feature k is not a contact of its own. A face is one
 * unless a kept face meets the ball at the same point in the same plane
 * (two facets met at their shared edge), or is nearer on a facet sharing a
 * corner with it within MESH_SMOOTH_COS (faces are taken nearest first).
 * An edge or a vertex is a contact
 * only where the mesh is nearest there: where every facet that has it
 * finds its own closest point there too (the point is then a local
 * minimum of the distance over the whole surface, as on a ridge or an
 * apex); a facet that has it but is nearer elsewhere (a face, or another
 * of its edges) carries the load there. Testing only the kept features'
 * own facets missed facets that share a vertex and no edge with them: a
 * ball pressed into a flat fan of facets near their common vertex felt one
 * contact per facet (up to four times the plane's force). The same edge or
 * vertex reached from several facets is kept once. The facets that have a
 * touching feature are all candidates (nearer than it, so than the
 * radius). Distances within 1e-9 of the radius count as equal, so a
 * centre over a boundary between two facets' regions, which rounding may
 * give to either, keeps one contact. */
static bool shadowed(const sx_mesh *s, const int32_t *facet, const facet_hit *h, const uint8_t *keep, int64_t n,
                     int64_t k, double r)
{
    const facet_hit *a = &h[k];
    const double tie = 1e-9 * r;
    for (int64_t j = 0; j < n; j++) {
        if (j == k) continue;
        const facet_hit *b = &h[j];
        if (a->kind == FACET_FACE) {
            if (!keep[j] || b->kind != FACET_FACE) continue;
            double dq[3];
            for (int e = 0; e < 3; e++) dq[e] = a->q[e] - b->q[e];
            if (dot(dq, dq) <= 1e-18 * r * r && dot(a->n, b->n) >= 1 - 1e-12) return true;
            if (smooth_faces(s, facet[j], facet[k], b->n, a->n)) return true;
        } else if (facet_has(s, facet[j], a->v0) && facet_has(s, facet[j], a->v1)) {
            if (b->dist < a->dist - tie) return true; /* nearer elsewhere: not a minimum */
            if (keep[j] && b->dist <= a->dist + tie) return true; /* felt already */
        }
    }
    return false;
}

/* Pair `to` takes over pair `from`'s history: every field of the store
 * but its ends (the shear force, the last normal, a law's history such as
 * the rolling moment, the touching flag). */
static void inherit(sx_model *m, int64_t to, int64_t from)
{
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, &m->bw, f);
    for (int q = 0; q < nf; q++) {
        if (f[q].end) continue;
        const size_t row = (size_t)f[q].per * sx__pair_size(&f[q]);
        char *data = *f[q].data;
        memcpy(data + (size_t)to * row, data + (size_t)from * row, row);
    }
}

/* Ball i's candidate facets of one mesh, rows [c0, c1): every touching
 * closest feature, faces first, then edges, then vertices, each kept
 * unless shadowed; a contact a facet takes over (the ball rolled onto it)
 * inherits the shear force and last normal of the nearest-normal contact
 * that just ended, so the history runs on as on one surface; then each
 * kept contact's force, as wall_force does for any wall. */
static bool mesh_rows(sx_model *m, sx_block *o, sx_wall_acc *acc, int64_t c0, int64_t c1, dash_memo *memo)
{
    sx_pairs *p = &m->bw;
    const int64_t i = p->a[c0], n = c1 - c0;
    const sx_wall *wl = &m->walls[p->b[c0]];
    const double r = m->balls.rad[i], *x = m->balls.x + i * D;
    if (n > MESH_ROWS_MAX) {
        o->st = SX_EINVAL;
        o->err_ball = m->balls.id[i], o->err_wall = wl->id, o->err_un = (double)n, o->err_r = r;
        return false;
    }
    facet_hit h[MESH_ROWS_MAX];
    uint8_t keep[MESH_ROWS_MAX], given[MESH_ROWS_MAX];
    for (int64_t k = 0; k < n; k++) {
        facet_closest(wl->mesh, p->facet[c0 + k], x, &h[k]);
        keep[k] = given[k] = 0;
    }
    /* the faces nearest first (a smooth surface's contact is its nearest
     * face's: continuous as a ball crosses a shallow crease), by insertion,
     * ties in row order; then the edges and vertices */
    int16_t order[MESH_ROWS_MAX];
    int64_t nf = 0;
    for (int64_t k = 0; k < n; k++) {
        if (h[k].kind != FACET_FACE || !(h[k].dist < r)) continue;
        int64_t at = nf++;
        for (; at > 0 && h[order[at - 1]].dist > h[k].dist; at--) order[at] = order[at - 1];
        order[at] = (int16_t)k;
    }
    for (int64_t e = 0; e < nf; e++) keep[order[e]] = !shadowed(wl->mesh, p->facet + c0, h, keep, n, order[e], r);
    for (int kind = FACET_EDGE; kind <= FACET_VERTEX; kind++)
        for (int64_t k = 0; k < n; k++)
            if (h[k].kind == kind && h[k].dist < r)
                keep[k] = !shadowed(wl->mesh, p->facet + c0, h, keep, n, k, r);
    /* a face that stands for faces merged with it (MESH_SMOOTH_COS) pushes
     * along their normals weighted by their overlaps, so the force turns
     * smoothly as a ball crosses a shallow crease (the nearest face's normal
     * alone flipped there: a ball never settled in a 10-degree valley);
     * alone, or with coplanar faces only, it keeps its own, to the bit */
    for (int64_t e = 0; e < nf; e++) {
        const int64_t k = order[e];
        if (!keep[k]) continue;
        double sum[3], w = r - h[k].dist;
        bool turned = false;
        for (int q = 0; q < 3; q++) sum[q] = w * h[k].n[q];
        for (int64_t f = 0; f < nf; f++) {
            const int64_t j = order[f];
            if (keep[j] || !smooth_faces(wl->mesh, p->facet[c0 + j], p->facet[c0 + k], h[j].n, h[k].n)) continue;
            w = r - h[j].dist;
            for (int q = 0; q < 3; q++) sum[q] += w * h[j].n[q];
            turned = turned || dot(h[j].n, h[k].n) < 1 - 1e-12;
        }
        if (!turned) continue;
        const double len = sqrt(dot(sum, sum));
        for (int q = 0; q < 3; q++) h[k].n[q] = sum[q] / len;
    }
    for (int64_t k = 0; k < n; k++) {
        if (!keep[k] || p->touching[c0 + k]) continue;
        int64_t best = -1;
        double near = 0;
        for (int64_t j = 0; j < n; j++) {
            if (keep[j] || given[j] || !p->touching[c0 + j]) continue;
            const double cosine = dot(p->geo + (c0 + j) * D, h[k].n);
            if (cosine > near) near = cosine, best = j;
        }
        if (best < 0) continue;
        given[best] = 1;
        inherit(m, c0 + k, c0 + best);
    }
    for (int64_t k = 0; k < n; k++) {
        if (keep[k]) continue;
        if (given[k]) p->touching[c0 + k] = 0; /* its history lives on in its heir */
        else wall_release(m, o, c0 + k);
    }
    for (int64_t k = 0; k < n; k++)
        if (keep[k] && !wall_force(m, o, acc, c0 + k, memo, h[k].dist, h[k].n)) return false;
    return true;
}
#endif

/* Four ball-wall contacts [c0, c0 + 4) at once where each is plain (an
 * infinite wall, a linear law without a shear dashpot, no energy
 * tracking): wall_contact's arithmetic in vector lanes, as
 * ball_chunk_batched does it for ball-ball pairs, then the results in
 * contact order; the same bits. false on an overlap error. */
/* GCC 12 takes a vector built from four scalars straight into an array
 * element for a read of the element's old value (-Wmaybe-uninitialized);
 * every element here is written before it is read. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
static inline __attribute__((always_inline)) bool wall_lanes(sx_model *m, sx_block *o, sx_wall_acc *acc, int64_t c0, dash_memo *memo)
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bw;
    const double dt = motion_dt(m);
    int64_t i[LANES];
    const sx_wall *wl[LANES];
    const sx_pair_law *law[LANES];
    for (int q = 0; q < LANES; q++) {
        i[q] = p->a[c0 + q];
        wl[q] = &m->walls[p->b[c0 + q]];
        law[q] = &m->wlaw[B->mat[i[q]] * m->nwall + p->b[c0 + q]];
    }
#define WALL_LANES(field) ((vd){wl[0]->def.field, wl[1]->def.field, wl[2]->def.field, wl[3]->def.field})
#define LAW_LANES(field) ((vd){law[0]->field, law[1]->field, law[2]->field, law[3]->field})
    vd x[D], v[D], pt[D], n[D], vel[D];
    for (int k = 0; k < D; k++) {
        x[k] = LANES_OF(B->x, i, D, k);
        v[k] = LANES_OF(B->v, i, D, k);
        pt[k] = WALL_LANES(point[k]);
        n[k] = WALL_LANES(normal[k]);
        vel[k] = WALL_LANES(vel[k]);
    }
    const vd rvel = WALL_LANES(radial_vel);
    const vd rad = LANES_OF(B->rad, i, 1, 0), im = LANES_OF(B->inv_mass, i, 1, 0);
    const vd kn = LAW_LANES(kn), ks = LAW_LANES(ks), mu = LAW_LANES(mu), dash = LAW_LANES(dash_n),
             bn = LAW_LANES(beta_n);
#undef WALL_LANES
#undef LAW_LANES
    vd fs_old[D], no_old[D];
    load_lanes(p->fs + c0 * D, fs_old);
    load_lanes(p->geo + c0 * D, no_old);
    v4u8 touched;
    memcpy(&touched, p->touching + c0, sizeof touched);
    const vm had = __builtin_convertvector(touched, vm) != 0;

    /* the distance from an infinite wall (sums from zero, as dot()) */
    vd dist = VZERO;
    for (int k = 0; k < D; k++) dist += (x[k] - pt[k]) * n[k];
    const vm live = dist < rad;
    const vd un = rad - dist; /* 4-3 */
    const vm bad = live & (un > rad);
    if (VANY(bad))
        for (int q = 0; q < LANES; q++)
            if (bad[q]) {
                o->st = SX_EUNSTABLE;
                o->err_ball = B->id[i[q]], o->err_wall = wl[q]->id, o->err_un = un[q], o->err_r = rad[q];
                return false;
            }
    const vd lb = rad - 0.5 * un;
    vd xc[D], wn[D], vc[D];
    for (int k = 0; k < D; k++) xc[k] = x[k] - lb * n[k]; /* 4-4 */
#if D == 3
    vd w[3];
    for (int k = 0; k < 3; k++) w[k] = LANES_OF(B->w, i, 3, k);
    wn[0] = w[1] * n[2] - w[2] * n[1];
    wn[1] = w[2] * n[0] - w[0] * n[2];
    wn[2] = w[0] * n[1] - w[1] * n[0];
#else
    const vd w0 = LANES_OF(B->w, i, 1, 0);
    wn[0] = -w0 * n[1];
    wn[1] = w0 * n[0];
#endif
    for (int k = 0; k < D; k++) vc[k] = (v[k] - lb * wn[k]) - (vel[k] - rvel * n[k]);
    vd vn = VZERO;
    for (int k = 0; k < D; k++) vn += vc[k] * n[k];
    vd vs[D];
    for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k];
    const vd fn = kn * un, fmax = mu * fn; /* 4-6 */
    /* the shear force (the wall does not spin) */
    vd g[D];
#if D == 3
    shear_lanes(g, fs_old, no_old, &had, n, w, vs, &ks, &fmax, dt);
#else
    shear_lanes(g, fs_old, no_old, &had, n, NULL, vs, &ks, &fmax, dt);
#endif
    /* the ball's full mass: c = 2 beta sqrt(m k) */
    vd cn = VZERO + memo->cn;
    const vm other = (im != memo->im) | (dash != memo->dash);
    if (VANY(other)) {
        cn = VSQRT(dash / im);
        memo->dash = dash[0], memo->im = im[0], memo->cn = cn[0];
    }
    const vd fd = VSEL(bn > VZERO, fn + -cn * vn, fn);
    vd F[D], nf[RD], mw[RD], arm[D];
    for (int k = 0; k < D; k++) {
        F[k] = fd * n[k] + g[k];
        arm[k] = xc[k] - pt[k];
    }
    /* 4-21: the ball's arm is -lb n */
#if D == 3
    nf[0] = n[1] * F[2] - n[2] * F[1], nf[1] = n[2] * F[0] - n[0] * F[2], nf[2] = n[0] * F[1] - n[1] * F[0];
    mw[0] = arm[1] * F[2] - arm[2] * F[1], mw[1] = arm[2] * F[0] - arm[0] * F[2], mw[2] = arm[0] * F[1] - arm[1] * F[0];
#else
    nf[0] = n[0] * F[1] - n[1] * F[0];
    mw[0] = arm[0] * F[1] - arm[1] * F[0];
#endif
    double *restrict f = B->f, *restrict t = B->t;
    for (int q = 0; q < LANES; q++) {
        const int64_t c = c0 + q;
        if (!live[q]) {
            p->touching[c] = 0;
            continue;
        }
        sx_wall_acc *wa = &acc[p->b[c]];
        for (int k = 0; k < D; k++) p->fs[c * D + k] = g[k][q], p->geo[c * D + k] = n[k][q];
        p->touching[c] = 1;
        p->un[c] = un[q];
        p->fn[c] = fd[q];
        wa->load += fd[q];
        wa->kn_sum += kn[q];
        wa->contacts++;
        for (int k = 0; k < D; k++) {
            f[i[q] * D + k] += F[k][q];
            wa->force[k] -= F[k][q];
        }
        for (int k = 0; k < RD; k++) {
            t[i[q] * RD + k] -= lb[q] * nf[k][q];
            wa->moment[k] -= mw[k][q];
        }
    }
    return true;
}

#pragma GCC diagnostic pop

/* A contact wall_lanes takes. */
static inline bool plain_wall_contact(const sx_model *m, int64_t c)
{
    const sx_wall *wl = &m->walls[m->bw.b[c]];
    const sx_pair_law *law = &m->wlaw[m->balls.mat[m->bw.a[c]] * m->nwall + m->bw.b[c]];
    return (wl->def.kind == SX_WALL_PLANE || wl->def.kind == SX_WALL_LINE) && law->plain &&
           law->beta_s == 0;
}

SX_VECTOR_CLONES static void wall_block(sx_model *m, sx_block *o, sx_wall_acc *acc)
{
    if (m->nwall) memset(acc, 0, (size_t)m->nwall * sizeof *acc);
    o->slip = o->viscous = 0;
    o->st = SX_OK;
    dash_memo memo = {NAN, NAN, 0};
    for (int64_t c = o->w0; c < o->w1;) {
#if D == 3
        if (m->mesh_pairs && m->walls[m->bw.b[c]].mesh) { /* the ball's rows of this mesh together */
            int64_t e = c + 1;
            while (e < o->w1 && m->bw.a[e] == m->bw.a[c] && m->bw.b[e] == m->bw.b[c]) e++;
            if (!mesh_rows(m, o, acc, c, e, &memo)) return;
            c = e;
            continue;
        }
#endif
        /* a contact-model row's law is read per contact (wall_force): lanes only without wall rows */
        bool lanes = !m->track_energy && !m->bw.cmodel && c + LANES <= o->w1;
        for (int q = 0; q < LANES && lanes; q++) lanes = plain_wall_contact(m, c + q);
        if (lanes) {
            if (!wall_lanes(m, o, acc, c, &memo)) return;
            c += LANES;
        } else {
            if (!wall_contact(m, o, acc, c, &memo)) return;
            c++;
        }
    }
}

/* The wall pass over all blocks (in parallel), then the walls' resultants,
 * energies and errors summed in block order. */
static sx_status KERNEL(walls)(sx_model *m)
{
    const int64_t nw = m->nwall, nb = m->nblock;
    /* the laws of each material against each wall, for this step */
    if (m->nmat * nw > m->cap_wlaw) {
        sx_pair_law *q = sx_alloc_resize(&m->alloc, m->wlaw, (size_t)m->cap_wlaw, (size_t)(m->nmat * nw), sizeof *q);
        if (!q) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
        m->wlaw = q;
        m->cap_wlaw = m->nmat * nw;
    }
    for (int a = 0; a < m->nmat; a++)
        for (int64_t w = 0; w < nw; w++) m->wlaw[a * nw + w] = sx__wall_law(m, a, &m->walls[w]);
    if (nb * nw > m->cap_wall_acc) {
        sx_wall_acc *q = sx_alloc_resize(&m->alloc, m->wall_acc, (size_t)m->cap_wall_acc, (size_t)(nb * nw), sizeof *q);
        if (!q) return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
        m->wall_acc = q;
        m->cap_wall_acc = nb * nw;
    }
    /* decomposed: this rank runs the blocks with a ball of its own, then
     * every rank has the sums of every block from the rank owning its last
     * ball (decompose.c) */
    const sx_dd *dd = m->dd && m->dd->active ? m->dd : NULL;
    const int64_t b_lo = dd ? dd->wrun[dd->x.rank].lo : 0, b_hi = dd ? dd->wrun[dd->x.rank].hi : nb;
    for (int64_t b = 0; dd && b < nb; b++)
        if (b < b_lo || b >= b_hi) m->blocks[b].st = SX_OK, m->blocks[b].slip = m->blocks[b].viscous = 0;
#pragma omp parallel for schedule(static) num_threads(m->threads) if (b_hi - b_lo > 1)
    for (int64_t b = b_lo; b < b_hi; b++) wall_block(m, &m->blocks[b], nw ? m->wall_acc + b * nw : NULL);
    /* decomposed, the blocks' sums come from the ranks sharing them when
     * the step reads the resultants; else once, at the cycle's end */
    if (dd && !sx__walls_read_in_step(m)) m->dd->walls_stale = true;
    else if (dd && !sx__dd_walls(m, true)) return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange wall forces");
    for (int64_t b = 0; b < nb; b++) {
        const sx_block *o = &m->blocks[b];
        if (o->st && m->dd) m->dd->own_error = true; /* past the exchange above: kept and agreed on */
        if (o->st == SX_EINVAL)
            return sx__fail(m, SX_EINVAL,
                            "ball %lld is near %.0f facets of mesh wall %lld, more than %d: the mesh is too fine for "
                            "a ball of radius %g m (coarsen it)",
                            (long long)o->err_ball, o->err_un, (long long)o->err_wall, MESH_ROWS_MAX, o->err_r);
        if (o->st) return overlap_error(m, "ball", "wall", o->err_ball, o->err_wall, o->err_un, o->err_r);
        if (!dd) { /* decomposed: the energy sums are the ranks' to chain (dd_energy.c, sx__dd_energy) */
            m->acc.slip += o->slip;
            m->acc.viscous += o->viscous;
        }
    }
    if (!dd) sx__walls_sum(m);
    if (m->track_energy) /* boundary work of the moving walls over this step (and a mesh's turn) */
        for (int64_t w = 0; w < nw; w++) {
            const sx_wall *wl = &m->walls[w];
            double turn = 0;
#if D == 3
            if (wl->mesh) turn = dot(wl->moment, wl->def.spin);
#endif
            m->acc.boundary_work -= (dot(wl->force, wl->def.vel) + wl->def.radial_vel * wl->load + turn) * m->dt;
        }
    return SX_OK;
}
