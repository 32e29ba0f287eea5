/* Periodic space and its deformable cell (issue 15): the cell's definition
 * and control, the ghost table's bookkeeping when balls come and go, and
 * the cell's motion after each step. The per-dimension work (wrapping
 * balls into the cell, making ghosts and their pairs, copying owners into
 * ghosts, the cell's stress) is in kernels/ghosts.c.
 *
 * The cell deforms as H' = G H, G upper triangular: the normal strain
 * rates on its diagonal, the shear rates above it (G_xy = d tilt_xy/dt /
 * len_y, simple shear). Balls are not moved with the cell: the cell's
 * motion reaches them through their images, whose velocity carries the
 * cell vectors' rate, so the contact law sees the relative motion the
 * deformation imposes (PFC's periodic space does the same). The servo is
 * PFC's: a rate proportional to the stress error, scaled by the stiffness
 * the cell measures so that one step removes a fraction alpha of it. */
#include "clumps.h"
#include "model_internal.h"
#include "state.h"

#include <math.h>
#include <stdio.h>
#include <string.h>


/* Component c's axes (i, j): a normal one (i, i), a shear one i < j. */
static void component_axes(int c, int *i, int *j)
{
    static const int ax[SX_CELL_COMPONENTS][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    *i = ax[c][0], *j = ax[c][1];
}

/* The components a model of dimension dim has (2D: xx, yy, xy). */
static bool component_in(int c, int dim)
{
    int i, j;
    component_axes(c, &i, &j);
    return i < dim && j < dim;
}

/* ------------------------------------------------------------ the cell */

static void drop_ghost_pairs(sx_model *m);
static double set_rates(sx_model *m, const double g[3][3]);
static void gradient(const sx_model *m, const double stress[3][3], const double *stiff, double g[3][3]);

sx_status sx_model_set_periodic(sx_model *m, const sx_periodic_def *def)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "set_periodic: the model is stepping; change the space between cycles");
    const int d = m->dim;
    bool any = false;
    for (int k = 0; k < d; k++) any |= def->axis[k];
    for (int k = d; k < 3; k++)
        if (def->axis[k]) return sx__fail(m, SX_EINVAL, "set_periodic: a %dD model has no axis %c", d, "xyz"[k]);
    if (!any) { /* back to open space: contacts through the boundary end (their bonds break) */
        if (m->cell) {
            drop_ghost_pairs(m);
            sx__cell_free(m);
            m->build_needed = true;
        }
        return SX_OK;
    }
    for (int k = 0; k < d; k++) {
        if (!def->axis[k]) continue;
        if (!isfinite(def->lo[k]) || !(def->len[k] > 0) || !isfinite(def->len[k]))
            return sx__fail(m, SX_EINVAL,
                            "set_periodic: axis %c needs a finite corner lo and a length > 0 m (got lo %g, len %g)",
                            "xyz"[k], def->lo[k], def->len[k]);
    }
    for (int c = SX_CELL_XY; c <= SX_CELL_YZ; c++) {
        int i, j;
        component_axes(c, &i, &j);
        const double t = def->tilt[c - SX_CELL_XY];
        if (!isfinite(t)) return sx__fail(m, SX_EINVAL, "set_periodic: the tilt %c%c must be finite", "xyz"[i], "xyz"[j]);
        if (t != 0 && !(j < d && def->axis[i] && def->axis[j]))
            return sx__fail(m, SX_EINVAL, "set_periodic: a tilt %c%c couples two periodic axes: make %c and %c periodic",
                            "xyz"[i], "xyz"[j], "xyz"[i], "xyz"[j]);
    }
    if (!m->cell) {
        m->cell = sx_alloc_resize(&m->alloc, NULL, 0, 1, sizeof *m->cell);
        if (!m->cell) return sx__fail(m, SX_ENOMEM, "set_periodic: out of memory");
        memset(m->cell, 0, sizeof *m->cell);
        m->cell->ctl = sx_cell_default_control();
        m->cell->base = m->balls.n;
    }
    sx_cell *c = m->cell;
    memset(c->h, 0, sizeof c->h);
    for (int k = 0; k < 3; k++) {
        c->axis[k] = k < d && def->axis[k];
        c->lo[k] = c->axis[k] ? def->lo[k] : 0;
        c->h[k][k] = c->axis[k] ? def->len[k] : 1;
    }
    c->h[1][0] = def->tilt[0], c->h[2][0] = def->tilt[1], c->h[2][1] = def->tilt[2];
    double g[3][3]; /* a control's rates hold for the new cell vectors */
    gradient(m, NULL, NULL, g);
    set_rates(m, g);
    m->build_needed = true; /* balls wrapped, ghosts made at the next build */
    m->guard_dirty = true;
    return SX_OK;
}

