/* Young's modulus of a regular 2D hexagonal packing of equal disks joined by
 * linear springs (normal Kn, shear Ks per contact), loaded uniaxially.
 *
 * Closed form. Disks of radius R touching in a triangular (hexagonal) Bravais
 * lattice, spacing d = 2R, contact directions n at 0, 60 and 120 degrees,
 * area per disk V = (sqrt 3 / 2) d^2 (unit thickness). Take a uniform strain
 * eps (symmetric) with every disk displaced affinely, u = eps x, and spinning
 * with the local rigid rotation (zero here). The relative displacement of the
 * contact points of a contact is then eps d n, so its force on the disk at +n
 * is (tension positive)
 *     f(n) = d [Kn (n.eps n) n + Ks (eps n - (n.eps n) n)].
 * Equilibrium of every disk: the contacts at +n and -n give opposite forces
 * (the lattice is centrosymmetric), so forces balance; their moments
 * R n x f(n) add, and over the three directions
 *     sum_n n x eps n = eps_xy sum (nx^2 - ny^2) + (eps_yy - eps_xx) sum nx ny
 *                     = eps_xy sum cos 2t + (eps_yy - eps_xx)/2 sum sin 2t = 0,
 * so the affine field is the exact equilibrium of the infinite lattice. The
 * stress is sigma = (1/V) sum over the three contacts of a disk of f(n) (x) d n;
 * with sum n_i n_j = (3/2) delta_ij and sum n_i n_j n_k n_l =
 * (3/8)(d_ij d_kl + d_ik d_jl + d_il d_jk) this is isotropic linear elasticity
 * with Lame constants
 *     lambda = (sqrt3/4)(Kn - Ks),   mu = (sqrt3/4)(Kn + Ks),
 * so the (2D, unit thickness) Young's modulus and Poisson's ratio are
 *     E  = 4 mu (lambda + mu) / (lambda + 2 mu) = 2 sqrt3 Kn (Kn + Ks) / (3 Kn + Ks),
 *     nu = lambda / (lambda + 2 mu) = (Kn - Ks) / (3 Kn + Ks)
 * (for Ks = 0, E = 2 Kn / sqrt 3 and nu = 1/3, the classical spring network).
 *
 * Scene: 30 x 30 disks, R = 1 mm, ball springs kn = 2e8, ks = 0.8e8 N/m, so
 * Kn = 1e8, Ks = 4e7 N/m per contact (4-22/4-23); E = 1.4265e8 N/m,
 * nu = 0.1765. Every touching pair carries a contact bond of unbreakable
 * strength so that the springs also carry tension (the lateral contacts are
 * stretched by the Poisson effect) and friction is off (bonded contacts do
 * not slip). Frictionless walls below and above; the top one moves down to a
 * strain of about 1e-4 and stops; local damping 0.7 brings the sample to
 * rest. The free sides and the walls perturb the affine field near them
 * (Saint-Venant), so stress and strain are measured in the central third:
 * strains from the mean positions of interior rows and columns of disks,
 * stress as the average of the disks' stresses
 *     sigma_disk = (1/V) (1/2) sum over its contacts of f (x) L
 * (L the branch vector, V the deformed cell area). E is computed from
 * the isotropic law, E = (s_yy^2 - s_xx^2) / (e_yy s_yy - e_xx s_xx), which
 * reduces to s_yy/e_yy in pure uniaxial stress, and likewise
 * nu = (s_xx - E e_xx)/s_yy. (s_xx is printed: it is small, 3e-3 of s_yy,
 * but the edge perturbation does not vanish exactly in the centre; s_yy/e_yy
 * is asserted too.)
 * Tolerance 1 %: the geometric nonlinearity is O(strain) = 1e-4 and the
 * residual imbalance after settling is checked to be below 1e-4 of the load.
 */
#include "bpm.h"

#include <stdlib.h>

enum { NX = 30, NY = 30 };
static const double R = 1e-3, KN_BALL = 2e8, KS_BALL = 0.8e8;

typedef struct lattice {
    sx_model *m;
    int64_t id[NY][NX];
    double x0[NY][NX][2];
    int64_t top;
    double height;
} lattice;

