/* A clump template's mass properties (sx__clump_mass_props). Volume,
 * centroid and inertia tensor of the union of the pebbles, per unit
 * density: exact sums (parallel axes) of the spheres or disks, minus what
 * the overlaps count twice. That correction is the integral of (number of
 * pebbles covering a point) - 1 over the points covered, nonzero only in
 * the lenses where pebbles overlap. It is integrated on a grid of lines
 * parallel to x through the lenses' bounding box: along each line the
 * covered intervals are exact (sphere chords), so the line integrals of 1,
 * x, x^2 are closed forms; across the lines the midpoint rule (3D: a 2D
 * grid, 2D: a row of lines). The integrand has square-root edges at the
 * lenses' rims, so the error falls as (lines)^-1.5; it is estimated from
 * the spread of two integrations with half the lines (ERROR_SAFETY below)
 * and stored with the template, relative to the union's volume, size and
 * largest principal moment. At the default lines the tests find it below
 * 1e-5 (3D) and 1e-7 (2D) for pairs of every depth of overlap. Principal
 * axes come from a cyclic Jacobi eigen-solver of the symmetric 3x3 tensor. */
#include "clump_math.h"
#include "clumps_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------- principal axes */

/* The unit quaternion of a rotation matrix (largest-component branch, so
 * the division is always by the largest of |w|, |x|, |y|, |z|). */
static void matrix_quat(const double *R, double *q)
{
    const double tr = R[0] + R[4] + R[8];
    if (tr >= R[0] && tr >= R[4] && tr >= R[8]) {
        const double s = 2 * sqrt(1 + tr);
        q[0] = 0.25 * s, q[1] = (R[7] - R[5]) / s, q[2] = (R[2] - R[6]) / s, q[3] = (R[3] - R[1]) / s;
    } else if (R[0] >= R[4] && R[0] >= R[8]) {
        const double s = 2 * sqrt(1 + R[0] - R[4] - R[8]);
        q[0] = (R[7] - R[5]) / s, q[1] = 0.25 * s, q[2] = (R[1] + R[3]) / s, q[3] = (R[2] + R[6]) / s;
    } else if (R[4] >= R[8]) {
        const double s = 2 * sqrt(1 - R[0] + R[4] - R[8]);
        q[0] = (R[2] - R[6]) / s, q[1] = (R[1] + R[3]) / s, q[2] = 0.25 * s, q[3] = (R[5] + R[7]) / s;
    } else {
        const double s = 2 * sqrt(1 - R[0] - R[4] + R[8]);
        q[0] = (R[3] - R[1]) / s, q[1] = (R[2] + R[6]) / s, q[2] = (R[5] + R[7]) / s, q[3] = 0.25 * s;
    }
    if (q[0] < 0)
        for (int k = 0; k < 4; k++) q[k] = -q[k];
    qnormalize(q);
}

/* Eigen-decomposition of a symmetric 3x3 matrix A (row-major) by cyclic
 * Jacobi rotations: eigenvalues ascending in val, eigenvectors as the
 * columns of the rotation V (det +1). Each rotation zeroes one
 * off-diagonal entry; the off-diagonal norm falls quadratically once
 * small, so a few sweeps reach round-off. */
static void jacobi3(const double *A, double *val, double *V)
{
    double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) a[i][j] = 0.5 * (A[3 * i + j] + A[3 * j + i]);
    for (int sweep = 0; sweep < 64; sweep++) {
        const double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        const double diag = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        if (off <= DBL_MIN || off <= 1e-18 * diag) break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0) continue;
                /* the angle that zeroes a[p][q]: t = tan(phi), the smaller root */
                const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                const double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
                const double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A J (columns p, q) */
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* A <- J^T A (rows p, q) */
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) { /* V <- V J */
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (a[order[j]][order[j]] < a[order[i]][order[i]]) {
                const int t = order[i];
                order[i] = order[j], order[j] = t;
            }
    for (int j = 0; j < 3; j++) {
        val[j] = a[order[j]][order[j]];
        for (int i = 0; i < 3; i++) V[3 * i + j] = v[i][order[j]];
    }
    const double det = V[0] * (V[4] * V[8] - V[5] * V[7]) - V[1] * (V[3] * V[8] - V[5] * V[6]) +
                       V[2] * (V[3] * V[7] - V[4] * V[6]);
    if (det < 0)
        for (int i = 0; i < 3; i++) V[3 * i + 2] = -V[3 * i + 2]; /* a rotation, not a reflection */
}

