/* Two balls joined by one flat joint (laws/flatjoint.h), 2D and 3D, against
 * closed forms.
 *
 * Scene: equal balls R = 1 mm, centres 2R + g apart (g = 10 um), face
 * radius Rf = lambda R with lambda = 0.8, Ec-bar = 1 GPa (kn = Ec/(2R),
 * ks = kn/2.5), sigma_c = 2 MPa, c = 3 MPa, phi = 0, mu = 0.5; 2D 4
 * segments, 3D 2 rings x 4 sectors. Ball A is held still and the load is
 * imposed kinematically (fixities), as in parallel_bond.c:
 *   tension      B moves along n: Fn = -kn A u, stiffness kn A, and every
 *                element reaches sigma_c together: the face breaks at
 *                sigma_c A, one tension crack per element;
 *   shear        B moves across n: stiffness ks A, every element breaks in
 *                shear at tau = c, so at c A;
 *   bending      A and B spin at -w and +w (relative rotation theta = 2 w t,
 *                no relative displacement of the contact points): the
 *                moment is kn I theta (the elements' own moments complete
 *                the sum of A_e y_e^2 to I), and the outermost element
 *                breaks when its centroid's stress kn theta y_max reaches
 *                sigma_c: M = sigma_c I / y_max, y_max the largest centroid
 *                offset along the opening direction (2D Rf (1 - 1/Nr); 3D
 *                the outer sectors' centroid distance (2/3)(r1^3 - r0^3) /
 *                (r1^2 - r0^2) sin(da/2)/(da/2) times sin 45 deg), and that
 *                many elements break at once (2D one, 3D two);
 *   half slit    the elements of one half unbonded (2D the two with y > 0,
 *                3D the sectors with z > 0): in tension the face carries
 *                kn A/2 and breaks at sigma_c A/2; in bending towards the
 *                slit half (which closes) the moment is the full kn I
 *                theta, bending away from it (the slit opens and carries
 *                nothing) the bonded half's kn (I/2) theta.
 * with 2D A = 2 Rf, I = 2 Rf^3/3 (unit thickness), 3D A = pi Rf^2,
 * I = pi Rf^4/4. Stiffnesses are measured between 25 % and 75 % of the
 * break load (exact up to rounding: the face is linear); the break load
 * the largest load carried, within 0.5 % (the load rate breaks the face
 * in 2000 steps: overshoot at most 0.05 %). Also: the cracks name the
 * flat joint, their element and mode; after a full break B carries
 * nothing and the joint is gone.
 */
#include "bpm.h"
#include "laws/flatjoint.h"

enum load { TENSION, SHEAR, BENDING, HALF_TENSION, HALF_CLOSE, HALF_OPEN };
static const char *const load_name[] = {"tension", "shear", "bending", "half slit: tension",
                                        "half slit: bending, slit closing", "half slit: bending, slit opening"};

static const double R = 1e-3, GAP = 1e-5;
static const double LAMBDA = 0.8, EBAR = 1e9, RATIO = 2.5, SIGMA_C = 2e6, COH = 3e6, MU = 0.5;
static const int NR2 = 4, NR3 = 2, NA3 = 4;
static const int STEPS_TO_BREAK = 2000;

typedef struct face {
    double kn, ks, rf, area, inertia, ymax;
    int nel, outer; /* elements; those breaking first in bending */
} face;

static face closed_face(int dim)
{
    face f;
    f.kn = EBAR / (2 * R);
    f.ks = f.kn / RATIO;
    f.rf = LAMBDA * R;
    if (dim == 3) {
        f.area = BPM_PI * f.rf * f.rf;
        f.inertia = 0.25 * BPM_PI * pow(f.rf, 4);
        const double r0 = f.rf * (NR3 - 1) / NR3, r1 = f.rf, da = 2 * BPM_PI / NA3;
        const double rho = 2.0 / 3.0 * (pow(r1, 3) - pow(r0, 3)) / (r1 * r1 - r0 * r0) * sin(da / 2) / (da / 2);
        f.ymax = rho * sin(BPM_PI / 4);
        f.nel = NR3 * NA3;
        f.outer = 2;
    } else {
        f.area = 2 * f.rf;
        f.inertia = 2.0 / 3.0 * pow(f.rf, 3);
        f.ymax = f.rf * (1 - 1.0 / NR2);
        f.nel = NR2;
        f.outer = 1;
    }
    return f;
}

