/* Clumps in contact: with walls, with each other, rolling and coming to
 * rest; energy, timestep, fixities and the pebble guards. */
#include "clump_test.h"

static const double RHO = 2500, G = 9.81;

/* The unit vector of body (template) axis k in space, from the orientation. */
static void body_axis(const sx_model *m, int64_t id, int k, double out[3])
{
    double q[4];
    V_CHECK(sx_clump_orientation(m, id, q) == SX_OK, "%s", sx_model_error(m));
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double Rm[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (int i = 0; i < 3; i++) out[i] = Rm[3 * i + k];
}

typedef struct wall_count {
    int64_t wall, balls;
} wall_count;

static bool count_wall(const sx_contact_info *c, void *ud)
{
    wall_count *w = ud;
    if (c->is_wall) w->wall++;
    else w->balls++;
    return true;
}

/* A flat clump of three spheres (an equilateral triangle in the template's
 * xy plane) dropped tilted by 1 rad onto a plane: it lands on one pebble,
 * tips over and comes to rest on its face, its three pebbles on the plane
 * and its normal (the major principal axis, template z) vertical. Local
 * damping 0.7 brings it to rest; at rest the unbalanced force vanishes and
 * the contact forces carry the weight. 2D: three disks in a triangle come
 * to rest on an edge, two disks on the line. */
static void drop(int dim)
{
    sx_model *m = ct_model(dim, G, 1e6, 0.5, RHO, 0.7);
    const double r = 0.01, side = 2.2 * r;
    double pos[9] = {0};
    for (int k = 0; k < 3; k++) {
        pos[k * dim] = side / sqrt(3.0) * cos(2 * V_PI * k / 3);
        pos[k * dim + 1] = side / sqrt(3.0) * sin(2 * V_PI * k / 3);
    }
    const double rad[3] = {r, r, r};
    const int t = ct_template(m, "tri", pos, rad, 3);
    double p0[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    n[dim - 1] = 1;
    scene_halfspace(m, p0, n, 1e6, 1e6, 0.5);
    /* tilted by 1 rad about the template x axis (2D: about z), 3 radii up */
    const double q[4] = {cos(0.5), dim == 3 ? sin(0.5) : 0, 0, dim == 3 ? 0 : sin(0.5)};
    double c[3] = {0, 0, 0};
    c[dim - 1] = 3 * r + side;
    const int64_t id = ct_clump(m, t, c, q, NULL, NULL);
    v_step(m, 40000);
    double v[3], w[3];
    ct_vec(m, id, SX_CLUMP_VEL, v);
    ct_vec(m, id, SX_CLUMP_SPIN, w);
    wall_count wc = {0, 0};
    sx_contact_each(m, count_wall, &wc);
    double mass;
    ck_assert(sx_clump_get(m, id, SX_CLUMP_MASS, &mass) == SX_OK);
    const double ratio = sx_model_unbalanced_ratio(m);
    double up;
    if (dim == 3) {
        double nz[3];
        body_axis(m, id, 2, nz);
        up = fabs(nz[2]);
    } else { /* the edge between the two lowest disks lies flat */
        int64_t peb[3], np;
        ck_assert(sx_clump_pebbles(m, id, peb, 3, &np) == SX_OK);
        double y[3];
        for (int k = 0; k < 3; k++) {
            double x[3];
            v_get(m, peb[k], SX_BALL_POS, x);
            y[k] = x[1];
        }
        const double lo = fmin(y[0], fmin(y[1], y[2])), hi = fmax(y[0], fmax(y[1], y[2]));
        const double mid = y[0] + y[1] + y[2] - lo - hi;
        up = 1 - fabs(mid - lo) / r; /* 1 when the two lowest are level */
    }
    printf("%dD drop: at rest on %lld pebbles, |v| %.1e m/s, |w| %.1e rad/s, ratio %.1e, face normal . vertical %.9f\n",
           dim, (long long)wc.wall, v_norm(v, dim), v_norm(w, dim == 3 ? 3 : 1), ratio, up);
    ck_assert_int_eq(wc.wall, dim == 3 ? 3 : 2);
    ck_assert_msg(up > 1 - 1e-6, "not on its face: %g", up);
    ck_assert_msg(v_norm(v, dim) < 1e-5 && v_norm(w, dim == 3 ? 3 : 1) < 1e-3, "not at rest");
    ck_assert_msg(ratio < 1e-3, "unbalanced ratio %g", ratio);
    sx_model_destroy(m);
}

START_TEST(drop_3d) { drop(3); }
END_TEST

START_TEST(drop_2d) { drop(2); }
END_TEST

/* A dumbbell (two spheres on an axis along y) rolling without slipping
 * along x on a plane for more than a turn, no damping: nothing dissipates, so kinetic +
 * gravitational + strain energy stays constant, and it keeps rolling at
 * its initial speed. It starts at the equilibrium overlap mg / (2 Kn) with
 * w = v / (R - Un/2) (the lever of the contact force, 4-4), so the contact
 * points are at rest and the shear springs stay nearly relaxed: leapfrog
 * then integrates a uniform motion exactly and the energy varies only by
 * the small normal vibration left by rounding the equilibrium (~1e-9 of the
 * kinetic energy); tolerance 1e-6. */
START_TEST(dumbbell_rolls)
{
    sx_model *m = ct_model(3, G, 1e6, 0.5, RHO, 0);
    const double r = 0.01, pos[6] = {0, -0.015, 0, 0, 0.015, 0}, rad[2] = {r, r};
    const int t = ct_template(m, "dumbbell", pos, rad, 2);
    const double p0[3] = {0, 0, 0}, n[3] = {0, 0, 1};
    scene_halfspace(m, p0, n, 1e6, 1e6, 0.5);
    const double mass = RHO * 2 * 4.0 / 3.0 * V_PI * r * r * r;
    const double Kn = 1e6 * 1e6 / 2e6, un = mass * G / (2 * Kn), v0 = 0.2;
    const double c[3] = {0, 0, r - un}, vel[3] = {v0, 0, 0}, spin[3] = {0, v0 / (r - 0.5 * un), 0};
    const int64_t id = ct_clump(m, t, c, NULL, vel, spin);
    const double dt = 0.5 * sx_model_timestep(m);
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
    sx_energy e = sx_model_energy(m);
    const double e0 = e.kinetic + e.gravitational + e.strain, k0 = e.kinetic;
    double dev = 0;
    const int64_t steps = 50000; /* more than a turn */
    for (int64_t s = 0; s < steps; s += 100) {
        v_step(m, 100);
        e = sx_model_energy(m);
        dev = fmax(dev, fabs(e.kinetic + e.gravitational + e.strain - e0) / k0);
    }
    double v[3], x[3];
    ct_vec(m, id, SX_CLUMP_VEL, v);
    ct_vec(m, id, SX_CLUMP_POS, x);
    printf("rolling dumbbell: %.3f m in %lld steps, energy within %.2e of the kinetic energy, speed %.9f m/s (v0 %.3f)\n",
           x[0], (long long)steps, dev, v[0], v0);
    ck_assert_msg(dev < 1e-6, "energy changed by %g of the kinetic energy", dev);
    ck_assert_double_eq_tol(v[0], v0, 1e-6 * v0);
    ck_assert_double_eq_tol(x[0], v0 * steps * dt, 1e-6 * x[0]);
    ck_assert(x[0] > 2 * V_PI * r);
    sx_model_destroy(m);
}
END_TEST

/* Pebbles of one clump (overlapping here) never contact each other; those
 * of two clumps do, and the clumps push each other apart with equal and
 * opposite forces. The kinetic energy counts each clump once, 1/2 M v^2 +
 * 1/2 w^T I w. */
START_TEST(self_contacts_and_energy)
{
    sx_model *m = ct_model(3, 0, 1e6, 0.5, RHO, 0);
    const double pos[9] = {0, 0, 0, 0.012, 0, 0, 0.006, 0.01, 0}, rad[3] = {0.01, 0.01, 0.008};
    const int t = ct_template(m, "blob", pos, rad, 3);
    const double c1[3] = {0, 0, 0}, c2[3] = {0.028, 0.003, 0}, w[3] = {1, -2, 3}, v[3] = {0.3, 0, -0.1};
    const int64_t a = ct_clump(m, t, c1, NULL, v, w);
    v_step(m, 1);
    ck_assert_int_eq(sx_contact_count(m), 0);
    /* energy: once per body */
    double mass, I[3][3];
    ck_assert(sx_clump_get(m, a, SX_CLUMP_MASS, &mass) == SX_OK);
    ck_assert(sx_clump_inertia(m, a, NULL, I) == SX_OK);
    double vv[3], ww[3];
    ct_vec(m, a, SX_CLUMP_VEL, vv);
    ct_vec(m, a, SX_CLUMP_SPIN, ww);
    double rot = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) rot += 0.5 * ww[i] * I[i][j] * ww[j];
    const double ke = 0.5 * mass * v_dot(vv, vv, 3) + rot;
    ck_assert_double_eq_tol(sx_model_energy(m).kinetic, ke, 1e-12 * ke);
    /* a measurement counts the union's volume once (the pebbles overlap) */
    sx_region reg = {.shape = SX_SHAPE_SPHERE, .centre = {0, 0, 0}, .radius = 0.1};
    sx_measurement meas;
    ck_assert(sx_measure(m, &reg, &meas) == SX_OK);
    double volume;
    ck_assert(sx_clump_get(m, a, SX_CLUMP_VOLUME, &volume) == SX_OK);
    ck_assert_double_eq_tol(meas.solid, volume, 1e-12 * volume);
    /* a second clump overlapping the first */
    const double q[4] = {cos(0.3), 0, 0, sin(0.3)};
    const int64_t b = ct_clump(m, t, c2, q, NULL, NULL);
    ck_assert(sx_clump_set_vec(m, a, SX_CLUMP_VEL, (double[3]){0, 0, 0}) == SX_OK);
    ck_assert(sx_clump_set_vec(m, a, SX_CLUMP_SPIN, (double[3]){0, 0, 0}) == SX_OK);
    ck_assert(sx_model_set_timestep(m, 1e-6) == SX_OK);
    v_step(m, 1);
    wall_count wc = {0, 0};
    sx_contact_each(m, count_wall, &wc);
    ck_assert_int_gt(wc.balls, 0);
    double fa[3], fb[3];
    ct_vec(m, a, SX_CLUMP_FORCE, fa);
    ct_vec(m, b, SX_CLUMP_FORCE, fb);
    for (int k = 0; k < 3; k++) ck_assert_double_eq_tol(fa[k], -fb[k], 1e-12 * v_norm(fa, 3));
    ck_assert(fa[0] < 0 && v_norm(fa, 3) > 0);
    sx_model_destroy(m);
}
END_TEST

/* The automatic timestep rates a clump as one body: its mass against the
 * sum of its pebbles' contact stiffnesses (a free pebble rated at its own
 * kn + ks = 2k, and ks R^2 for its rotation), and its rotation by the bound
 * sum_i K_i / I_i over the principal axes, K_i = sum kt h^2 + kr (1 + 2 h / R)
 * with h a pebble centre's distance from axis i. A dumbbell along x of
 * pebbles 0.01 and 0.005 m: h = 0 about x, the distances from the centroid
 * about y and z. */
START_TEST(timestep_rating)
{
    const double k = 1e6;
    sx_model *m = ct_model(3, 0, k, 0.5, RHO, 0);
    const double pos[6] = {0, 0, 0, 0.03, 0, 0}, rad[2] = {0.01, 0.005};
    const int t = ct_template(m, "pair", pos, rad, 2);
    const double c[3] = {0, 0, 0};
    const int64_t id = ct_clump(m, t, c, NULL, NULL, NULL);
    double mass, I[3];
    ck_assert(sx_clump_get(m, id, SX_CLUMP_MASS, &mass) == SX_OK);
    ck_assert(sx_clump_inertia(m, id, I, NULL) == SX_OK);
    sx_clump_props p;
    ck_assert(sx_clump_template_props(m, t, &p) == SX_OK);
    const double d1 = fabs(p.centroid[0]), d2 = fabs(0.03 - p.centroid[0]);
    const double kt = 2 * k;                           /* kn + ks of a free pebble */
    const double kr1 = k * 0.01 * 0.01, kr2 = k * 0.005 * 0.005; /* ks R^2 */
    const double k_axis = kr1 + kr2;
    const double k_perp = kt * d1 * d1 + kr1 * (1 + 2 * d1 / 0.01) + kt * d2 * d2 + kr2 * (1 + 2 * d2 / 0.005);
    const double dt_t = sqrt(mass / (2 * kt)), dt_r = 1 / sqrt(k_axis / I[0] + k_perp / I[1] + k_perp / I[2]);
    const double expect = fmin(dt_t, dt_r);
    ck_assert_double_eq_tol(sx_model_critical_timestep(m), expect, 1e-12 * expect);
    sx_model_destroy(m);
}
END_TEST

/* Fixities: a fixed velocity carries the clump at that velocity whatever
 * the gravity; a fixed spin turns it at that spin; 3D spin is fixed as a
 * whole. Pebbles refuse what belongs to their clump. */
START_TEST(fixities_and_guards)
{
    sx_model *m = ct_model(3, G, 1e6, 0.5, RHO, 0.7);
    const double pos[6] = {0, 0, 0, 0.03, 0, 0}, rad[2] = {0.01, 0.01};
    const int t = ct_template(m, "pair", pos, rad, 2);
    const double c[3] = {0, 0, 1}, v[3] = {0.1, 0.2, 0.3}, w[3] = {0, 0, 2};
    const int64_t id = ct_clump(m, t, c, NULL, v, w);
    ck_assert(sx_clump_set_fixity(m, id, SX_FIX_WX) == SX_EINVAL);
    ck_assert(sx_clump_set_fixity(m, id, SX_FIX_VEL | SX_FIX_SPIN) == SX_OK);
    const double dt = 1e-4;
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
    v_step(m, 1000);
    double x[3], vv[3], ax[3];
    ct_vec(m, id, SX_CLUMP_POS, x);
    ct_vec(m, id, SX_CLUMP_VEL, vv);
    for (int k = 0; k < 3; k++) {
        ck_assert_double_eq_tol(vv[k], v[k], 1e-15);
        ck_assert_double_eq_tol(x[k], c[k] + v[k] * 1000 * dt, 1e-12);
    }
    body_axis(m, id, 0, ax); /* the dumbbell axis turned by w t about z */
    ck_assert_double_eq_tol(atan2(ax[1], ax[0]), 2 * 1000 * dt, 1e-12);
    unsigned mask;
    ck_assert(sx_clump_fixity(m, id, &mask) == SX_OK && mask == (SX_FIX_VEL | SX_FIX_SPIN));
    /* guards */
    int64_t peb[2], np;
    ck_assert(sx_clump_pebbles(m, id, peb, 2, &np) == SX_OK);
    ck_assert(sx_ball_set_vec(m, peb[0], SX_BALL_VEL, v) == SX_EINVAL);
    ck_assert(strstr(sx_model_error(m), "pebble of clump") != NULL);
    ck_assert(sx_ball_set(m, peb[0], SX_BALL_RADIUS, 0.02) == SX_EINVAL);
    ck_assert(sx_ball_set_fixity(m, peb[0], SX_FIX_VX) == SX_EINVAL);
    ck_assert(sx_ball_remove(m, peb[0]) == SX_EINVAL);
    sx_material_def md = sx_material_default_def();
    md.density = 1000;
    int light;
    ck_assert(sx_material_set(m, "light", &md, &light) == SX_OK);
    ck_assert(sx_ball_set_material(m, peb[0], light) == SX_EINVAL);
    md.density = RHO;
    md.friction = 0.1;
    int slick;
    ck_assert(sx_material_set(m, "slick", &md, &slick) == SX_OK);
    ck_assert(sx_ball_set_material(m, peb[0], slick) == SX_OK); /* same density: allowed */
    /* the body's material sets its mass; a density change follows */
    double m0, m1;
    ck_assert(sx_clump_get(m, id, SX_CLUMP_MASS, &m0) == SX_OK);
    ck_assert(sx_clump_set_material(m, id, light) == SX_OK);
    ck_assert(sx_clump_get(m, id, SX_CLUMP_MASS, &m1) == SX_OK);
    ck_assert_double_eq_tol(m1, m0 * 1000 / RHO, 1e-12 * m1);
    md.density = 2000;
    ck_assert(sx_material_set(m, "light", &md, NULL) == SX_OK);
    ck_assert(sx_clump_get(m, id, SX_CLUMP_MASS, &m1) == SX_OK);
    ck_assert_double_eq_tol(m1, m0 * 2000 / RHO, 1e-12 * m1);
    ck_assert_double_eq_tol(v_scalar(m, peb[1], SX_BALL_MASS), m1, 1e-12 * m1);
    md.damping = 0.4; /* and so does a damping change */
    ck_assert(sx_material_set(m, "light", &md, NULL) == SX_OK);
    double alpha;
    ck_assert(sx_clump_get(m, id, SX_CLUMP_DAMPING, &alpha) == SX_OK);
    ck_assert(alpha == 0.4);
    /* removal takes the pebbles */
    const int64_t nb = sx_ball_count(m);
    ck_assert(sx_clump_remove(m, id) == SX_OK);
    ck_assert_int_eq(sx_ball_count(m), nb - 2);
    ck_assert(!sx_clump_exists(m, id) && !sx_ball_exists(m, peb[0]));
    ck_assert_int_eq(sx_clump_count(m), 0);
    sx_model_destroy(m);
}
END_TEST

/* Local damping dissipates a clump's motion as a ball's, and with energy
 * tracking the balance closes: kinetic + gravitational + strain - damping
 * work stays at its start. */
START_TEST(damping_balance)
{
    sx_model *m = ct_model(3, G, 1e6, 0.5, RHO, 0.3);
    const double pos[9] = {0, 0, 0, 0.022, 0, 0, 0.011, 0.019, 0}, rad[3] = {0.01, 0.01, 0.01};
    const int t = ct_template(m, "tri", pos, rad, 3);
    const double p0[3] = {0, 0, 0}, n[3] = {0, 0, 1};
    scene_halfspace(m, p0, n, 1e6, 1e6, 0.5);
    const double q[4] = {cos(0.4), sin(0.4) * 0.6, sin(0.4) * 0.8, 0};
    const double c[3] = {0, 0, 0.05}, w[3] = {3, -1, 2};
    ct_clump(m, t, c, q, NULL, w);
    sx_model_track_energy(m, true);
    sx_energy e = sx_model_energy(m);
    const double e0 = e.kinetic + e.gravitational + e.strain;
    v_step(m, 20000);
    e = sx_model_energy(m);
    const double e1 = e.kinetic + e.gravitational + e.strain;
    const double lost = e.local_damping + e.slip + e.viscous;
    printf("damped drop: mechanical energy %.6e -> %.6e J, dissipated %.6e J (damping %.3e, slip %.3e), balance %.2e\n",
           e0, e1, lost, e.local_damping, e.slip, fabs(e1 + lost - e0) / fabs(e0 - e1));
    ck_assert(e.local_damping > 0);
    ck_assert_msg(fabs(e1 + lost - e0) < 0.02 * fabs(e0 - e1), "the balance misses %g J", e1 + lost - e0);
    sx_model_destroy(m);
}
END_TEST

/* A specimen of clumps squeezed by a servo wall (no gravity) and brought
 * to rest: the average stress measured in a box holding every clump must equal
 * the walls' traction, sigma_zz = F_top / A. That is the equilibrium
 * identity sum over bodies of F (x_c - x_ref) = sum over the boundary of
 * F x_c, which holds when every body's arms start at one point of it: a
 * clump carries load from pebble to pebble inside itself, and arms from
 * each pebble's own centre would miss that internal stress (here they
 * would measure 22 % less). Tolerance 1 %: the residual unbalanced forces
 * of the settled state and the servo's slow motion. */
START_TEST(specimen_stress)
{
    sx_model *m = ct_model(3, 0, 1e6, 0.3, RHO, 0.7);
    const double r = 0.004, pos[9] = {-0.005, 0, 0, 0.005, 0, 0, 0, 0.006, 0}, rad[3] = {r, r, 0.0035};
    const int t = ct_template(m, "tri", pos, rad, 3);
    const double L = 0.08; /* 4 x 4 x 4 clumps 20 mm apart, each within 9.5 mm of its centroid */
    const double lo[3] = {0, 0, 0}, hi[3] = {L, L, L};
    scene_box_walls(m, lo, hi, 1e6, 0.3);
    uint64_t seed = 9;
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                const double c[3] = {(i + 0.5) * L / 4, (j + 0.5) * L / 4, (k + 0.5) * L / 4};
                const double a = scene_rng_uniform(&seed, 0, 6.28), u = scene_rng_uniform(&seed, -1, 1);
                const double q[4] = {cos(a / 2), sin(a / 2) * sqrt(1 - u * u), 0, sin(a / 2) * u};
                ct_clump(m, t, c, q, NULL, NULL);
            }
    /* the top wall (the last of the box) is a servo at 2 kPa: it comes down and holds the specimen */
    const int64_t top = sx_wall_id_at(m, 5);
    sx_servo_def sd = sx_servo_default_def();
    sd.target = 2e3, sd.area = L * L, sd.max_speed = 0.2;
    ck_assert(sx_wall_set_servo(m, top, &sd) == SX_OK);
    v_step(m, 80000);
    double f[3], mo[3];
    ck_assert(sx_wall_force(m, top, f, mo) == SX_OK);
    sx_wall_def wd;
    ck_assert(sx_wall_get(m, top, &wd) == SX_OK);
    sx_region reg = {.shape = SX_SHAPE_BOX, .lo = {0, 0, 0}, .hi = {L, L, wd.point[2]}};
    sx_measurement meas;
    ck_assert(sx_measure(m, &reg, &meas) == SX_OK);
    const double traction = f[2] / (L * L); /* the balls push the top wall up: compression */
    printf("clump specimen: sigma_zz %.4g Pa measured, top wall traction %.4g Pa (%.2e relative), ratio %.1e\n",
           meas.stress[2][2], traction, fabs(meas.stress[2][2] - traction) / traction, sx_model_unbalanced_ratio(m));
    ck_assert(traction > 0);
    ck_assert_double_eq_tol(meas.stress[2][2], traction, 0.01 * traction);
    ck_assert_int_eq(meas.balls, 192);
    sx_model_destroy(m);
}
END_TEST