/* ---------------------------------------------------------- integration */

/* Sums of a set of pebbles per unit density, about a reference point:
 * volume, first moments and the second-moment tensor J = integral of
 * r r^T (3x3; 2D uses the upper 2x2). */
typedef struct moments {
    double v, s[3], j[9];
} moments;

/* A covered interval of one line. */
typedef struct span {
    double a, b;
} span;

static int by_start(const void *p, const void *q)
{
    const span *a = p, *b = q;
    return a->a < b->a ? -1 : a->a > b->a;
}

/* Adds the line integrals of 1, u, u^2 over [a, b] (u = x - x0) times w. */
static void span_moments(double a, double b, double w, double *m0, double *m1, double *m2)
{
    *m0 += w * (b - a);
    *m1 += w * 0.5 * (b * b - a * a);
    *m2 += w * (b * b * b - a * a * a) / 3;
}

/* What the overlaps count twice, over a grid of n lines per axis parallel
 * to x across [lo, hi] (3D: in y and z, 2D: in y), about the point c: the
 * moments of sum over pebbles of their chords minus the chords' union.
 * Only the pebbles flagged in `in` (those overlapping another) take part. */
static sx_status overlap_correction(const sx_model *m, const double *pos, const double *rad, const uint8_t *in,
                                    int64_t np, const double *lo, const double *hi, int64_t n, double offset,
                                    const double *c, moments *out)
{
    const int d = m->dim;
    memset(out, 0, sizeof *out);
    span *sp = malloc((size_t)np * sizeof *sp);
    int64_t *row = malloc((size_t)np * sizeof *row);
    if (!sp || !row) {
        free(sp);
        free(row);
        return SX_ENOMEM;
    }
    const double hy = (hi[1] - lo[1]) / (double)n, hz = d == 3 ? (hi[2] - lo[2]) / (double)n : 1;
    const int64_t nz = d == 3 ? n : 1;
    const double w = hy * hz;
    for (int64_t iy = 0; iy < n; iy++) {
        const double y = lo[1] + ((double)iy + offset) * hy;
        /* the pebbles this row of lines crosses */
        int64_t nr = 0;
        for (int64_t i = 0; i < np; i++)
            if (in[i] && fabs(y - pos[i * d + 1]) < rad[i]) row[nr++] = i;
        if (nr < 2) continue;
        for (int64_t iz = 0; iz < nz; iz++) {
            /* up to 2048^2 lines across up to a million pebbles */
            if (sx__interrupted(m)) {
                free(sp);
                free(row);
                return SX_EINTERRUPT;
            }
            const double z = d == 3 ? lo[2] + ((double)iz + offset) * hz : 0;
            int64_t ns = 0;
            for (int64_t k = 0; k < nr; k++) {
                const int64_t i = row[k];
                const double dy = y - pos[i * d + 1], dz = d == 3 ? z - pos[i * d + 2] : 0;
                const double h2 = rad[i] * rad[i] - dy * dy - dz * dz;
                if (h2 <= 0) continue;
                const double h = sqrt(h2);
                sp[ns].a = pos[i * d] - h - c[0];
                sp[ns].b = pos[i * d] + h - c[0];
                ns++;
            }
            if (ns < 2) continue;
            qsort(sp, (size_t)ns, sizeof *sp, by_start);
            /* sum of the chords minus their union */
            double m0 = 0, m1 = 0, m2 = 0;
            double ua = sp[0].a, ub = sp[0].b;
            span_moments(sp[0].a, sp[0].b, 1, &m0, &m1, &m2);
            for (int64_t k = 1; k < ns; k++) {
                span_moments(sp[k].a, sp[k].b, 1, &m0, &m1, &m2);
                if (sp[k].a > ub) {
                    span_moments(ua, ub, -1, &m0, &m1, &m2);
                    ua = sp[k].a, ub = sp[k].b;
                } else if (sp[k].b > ub) {
                    ub = sp[k].b;
                }
            }
            span_moments(ua, ub, -1, &m0, &m1, &m2);
            if (m0 == 0 && m1 == 0 && m2 == 0) continue;
            const double yy = y - c[1], zz = d == 3 ? z - c[2] : 0;
            out->v += w * m0;
            out->s[0] += w * m1;
            out->s[1] += w * yy * m0;
            out->s[2] += w * zz * m0;
            out->j[0] += w * m2;
            out->j[1] += w * yy * m1;
            out->j[2] += w * zz * m1;
            out->j[4] += w * yy * yy * m0;
            out->j[5] += w * yy * zz * m0;
            out->j[8] += w * zz * zz * m0;
        }
    }
    out->j[3] = out->j[1], out->j[6] = out->j[2], out->j[7] = out->j[5];
    free(sp);
    free(row);
    return SX_OK;
}