bool sx_model_periodic(const sx_model *m, sx_periodic_def *out)
{
    memset(out, 0, sizeof *out);
    const sx_cell *c = m->cell;
    if (!c) return false;
    for (int k = 0; k < 3; k++) {
        out->axis[k] = c->axis[k];
        out->lo[k] = c->lo[k];
        out->len[k] = c->axis[k] ? c->h[k][k] : 0;
    }
    out->tilt[0] = c->h[1][0], out->tilt[1] = c->h[2][0], out->tilt[2] = c->h[2][1];
    return true;
}

/* The thickness of the cell across axis k: the distance between its two
 * faces f_k = 0 and f_k = 1 (volume over the area of the face). */
double sx__cell_thickness(const sx_cell *c, int dim, int k)
{
    if (dim == 2) {
        const double area = c->h[0][0] * c->h[1][1];
        const double *o = c->h[1 - k];
        return area / sqrt(o[0] * o[0] + o[1] * o[1]);
    }
    const double *p = c->h[(k + 1) % 3], *q = c->h[(k + 2) % 3];
    const double n[3] = {p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]};
    return c->h[0][0] * c->h[1][1] * c->h[2][2] / sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

sx_status sx__cell_check(sx_model *m)
{
    const sx_balls *b = &m->balls;
    if (!m->cell || b->n == 0) return SX_OK;
    /* the reach of a contact the broad phase lists: two of the largest
     * balls and the skin (the build's automatic skin, a fifth of the mean radius) */
    double rmax = 0, sum = 0;
    for (int64_t i = 0; i < b->n; i++) {
        if (b->rad[i] > rmax) rmax = b->rad[i];
        sum += b->rad[i];
    }
    const double skin = m->skin_user > 0 ? m->skin_user : 0.2 * sum / (double)b->n;
    const double reach = 2 * rmax + skin;
    for (int k = 0; k < m->dim; k++) {
        if (!m->cell->axis[k]) continue;
        const double t = sx__cell_thickness(m->cell, m->dim, k);
        /* an image nearer than the reach on both sides would pair twice */
        if (!(t > 2 * reach)) {
            /* a tilt thins the cell across its other axes (a sheared cell:
             * the message had said only "make the cell larger") */
            bool tilted = false;
            for (int a = 0; a < m->dim; a++)
                for (int i = 0; i < m->dim; i++) tilted |= i != a && m->cell->h[a][i] != 0;
            return sx__fail(m, SX_EINVAL,
                            "periodic space: the cell is %g m thick across axis %c, less than twice the contact "
                            "reach (2 x (2 x largest radius %g m + skin %g m) = %g m); %s",
                            t, "xyz"[k], rmax, skin, 2 * reach,
                            tilted ? "its tilt thins it (a simple shear to a strain of about the cell's aspect "
                                     "ratio or more): shear less, or start from a taller cell"
                                   : "make the cell larger");
        }
    }
    return SX_OK;
}

void sx__cell_frac(const sx_cell *c, int dim, const double *x, double *f)
{
    for (int k = 2; k >= 0; k--) {
        f[k] = 0;
        if (k >= dim || !c->axis[k]) continue;
        double r = x[k] - c->lo[k];
        for (int j = k + 1; j < dim; j++) r -= c->h[j][k] * f[j];
        f[k] = r / c->h[k][k];
    }
}

void sx__cell_wrap(const sx_cell *c, int dim, double *x, int32_t *n)
{
    double f[3];
    sx__cell_frac(c, dim, x, f);
    for (int k = 0; k < 3; k++) n[k] = k < dim && c->axis[k] ? (int32_t)floor(f[k]) : 0;
    for (int k = 0; k < dim; k++)
        if (n[k])
            for (int q = 0; q <= k; q++) x[q] -= n[k] * c->h[k][q];
}