/* Bonds join pebbles of different clumps (never those of one clump, which
 * never pair): of two bonded clumps, one pulled by its fixed velocity drags
 * the other along; held back, the other lets the bond stretch until it
 * breaks in tension. */
START_TEST(bonds_between_clumps)
{
    sx_model *m = ct_model(3, 0, 1e6, 0.5, RHO, 0);
    const double r = 0.005, pos[6] = {0, 0, 0, 0.009, 0, 0}, rad[2] = {r, r};
    const int t = ct_template(m, "pair", pos, rad, 2);
    const double a[3] = {0, 0, 0}, b[3] = {0.009 + 2 * r, 0, 0};
    const int64_t ca = ct_clump(m, t, a, NULL, NULL, NULL), cb = ct_clump(m, t, b, NULL, NULL, NULL);
    sx_bond_def bd = sx_bond_default_def();
    bd.kind = SX_BOND_PARALLEL;
    bd.gap = 1e-4;
    bd.radius_multiplier = 1;
    bd.modulus = 1e6;
    bd.stiffness_ratio = 1;
    bd.tensile_strength = 1e5;
    bd.cohesion = 1e5;
    int64_t n = 0;
    ck_assert_msg(sx_bond_install(m, &bd, &n) == SX_OK, "%s", sx_model_error(m));
    ck_assert_int_eq(n, 1); /* the facing pebbles only: those of one clump overlap yet are not bonded */
    const double pull[3] = {-0.01, 0, 0};
    ck_assert(sx_clump_set_vec(m, ca, SX_CLUMP_VEL, pull) == SX_OK);
    ck_assert(sx_clump_set_fixity(m, ca, SX_FIX_VEL | SX_FIX_SPIN) == SX_OK);
    ck_assert(sx_model_set_timestep(m, 1e-6) == SX_OK);
    v_step(m, 2000);
    double vb[3];
    ct_vec(m, cb, SX_CLUMP_VEL, vb);
    ck_assert_msg(vb[0] < -1e-4, "the bonded clump was not dragged: %g", vb[0]);
    const double zero[3] = {0, 0, 0};
    ck_assert(sx_clump_set_vec(m, cb, SX_CLUMP_VEL, zero) == SX_OK);
    ck_assert(sx_clump_set_fixity(m, cb, SX_FIX_VEL) == SX_OK);
    for (int s = 0; s < 200 && sx_bond_count(m) > 0; s++) v_step(m, 1000);
    ck_assert_int_eq(sx_bond_count(m), 0);
    ck_assert_int_eq(sx_crack_count(m), 1);
    sx_model_destroy(m);
}
END_TEST