/* Volume, centroid and inertia per unit density (about the centroid, in
 * the template frame) of exact sums less the overlap correction c. */
static void finish_props(int d, const moments *e, const moments *corr, const double *c0, double *volume,
                         double *centroid, double *inertia)
{
    const double v = e->v - corr->v;
    double s[3], j[9];
    for (int k = 0; k < 3; k++) s[k] = (e->s[k] - corr->s[k]) / v; /* centroid relative to c0 */
    for (int k = 0; k < 9; k++) j[k] = e->j[k] - corr->j[k];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) j[3 * a + b] -= v * s[a] * s[b]; /* to the centroid (parallel axes) */
    *volume = v;
    for (int k = 0; k < 3; k++) centroid[k] = k < d ? c0[k] + s[k] : 0;
    memset(inertia, 0, 9 * sizeof(double));
    if (d == 3) {
        const double tr = j[0] + j[4] + j[8];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) inertia[3 * a + b] = (a == b ? tr : 0) - j[3 * a + b];
    } else {
        inertia[0] = j[0] + j[4]; /* Izz of a unit-thickness slice */
    }
}

/* The relative difference of two integrations (the error estimate). */
static double props_difference(int d, double v1, const double *c1, const double *i1, double v2, const double *c2,
                               const double *i2)
{
    const int ni = d == 3 ? 9 : 1;
    double imax = 0, tr = 0;
    for (int k = 0; k < ni; k++) imax = fmax(imax, fabs(i1[k]));
    for (int k = 0; k < (d == 3 ? 3 : 1); k++) tr += i1[4 * k];
    const double size = sqrt(tr / v1); /* radius of gyration */
    double e = fabs(v1 - v2) / v1, dc = 0;
    for (int k = 0; k < d; k++) dc += (c1[k] - c2[k]) * (c1[k] - c2[k]);
    e = fmax(e, sqrt(dc) / size);
    for (int k = 0; k < ni; k++) e = fmax(e, fabs(i1[k] - i2[k]) / imax);
    return e;
}

/* The midpoint rule's error across the lines fluctuates with how the grid
 * meets the lenses' rims, so the spread of two coarser grids (half the
 * lines, two offsets) is an estimate, not a bound: it is taken 4 times,
 * which bounded the actual error over the sweep of pair geometries in
 * tests/clump/mass.c (the largest actual / spread seen there is 3.6). */
#define ERROR_SAFETY 4.0

