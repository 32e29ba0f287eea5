/* Clumps: mass properties against closed forms.
 *
 * Non-overlapping pebbles are summed exactly (parallel axes), so the
 * dumbbell and the three-pebble clump must match their closed forms to
 * round-off: 1e-12 relative to the largest principal moment (the sums are
 * a few dozen operations on O(1) numbers; 1e-12 leaves a margin of ~1e3
 * over double round-off).
 *
 * Overlapping pairs are integrated numerically (line integration; see
 * clump_mass.c). Their reference is exact: the union of two spheres (disks)
 * is symmetric about the line of centres, so every moment is a 1D
 * integral along it of the cross-section of the union, which is that of
 * one pebble on either side of the plane of the intersection circle. In
 * 3D the integrands are polynomials in the axial coordinate (pi rho^2,
 * pi rho^4 / 4 with rho^2 quadratic), which 5-point Gauss-Legendre
 * integrates exactly on each side; in 2D (chords 2h, h = sqrt(r^2 - s^2))
 * the substitution s = r sin(phi) makes them trigonometric polynomials,
 * integrated to round-off by 24-point Gauss-Legendre. Over a sweep of
 * pair geometries the actual error must stay within the template's own
 * estimate and within the accuracy the documentation states at the default
 * number of lines: 1e-5 relative in 3D, 1e-7 in 2D. */
#include "clump_test.h"

static const double RHO = 2500;

/* Gauss-Legendre nodes and weights on [-1, 1] (n = 5 and 24), computed by
 * Newton's iteration on the Legendre polynomial. */
static void gauss(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(V_PI * (i + 0.75) / (n + 0.5)), dp = 0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1, p1 = z;
            for (int k = 2; k <= n; k++) {
                const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                p0 = p1, p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1);
            const double dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16) break;
        }
        x[i] = z;
        w[i] = 2 / ((1 - z * z) * dp * dp);
    }
}

/* Reference moments of the union of two overlapping pebbles on a line:
 * centres at s1 < s2 along it, radii r1, r2. Volume, axial centroid, and
 * inertia about the axis and about a perpendicular through the centroid
 * (per unit density). */
typedef struct pair_ref {
    double volume, centroid, axial, perp;
} pair_ref;

static pair_ref union_of_pair(int dim, double s1, double r1, double s2, double r2)
{
    /* the plane of the intersection circle: where both cross-sections are equal */
    const double cut = (r1 * r1 - r2 * r2 + s2 * s2 - s1 * s1) / (2 * (s2 - s1));
    ck_assert(cut > s1 - r1 && cut < s2 + r2 && cut > s2 - r2 && cut < s1 + r1);
    double x[24], w[24];
    const int n = dim == 3 ? 5 : 24;
    gauss(n, x, w);
    double v = 0, s = 0, ss = 0, tt = 0; /* moments of 1, s, s^2 and of the transverse second moment */
    const double piece[2][4] = {{s1, r1, s1 - r1, cut}, {s2, r2, cut, s2 + r2}};
    for (int p = 0; p < 2; p++) {
        const double c = piece[p][0], r = piece[p][1], a = piece[p][2], b = piece[p][3];
        if (dim == 3) {
            for (int i = 0; i < n; i++) {
                const double sx = 0.5 * (a + b) + 0.5 * (b - a) * x[i], wt = 0.5 * (b - a) * w[i];
                const double rho2 = r * r - (sx - c) * (sx - c);
                const double area = V_PI * rho2;
                v += wt * area, s += wt * area * sx, ss += wt * area * sx * sx;
                tt += wt * V_PI * rho2 * rho2 / 4; /* a disk's second moment about a diameter */
            }
        } else {
            const double pa = asin(fmax(-1, (a - c) / r)), pb = asin(fmin(1, (b - c) / r));
            for (int i = 0; i < n; i++) {
                const double ph = 0.5 * (pa + pb) + 0.5 * (pb - pa) * x[i], wt = 0.5 * (pb - pa) * w[i];
                const double sx = c + r * sin(ph), h = r * cos(ph), ds = r * cos(ph);
                v += wt * ds * 2 * h, s += wt * ds * 2 * h * sx, ss += wt * ds * 2 * h * sx * sx;
                tt += wt * ds * 2 * h * h * h / 3; /* a chord's second moment about the axis */
            }
        }
    }
    pair_ref ref;
    ref.volume = v;
    ref.centroid = s / v;
    const double jss = ss - v * ref.centroid * ref.centroid;
    ref.axial = dim == 3 ? 2 * tt : 0; /* 2D has no axial moment: Izz is the perpendicular one */
    ref.perp = tt + jss;
    return ref;
}

