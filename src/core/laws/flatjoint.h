/* The flat joint (Potyondy 2012; PFC's `flatjoint`): the interface of two
 * balls is a notional flat face centred at the contact point, normal to
 * the centre line, of radius R = lambda min(RA, RB) (4-53's multiplier) --
 * a segment of length 2R and unit thickness in 2D, a disk in 3D -- cut into
 * elements: 2D, Nr equal segments; 3D, Nr equal rings of Na equal sectors.
 * The flat joint replaces the contact law of its pair (it is the contact).
 *
 * Kinematics, in the face's axes (t1, t2, n): 3D, t1 is carried with the
 * contact (4-13 ... 4-15) and t2 = n x t1; 2D, t1 = n turned by +90 deg and
 * t2 = z, so 2D is 3D with z = 0. A point r = y t1 + z t2 of the face opens
 * by the gap
 *     g(r) = g0 + delta - theta2 y + theta1 z,
 * delta = d - d0 the change of the centre distance since installation,
 * (theta1, theta2) the relative bend rotation of b from a (the increments
 * (wb - wa) dt projected on t1, t2), g0 an unbonded element's initial gap
 * (0 for bonded ones: every element starts stress free).
 *
 * Element e (area Ae, centroid re, central second moments Jyy, Jyz, Jzz)
 * carries, on b:
 *   normal stress  sigma(r) = -kn g(r) where bonded, or where g < 0
 *                  (unbonded: compression only), so
 *                  Fn_e = integral of sigma, the element's moment about its
 *                  centroid integral of (r - re) x n sigma, exactly (an
 *                  unbonded element over its closed part: 2D a segment, 3D
 *                  an annular sector cut by a straight line);
 *   shear force    incremental, Fs_e -= ks Ae (dUs + dtheta_n n x re),
 *                  dUs the contact point's shear displacement (4-17 ...
 *                  4-20) and dtheta_n the relative twist increment (3D), so
 *                  the face resists twist through its elements' shear.
 * A bonded element breaks
 *   in tension    when sigma-bar = -Fn_e / Ae >= sigma_c (its centroid's
 *                 tensile stress),
 *   in shear      when tau = |Fs_e| / Ae >= c - sigma-bar tan(phi),
 * and is from then on unbonded, with the gap it has: compression only, and
 * Coulomb friction |Fs_e| <= mu Fn_e. The face's force on b is
 * sum (Fn_e n + Fs_e), its moment about the contact point
 * sum (re x (Fn_e n + Fs_e) + M_e); on a the opposite (4-39).
 *
 * Energy: the strain energy is (1/2) kn integral of g^2 over the loaded
 * parts plus |Fs_e|^2 / (2 ks Ae); a break releases the element's energy
 * before it minus after it (bond_released); friction's work goes to slip.
 */
#pragma once

#include <math.h>
#include <stdbool.h>

#define SX_FJ_PI 3.14159265358979323846

/* An element's (or sub-sector's) area, centroid and central second moments
 * in the face's axes (2D: y along the face, z = 0). */
typedef struct sx_law_fj_geom {
    double area, y, z, jyy, jyz, jzz;
    double r0, r1, a0, a1; /* 3D: rings [r0, r1], angles [a0, a1]; 2D: the segment [r0, r1] along y */
} sx_law_fj_geom;

/* The annular sector r0 <= r <= r1, a0 <= alpha <= a1 (y = r cos alpha). */
static inline void sx_law_fj_sector(double r0, double r1, double a0, double a1, sx_law_fj_geom *g)
{
    const double da = a1 - a0, q2 = (r1 * r1 - r0 * r0) / 2, q3 = (r1 * r1 * r1 - r0 * r0 * r0) / 3;
    const double q4 = (r1 * r1 * r1 * r1 - r0 * r0 * r0 * r0) / 4;
    const double s0 = sin(a0), s1 = sin(a1), c0 = cos(a0), c1 = cos(a1);
    g->area = q2 * da;
    g->y = q3 * (s1 - s0) / g->area;
    g->z = q3 * (c0 - c1) / g->area;
    const double s2 = (sin(2 * a1) - sin(2 * a0)) / 4;
    g->jyy = q4 * (da / 2 + s2) - g->area * g->y * g->y;
    g->jzz = q4 * (da / 2 - s2) - g->area * g->z * g->z;
    g->jyz = q4 * (s1 * s1 - s0 * s0) / 2 - g->area * g->y * g->z;
    g->r0 = r0, g->r1 = r1, g->a0 = a0, g->a1 = a1;
}

