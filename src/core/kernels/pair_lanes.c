/* The common case (linear laws without a shear dashpot, no bonds, no
 * energy tracking) of ball_chunk_pass, four pairs at a time: each pair's
 * inputs are loaded straight into one lane of vector registers, every
 * formula runs on the four lanes at once (branches become selects: a pair
 * out of contact or not slipping takes the same lanes, and multiplying by
 * a scale of exactly 1 changes nothing), and the results are scattered
 * in pair order. Each lane does the scalar pass's arithmetic in its
 * order, so both give the same bits. Included twice by pair_contacts.c
 * (part of the per-dimension unit kernels.c; not compiled alone): with
 * LISTED 0 it makes ball_chunk_batched, over the chunk's pairs [first,
 * last); with LISTED 1 ball_chunk_listed, over the pairs list[first,
 * last) (decomposed: decompose.c, plan_inpairs), gathered into the lanes
 * as a short batch is. */
#if LISTED
SX_VECTOR_CLONES static void ball_chunk_listed(sx_model *m, sx_chunk *o, const int32_t *list)
#else
SX_VECTOR_CLONES static void ball_chunk_batched(sx_model *m, sx_chunk *o)
#endif
{
    sx_balls *B = &m->balls;
    sx_pairs *p = &m->bb;
    const double *restrict x = B->x, *restrict v = B->v, *restrict w = B->w, *restrict rad = B->rad;
    const double *restrict im = m->dash_im_now; /* the dashpots' (dashpot_inverse_mass) */
    const uint16_t *restrict mat = B->mat;
    const int32_t *restrict pa = p->a, *restrict pb = p->b;
    double *restrict fs_all = p->fs, *restrict geo_all = p->geo, *restrict fn_all = p->fn;
    uint8_t *restrict touching = p->touching;
    double *restrict f = B->f, *restrict t = B->t;
    const sx_pair_law *laws = m->law;
    const int nlaw = m->law_n;
    chunk_start(m, o);
    const double dt = motion_dt(m);
    /* the law's parameters per lane; with one material, the same in every lane */
    vd kn = VZERO + laws->kn, ks = VZERO + laws->ks, mu = VZERO + laws->mu, dash = VZERO + laws->dash_n,
       bn = VZERO + laws->beta_n;
    /* the dashpot's sqrt(dash / (1/ma + 1/mb)) of the last lanes that needed one:
     * balls of one size and material share it */
    double memo_dash = NAN, memo_sim = NAN, memo_cn = 0;

    for (int64_t c0 = o->first; c0 < o->last; c0 += LANES) {
        const int nb = o->last - c0 < LANES ? (int)(o->last - c0) : LANES;
        int64_t cc[LANES], i[LANES], j[LANES]; /* lanes past nb repeat the first pair */
        for (int q = 0; q < LANES; q++) {
#if LISTED
            cc[q] = list[c0 + (q < nb ? q : 0)];
#else
            cc[q] = c0 + (q < nb ? q : 0);
#endif
            i[q] = pa[cc[q]], j[q] = pb[cc[q]];
        }
        if (nlaw > 1)
            for (int q = 0; q < LANES; q++) {
                const sx_pair_law *law = &laws[mat[i[q]] * nlaw + mat[j[q]]];
                kn[q] = law->kn, ks[q] = law->ks, mu[q] = law->mu, dash[q] = law->dash_n, bn[q] = law->beta_n;
            }
        /* the history as stored, four consecutive pairs by shuffles (a short
         * batch, or listed pairs, copied to four pairs first) */
#if LISTED
        const bool full = false;
#else
        const bool full = nb == LANES;
#endif
        double tail[2 * LANES * D];
        uint8_t tail_touching[LANES];
        const double *hfs = fs_all + c0 * D, *hrel = geo_all + c0 * D;
        const uint8_t *htouching = touching + c0;
        if (!full) {
            for (int q = 0; q < LANES; q++) {
                memcpy(tail + q * D, fs_all + cc[q] * D, D * sizeof(double));
                memcpy(tail + (LANES + q) * D, geo_all + cc[q] * D, D * sizeof(double));
                tail_touching[q] = touching[cc[q]];
            }
            hfs = tail, hrel = tail + LANES * D, htouching = tail_touching;
        }
        vd fs_old[D], rel_old[D];
        load_lanes(hfs, fs_old);
        load_lanes(hrel, rel_old);
        v4u8 touched;
        memcpy(&touched, htouching, sizeof touched);
        const vm had = __builtin_convertvector(touched, vm) != 0;

        /* the previous normal from the relative position as in ball_chunk_pass
         * (first: its square root and division overlap the loads below) */
        vd rr = VZERO;
        for (int k = 0; k < D; k++) rr += rel_old[k] * rel_old[k];
        const vd inv_r = 1.0 / VSQRT(rr);

        vd dx[D], dv[D];
        for (int k = 0; k < D; k++) {
            dx[k] = LANES_OF(x, j, D, k) - LANES_OF(x, i, D, k);
            dv[k] = LANES_OF(v, j, D, k) - LANES_OF(v, i, D, k);
        }
        const vd ri = LANES_OF(rad, i, 1, 0), rj = LANES_OF(rad, j, 1, 0);

        /* 4-1 ... 4-4 */
        /* sums from zero, as dot() (the sign of a zero sum) */
        vd d2 = VZERO;
        for (int k = 0; k < D; k++) d2 += dx[k] * dx[k];
        const vd d = VSQRT(d2), inv_d = 1.0 / d;
        vd n[D];
        for (int k = 0; k < D; k++) n[k] = dx[k] * inv_d;
        const vd rsum = ri + rj, u = rsum - d;
        const vd la = ri - 0.5 * u, lb = rj - 0.5 * u;
        /* 4-16, 4-17 as in ball_chunk_pass */
        vd ws[RD], vc[D];
#if D == 3
        vd wsum[3]; /* for 4-15 */
#endif
        for (int k = 0; k < RD; k++) {
            const vd wa = LANES_OF(w, i, RD, k), wb = LANES_OF(w, j, RD, k);
            ws[k] = la * wa + lb * wb;
#if D == 3
            wsum[k] = wa + wb;
#endif
        }
#if D == 3
        vc[0] = dv[0] - (ws[1] * n[2] - ws[2] * n[1]);
        vc[1] = dv[1] - (ws[2] * n[0] - ws[0] * n[2]);
        vc[2] = dv[2] - (ws[0] * n[1] - ws[1] * n[0]);
#else
        vc[0] = dv[0] - -ws[0] * n[1];
        vc[1] = dv[1] - ws[0] * n[0];
#endif
        vd vn = VZERO;
        for (int k = 0; k < D; k++) vn += vc[k] * n[k];
        vd vs[D];
        for (int k = 0; k < D; k++) vs[k] = vc[k] - vn * n[k];
        const vd fn = kn * u; /* 4-6 */
        const vd fmax = mu * VSEL(fn > VZERO, fn, VZERO);
        /* the shear force (none for a new contact) */
        vd g[D], prev[D];
        for (int k = 0; k < D; k++) prev[k] = rel_old[k] * inv_r;
#if D == 3
        shear_lanes(g, fs_old, prev, &had, n, wsum, vs, &ks, &fmax, dt);
#else
        shear_lanes(g, fs_old, prev, &had, n, NULL, vs, &ks, &fmax, dt);
#endif
        const vm active = u > VZERO;
        const vd sim = LANES_OF(im, i, 1, 0) + LANES_OF(im, j, 1, 0);
        vd cn;
        const vm other = (sim != memo_sim) | (dash != memo_dash);
        if (!VANY(other)) {
            cn = VZERO + memo_cn;
        } else {
            cn = VSQRT(VSEL(sim > VZERO, dash / sim, VZERO)); /* 0: both balls fixed, no dashpot */
            memo_sim = sim[0], memo_dash = dash[0], memo_cn = cn[0];
        }
        const vd fd = VSEL(active & (bn > VZERO), fn + -cn * vn, fn);
        vd F[D];
        for (int k = 0; k < D; k++) {
            F[k] = VSEL(active, fd * n[k] + g[k], VZERO); /* 4-5 */
            g[k] = VSEL(active, g[k], VZERO);
        }
        /* 4-21: both arms lie along n */
        vd nf[RD];
#if D == 3
        nf[0] = n[1] * F[2] - n[2] * F[1];
        nf[1] = n[2] * F[0] - n[0] * F[2];
        nf[2] = n[0] * F[1] - n[1] * F[0];
#else
        nf[0] = n[0] * F[1] - n[1] * F[0];
#endif
        vd ma[RD], mj[RD];
        for (int k = 0; k < RD; k++) ma[k] = la * nf[k], mj[k] = -lb * nf[k];
        const vd fdo = VSEL(active, fd, VZERO);
        const vm live = d2 < rsum * rsum;
        const vm bad = live & (u > VSEL(ri < rj, ri, rj));
        if (VANY(bad))
            for (int q = 0; q < nb; q++)
                if (bad[q]) {
                    o->st = SX_EUNSTABLE;
                    o->err_a = B->id[i[q]], o->err_b = B->id[j[q]], o->err_un = u[q];
                    o->err_r = ri[q] < rj[q] ? ri[q] : rj[q];
                    return;
                }
        /* a pair out of reach this step keeps its history, untouched, and has no force */
        if (full) {
            vd keep[D];
            for (int k = 0; k < D; k++) keep[k] = VSEL(live, g[k], fs_old[k]);
            store_lanes(fs_all + c0 * D, keep);
            for (int k = 0; k < D; k++) keep[k] = VSEL(live, dx[k], rel_old[k]);
            store_lanes(geo_all + c0 * D, keep);
            memcpy(fn_all + c0, &fdo, sizeof fdo); /* 0 out of reach, as in ball_chunk_pass */
            for (int q = 0; q < LANES; q++) touching[c0 + q] = (live[q] & active[q]) != 0;
        } else {
            for (int q = 0; q < nb; q++) {
                const int64_t c = cc[q];
                touching[c] = (live[q] & active[q]) != 0;
                fn_all[c] = fdo[q];
                if (!live[q]) continue;
                for (int k = 0; k < D; k++) fs_all[c * D + k] = g[k][q], geo_all[c * D + k] = dx[k][q];
            }
        }
        for (int q = 0; q < nb; q++) {
            if (!live[q]) continue;
            double *fi = f + i[q] * D, *ti = t + i[q] * RD, *fj = f + j[q] * D, *tj = t + j[q] * RD;
            for (int k = 0; k < D; k++) {
                fi[k] -= F[k][q];
                fj[k] += F[k][q];
            }
            for (int k = 0; k < RD; k++) {
                ti[k] -= ma[k][q];
                tj[k] += mj[k][q];
            }
        }
    }
}