/* Checks props against a body symmetric about the axis u through the
 * centroid c with moments axial (about u) and perp: I = perp E + (axial -
 * perp) u u^T. Returns the largest relative difference (to the largest moment). */
static double axisymmetric_diff(int dim, const sx_clump_props *p, double volume, const double *c, const double *u,
                                double axial, double perp)
{
    const double scale = fmax(axial, perp);
    double e = ct_rel(p->volume, volume, volume);
    const double size = sqrt(scale / volume);
    for (int k = 0; k < dim; k++) e = fmax(e, ct_rel(p->centroid[k], c[k], size));
    if (dim == 3) {
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                const double ref = (a == b ? perp : 0) + (axial - perp) * u[a] * u[b];
                e = fmax(e, ct_rel(p->inertia[a][b], ref, scale));
            }
    } else {
        e = fmax(e, ct_rel(p->inertia[2][2], perp, scale));
    }
    return e;
}

static double sphere_volume(int dim, double r) { return dim == 3 ? 4.0 / 3.0 * V_PI * r * r * r : V_PI * r * r; }

/* Dumbbells: two pebbles on an oblique axis, apart (and touching). */
static void check_dumbbell(int dim, double r1, double r2, double gap)
{
    sx_model *m = ct_model(dim, 0, 1e7, 0.5, RHO, 0);
    const double u3[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3}, u2[3] = {0.6, 0.8, 0};
    const double *u = dim == 3 ? u3 : u2;
    const double p0[3] = {0.1, -0.2, 0.05};
    const double L = r1 + r2 + gap; /* distance of the centres */
    double pos[6];
    for (int k = 0; k < dim; k++) {
        pos[k] = p0[k] - 0.3 * L * u[k];
        pos[dim + k] = p0[k] + 0.7 * L * u[k];
    }
    const double rad[2] = {r1, r2};
    const int t = ct_template(m, "dumbbell", pos, rad, 2);
    sx_clump_props p;
    ck_assert(sx_clump_template_props(m, t, &p) == SX_OK);
    ck_assert(!p.overlapping && p.error == 0);
    /* closed form: a sphere's own 2/5 v r^2 (disk: 1/2 v r^2), plus v d^2 about a perpendicular axis */
    const double v1 = sphere_volume(dim, r1), v2 = sphere_volume(dim, r2), own = dim == 3 ? 0.4 : 0.5;
    const double V = v1 + v2, sc = (v2 * L) / V; /* centroid from pebble 1 along u */
    const double axial = own * (v1 * r1 * r1 + v2 * r2 * r2);
    const double perp = axial + v1 * sc * sc + v2 * (L - sc) * (L - sc);
    double c[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) c[k] = pos[k] + sc * u[k];
    const double e = axisymmetric_diff(dim, &p, V, c, u, axial, perp);
    ck_assert_msg(e < 1e-12, "dumbbell %dD: relative error %g", dim, e);
    if (dim == 3) { /* the smallest principal moment is the axial one, about u */
        ck_assert_double_eq_tol(p.principal[0], axial, 1e-12 * perp);
        ck_assert_double_eq_tol(p.principal[1], perp, 1e-12 * perp);
        ck_assert_double_eq_tol(p.principal[2], perp, 1e-12 * perp);
        const double align = fabs(p.axes[0][0] * u[0] + p.axes[1][0] * u[1] + p.axes[2][0] * u[2]);
        ck_assert_double_eq_tol(align, 1, 1e-12);
    }
    printf("dumbbell %dD (r %g, %g, gap %g): max relative error %.2e\n", dim, r1, r2, gap, e);
    sx_model_destroy(m);
}