void sx__cell_wrap_clumps(sx_model *m, int32_t *wrap)
{
    sx_clumps *cl = m->clumps;
    const int d = m->dim;
    for (int64_t c = 0; c < cl->n; c++) {
        int32_t n[3];
        sx__cell_wrap(m->cell, d, cl->x + c * d, n);
        if (!n[0] && !n[1] && !n[2]) continue;
        const int64_t np = cl->tpl[cl->tpl_of[c]].n;
        for (int64_t k = 0; k < np; k++) { /* its pebbles by the same cell vectors */
            const int64_t i = m->balls.index_of[cl->pebble[cl->first[c] + k]];
            for (int a = 0; a < d; a++)
                if (n[a])
                    for (int q = 0; q <= a; q++) m->balls.x[i * d + q] -= n[a] * m->cell->h[a][q];
            memcpy(wrap + i * 3, n, sizeof n);
        }
    }
}

/* ------------------------------------------------------------- control */

sx_cell_control sx_cell_default_control(void)
{
    sx_cell_control c;
    memset(&c, 0, sizeof c);
    c.alpha = 0.5;
    c.max_rate = 1;
    return c;
}

/* Why a control cannot drive m's cell (written into why), or NULL. */
static const char *control_problem(const sx_model *m, const sx_cell_control *ctl, bool *on, char *why, size_t len)
{
    *on = false;
    for (int k = 0; k < SX_CELL_COMPONENTS; k++) {
        const sx_cell_mode mode = ctl->mode[k];
        if (mode != SX_CELL_FIXED && mode != SX_CELL_RATE && mode != SX_CELL_STRESS)
            return snprintf(why, len, "unknown mode %d", (int)mode), why;
        if (mode != SX_CELL_FIXED && !component_in(k, m->dim))
            return snprintf(why, len, "a 2D cell has no component %d (xx, yy, xy only)", k), why;
        if (!isfinite(ctl->rate[k]) || !isfinite(ctl->target[k]))
            return snprintf(why, len, "rates and targets must be finite"), why;
        *on |= mode != SX_CELL_FIXED;
    }
    for (int k = 0; k < m->dim && *on; k++)
        if (!m->cell || !m->cell->axis[k])
            return snprintf(why, len, "the space must be periodic on every axis (make it periodic first)"), why;
    if (!(ctl->alpha > 0 && ctl->alpha <= 1)) return snprintf(why, len, "alpha must be in (0, 1] (got %g)", ctl->alpha), why;
    if (!(ctl->max_rate > 0) || !isfinite(ctl->max_rate))
        return snprintf(why, len, "max_rate must be > 0 1/s (got %g)", ctl->max_rate), why;
    return NULL;
}

sx_status sx_cell_set_control(sx_model *m, const sx_cell_control *ctl)
{
    char why[160];
    bool on;
    if (control_problem(m, ctl, &on, why, sizeof why)) return sx__fail(m, SX_EINVAL, "cell_control: %s", why);
    if (!m->cell) return sx__fail(m, SX_EINVAL, "cell_control: the space is not periodic (make it periodic first)");
    m->cell->ctl = *ctl;
    m->cell->controlled = on;
    /* the rates hold from the next step on, so the images move with the
     * cell in its first contact pass already (a servo starts at rest) */
    double g[3][3];
    gradient(m, NULL, NULL, g);
    set_rates(m, g);
    m->guard_dirty = true;
    return SX_OK;
}

sx_status sx_cell_control_get(const sx_model *m, sx_cell_control *ctl)
{
    *ctl = m->cell ? m->cell->ctl : sx_cell_default_control();
    return SX_OK;
}

sx_status sx_cell_stress(const sx_model *m, double stress[3][3], double *volume)
{
    memset(stress, 0, 9 * sizeof(double));
    *volume = 0;
    for (int k = 0; k < m->dim; k++)
        if (!m->cell || !m->cell->axis[k])
            return sx__fail((sx_model *)m, SX_EINVAL, "cell_stress: the space must be periodic on every axis");
    if (!sx__kernels(m)->cell_stress(m, stress, NULL))
        return sx__fail((sx_model *)m, SX_EINVAL, "cell_stress: the ranks could not exchange");
    *volume = 1;
    for (int k = 0; k < m->dim; k++) *volume *= m->cell->h[k][k];
    return SX_OK;
}