typedef struct stress_acc {
    const lattice *L;
    const bool *inner; /* by ball id */
    int64_t maxid;
    double s[2][2];
} stress_acc;

static bool add_contact(const sx_contact_info *ci, void *ud)
{
    stress_acc *a = ud;
    if (ci->is_wall) return true;
    const bool ia = ci->a <= a->maxid && a->inner[ci->a], ib = ci->b <= a->maxid && a->inner[ci->b];
    if (!ia && !ib) return true;
    double xa[3], xb[3], f[2], l[2];
    bpm_vec(a->L->m, ci->a, SX_BALL_POS, xa);
    bpm_vec(a->L->m, ci->b, SX_BALL_POS, xb);
    for (int k = 0; k < 2; k++) {
        f[k] = ci->fn * ci->normal[k] + ci->shear[k]; /* on b, compression positive along n */
        l[k] = xb[k] - xa[k];
    }
    const double w = 0.5 * ((ia ? 1 : 0) + (ib ? 1 : 0));
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) a->s[i][j] += w * f[i] * l[j];
    return true;
}

START_TEST(hex_young)
{
    lattice L;
    L.m = bpm_model(2, 0);
    sx_material_def md = sx_material_default_def();
    md.kn = KN_BALL, md.ks = KS_BALL;
    md.friction = 0;
    md.damping = 0.7;
    const int mat = bpm_material(L.m, "disk", &md);
    const double dy = sqrt(3.0) * R;
    for (int j = 0; j < NY; j++)
        for (int i = 0; i < NX; i++) {
            const double x[3] = {R + 2 * R * i + (j % 2 ? R : 0), R + dy * j, 0};
            L.id[j][i] = scene_ball_of(L.m, mat, x, NULL, R);
            L.x0[j][i][0] = x[0], L.x0[j][i][1] = x[1];
        }
    L.height = 2 * R + dy * (NY - 1);
    sx_wall_def wd = sx_wall_default_def(2);
    wd.kn = wd.ks = KN_BALL;
    wd.friction = 0;
    ck_assert(sx_wall_add(L.m, &wd, NULL) == SX_OK); /* y = 0, normal +y */
    wd.point[1] = L.height;
    wd.normal[1] = -1;
    ck_assert(sx_wall_add(L.m, &wd, &L.top) == SX_OK);

    sx_bond_def bd = sx_bond_default_def();
    bd.kind = SX_BOND_CONTACT;
    bd.gap = 1e-9;
    bd.normal_strength = bd.shear_strength = 1e30;
    int64_t nb = 0;
    ck_assert_msg(sx_bond_install(L.m, &bd, &nb) == SX_OK, "%s", sx_model_error(L.m));
    const int64_t expected_bonds = (int64_t)NY * (NX - 1) + (int64_t)(NY - 1) * (2 * NX - 1);
    ck_assert_int_eq(nb, expected_bonds);

    const double Kn = 0.5 * KN_BALL, Ks = 0.5 * KS_BALL;
    const double E = 2 * sqrt(3.0) * Kn * (Kn + Ks) / (3 * Kn + Ks), nu = (Kn - Ks) / (3 * Kn + Ks);

    /* load: the top wall moves down 1.2e-4 of the height in 3000 steps, then stops */
    const double dt = sx_model_timestep(L.m);
    const int ramp = 3000, hold = 6000;
    const double vtop[3] = {0, -1.2e-4 * L.height / (ramp * dt), 0}, still[3] = {0, 0, 0};
    ck_assert(sx_wall_set_vel(L.m, L.top, vtop) == SX_OK);
    bpm_cycle(L.m, ramp);
    ck_assert(sx_wall_set_vel(L.m, L.top, still) == SX_OK);
    bpm_cycle(L.m, hold);
    ck_assert_int_eq(sx_crack_count(L.m), 0);

    /* residual imbalance: the largest unbalanced force against the typical contact force */
    double fmax = 0, wf[3], wm[3];
    for (int64_t k = 0; k < sx_ball_count(L.m); k++) {
        double f[3];
        bpm_vec(L.m, sx_ball_id_at(L.m, k), SX_BALL_FORCE, f);
        const double a = hypot(f[0], f[1]);
        if (a > fmax) fmax = a;
    }
    ck_assert(sx_wall_force(L.m, L.top, wf, wm) == SX_OK);
    const double fcontact = fabs(wf[1]) / NX;
    printf("2D hexagonal lattice %dx%d, Kn = %g, Ks = %g N/m: largest unbalanced force %.2e of the mean wall contact "
           "force\n", NX, NY, Kn, Ks, fmax / fcontact);
    ck_assert_msg(fmax <= 1e-4 * fcontact, "not at rest: unbalanced force %g N vs contact force %g N", fmax, fcontact);

    /* strains from the central third */
    const int i0 = NX / 3, i1 = NX - NX / 3 - 1, j0 = NY / 3, j1 = NY - NY / 3 - 1;
    double ylo = 0, yhi = 0, ylo0 = 0, yhi0 = 0, xl = 0, xr = 0, xl0 = 0, xr0 = 0;
    for (int i = i0; i <= i1; i++) {
        double a[3], b[3];
        bpm_vec(L.m, L.id[j0][i], SX_BALL_POS, a);
        bpm_vec(L.m, L.id[j1][i], SX_BALL_POS, b);
        ylo += a[1], yhi += b[1], ylo0 += L.x0[j0][i][1], yhi0 += L.x0[j1][i][1];
    }
    for (int j = j0; j <= j1; j++) {
        double a[3], b[3];
        bpm_vec(L.m, L.id[j][i0], SX_BALL_POS, a);
        bpm_vec(L.m, L.id[j][i1], SX_BALL_POS, b);
        xl += a[0], xr += b[0], xl0 += L.x0[j][i0][0], xr0 += L.x0[j][i1][0];
    }
    const double eyy = ((yhi - ylo) - (yhi0 - ylo0)) / (yhi0 - ylo0); /* tension positive */
    const double exx = ((xr - xl) - (xr0 - xl0)) / (xr0 - xl0);

    /* stress of the same disks (those strictly inside the strain gauges) */
    int64_t maxid = 0;
    for (int j = 0; j < NY; j++)
        for (int i = 0; i < NX; i++)
            if (L.id[j][i] > maxid) maxid = L.id[j][i];
    bool *inner = calloc((size_t)maxid + 1, sizeof *inner);
    ck_assert(inner);
    int ninner = 0;
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++) inner[L.id[j][i]] = true, ninner++;
    stress_acc acc = {.L = &L, .inner = inner, .maxid = maxid};
    sx_contact_each(L.m, add_contact, &acc);
    free(inner);
    const double cell = sqrt(3.0) / 2 * 4 * R * R * (1 + exx) * (1 + eyy);
    const double sxx = -acc.s[0][0] / (ninner * cell), syy = -acc.s[1][1] / (ninner * cell); /* tension positive */
    const double sxy = -acc.s[0][1] / (ninner * cell);

    printf("  interior (%d disks): strain e_xx = %.6e, e_yy = %.6e; stress s_xx = %.5g, s_yy = %.5g, s_xy = %.3g N/m "
           "(s_xx/s_yy = %.2e)\n", ninner, exx, eyy, sxx, syy, sxy, sxx / syy);
    const double e_iso = (syy * syy - sxx * sxx) / (eyy * syy - exx * sxx);
    BPM_CHECK("Young's modulus (isotropic law) (N/m)", e_iso, E, 0.01);
    BPM_CHECK("Poisson's ratio (isotropic law)", (sxx - e_iso * exx) / syy, nu, 0.01);
    BPM_CHECK("Young's modulus s_yy/e_yy (N/m)", syy / eyy, E, 0.01);
    /* not asserted: with s_xx/s_yy = O(1e-3) left by the edges, -e_xx/e_yy = (nu s_yy - s_xx)/(s_yy - nu s_xx)
     * differs from nu by O(s_xx/(nu s_yy)) */
    bpm_report("apparent Poisson's ratio -e_xx/e_yy (not asserted)", -exx / eyy, nu);
    sx_model_destroy(L.m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("hex_modulus");
    TCase *tc = tcase_create("lattice");
    tcase_add_test(tc, hex_young);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