/* The segment [s0, s1] of unit thickness (2D). */
static inline void sx_law_fj_segment(double s0, double s1, sx_law_fj_geom *g)
{
    const double len = s1 - s0;
    g->area = len;
    g->y = 0.5 * (s0 + s1);
    g->z = 0;
    g->jyy = len * len * len / 12;
    g->jyz = g->jzz = 0;
    g->r0 = s0, g->r1 = s1, g->a0 = g->a1 = 0;
}

/* Element e of a face of radius r: 2D, segment e of nr along [-r, r];
 * 3D, ring e / na (from the centre) and sector e % na (from t1 towards t2). */
static inline void sx_law_fj_element(int dim, double r, int nr, int na, int e, sx_law_fj_geom *g)
{
    if (dim == 2) {
        sx_law_fj_segment(-r + 2 * r * e / nr, -r + 2 * r * (e + 1) / nr, g);
    } else {
        const int ring = e / na, sector = e % na;
        sx_law_fj_sector(r * ring / nr, r * (ring + 1) / nr, 2 * SX_FJ_PI * sector / na,
                     2 * SX_FJ_PI * (sector + 1) / na, g);
    }
}

/* What a region carries: normal force (compression positive), moment about
 * its centroid (m1 along t1, m2 along t2; 2D: m2 is the moment about z),
 * and its normal springs' strain energy. */
typedef struct sx_law_fj_load {
    double fn, m1, m2, energy;
} sx_law_fj_load;

/* A wholly loaded region (bonded, or closed everywhere) with gap gc at its
 * centroid and gap gradient (ay, az) = (-theta2, theta1). */
static inline sx_law_fj_load sx_law_fj_whole(const sx_law_fj_geom *g, double kn, double gc, double ay, double az)
{
    sx_law_fj_load l;
    l.fn = -kn * g->area * gc;
    l.m1 = -kn * (ay * g->jyz + az * g->jzz);
    l.m2 = kn * (ay * g->jyy + az * g->jyz);
    l.energy = 0.5 * kn * (g->area * gc * gc + ay * ay * g->jyy + 2 * ay * az * g->jyz + az * az * g->jzz);
    return l;
}

/* The range [lo, hi] of a.(r - centroid) over a region. */
static inline void sx_law_fj_range(int dim, const sx_law_fj_geom *g, double ay, double az, double *lo, double *hi)
{
    if (dim == 2) {
        const double u = ay * (g->r0 - g->y), v = ay * (g->r1 - g->y);
        *lo = fmin(u, v), *hi = fmax(u, v);
        return;
    }
    /* a linear function on an annular sector peaks at a corner or where an
     * arc is parallel to the gradient's normal */
    const double rr[2] = {g->r0, g->r1};
    double al[4] = {g->a0, g->a1, atan2(az, ay), atan2(az, ay) + SX_FJ_PI};
    int na = 2;
    for (int k = 2; k < 4; k++) {
        double a = al[k];
        while (a < g->a0) a += 2 * SX_FJ_PI;
        while (a > g->a1) a -= 2 * SX_FJ_PI;
        if (a >= g->a0 && a <= g->a1) al[na++] = a;
    }
    *lo = INFINITY, *hi = -INFINITY;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < na; k++) {
            const double f = ay * (rr[i] * cos(al[k]) - g->y) + az * (rr[i] * sin(al[k]) - g->z);
            *lo = fmin(*lo, f), *hi = fmax(*hi, f);
        }
}

/* Raw moments of a plane region about the face's centre: its area and
 * the integrals of y, z, y^2, yz, z^2. */
typedef struct sx_law_fj_moments {
    double a, y, z, yy, yz, zz;
} sx_law_fj_moments;

static inline void sx_law_fj_add(sx_law_fj_moments *q, double s, const sx_law_fj_moments *p)
{
    q->a += s * p->a, q->y += s * p->y, q->z += s * p->z;
    q->yy += s * p->yy, q->yz += s * p->yz, q->zz += s * p->zz;
}

/* The circular sector 0 <= r <= R, b0 <= alpha <= b1. */
static inline sx_law_fj_moments sx_law_fj_disk_sector(double R, double b0, double b1)
{
    const double r2 = R * R / 2, r3 = R * R * R / 3, r4 = R * R * R * R / 4, db = b1 - b0;
    const double s0 = sin(b0), s1 = sin(b1), c0 = cos(b0), c1 = cos(b1), s2 = (sin(2 * b1) - sin(2 * b0)) / 4;
    return (sx_law_fj_moments){r2 * db, r3 * (s1 - s0), r3 * (c0 - c1), r4 * (db / 2 + s2), r4 * (s1 * s1 - s0 * s0) / 2,
                               r4 * (db / 2 - s2)};
}

