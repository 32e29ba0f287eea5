/* The part of a ball inside a measurement region (measure.c): the volume
 * of a sphere (2D: the area of a disk) cut by a sphere or a box, so that a
 * region's porosity counts the solid in it, not every ball whose centre is
 * in it whole (a sphere of half a ball's radius read a porosity of -7, a
 * dense packing's region a radius across -0.30 for 0.24: a newcomer's
 * finding). Exact, but for a sphere in a 3D box: there the areas of its
 * slices (a disk in a rectangle, exact) are summed by Gauss-Legendre
 * between the heights where a slice meets a rectangle's edge or corner
 * (within 1e-7 of the volume). */
#include "model_internal.h"

#include <math.h>
#include <stdlib.h>

/* The area of the disk of radius r about the origin with X <= x. */
static double slice_below(double r, double x)
{
    if (x <= -r) return 0;
    if (x >= r) return SX_PI * r * r;
    return SX_PI * r * r - (r * r * acos(x / r) - x * sqrt(r * r - x * x));
}

/* The integral of sqrt(r^2 - X^2) from 0 to X (|X| <= r). */
static double half_chord_integral(double r, double X)
{
    return 0.5 * (X * sqrt(fmax(r * r - X * X, 0)) + r * r * asin(fmax(-1, fmin(1, X / r))));
}

/* The area of the disk of radius r about the origin with X <= x and Y <= y. */
static double corner_area(double r, double x, double y)
{
    if (x <= -r || y <= -r) return 0;
    if (y >= r) return slice_below(r, x);
    if (x >= r) return slice_below(r, y);
    /* over X: the chord's part below y; |X| <= w where the chord reaches past y */
    const double w = sqrt(r * r - y * y);
    double a = 0;
    const double e1 = fmin(x, -w); /* X in [-r, -w]: the whole chord (y > 0) or none */
    if (y > 0 && e1 > -r) a += 2 * (half_chord_integral(r, e1) - half_chord_integral(r, -r));
    if (x > -w) { /* X in [-w, w]: from -h to y */
        const double e2 = fmin(x, w);
        a += y * (e2 + w) + half_chord_integral(r, e2) - half_chord_integral(r, -w);
    }
    if (y > 0 && x > w) a += 2 * (half_chord_integral(r, x) - half_chord_integral(r, w));
    return a;
}

/* The area of the disk of radius r about the origin in [x0, x1] x [y0, y1]. */
static double disk_in_rect(double r, double x0, double x1, double y0, double y1)
{
    return corner_area(r, x1, y1) - corner_area(r, x0, y1) - corner_area(r, x1, y0) + corner_area(r, x0, y0);
}

static int compare_doubles(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The volume of the sphere of radius r about the origin in the box lo..hi. */
static double sphere_in_box(double r, const double *lo, const double *hi)
{
    /* Gauss-Legendre, 16 points: the positive nodes and their weights */
    static const double gx[8] = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274, 0.6178762444026438,
                                 0.7554044083550030, 0.8656312023878318, 0.9445750230732326, 0.9894009349916499};
    static const double gw[8] = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025, 0.1495959888165767,
                                 0.1246289712555339, 0.0951585116824928, 0.0622535239386479, 0.0271524594117541};
    const double z0 = fmax(lo[2], -r), z1 = fmin(hi[2], r);
    if (!(z1 > z0)) return 0;
    /* the heights where a slice's disk meets an edge (at distance d) or a corner */
    double cut[2 + 2 * 8];
    int n = 0;
    cut[n++] = z0, cut[n++] = z1;
    const double d[8] = {lo[0], hi[0], lo[1], hi[1], hypot(lo[0], lo[1]), hypot(lo[0], hi[1]), hypot(hi[0], lo[1]),
                         hypot(hi[0], hi[1])};
    for (int k = 0; k < 8; k++) {
        if (!(fabs(d[k]) < r)) continue;
        const double z = sqrt(r * r - d[k] * d[k]);
        if (z > z0 && z < z1) cut[n++] = z;
        if (-z > z0 && -z < z1) cut[n++] = -z;
    }
    qsort(cut, (size_t)n, sizeof *cut, compare_doubles);
    /* on each piece z = a + (b - a)(1 - cos t)/2, t in [0, pi]: the area
     * goes as the root of the distance to a piece's end (an edge met
     * there), which the substitution makes smooth */
    double v = 0;
    for (int k = 0; k + 1 < n; k++) {
        const double a = cut[k], b = cut[k + 1];
        if (!(b > a)) continue;
        for (int q = 0; q < 8; q++)
            for (int s = -1; s <= 1; s += 2) {
                const double t = 0.5 * SX_PI * (1 + s * gx[q]);
                const double z = a + 0.5 * (b - a) * (1 - cos(t)), rho = sqrt(fmax(r * r - z * z, 0));
                v += 0.5 * SX_PI * gw[q] * 0.5 * (b - a) * sin(t) * disk_in_rect(rho, lo[0], hi[0], lo[1], hi[1]);
            }
    }
    return v;
}

/* The lens of two balls of radii r and R, centres d apart (|R - r| < d < R + r). */
static double lens(int dim, double r, double R, double d)
{
    if (dim == 3)
        return SX_PI * (R + r - d) * (R + r - d) * (d * d + 2 * d * r - 3 * r * r + 2 * d * R + 6 * r * R - 3 * R * R) /
               (12 * d);
    const double a = (d * d + r * r - R * R) / (2 * d * r), b = (d * d + R * R - r * r) / (2 * d * R);
    return r * r * acos(fmax(-1, fmin(1, a))) + R * R * acos(fmax(-1, fmin(1, b))) -
           0.5 * sqrt(fmax(0, (-d + r + R) * (d + r - R) * (d - r + R) * (d + r + R)));
}

double sx__region_cut(const sx_region *region, int dim, const double *x, double r)
{
    /* a boundary within a part in 1e12 of the radius of touching the ball is
     * taken as touching: a lattice's balls touch its cells' faces, and the
     * formulas lose their digits in a sliver (the sliver left out is under
     * 1e-17 of the ball) */
    const double whole = sx__ball_volume(dim, r), touch = 1e-12 * r;
    if (region->shape == SX_SHAPE_SPHERE) {
        double d2 = 0;
        for (int k = 0; k < dim; k++) d2 += (x[k] - region->centre[k]) * (x[k] - region->centre[k]);
        const double d = sqrt(d2), R = region->radius;
        if (d + r <= R + touch) return whole;
        if (d >= R + r - touch) return 0;
        if (d + R <= r + touch) return sx__ball_volume(dim, R); /* the region inside the ball */
        return lens(dim, r, R, d);
    }
    double lo[3], hi[3];
    bool all = true;
    for (int k = 0; k < dim; k++) {
        lo[k] = region->lo[k] - x[k], hi[k] = region->hi[k] - x[k];
        if (hi[k] <= -r + touch || lo[k] >= r - touch) return 0;
        all = all && lo[k] <= -r + touch && hi[k] >= r - touch;
    }
    if (all) return whole;
    return dim == 3 ? sphere_in_box(r, lo, hi) : disk_in_rect(r, lo[0], hi[0], lo[1], hi[1]);
}
