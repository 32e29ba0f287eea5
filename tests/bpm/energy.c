/* Energy closure of a bonded sample loaded by a moving wall until bonds break.
 *
 * Closed form (the first law for the balls): the work done on them by the
 * moving walls and applied loads goes into the change of kinetic,
 * gravitational and stored (contact springs, parallel bonds) energy, or is
 * dissipated by slip, local damping and the contact dashpots, or is released
 * by breaking bonds:
 *     W_boundary = D(kinetic + gravitational + strain + bond_strain)
 *                  + slip + local_damping + viscous + bond_released.
 * With the central-difference scheme this balance holds to O(dt) per unit of
 * work (the terms are sampled at half steps against whole steps), far below
 * the 1 % of the work asserted here (the residual is printed).
 *
 * Scenes, at the automatic timestep, under gravity, local damping 0.7 and
 * friction 0.5, between a fixed floor and a roof moving down at a strain of
 * 1e-6 per step until a tenth of the bonds broke, then 2000 steps further:
 *   2D: a 14 x 14 hexagonal packing of disks (R = 1 mm, kn = ks = 1e8 N/m),
 *       every touching pair parallel-bonded (lambda 1, Ec-bar 50 MPa,
 *       kn-bar/ks-bar 2.5, sigma_c 0.1 MPa +- 20 %, tau_c 0.2 MPa +- 20 %);
 *       normal dashpots at 0.2 of critical.
 *   3D: a face-centred cubic block of 4 x 4 x 5 cells (R = 1 mm), every
 *       touching pair with both a contact bond and a parallel bond; the [001]
 *       compression stretches the bonds across it (Poisson effect) until they
 *       break; normal dashpots at 0.2 of critical.
 *   2D with shear dashpots too (0.2 of critical, the same scene otherwise):
 *       see the note at energy_2d_shear_dashpot.
 * And the slip term alone against its closed form (slip_work, below).
 * Asserted: bonds broke (sx_crack_count > 0, bond_released > 0) and the
 * balance closes within 1 % of W.
 */
#include "bpm.h"

static const double R = 1e-3;

typedef struct sample {
    sx_model *m;
    int64_t roof;
    int dim;
    double height;
    int64_t bonds;
    int64_t elements; /* flat joints: their elements (0: parallel and contact bonds) */
} sample;

/* Flat joints in place of the bonds of bd (laws/flatjoint.h): a fifth of
 * their elements slit, phi-bar 30 deg, mu 0.5, 2D 3 elements, 3D 2 x 3. */
static void flat(sample *s, sx_bond_def *bd)
{
    bd->kind = SX_BOND_FLATJOINT;
    bd->friction_angle = 30;
    bd->friction = 0.5;
    bd->unbonded_fraction = 0.2;
    bd->elements = s->dim == 3 ? 2 : 3;
    bd->sectors = 3;
    s->elements = s->dim == 3 ? 6 : 3;
}

static sx_model *model_with_gravity(int dim)
{
    sx_model_def d = sx_model_default_def();
    d.dim = dim;
    d.gravity[dim - 1] = -9.81;
    char err[256];
    sx_model *m = sx_model_create(&d, err, sizeof err);
    ck_assert_msg(m, "%s", err);
    return m;
}

static int rock(sx_model *m, double viscous_shear)
{
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = 1e8;
    md.friction = 0.5;
    md.damping = 0.7;
    md.viscous_normal = 0.2;
    md.viscous_shear = viscous_shear;
    return bpm_material(m, "rock", &md);
}

/* Floor at 0 and roof at `height` along the last axis. */
static void walls(sample *s)
{
    sx_wall_def wd = sx_wall_default_def(s->dim);
    wd.kn = wd.ks = 1e8;
    wd.friction = 0.5;
    ck_assert(sx_wall_add(s->m, &wd, NULL) == SX_OK);
    wd.point[s->dim - 1] = s->height;
    wd.normal[s->dim - 1] = -1;
    ck_assert(sx_wall_add(s->m, &wd, &s->roof) == SX_OK);
}

static sample hex_2d(double viscous_shear, bool flat_joints)
{
    sample s = {.dim = 2};
    s.m = model_with_gravity(2);
    const int mat = rock(s.m, viscous_shear);
    const int N = 14;
    const double dy = sqrt(3.0) * R;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            const double x[3] = {R + 2 * R * i + (j % 2 ? R : 0), R + dy * j, 0};
            scene_ball_of(s.m, mat, x, NULL, R);
        }
    s.height = 2 * R + dy * (N - 1);
    walls(&s);
    sx_bond_def bd = sx_bond_default_def();
    bd.kind = SX_BOND_PARALLEL;
    bd.gap = 1e-9;
    bd.radius_multiplier = 1;
    bd.modulus = 5e7;
    bd.stiffness_ratio = 2.5;
    bd.tensile_strength = 1e5, bd.tensile_strength_sd = 2e4;
    bd.cohesion = 2e5, bd.cohesion_sd = 4e4;
    bd.seed = 7;
    if (flat_joints) flat(&s, &bd);
    ck_assert_msg(sx_bond_install(s.m, &bd, &s.bonds) == SX_OK, "%s", sx_model_error(s.m));
    ck_assert_int_eq(s.bonds, (int64_t)N * (N - 1) + (int64_t)(N - 1) * (2 * N - 1));
    return s;
}