/* The triangle of the centre and the points p, q (counterclockwise). */
static inline sx_law_fj_moments sx_law_fj_triangle(double py, double pz, double qy, double qz)
{
    const double a = 0.5 * (py * qz - qy * pz);
    return (sx_law_fj_moments){a, a * (py + qy) / 3, a * (pz + qz) / 3, a / 6 * (py * py + qy * qy + py * qy),
                               a / 12 * (py * pz + qy * qz + (py + qy) * (pz + qz)), a / 6 * (pz * pz + qz * qz + pz * qz)};
}

/* The closed part of an annular sector (g->r0 <= r <= g->r1, g->a0 <= alpha
 * <= g->a1) where the gap gc + ay (y - yc) + az (z - zc) < 0, exactly: it is
 * the half-plane u.p < h (u the gradient's direction), in polar r cos(alpha
 * - beta) < h, so between the angles where the line r = h / cos(alpha -
 * beta) crosses the rings (or turns parallel to the rays) each radial
 * stretch runs between two of r0, r1 and the line; a stretch [lo, hi] is
 * the sector out to hi less the one out to lo, out to the line the triangle
 * of the centre and the line's points. */
static inline sx_law_fj_moments sx_law_fj_closed(const sx_law_fj_geom *g, double gc, double ay, double az)
{
    sx_law_fj_moments q = {0, 0, 0, 0, 0, 0};
    const double amod = hypot(ay, az);
    if (!(amod > 0)) {
        if (gc < 0) sx_law_fj_add(&q, 1, &(sx_law_fj_moments){g->area, g->area * g->y, g->area * g->z,
                                                            g->jyy + g->area * g->y * g->y, g->jyz + g->area * g->y * g->z,
                                                            g->jzz + g->area * g->z * g->z});
        return q;
    }
    const double h = (ay * g->y + az * g->z - gc) / amod, beta = atan2(az, ay);
    /* the breaks: where the line meets r0 and r1, and beta +- 90 deg */
    double br[16];
    int nb = 0;
    br[nb++] = g->a0;
    const double ang[2] = {SX_FJ_PI / 2, -SX_FJ_PI / 2};
    double cand[6];
    int nc = 0;
    cand[nc++] = beta + ang[0], cand[nc++] = beta + ang[1];
    const double rr[2] = {g->r0, g->r1};
    for (int i = 0; i < 2; i++)
        if (rr[i] > 0 && fabs(h) < rr[i]) {
            const double phi = acos(h / rr[i]);
            cand[nc++] = beta + phi, cand[nc++] = beta - phi;
        }
    for (int i = 0; i < nc; i++)
        for (int k = -2; k <= 2; k++) {
            const double a = cand[i] + 2 * SX_FJ_PI * k;
            if (a > g->a0 && a < g->a1 && nb < 15) br[nb++] = a;
        }
    br[nb++] = g->a1;
    for (int i = 1; i < nb; i++) /* insertion sort: a dozen at most */
        for (int k = i; k > 0 && br[k] < br[k - 1]; k--) {
            const double t = br[k];
            br[k] = br[k - 1], br[k - 1] = t;
        }
    for (int i = 0; i + 1 < nb; i++) {
        const double b0 = br[i], b1 = br[i + 1];
        if (!(b1 > b0)) continue;
        const double w = cos(0.5 * (b0 + b1) - beta);
        /* the closed stretch of the ray: r < h/w for w > 0, r > h/w for w < 0,
         * within [r0, r1]; its ends r0, r1 or the line */
        bool lo_line = false, hi_line = false;
        if (w > 0) {
            const double L = h / w;
            if (L <= g->r0) continue;
            hi_line = L < g->r1;
        } else if (h < 0) {
            const double L = h / w;
            if (L >= g->r1) continue;
            lo_line = L > g->r0;
        }
        sx_law_fj_moments part;
        if (hi_line || lo_line) { /* the line's points at the stretch's ends */
            const double l0 = h / cos(b0 - beta), l1 = h / cos(b1 - beta);
            part = sx_law_fj_triangle(l0 * cos(b0), l0 * sin(b0), l1 * cos(b1), l1 * sin(b1));
        }
        if (hi_line) {
            sx_law_fj_add(&q, 1, &part);
        } else {
            const sx_law_fj_moments s = sx_law_fj_disk_sector(g->r1, b0, b1);
            sx_law_fj_add(&q, 1, &s);
        }
        if (lo_line) {
            sx_law_fj_add(&q, -1, &part);
        } else if (g->r0 > 0) {
            const sx_law_fj_moments s = sx_law_fj_disk_sector(g->r0, b0, b1);
            sx_law_fj_add(&q, -1, &s);
        }
    }
    return q;
}