/* The cell vectors' rate H' = G H, G the velocity gradient (upper
 * triangular); returns how far an image may move in a step. */
static double set_rates(sx_model *m, const double g[3][3])
{
    sx_cell *c = m->cell;
    const int d = m->dim;
    double moved = 0;
    for (int k = 0; k < d; k++) {
        double s = 0;
        for (int i = 0; i < d; i++) {
            double r = 0;
            for (int j = 0; j < d; j++) r += g[i][j] * c->h[k][j];
            c->hdot[k][i] = r;
            s += r * r;
        }
        moved += sqrt(s) * m->dt; /* an image shifted by several cell vectors moves by at most their sum */
    }
    return moved;
}

/* The velocity gradient the control asks for: its rates, and the servo's
 * from the stress of the last step (stress, stiff; NULL before any). */
static void gradient(const sx_model *m, const double stress[3][3], const double *stiff, double g[3][3])
{
    const sx_cell_control *ctl = &m->cell->ctl;
    memset(g, 0, 9 * sizeof(double));
    for (int k = 0; k < SX_CELL_COMPONENTS; k++) {
        int i, j;
        component_axes(k, &i, &j);
        if (ctl->mode[k] == SX_CELL_RATE) {
            g[i][j] = ctl->rate[k];
        } else if (ctl->mode[k] == SX_CELL_STRESS && stress) {
            /* PFC's servo: the error over the stress per unit strain, a fraction alpha of it per step;
             * without contacts (K = 0) the cell closes (or opens) at the bound */
            const double err = stress[i][j] - ctl->target[k], lim = ctl->max_rate;
            double rate = stiff[k] > 0 ? ctl->alpha * err / (stiff[k] * m->dt) : (err > 0 ? lim : -lim);
            if (err == 0) rate = 0;
            g[i][j] = rate > lim ? lim : rate < -lim ? -lim : rate;
        }
    }
}

sx_status sx__cell_rate(sx_model *m)
{
    sx_cell *c = m->cell;
    if (!c->controlled) return SX_OK;
    bool servo = false;
    for (int k = 0; k < SX_CELL_COMPONENTS; k++) servo |= c->ctl.mode[k] == SX_CELL_STRESS;
    double stress[3][3], stiff[SX_CELL_COMPONENTS], g[3][3];
    if (servo && !sx__kernels(m)->cell_stress(m, stress, stiff)) /* decomposed: the ranks failed */
        return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the cell's stress");
    gradient(m, servo ? stress : NULL, stiff, g);
    /* a move that would flatten the cell or turn it inside out is an error
     * before any body moves, the step undone (a rate of -1e4/s had made a
     * cell -0.9 m wide, and the model saved then could not be loaded) */
    const sx_cell before = *c;
    c->moved += set_rates(m, g);
    sx_cell trial = *c;
    for (int k = 0; k < m->dim; k++)
        for (int i = 0; i < m->dim; i++) trial.h[k][i] += c->hdot[k][i] * m->dt;
    for (int k = 0; k < m->dim; k++) {
        const double t = sx__cell_thickness(&trial, m->dim, k);
        if (isfinite(t) && t > 0 && isfinite(trial.h[k][k])) continue;
        *c = before;
        return sx__fail(m, SX_EINVAL,
                        "periodic space: the cell's deformation would make it %g m thick across axis %c at step %lld; "
                        "lower the rate of its control (m:cell_control)",
                        t, "xyz"[k], (long long)m->step + 1);
    }
    return SX_OK;
}

void sx__cell_move(sx_model *m)
{
    sx_cell *c = m->cell;
    if (!c->controlled) return;
    /* by H' dt, as the balls moved (leapfrog: H' at the half step) */
    for (int k = 0; k < m->dim; k++)
        for (int i = 0; i < m->dim; i++) c->h[k][i] += c->hdot[k][i] * m->dt;
}

/* ------------------------------------------------------- ghost bookkeeping */

int64_t sx__cell_owner(const sx_model *m, int64_t j, double *shift)
{
    const sx_cell *c = m->cell;
    for (int k = 0; k < m->dim; k++) shift[k] = 0;
    if (!c || j < c->base) return j;
    const int8_t *s = c->image + (j - c->base) * 3;
    for (int k = 0; k < m->dim; k++)
        for (int i = 0; i < m->dim; i++) shift[i] += s[k] * c->h[k][i];
    return c->owner[j - c->base];
}