static sample fcc_3d(bool flat_joints)
{
    sample s = {.dim = 3};
    s.m = model_with_gravity(3);
    const int mat = rock(s.m, 0);
    enum { NX = 4, NY = 4, NZ = 5 };
    const double a = 2 * sqrt(2.0) * R; /* cube edge: face diagonal 2 a/sqrt2 ... neighbours at 2R */
    const double basis[4][3] = {{0, 0, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}, {0.5, 0.5, 0}};
    double zmax = 0;
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++)
                for (int b = 0; b < 4; b++) {
                    const double x[3] = {R + a * (i + basis[b][0]), R + a * (j + basis[b][1]),
                                         R + a * (k + basis[b][2])};
                    if (x[2] > zmax) zmax = x[2];
                    scene_ball_of(s.m, mat, x, NULL, R);
                }
    s.height = zmax + R;
    walls(&s);
    sx_bond_def bd = sx_bond_default_def();
    bd.gap = 1e-9;
    bd.seed = 11;
    bd.kind = SX_BOND_CONTACT;
    bd.normal_strength = 15, bd.normal_strength_sd = 3;
    bd.shear_strength = 30, bd.shear_strength_sd = 6;
    int64_t n_contact = 0;
    if (!flat_joints) ck_assert_msg(sx_bond_install(s.m, &bd, &n_contact) == SX_OK, "%s", sx_model_error(s.m));
    bd.kind = SX_BOND_PARALLEL;
    bd.radius_multiplier = 1;
    bd.modulus = 3e10;
    bd.stiffness_ratio = 2.5;
    bd.tensile_strength = 5e6, bd.tensile_strength_sd = 1e6;
    bd.cohesion = 1e7, bd.cohesion_sd = 2e6;
    if (flat_joints) flat(&s, &bd);
    ck_assert_msg(sx_bond_install(s.m, &bd, &s.bonds) == SX_OK, "%s", sx_model_error(s.m));
    if (!flat_joints) ck_assert_int_eq(n_contact, s.bonds);
    ck_assert_int_eq(sx_bond_count(s.m), s.bonds); /* a pair with both kinds counts once */
    return s;
}

/* Moves the roof down until a tenth of the bonds broke, then 2000 steps more,
 * and checks the balance. */
static void load_and_check(sample *s, const char *what)
{
    sx_model_track_energy(s->m, true);
    const sx_energy e0 = sx_model_energy(s->m);
    const double dt = sx_model_timestep(s->m);
    double v[3] = {0, 0, 0};
    v[s->dim - 1] = -1e-6 * s->height / dt;
    ck_assert(sx_wall_set_vel(s->m, s->roof, v) == SX_OK);
    const int64_t max_steps = 60000;
    int64_t steps = 0;
    /* a tenth broken: of the bonds, or of the flat joints' elements (a joint
     * in compression stays, whatever its elements) */
    while (steps < max_steps && (s->elements ? (double)sx_crack_count(s->m) < 0.1 * (double)(s->bonds * s->elements)
                                             : sx_bond_count(s->m) > 0.9 * (double)s->bonds)) {
        bpm_cycle(s->m, 100);
        steps += 100;
    }
    ck_assert_msg(steps < max_steps, "%s: only %lld of %lld bonds broke in %lld steps", what,
                  (long long)(s->bonds - sx_bond_count(s->m)), (long long)s->bonds, (long long)max_steps);
    bpm_cycle(s->m, 2000);
    steps += 2000;
    sx_wall_def roof;
    ck_assert(sx_wall_get(s->m, s->roof, &roof) == SX_OK);
    const sx_energy e = sx_model_energy(s->m);
    const double dstore = (e.kinetic - e0.kinetic) + (e.gravitational - e0.gravitational) + (e.strain - e0.strain) +
                          (e.bond_strain - e0.bond_strain);
    const double diss = e.slip + e.local_damping + e.viscous + e.bond_released;
    const double w = e.boundary_work, res = w - dstore - diss;
    printf("%s: %lld steps (automatic dt now %.4g s), roof moved %.3g of the height\n", what, (long long)steps,
           sx_model_timestep(s->m), (s->height - roof.point[s->dim - 1]) / s->height);
    printf("  bonds: %lld installed, %lld intact, %lld cracks\n", (long long)s->bonds,
           (long long)sx_bond_count(s->m), (long long)sx_crack_count(s->m));
    printf("  boundary work W %.6e J\n", w);
    printf("  change of kinetic %.4e, gravitational %.4e, strain %.4e, bond strain %.4e J\n", e.kinetic - e0.kinetic,
           e.gravitational - e0.gravitational, e.strain - e0.strain, e.bond_strain - e0.bond_strain);
    printf("  slip %.4e, local damping %.4e, viscous %.4e, bond released %.4e J\n", e.slip, e.local_damping, e.viscous,
           e.bond_released);
    printf("  residual W - (stored + dissipated + released) = %.4e J = %.3e of W\n", res, res / w);
    fflush(stdout);
    ck_assert(sx_crack_count(s->m) > 0);
    ck_assert(w > 0);
    ck_assert_msg(e.bond_released > 0, "no bond energy released");
    ck_assert_msg(fabs(res) <= 0.01 * w, "%s: energy balance off by %.3e of the boundary work", what, res / w);
    sx_model_destroy(s->m);
}