typedef struct pair_scene {
    sx_model *m;
    int64_t a, b;
} pair_scene;

static pair_scene joined_pair(int dim)
{
    pair_scene p;
    p.m = bpm_model(dim, 0);
    sx_material_def md = sx_material_default_def();
    const int mat = bpm_material(p.m, "rock", &md);
    const double xa[3] = {0, 0, 0}, xb[3] = {2 * R + GAP, 0, 0};
    p.a = scene_ball_of(p.m, mat, xa, NULL, R);
    p.b = scene_ball_of(p.m, mat, xb, NULL, R);
    sx_bond_def bd = sx_bond_default_def();
    bd.kind = SX_BOND_FLATJOINT;
    bd.gap = 2 * GAP;
    bd.radius_multiplier = LAMBDA;
    bd.modulus = EBAR;
    bd.stiffness_ratio = RATIO;
    bd.tensile_strength = SIGMA_C;
    bd.cohesion = COH;
    bd.friction = MU;
    bd.elements = dim == 3 ? NR3 : NR2;
    bd.sectors = NA3;
    int64_t n = 0;
    ck_assert_msg(sx_bond_install(p.m, &bd, &n) == SX_OK, "%s", sx_model_error(p.m));
    ck_assert_int_eq(n, 1);
    ck_assert_int_eq(sx_flatjoint_get(p.m, p.a, p.b, -1, NULL), dim == 3 ? NR3 * NA3 : NR2);
    return p;
}

/* One half of the face slit: 2D the segments with y > 0, 3D the sectors
 * with z > 0 (the first na/2 of each ring); checked from the centroids. */
static void slit_half(pair_scene *p, int dim)
{
    const int nel = sx_flatjoint_get(p->m, p->a, p->b, -1, NULL);
    int slit = 0;
    for (int e = 0; e < nel; e++) {
        sx_fj_element el;
        sx_flatjoint_get(p->m, p->a, p->b, e, &el);
        if (el.centroid[dim == 3 ? 2 : 1] > 0) {
            ck_assert_int_eq(sx_flatjoint_unbond(p->m, p->a, p->b, e), SX_OK);
            slit++;
        }
    }
    ck_assert_int_eq(slit, nel / 2);
}

static double load_on_b(const pair_scene *p, int dim, enum load ld)
{
    double f[3], t[3];
    bpm_vec(p->m, p->b, SX_BALL_FORCE, f);
    bpm_vec(p->m, p->b, SX_BALL_MOMENT, t);
    switch (ld) {
    case TENSION:
    case HALF_TENSION: return -f[0];
    case SHEAR: return -f[1];
    default: return dim == 3 ? -t[1] : -t[0];
    }
}