void sx__cell_ghosts_move(sx_model *m, int64_t to, bool rename)
{
    sx_cell *c = m->cell;
    const int64_t from = c->base, n = c->n;
    if (to == from) return;
    if (n > 0) {
        sx_ball_field f[SX_BALL_FIELDS_MAX];
        const int nf = sx__ball_fields(m, &m->balls, f);
        for (int k = 0; k < nf; k++) {
            if (!f[k].ghost) continue;
            const size_t row = sx__ball_row(&f[k]);
            memmove((char *)*f[k].data + (size_t)to * row, (char *)*f[k].data + (size_t)from * row, (size_t)n * row);
        }
        for (int64_t q = 0; q < m->bb.n && rename; q++)
            if (m->bb.b[q] >= from) m->bb.b[q] += (int32_t)(to - from);
    }
    c->base = to;
}

void sx__cell_ghosts_remap(sx_model *m, int32_t *remap, int64_t keep)
{
    sx_cell *c = m->cell;
    for (int64_t g = 0; g < c->n; g++) {
        const int32_t o = c->owner[g] >= 0 ? remap[c->owner[g]] : -1;
        c->owner[g] = o;
        remap[c->base + g] = o >= 0 ? (int32_t)(keep + g) : -1;
    }
}

sx_status sx__cell_reserve(sx_model *m, int64_t base, int64_t n)
{
    sx_cell *c = m->cell;
    if (sx__balls_reserve(m, base + n)) return SX_ENOMEM;
    if (n <= c->cap) return SX_OK;
    int64_t cap = c->cap ? 2 * c->cap : 64;
    if (cap < n) cap = n;
    int32_t *o = sx_alloc_resize(&m->alloc, c->owner, (size_t)c->cap, (size_t)cap, sizeof *o);
    if (!o) return SX_ENOMEM;
    c->owner = o;
    int8_t *s = sx_alloc_resize(&m->alloc, c->image, (size_t)c->cap * 3, (size_t)cap * 3, sizeof *s);
    if (!s) return SX_ENOMEM;
    c->image = s;
    c->cap = cap;
    return SX_OK;
}

/* The pairs through the boundary leave the store (their bonds break). */
static void drop_ghost_pairs(sx_model *m)
{
    sx_pairs *p = &m->bb;
    int64_t k = 0;
    for (int64_t q = 0; q < p->n; q++) {
        if (p->b[q] >= m->cell->base) {
            if (p->bond && p->bond[q]) sx__bond_break(m, p->bond[q] - 1, m->bonds.kind[p->bond[q] - 1]);
            continue;
        }
        sx__pair_move(m, p, k++, q);
    }
    p->n = k;
}

sx_status sx__cell_restore(sx_model *m, const sx_cell *saved)
{
    if (!m->cell) {
        m->cell = sx_alloc_resize(&m->alloc, NULL, 0, 1, sizeof *m->cell);
        if (!m->cell) return sx__fail(m, SX_ENOMEM, "state: out of memory");
        memset(m->cell, 0, sizeof *m->cell);
    }
    sx_cell *c = m->cell;
    const int64_t cap = c->cap;
    int32_t *owner = c->owner;
    int8_t *image = c->image;
    double *shifted = c->shifted;
    const int64_t cap_shifted = c->cap_shifted;
    *c = *saved;
    c->cap = cap, c->owner = owner, c->image = image, c->shifted = shifted, c->cap_shifted = cap_shifted;
    c->base = m->balls.n;
    if (c->n < 0 || c->n > INT32_MAX - m->balls.n)
        return sx__fail(m, SX_EINVAL, "state: %lld ghosts", (long long)c->n);
    return sx__cell_reserve(m, c->base, c->n) ? sx__fail(m, SX_ENOMEM, "state: out of memory for the ghosts")
                                               : SX_OK;
}