START_TEST(energy_2d)
{
    sample s = hex_2d(0, false);
    load_and_check(&s, "2D hexagonal parallel-bonded sample");
}
END_TEST

START_TEST(energy_2d_flatjoint)
{
    sample s = hex_2d(0, true);
    load_and_check(&s, "2D hexagonal flat-jointed sample");
}
END_TEST

START_TEST(energy_3d_flatjoint)
{
    sample s = fcc_3d(true);
    load_and_check(&s, "3D fcc flat-jointed sample");
}
END_TEST

START_TEST(energy_3d)
{
    sample s = fcc_3d(false);
    load_and_check(&s, "3D fcc sample with contact and parallel bonds");
}
END_TEST

/* The same 2D scene with shear dashpots as well. The shear dashpot, sized on
 * the translational reduced mass, damps the spins more than its ratio says
 * (I = m R^2/2), amplified by local damping by up to (1 + alpha): the
 * automatic timestep allows for the dashpots (critical_dt), without which
 * the spins near the floor oscillate with period 2 steps once bonds break. */
START_TEST(energy_2d_shear_dashpot)
{
    sample s = hex_2d(0.2, false);
    load_and_check(&s, "2D hexagonal parallel-bonded sample, with shear dashpots");
}
END_TEST

/* The slip term alone against its closed form: a ball held in a floor at overlap
 * Un (Fn = Kn Un, springs in series with the wall's) and dragged along it at
 * an imposed speed over a distance L (N = 2000 steps). Its shear spring loads
 * elastically up to mu Fn (over u0 = mu Fn / Ks), then slides, so
 *     slip = mu Fn (L - u0),
 * and the spring keeps (mu Fn)^2 / (2 Ks). The booking may err only in the
 * step where sliding starts (O(dL/L) = 1/N), so tolerance 1e-3. Frictionless
 * (mu = 0): the shear force stays zero and nothing is dissipated, exactly. */
static void slip_case(int dim, double mu)
{
    sx_model *m = bpm_model(dim, 0);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = 1e8;
    md.friction = mu;
    const int mat = bpm_material(m, "grain", &md);
    sx_wall_def wd = sx_wall_default_def(dim);
    wd.kn = wd.ks = 1e8;
    wd.friction = mu;
    ck_assert(sx_wall_add(m, &wd, NULL) == SX_OK);
    const double un = 1e-6, kn = 5e7, ks = 5e7, fn = kn * un;
    double x[3] = {0, 0, 0};
    x[dim - 1] = R - un;
    const int64_t id = scene_ball_of(m, mat, x, NULL, R);
    const int N = 2000;
    const double dt = sx_model_timestep(m), L = 4 * mu * fn / ks + 1e-6;
    const double v[3] = {L / (N * dt), 0, 0};
    scene_impose(m, id, v, NULL);
    sx_model_track_energy(m, true);
    bpm_cycle(m, N);
    const sx_energy e = sx_model_energy(m);
    const double want = mu * fn * (L - mu * fn / ks);
    printf("%dD ball dragged along a floor, mu = %g: slip %.6e J (closed form %.6e J), shear spring %.6e J "
           "(closed form %.6e J)\n", dim, mu, e.slip, want, e.strain - 0.5 * fn * un, 0.5 * mu * mu * fn * fn / ks);
    if (mu > 0) {
        BPM_CHECK("slip dissipation mu Fn (L - u0) (J)", e.slip, want, 1e-3);
    } else {
        ck_assert_msg(e.slip == 0, "frictionless sliding booked %g J of slip", e.slip);
    }
    sx_model_destroy(m);
}

START_TEST(slip_work)
{
    const double mus[2] = {0.5, 0};
    slip_case(_i < 2 ? 2 : 3, mus[_i % 2]);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("energy");
    TCase *tc = tcase_create("closure");
    tcase_add_loop_test(tc, slip_work, 0, 4);
    tcase_add_test(tc, energy_2d);
    tcase_add_test(tc, energy_3d);
    tcase_add_test(tc, energy_2d_shear_dashpot);
    tcase_add_test(tc, energy_2d_flatjoint);
    tcase_add_test(tc, energy_3d_flatjoint);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