static void run_load(int dim, enum load ld)
{
    printf("%dD flat joint, %s\n", dim, load_name[ld]);
    const face s = closed_face(dim);
    pair_scene p = joined_pair(dim);
    if (ld >= HALF_TENSION) slit_half(&p, dim);
    double area[64]; /* the elements' areas, for their stresses once the joint is gone */
    for (int e = 0; e < s.nel; e++) {
        sx_fj_element el;
        ck_assert_int_eq(sx_flatjoint_get(p.m, p.a, p.b, e, &el), s.nel);
        area[e] = el.area;
    }
    const double dt = sx_model_timestep(p.m);
    ck_assert(dt > 0);
    const double T = STEPS_TO_BREAK * dt;
    double stiff = 0, brk = 0, vel[3] = {0, 0, 0}, spin[3] = {0, 0, 0};
    const int ax = dim == 3 ? 1 : 0; /* the bending axis: world y in 3D (t1), z in 2D */
    switch (ld) {
    case TENSION:
        stiff = s.kn * s.area, brk = SIGMA_C * s.area;
        vel[0] = brk / stiff / T;
        break;
    case SHEAR:
        stiff = s.ks * s.area, brk = COH * s.area;
        vel[1] = brk / stiff / T;
        break;
    case BENDING:
        stiff = s.kn * s.inertia, brk = SIGMA_C * s.inertia / s.ymax;
        spin[ax] = 0.5 * brk / stiff / T;
        break;
    case HALF_TENSION:
        stiff = 0.5 * s.kn * s.area, brk = 0.5 * SIGMA_C * s.area;
        vel[0] = brk / stiff / T;
        break;
    case HALF_CLOSE:
    case HALF_OPEN: {
        /* 2D: theta > 0 closes y > 0 (g = g0 - theta y); 3D: a rotation
         * about t1 = y by theta1 opens z > 0 (g = g0 + theta1 z) */
        const double closing = dim == 3 ? -1 : 1;
        stiff = (ld == HALF_CLOSE ? 1 : 0.5) * s.kn * s.inertia;
        brk = 0.5 * SIGMA_C * s.inertia / s.ymax; /* kept below any break */
        spin[ax] = (ld == HALF_CLOSE ? closing : -closing) * 0.5 * brk / stiff / T;
        break;
    }
    }
    const double mspin[3] = {-spin[0], -spin[1], -spin[2]};
    scene_impose(p.m, p.a, NULL, mspin);
    scene_impose(p.m, p.b, vel, spin);
    const double rate = vel[0] + vel[1] + 2 * spin[ax];
    const double sign = rate > 0 ? 1 : -1;
    double q1 = NAN, q2 = NAN, p1 = NAN, p2 = NAN, peak = 0;
    int64_t broke_at = -1;
    const int64_t steps = ld >= HALF_CLOSE ? STEPS_TO_BREAK : 2 * STEPS_TO_BREAK;
    for (int64_t step = 0; step < steps; step++) {
        const double q = fabs(rate) * sx_model_time(p.m);
        bpm_cycle(p.m, 1);
        if (sx_crack_count(p.m) > 0) {
            broke_at = step;
            break;
        }
        const double load = sign * load_on_b(&p, dim, ld);
        if (load > peak) peak = load;
        if (isnan(p1) && load >= 0.25 * brk) q1 = q, p1 = load;
        if (isnan(p2) && load >= 0.75 * brk) q2 = q, p2 = load;
    }
    BPM_CHECK("stiffness (N/m or N m/rad)", (p2 - p1) / (q2 - q1), stiff, 0.005);
    if (ld >= HALF_CLOSE) {
        ck_assert_int_eq(sx_crack_count(p.m), 0);
        sx_model_destroy(p.m);
        return;
    }
    ck_assert_msg(broke_at > 0, "the face did not break");
    BPM_CHECK("largest load carried before the break", peak, brk, 0.005);
    const int64_t nc = sx_crack_count(p.m);
    const int64_t want = ld == BENDING ? s.outer : ld == HALF_TENSION ? s.nel / 2 : s.nel;
    ck_assert_msg(nc == want, "%lld elements broke at the first break, expected %lld", (long long)nc,
                  (long long)want);
    for (int64_t k = 0; k < nc; k++) {
        sx_crack c;
        ck_assert(sx_crack_get(p.m, k, &c) == SX_OK);
        ck_assert_int_eq(c.kind, SX_BOND_FLATJOINT);
        ck_assert_int_eq(c.mode, ld == SHEAR ? SX_CRACK_SHEAR : SX_CRACK_TENSION);
        ck_assert(c.element >= 0 && c.element < s.nel);
        if (ld != SHEAR) BPM_CHECK("element's tensile stress at its break (Pa)", -c.fn / area[c.element], SIGMA_C, 0.005);
        else BPM_CHECK("element's shear stress at its break (Pa)", c.fs / area[c.element], COH, 0.005);
        sx_fj_element el;
        if (sx_flatjoint_get(p.m, p.a, p.b, c.element, &el)) /* the joint holds on: its element's state */
            ck_assert_int_eq(el.state, ld == SHEAR ? SX_FJ_SHEAR : SX_FJ_TENSION);
    }
    /* bending: the joint holds on the other elements, each still bonded */
    if (ld == BENDING) {
        int bonded = 0;
        for (int e = 0; e < s.nel; e++) {
            sx_fj_element el;
            ck_assert_int_eq(sx_flatjoint_get(p.m, p.a, p.b, e, &el), s.nel);
            bonded += el.state == SX_FJ_BONDED;
        }
        ck_assert_int_eq(bonded, s.nel - s.outer);
        ck_assert_int_eq(sx_bond_count(p.m), 1);
    }
    printf("  %lld elements broke at step %lld, expected about %d\n", (long long)nc, (long long)broke_at,
           STEPS_TO_BREAK);
    if (ld == TENSION || ld == SHEAR || ld == HALF_TENSION) {
        /* open (tension), or unloaded in shear with no normal force: nothing holds B */
        bpm_cycle(p.m, 2);
        ck_assert_int_eq(sx_bond_count(p.m), 0);
        double f[3], t[3];
        bpm_vec(p.m, p.b, SX_BALL_FORCE, f);
        bpm_vec(p.m, p.b, SX_BALL_MOMENT, t);
        ck_assert_msg(f[0] == 0 && f[1] == 0 && f[2] == 0 && t[0] == 0 && t[1] == 0 && t[2] == 0,
                      "B still loaded after the break: F = (%g, %g, %g), M = (%g, %g, %g)", f[0], f[1], f[2], t[0],
                      t[1], t[2]);
    }
    sx_model_destroy(p.m);
}