START_TEST(dumbbell_3d)
{
    check_dumbbell(3, 0.01, 0.01, 0.004);
    check_dumbbell(3, 0.01, 0.006, 0);
}
END_TEST

START_TEST(dumbbell_2d)
{
    check_dumbbell(2, 0.01, 0.01, 0.004);
    check_dumbbell(2, 0.01, 0.006, 0);
}
END_TEST

/* Three equal spheres at (0,0,0), (2a,0,0), (0,2a,0) (a >= r: apart).
 * Centroid (2a/3, 2a/3, 0); with v the volume of one,
 *   I_xx = I_yy = 6/5 v r^2 + 8/3 v a^2,  I_zz = 6/5 v r^2 + 16/3 v a^2,  I_xy = 4/3 v a^2,
 * principal moments 6/5 v r^2 + {4/3, 4, 16/3} v a^2 about (1,-1,0)/sqrt2,
 * (1,1,0)/sqrt2 and z. */
START_TEST(three_pebbles)
{
    sx_model *m = ct_model(3, 0, 1e7, 0.5, RHO, 0);
    const double r = 0.01, a = 0.013;
    const double pos[9] = {0, 0, 0, 2 * a, 0, 0, 0, 2 * a, 0}, rad[3] = {r, r, r};
    const int t = ct_template(m, "ell", pos, rad, 3);
    sx_clump_props p;
    ck_assert(sx_clump_template_props(m, t, &p) == SX_OK);
    const double v = sphere_volume(3, r), own = 1.2 * v * r * r, va = v * a * a;
    const double I[3][3] = {{own + 8.0 / 3 * va, 4.0 / 3 * va, 0}, {4.0 / 3 * va, own + 8.0 / 3 * va, 0},
                            {0, 0, own + 16.0 / 3 * va}};
    const double scale = I[2][2];
    double e = ct_rel(p.volume, 3 * v, 3 * v);
    e = fmax(e, ct_rel(p.centroid[0], 2 * a / 3, a));
    e = fmax(e, ct_rel(p.centroid[1], 2 * a / 3, a));
    e = fmax(e, ct_rel(p.centroid[2], 0, a));
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) e = fmax(e, ct_rel(p.inertia[i][j], I[i][j], scale));
    const double principal[3] = {own + 4.0 / 3 * va, own + 4 * va, own + 16.0 / 3 * va};
    for (int k = 0; k < 3; k++) e = fmax(e, ct_rel(p.principal[k], principal[k], scale));
    /* the axes: (1,-1,0)/sqrt2 for the smallest, (1,1,0)/sqrt2 next, z for the largest */
    e = fmax(e, fabs(fabs(p.axes[0][0] - p.axes[1][0]) / sqrt(2.0) - 1));
    e = fmax(e, fabs(fabs(p.axes[0][1] + p.axes[1][1]) / sqrt(2.0) - 1));
    e = fmax(e, fabs(fabs(p.axes[2][2]) - 1));
    ck_assert_msg(e < 1e-12, "three pebbles: relative error %g", e);
    printf("three pebbles: max relative error %.2e\n", e);

    /* a clump of it, turned and scaled: mass rho s^3 V, inertia rho s^5 R I R^T in space */
    sx_clump_def cd = sx_clump_default_def();
    cd.template_index = t;
    cd.scale = 1.5;
    const double ang = 0.7, ax[3] = {2.0 / 7, 3.0 / 7, 6.0 / 7};
    cd.orientation[0] = cos(ang / 2);
    for (int k = 0; k < 3; k++) cd.orientation[k + 1] = sin(ang / 2) * ax[k];
    int64_t id;
    ck_assert(sx_clump_add(m, &cd, &id) == SX_OK);
    double mass, tensor[3][3], pr[3];
    ck_assert(sx_clump_get(m, id, SX_CLUMP_MASS, &mass) == SX_OK);
    ck_assert_double_eq_tol(mass, RHO * pow(1.5, 3) * 3 * v, 1e-12 * mass);
    ck_assert(sx_clump_inertia(m, id, pr, tensor) == SX_OK);
    /* R from the quaternion (Rodrigues) */
    double R[3][3];
    const double cs = cos(ang), sn = sin(ang);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            const int k = 3 - i - j;
            const double cross = i == j ? 0 : ((j == (i + 1) % 3) ? -1 : 1) * ax[k];
            R[i][j] = (i == j ? cs : 0) + (1 - cs) * ax[i] * ax[j] + sn * cross;
        }
    const double k5 = RHO * pow(1.5, 5);
    double e2 = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double ref = 0;
            for (int a1 = 0; a1 < 3; a1++)
                for (int b1 = 0; b1 < 3; b1++) ref += R[i][a1] * I[a1][b1] * R[j][b1];
            e2 = fmax(e2, ct_rel(tensor[i][j], k5 * ref, k5 * scale));
        }
    ck_assert_msg(e2 < 1e-12, "clump inertia in space: relative error %g", e2);
    /* its pebbles sit where the template puts them: pos + R s (p - centroid) */
    int64_t peb[3], np;
    ck_assert(sx_clump_pebbles(m, id, peb, 3, &np) == SX_OK && np == 3);
    for (int k = 0; k < 3; k++) {
        double x[3], rb;
        v_get(m, peb[k], SX_BALL_POS, x);
        rb = v_scalar(m, peb[k], SX_BALL_RADIUS);
        ck_assert_double_eq_tol(rb, 1.5 * r, 1e-15);
        for (int i = 0; i < 3; i++) {
            double ref = 0;
            for (int j = 0; j < 3; j++) ref += R[i][j] * 1.5 * (pos[3 * k + j] - p.centroid[j]);
            ck_assert_double_eq_tol(x[i], ref, 1e-14);
        }
        ck_assert_int_eq(sx_ball_clump(m, peb[k]), id);
    }
    double q[4];
    ck_assert(sx_clump_orientation(m, id, q) == SX_OK);
    for (int k = 0; k < 4; k++) ck_assert_double_eq_tol(q[k], cd.orientation[k], 1e-14);
    sx_model_destroy(m);
}
END_TEST