/* Results do not depend on the thread count: 1600 dumbbells (several
 * blocks of the clump step, several chunks of the contact pass) settling in
 * a box give bit-identical states with 1 and 3 threads. */
static uint64_t lattice_hash(int threads)
{
    sx_model *m = ct_model(3, G, 1e6, 0.5, RHO, 0.2);
    ck_assert(sx_model_set_threads(m, threads) == SX_OK);
    const double r = 0.005, pos[6] = {0, 0, 0, 2 * r - 1e-6, 0, 0}, rad[2] = {r, r};
    const int t = ct_template(m, "pair", pos, rad, 2);
    const double lo[3] = {0, 0, 0}, hi[3] = {40 * r, 40 * r, 1};
    scene_box_walls(m, lo, hi, 1e6, 0.5);
    uint64_t seed = 3;
    for (int k = 0; k < 8; k++)
        for (int j = 0; j < 20; j++)
            for (int i = 0; i < 10; i++) {
                const double c[3] = {(4 * i + 2) * r, (2 * j + 1) * r + 1e-4 * scene_rng_uniform(&seed, -1, 1),
                                     (2 * k + 1) * r * 0.999};
                const double w[3] = {scene_rng_uniform(&seed, -1, 1), scene_rng_uniform(&seed, -1, 1), 0};
                ct_clump(m, t, c, NULL, NULL, w);
            }
    ck_assert_int_eq(sx_clump_count(m), 1600);
    sx_model_track_energy(m, true);
    v_step(m, 300);
    const uint64_t h = sx_model_state_hash(m);
    sx_model_destroy(m);
    return h;
}

START_TEST(thread_independent)
{
    const uint64_t one = lattice_hash(1), three = lattice_hash(3);
    ck_assert_msg(one == three, "hash %016llx with 1 thread, %016llx with 3", (unsigned long long)one,
                  (unsigned long long)three);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("clump_contact");
    V_TCASE(s, drop_3d);
    V_TCASE(s, drop_2d);
    V_TCASE(s, dumbbell_rolls);
    V_TCASE(s, self_contacts_and_energy);
    V_TCASE(s, timestep_rating);
    V_TCASE(s, fixities_and_guards);
    V_TCASE(s, damping_balance);
    V_TCASE(s, thread_independent);
    V_TCASE(s, specimen_stress);
    V_TCASE(s, bonds_between_clumps);
    return v_run(s);
}