START_TEST(face_3d) { run_load(3, (enum load)_i); }
END_TEST

START_TEST(face_2d) { run_load(2, (enum load)_i); }
END_TEST

/* The 3D closed part of an unbonded element (sx_law_fj_closed), exactly:
 * a full disk of radius 1 cut by the line u.p = h against the circular
 * segment's closed forms; the elements of a face (2 x 4 and 3 x 6) cut by
 * one line adding up to the disk's part to rounding; a closed element's
 * load equal to the bonded (whole) one; the load the derivative of the
 * energy (fn = -dE/dgc, m2 = dE/day, m1 = -dE/daz). */
static sx_law_fj_geom disk_geom(void)
{
    sx_law_fj_geom g;
    sx_law_fj_element(3, 1.0, 1, 1, 0, &g);
    return g;
}

/* gc that puts the line u.p = h (u at angle beta) through element g's gap field of slope a */
static double gc_for(const sx_law_fj_geom *g, double a, double beta, double h)
{
    return a * cos(beta) * g->y + a * sin(beta) * g->z - h * a;
}

static void near(double got, double want, double tol, const char *what, double beta, double h)
{
    ck_assert_msg(fabs(got - want) <= tol, "%s at beta %g, h %g: %.17g, expected %.17g", what, beta, h, got, want);
}