/* Overlapping pairs: the numerical union against the exact reference;
 * returns the actual error and writes the template's estimate. */
static double overlap_error(int dim, double r1, double r2, double dist, double *estimate, double *lens)
{
    sx_model *m = ct_model(dim, 0, 1e7, 0.5, RHO, 0);
    const double u3[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3}, u2[3] = {0.6, 0.8, 0};
    const double *u = dim == 3 ? u3 : u2;
    const double p0[3] = {0.02, 0.01, -0.03};
    double pos[6];
    for (int k = 0; k < dim; k++) {
        pos[k] = p0[k];
        pos[dim + k] = p0[k] + dist * u[k];
    }
    const double rad[2] = {r1, r2};
    const int t = ct_template(m, "lens", pos, rad, 2);
    sx_clump_props p;
    ck_assert(sx_clump_template_props(m, t, &p) == SX_OK);
    ck_assert(p.overlapping);
    const pair_ref ref = union_of_pair(dim, 0, r1, dist, r2);
    double c[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) c[k] = p0[k] + ref.centroid * u[k];
    *estimate = p.error;
    *lens = (sphere_volume(dim, r1) + sphere_volume(dim, r2) - ref.volume) / ref.volume;
    sx_model_destroy(m);
    return axisymmetric_diff(dim, &p, ref.volume, c, u, ref.axial, ref.perp);
}

/* A sweep of pairs, from one pebble nearly inside the other to nearly
 * apart, radius ratios 0.4 to 1: the actual error within the template's
 * estimate and within the stated accuracy (1e-5 in 3D, 1e-7 in 2D at the
 * default lines). */