sx_status sx__cell_finish(sx_model *m)
{
    sx_cell *c = m->cell;
    const int d = m->dim;
    bool any = false;
    for (int k = 0; k < 3; k++) {
        if (!c->axis[k]) continue;
        any = true;
        if (k >= d || !(c->h[k][k] > 0) || !isfinite(c->h[k][k]) || !isfinite(c->lo[k]))
            return sx__fail(m, SX_EINVAL, "state: the periodic cell's axis %c is out of range", "xyz"[k]);
    }
    /* by rows' squared lengths and the volume: a finite 1e300 overflows the cell's products */
    double volume = 1;
    for (int k = 0; k < 3; k++) {
        if (c->axis[k]) volume *= c->h[k][k];
        if (!sx__state_length_finite(c->h[k], 3) || !sx__state_length_finite(c->hdot[k], 3) || !isfinite(volume))
            return sx__fail(m, SX_EINVAL, "state: the periodic cell's vectors or rates are not finite or too large");
        for (int i = k + 1; i < 3; i++)
            if (c->h[k][i] != 0)
                return sx__fail(m, SX_EINVAL, "state: the periodic cell's vectors are not upper triangular");
    }
    if (!any) return sx__fail(m, SX_EINVAL, "state: a periodic cell without a periodic axis");
    char why[160];
    if (control_problem(m, &c->ctl, &c->controlled, why, sizeof why))
        return sx__fail(m, SX_EINVAL, "state: the cell's control: %s", why);
    for (int64_t g = 0; g < c->n; g++) {
        if (c->owner[g] < 0 || c->owner[g] >= m->balls.n)
            return sx__fail(m, SX_EINVAL, "state: ghost %lld images ball %d of %lld", (long long)g, c->owner[g],
                            (long long)m->balls.n);
        for (int k = 0; k < 3; k++) {
            const int s = c->image[g * 3 + k];
            if (s < -1 || s > 1 || (s && !c->axis[k]))
                return sx__fail(m, SX_EINVAL, "state: ghost %lld has a bad image", (long long)g);
        }
    }
    sx__kernels(m)->ghosts_refresh(m, true);
    return SX_OK;
}

uint64_t sx__cell_hash(const sx_model *m, uint64_t h)
{
    const sx_cell *c = m->cell;
    for (int k = 0; k < 3; k++) h = sx__fnv(h, &c->axis[k], sizeof c->axis[k]);
    h = sx__fnv_doubles(h, c->lo, 3, 1);
    h = sx__fnv_doubles(h, &c->h[0][0], 9, 1);
    h = sx__fnv_doubles(h, &c->hdot[0][0], 9, 1);
    /* the control (the snapshot's /periodic) */
    for (int k = 0; k < SX_CELL_COMPONENTS; k++) h = sx__fnv(h, &c->ctl.mode[k], sizeof c->ctl.mode[k]);
    h = sx__fnv_doubles(h, c->ctl.rate, SX_CELL_COMPONENTS, 1);
    h = sx__fnv_doubles(h, c->ctl.target, SX_CELL_COMPONENTS, 1);
    h = sx__fnv_doubles(h, &c->ctl.alpha, 1, 1);
    h = sx__fnv_doubles(h, &c->ctl.max_rate, 1, 1);
    /* a pending build counts as done (state.c) */
    const double moved = m->build_needed ? 0 : c->moved;
    h = sx__fnv_doubles(h, &moved, 1, 1);
    h = sx__fnv(h, &c->n, sizeof c->n);
    for (int64_t g = 0; g < c->n; g++) { /* owners by id: the hash does not depend on the balls' row order */
        const int32_t id = c->owner[g] >= 0 ? m->balls.id[c->owner[g]] : -1;
        h = sx__fnv(h, &id, sizeof id);
    }
    return sx__fnv(h, c->image, (size_t)c->n * 3);
}

size_t sx__cell_bytes(const sx_model *m)
{
    const sx_cell *c = m->cell;
    return c ? sizeof *c + (size_t)c->cap * (sizeof *c->owner + 3) + (size_t)c->cap_shifted * sizeof(double) : 0;
}

void sx__cell_free(sx_model *m)
{
    sx_cell *c = m->cell;
    if (!c) return;
    sx_alloc_free(&m->alloc, c->owner, (size_t)c->cap, sizeof *c->owner);
    sx_alloc_free(&m->alloc, c->image, (size_t)c->cap * 3, sizeof *c->image);
    sx_alloc_free(&m->alloc, c->shifted, (size_t)c->cap_shifted, sizeof *c->shifted);
    sx_alloc_free(&m->alloc, c, 1, sizeof *c);
    m->cell = NULL;
}