START_TEST(closed_part_3d)
{
    const double pi = BPM_PI;
    const sx_law_fj_geom disk = disk_geom();
    int cuts = 0;
    for (int ib = 0; ib < 13; ib++)
        for (int ih = 0; ih < 11; ih++) {
            const double beta = -pi + 2 * pi * ib / 13 + 0.1, h = -1.25 + 0.25 * ih + 0.01 * ib, a = 0.7;
            const double ay = a * cos(beta), az = a * sin(beta);
            const sx_law_fj_moments q = sx_law_fj_closed(&disk, gc_for(&disk, a, beta, h), ay, az);
            /* the segment beyond the line, s = u.p in (h, 1): area, first and second moments */
            double sa = 0, sm = 0, sss = 0, stt = 0;
            if (h < 1) {
                const double hh = h > -1 ? h : -1, w = sqrt(1 - hh * hh);
                sa = acos(hh) - hh * w;
                sm = 2.0 / 3.0 * w * w * w;
                /* int s^2 2 sqrt(1 - s^2) ds and int (2/3)(1 - s^2)^(3/2) ds from hh to 1 */
                sss = 2 * (pi / 16 - (hh * (2 * hh * hh - 1) * w / 8 + asin(hh) / 8));
                stt = 2.0 / 3.0 * (3 * pi / 16 - (hh * (5 - 2 * hh * hh) * w / 8 + 3 * asin(hh) / 8));
            }
            const double ca = pi - sa, cm = -sm, css = pi / 4 - sss, ctt = pi / 4 - stt; /* the closed side */
            const double c = cos(beta), s = sin(beta), tol = 1e-13;
            near(q.a, ca, tol, "area", beta, h);
            near(q.y, c * cm, tol, "y moment", beta, h);
            near(q.z, s * cm, tol, "z moment", beta, h);
            near(q.yy, c * c * css + s * s * ctt, tol, "yy", beta, h);
            near(q.zz, s * s * css + c * c * ctt, tol, "zz", beta, h);
            near(q.yz, s * c * (css - ctt), tol, "yz", beta, h);
            cuts += h > -1 && h < 1;
            /* the elements of faces cut by the same line add up to the disk's part */
            const int nrs[2] = {2, 3}, nas[2] = {4, 6};
            for (int f = 0; f < 2; f++) {
                sx_law_fj_moments sum = {0, 0, 0, 0, 0, 0};
                for (int e = 0; e < nrs[f] * nas[f]; e++) {
                    sx_law_fj_geom g;
                    sx_law_fj_element(3, 1.0, nrs[f], nas[f], e, &g);
                    const sx_law_fj_moments p = sx_law_fj_closed(&g, gc_for(&g, a, beta, h), ay, az);
                    sx_law_fj_add(&sum, 1, &p);
                }
                near(sum.a, q.a, tol, "elements' area", beta, h);
                near(sum.y, q.y, tol, "elements' y moment", beta, h);
                near(sum.z, q.z, tol, "elements' z moment", beta, h);
                near(sum.yy, q.yy, tol, "elements' yy", beta, h);
                near(sum.yz, q.yz, tol, "elements' yz", beta, h);
                near(sum.zz, q.zz, tol, "elements' zz", beta, h);
            }
        }
    ck_assert_int_ge(cuts, 80);
    /* a closed element carries what it carries bonded; the load is the energy's derivative */
    const double kn = 3e12;
    for (int e = 0; e < 8; e++) {
        sx_law_fj_geom g;
        sx_law_fj_element(3, 1e-3, 2, 4, e, &g);
        const double ay = 2e-3, az = -1.3e-3, closed = -5e-6; /* |a| r < 2.4e-6: closed everywhere */
        const sx_law_fj_load w = sx_law_fj_whole(&g, kn, closed, ay, az), l = sx_law_fj_contact(3, &g, kn, closed, ay, az);
        near(l.fn, w.fn, 1e-12 * fabs(w.fn), "closed fn", e, 0);
        near(l.m1, w.m1, 1e-12 * fabs(w.fn) * 1e-3, "closed m1", e, 0);
        near(l.m2, w.m2, 1e-12 * fabs(w.fn) * 1e-3, "closed m2", e, 0);
        near(l.energy, w.energy, 1e-12 * w.energy, "closed energy", e, 0);
        const double gc = 2e-7, d = 1e-13, dd = 1e-9; /* partly closed: the gap varies by +- 0.6e-6 over an element */
        const sx_law_fj_load p = sx_law_fj_contact(3, &g, kn, gc, ay, az);
        ck_assert_msg(p.fn > 0 && p.fn < sx_law_fj_contact(3, &g, kn, gc - 1e-7, ay, az).fn &&
                          p.fn < sx_law_fj_whole(&g, kn, gc - 1e-5, ay, az).fn, "partly closed");
        const double e_gc = (sx_law_fj_contact(3, &g, kn, gc + d, ay, az).energy -
                             sx_law_fj_contact(3, &g, kn, gc - d, ay, az).energy) / (2 * d);
        const double e_ay = (sx_law_fj_contact(3, &g, kn, gc, ay + dd, az).energy -
                             sx_law_fj_contact(3, &g, kn, gc, ay - dd, az).energy) / (2 * dd);
        const double e_az = (sx_law_fj_contact(3, &g, kn, gc, ay, az + dd).energy -
                             sx_law_fj_contact(3, &g, kn, gc, ay, az - dd).energy) / (2 * dd);
        near(-e_gc, p.fn, 1e-6 * p.fn, "fn = -dE/dgc", e, gc);
        near(e_ay, p.m2, 1e-6 * fabs(p.fn) * 1e-3, "m2 = dE/day", e, gc);
        near(-e_az, p.m1, 1e-6 * fabs(p.fn) * 1e-3, "m1 = -dE/daz", e, gc);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("flat_joint");
    TCase *tc = tcase_create("loads");
    tcase_add_loop_test(tc, face_2d, TENSION, HALF_OPEN + 1);
    tcase_add_loop_test(tc, face_3d, TENSION, HALF_OPEN + 1);
    tcase_add_test(tc, closed_part_3d);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