sx_status sx__clump_mass_props(sx_model *m, sx_clump_tpl *t, int64_t lines)
{
    sx_clumps *C = m->clumps;
    const int d = m->dim;
    const int64_t n = t->n;
    const double *pos = C->tp_pos + t->first * d, *rad = C->tp_rad + t->first;
    /* exact sums about the centroid of the spheres (disks), c0 */
    double c0[3] = {0, 0, 0}, vsum = 0;
    for (int64_t i = 0; i < n; i++) {
        const double v = sx__ball_volume(d, rad[i]);
        vsum += v;
        for (int k = 0; k < d; k++) c0[k] += v * pos[i * d + k];
    }
    for (int k = 0; k < d; k++) c0[k] /= vsum;
    t->power_sum = vsum / (d == 3 ? 4.0 / 3.0 * SX_PI : SX_PI);
    moments e;
    memset(&e, 0, sizeof e);
    for (int64_t i = 0; i < n; i++) {
        const double r = rad[i];
        const double v = sx__ball_volume(d, r);
        /* a sphere's own second moment is v r^2 / 5 per axis, a disk's v r^2 / 4 */
        const double self = v * r * r / (d == 3 ? 5.0 : 4.0);
        double x[3] = {0, 0, 0};
        for (int k = 0; k < d; k++) x[k] = pos[i * d + k] - c0[k];
        e.v += v;
        for (int a = 0; a < 3; a++) {
            e.s[a] += v * x[a];
            for (int b = 0; b < 3; b++) e.j[3 * a + b] += v * x[a] * x[b] + (a == b && a < d ? self : 0);
        }
    }
    /* the overlapping pebbles and the bounding box of their lenses */
    uint8_t *in = calloc((size_t)n, 1);
    if (!in) return SX_ENOMEM;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    bool overlaps = false;
    for (int64_t i = 0; i < n; i++) {
        /* a million pebbles make 5e11 pairs */
        if (i % 256 == 0 && sx__interrupted(m)) {
            free(in);
            return SX_EINTERRUPT;
        }
        for (int64_t j = i + 1; j < n; j++) {
            double d2 = 0;
            for (int k = 0; k < d; k++) d2 += (pos[j * d + k] - pos[i * d + k]) * (pos[j * d + k] - pos[i * d + k]);
            const double s = rad[i] + rad[j];
            if (d2 >= s * s) continue;
            overlaps = true;
            in[i] = in[j] = 1;
            /* the lens lies in both pebbles' bounding boxes */
            for (int k = 0; k < d; k++) {
                lo[k] = fmin(lo[k], fmax(pos[i * d + k] - rad[i], pos[j * d + k] - rad[j]));
                hi[k] = fmax(hi[k], fmin(pos[i * d + k] + rad[i], pos[j * d + k] + rad[j]));
            }
        }
    }
    moments corr;
    memset(&corr, 0, sizeof corr);
    t->error = 0;
    t->lines = 0;
    if (overlaps) {
        if (lines == 0) lines = d == 3 ? LINES_3D : LINES_2D;
        moments half[2];
        sx_status st = overlap_correction(m, pos, rad, in, n, lo, hi, lines, 0.5, c0, &corr);
        if (!st) st = overlap_correction(m, pos, rad, in, n, lo, hi, lines / 2, 0.5, c0, &half[0]);
        if (!st) st = overlap_correction(m, pos, rad, in, n, lo, hi, lines / 2, 0.25, c0, &half[1]);
        if (st) {
            free(in);
            return st;
        }
        finish_props(d, &e, &corr, c0, &t->volume, t->centroid, t->inertia);
        double spread = 0;
        for (int k = 0; k < 2; k++) {
            double v2, c2[3], i2[9];
            finish_props(d, &e, &half[k], c0, &v2, c2, i2);
            spread = fmax(spread, props_difference(d, t->volume, t->centroid, t->inertia, v2, c2, i2));
        }
        t->error = ERROR_SAFETY * spread;
        t->lines = lines;
    } else {
        finish_props(d, &e, &corr, c0, &t->volume, t->centroid, t->inertia);
    }
    free(in);
    /* principal frame */
    double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (d == 3) {
        jacobi3(t->inertia, t->principal, R);
        matrix_quat(R, t->frame);
    } else {
        t->principal[0] = t->inertia[0];
        t->principal[1] = t->principal[2] = 0;
        t->frame[0] = 1, t->frame[1] = t->frame[2] = t->frame[3] = 0;
    }
    if (!(t->volume > 0) || !(t->principal[0] > 0) || !isfinite(t->principal[d == 3 ? 2 : 0]))
        return SX_EINVAL;
    /* pebble centres in the body frame, from the same rotation a clump uses */
    qmatrix(t->frame, R);
    for (int64_t i = 0; i < n; i++) {
        double r[3] = {0, 0, 0}, b[3];
        for (int k = 0; k < d; k++) r[k] = pos[i * d + k] - t->centroid[k];
        if (d == 3) mat_tvec(R, r, b);
        else b[0] = r[0], b[1] = r[1];
        for (int k = 0; k < d; k++) C->tp_body[(t->first + i) * d + k] = b[k];
    }
    return SX_OK;
}