static void sweep_overlaps(int dim, double stated)
{
    const double r1 = 0.01;
    double worst = 0, worst_est = 0;
    int cases = 0;
    for (int ir = 0; ir < 4; ir++) {
        const double r2 = r1 * (0.4 + 0.2 * ir);
        for (int k = 1; k < 13; k++) {
            /* centre distances strictly between nesting (r1 - r2) and touching (r1 + r2) */
            const double dist = (r1 - r2) + (2 * r2) * k / 13.0;
            const double cut = (r1 * r1 - r2 * r2 + dist * dist) / (2 * dist);
            if (!(cut > dist - r2 && cut < r1)) continue; /* no intersection circle: not a lens */
            double est, lens;
            const double e = overlap_error(dim, r1, r2, dist, &est, &lens);
            ck_assert_msg(e <= est, "%dD r2 %g d %g: actual error %g above the estimate %g", dim, r2, dist, e, est);
            ck_assert_msg(e <= stated, "%dD r2 %g d %g: actual error %g above the stated %g", dim, r2, dist, e, stated);
            if (e > worst) worst = e, worst_est = est;
            cases++;
        }
    }
    printf("overlapping pairs %dD: %d geometries, largest actual error %.2e (its estimate %.2e), stated accuracy %.0e\n",
           dim, cases, worst, worst_est, stated);
    ck_assert_int_ge(cases, 30);
}

START_TEST(overlapping_pair_3d)
{
    double est, lens;
    const double e = overlap_error(3, 0.01, 0.01, 0.012, &est, &lens);
    printf("overlapping pair 3D (r 0.01, 0.01, d 0.012; lens %.1f %% of the union): error %.2e, estimate %.2e\n",
           100 * lens, e, est);
    sweep_overlaps(3, 1e-5);
}
END_TEST

START_TEST(overlapping_pair_2d)
{
    double est, lens;
    const double e = overlap_error(2, 0.01, 0.01, 0.012, &est, &lens);
    printf("overlapping pair 2D (r 0.01, 0.01, d 0.012; lens %.1f %% of the union): error %.2e, estimate %.2e\n",
           100 * lens, e, est);
    sweep_overlaps(2, 1e-7);
}
END_TEST

/* Bad templates are refused with a message, and names are unique. */
START_TEST(bad_templates)
{
    sx_model *m = ct_model(3, 0, 1e7, 0.5, RHO, 0);
    const double pos[6] = {0, 0, 0, 1, 0, 0}, bad_rad[2] = {0.5, -1}, rad[2] = {0.5, 0.5};
    sx_clump_template_def td = {pos, bad_rad, 2, 0};
    ck_assert(sx_clump_template_add(m, "x", &td, NULL) == SX_EINVAL);
    ck_assert(strstr(sx_model_error(m), "pebble 2") != NULL);
    td.radius = rad;
    td.lines = 3;
    ck_assert(sx_clump_template_add(m, "x", &td, NULL) == SX_EINVAL);
    td.lines = 0;
    ck_assert(sx_clump_template_add(m, "x", &td, NULL) == SX_OK);
    ck_assert(sx_clump_template_add(m, "x", &td, NULL) == SX_EINVAL);
    ck_assert_int_eq(sx_clump_template_count(m), 1);
    ck_assert_int_eq(sx_clump_template_find(m, "x"), 0);
    sx_clump_def cd = sx_clump_default_def();
    cd.scale = 0;
    ck_assert(sx_clump_add(m, &cd, NULL) == SX_EINVAL);
    cd.scale = 1;
    cd.orientation[0] = 0;
    ck_assert(sx_clump_add(m, &cd, NULL) == SX_EINVAL);
    cd.template_index = 5;
    ck_assert(sx_clump_add(m, &cd, NULL) == SX_ENOTFOUND);
    ck_assert_int_eq(sx_ball_count(m), 0);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("clump_mass");
    V_TCASE(s, dumbbell_3d);
    V_TCASE(s, dumbbell_2d);
    V_TCASE(s, three_pebbles);
    V_TCASE(s, overlapping_pair_3d);
    V_TCASE(s, overlapping_pair_2d);
    V_TCASE(s, bad_templates);
    return v_run(s);
}