/* The load of the closed region q (raw moments) under the gap field gc +
 * ay dy + az dz, (dy, dz) from the element's centroid (y, z): the moments
 * moved to the centroid, then Fn = -kn int g, m1 = -kn int g dz,
 * m2 = kn int g dy, energy (1/2) kn int g^2. */
static inline sx_law_fj_load sx_law_fj_integrate_at(const sx_law_fj_moments *q, double yc, double zc, double kn,
                                                   double gc, double ay, double az)
{
    const double j1 = q->a, jy = q->y - yc * q->a, jz = q->z - zc * q->a;
    const double jyy = q->yy - 2 * yc * q->y + yc * yc * q->a, jzz = q->zz - 2 * zc * q->z + zc * zc * q->a;
    const double jyz = q->yz - yc * q->z - zc * q->y + yc * zc * q->a;
    const double ig = gc * j1 + ay * jy + az * jz;
    sx_law_fj_load l;
    l.fn = -kn * ig;
    l.m1 = -kn * (gc * jz + ay * jyz + az * jzz);
    l.m2 = kn * (gc * jy + ay * jyy + az * jyz);
    l.energy = 0.5 * kn * (gc * gc * j1 + 2 * gc * (ay * jy + az * jz) + ay * ay * jyy + 2 * ay * az * jyz + az * az * jzz);
    return l;
}

/* An unbonded region: compression only, where g < 0. */
static inline sx_law_fj_load sx_law_fj_contact(int dim, const sx_law_fj_geom *g, double kn, double gc, double ay, double az)
{
    sx_law_fj_load l = {0, 0, 0, 0};
    double lo, hi;
    sx_law_fj_range(dim, g, ay, az, &lo, &hi);
    if (gc + lo >= 0) return l;
    if (gc + hi <= 0) return sx_law_fj_whole(g, kn, gc, ay, az);
    if (dim == 2) {
        /* exactly over the closed part [p, q] of the segment (centroid at 0) */
        const double h = 0.5 * g->area, root = -gc / ay;
        const double p = ay > 0 ? -h : root, q = ay > 0 ? root : h;
        const double d1 = q - p, d2 = (q * q - p * p) / 2, d3 = (q * q * q - p * p * p) / 3;
        l.fn = -kn * (gc * d1 + ay * d2);
        l.m2 = kn * (gc * d2 + ay * d3);
        l.energy = 0.5 * kn * (gc * gc * d1 + 2 * gc * ay * d2 + ay * ay * d3);
        return l;
    }
    /* 3D: the annular sector cut by the line g = 0 (sx_law_fj_closed) */
    const sx_law_fj_moments q = sx_law_fj_closed(g, gc, ay, az);
    return sx_law_fj_integrate_at(&q, g->y, g->z, kn, gc, ay, az);
}

/* The normal load of element e: bonded, or compression only. */
static inline sx_law_fj_load sx_law_fj_load_of(int dim, const sx_law_fj_geom *g, bool bonded, double kn, double gc, double ay,
                                       double az)
{
    return bonded ? sx_law_fj_whole(g, kn, gc, ay, az) : sx_law_fj_contact(dim, g, kn, gc, ay, az);
}

/* Its micro-parameters (laws/bond.h): the parallel bond's face and
 * strengths (drawn per element) and its own. */
#include "bond.h"

static inline const sx_bond_law *sx_bond_flatjoint(void)
{
    static const sx_bond_param params[] = {
        SX_BOND_FACE_PARAMS,
        SX_BOND_PARAM(friction_angle, "deg", 90, false),
        SX_BOND_PARAM(friction, "1", INFINITY, false),
        SX_BOND_COUNT(elements, 64), /* a joint's uint8 holds them */
        SX_BOND_COUNT(sectors, 64),
        SX_BOND_PARAM(unbonded_fraction, "1", 1, true),
        SX_BOND_PARAM(initial_gap, "m", INFINITY, false),
    };
    static const sx_bond_law law = {
        .name = "flatjoint",
        .kind = SX_BOND_FLATJOINT,
        .summary = "flat joint: a face of bonded and unbonded elements in place of the contact law (Potyondy 2012)",
        .params = params,
        .nparams = 13,
    };
    return &law;
}
