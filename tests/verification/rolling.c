/* Verification: a ball launched sliding on a floor with friction reaches
 * pure rolling, 2D (disk) and 3D (sphere).
 *
 * Closed form. Launched at v0 without spin, the ball slides while the
 * friction force mu m g decelerates it and spins it up:
 *     v(t) = v0 - mu g t,    R w(t) = (m R^2 / I) mu g t,
 * until the contact point stops slipping, v = R w:
 *     sphere (I = 2/5 m R^2):  t* = 2 v0 / (7 mu g),  v* = 5/7 v0
 *     disk   (I = 1/2 m R^2):  t* =   v0 / (3 mu g),  v* = 2/3 v0.
 * After t* the angular momentum about the contact line, m v R + I w, is
 * unchanged by the contact force, so the ball keeps rolling at v*.
 *
 * Model. The ball starts at rest on the floor at its equilibrium overlap
 * mg/Kn (so it does not bounce), the contact friction is the smaller of the
 * ball's (0.3) and the wall's (0.5), the shear spring is stiff and a shear
 * dashpot damps the tangential vibration left when the contact sticks.
 *
 * Error analysis. While sliding the contact force is constant (mu Kn Un =
 * mu m g) and leapfrog integrates a constant force exactly; the slip
 * velocity is linear in time, so interpolating its zero between two
 * half-step samples is exact. The only departures are (i) the initial
 * velocity is the velocity at t = -dt/2 in leapfrog, which shifts t* by
 * dt/2 (allowed: one step), and (ii) the lever arm of the contact force is
 * R - Un/2, not R, which changes t* and v* by less than Un/R relative.
 * m v R' + I w is conserved exactly by the discrete update (the torque is
 * R' times the force), so once the vibration has been damped the final
 * velocity is v0/(1 + I/(m R'^2)) up to round-off. Tolerances:
 *     |t - t*| <= dt + 2 (Un/R) t*,    |v - v*| <= 2 (Un/R) v*.
 * (Un/R ~ 1e-5 and dt/t* ~ 1e-4 here: far tighter than 1 %.)
 */
#include "verify.h"

static const double R = 0.01, RHO = 2650, G = 9.81, MU_BALL = 0.3, MU_WALL = 0.5, V0 = 1.0;

static void check_rolling(int dim)
{
    /* 2D disks are ~75 times heavier than 3D spheres of the same radius: scale
     * the stiffness so that the overlap stays ~1e-5 R in both */
    const double kb = dim == 3 ? 1e6 : 1e8, kw = 4 * kb;
    int mat;
    sx_model *m = v_ball_model(dim, G, RHO, kb, MU_BALL, &mat);
    double p0[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    n[dim - 1] = 1;
    scene_halfspace(m, p0, n, kw, kw, MU_WALL);

    const double mass = dim == 3 ? RHO * 4.0 / 3.0 * V_PI * R * R * R : RHO * V_PI * R * R;
    const double inertia = (dim == 3 ? 0.4 : 0.5) * mass * R * R;
    const double Kn = kb * kw / (kb + kw), Ks = Kn, mu = fmin(MU_BALL, MU_WALL);
    const double un = mass * G / Kn;
    /* sliding direction: not along an axis in 3D */
    double e[3] = {1, 0, 0};
    if (dim == 3) e[0] = 0.6, e[1] = 0.8;
    double pos[3] = {0.1, -0.2, 0}, vel[3] = {0, 0, 0};
    pos[dim - 1] = R - un;
    for (int k = 0; k < dim - 1; k++) vel[k] = V0 * e[k];
    const int64_t id = scene_ball_full(m, pos, vel, NULL, R, mat);
    ck_assert_double_eq_tol(v_scalar(m, id, SX_BALL_INERTIA), inertia, 1e-14 * inertia);

    const double ratio = inertia / (mass * R * R); /* 2/5 or 1/2 */
    const double t_star = V0 / (mu * G * (1 + 1 / ratio));
    const double v_star = V0 / (1 + ratio); /* 5/7 or 2/3 of v0 */
    /* the tangential vibration of the stuck contact: resolve it by ~60 steps */
    const double w_s = sqrt(Ks * (1 / mass + R * R / inertia));
    const double dt = 0.1 / w_s;
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);

    /* slip velocity of the contact point along e, sampled at half steps */
    double t_roll = NAN, v_roll = NAN, s_prev = NAN, v_prev = NAN, t_prev = NAN;
    const int64_t nsteps = (int64_t)ceil(2.5 * t_star / dt);
    double zmin = INFINITY, zmax = -INFINITY;
    for (int64_t s = 0; s < nsteps; s++) {
        v_step(m, 1);
        double x[3], v[3], w[3];
        v_get(m, id, SX_BALL_POS, x);
        v_get(m, id, SX_BALL_VEL, v);
        v_get(m, id, SX_BALL_SPIN, w);
        zmin = fmin(zmin, x[dim - 1]);
        zmax = fmax(zmax, x[dim - 1]);
        const double arm = R - (R - x[dim - 1]) / 2; /* R - Un/2 */
        double slip[3] = {v[0], v[1], v[2]};
        if (dim == 3) { /* v + w x (-arm z) */
            slip[0] += -w[1] * arm;
            slip[1] += w[0] * arm;
        } else { /* v + w x (-arm y), w about z */
            slip[0] += w[0] * arm;
        }
        const double sl = v_dot(slip, e, dim), ve = v_dot(v, e, dim);
        const double t = sx_model_time(m) - dt / 2; /* the velocities' time */
        if (isnan(t_roll) && s_prev > 0 && sl <= 0) {
            const double f = s_prev / (s_prev - sl);
            t_roll = t_prev + f * (t - t_prev);
            v_roll = v_prev + f * (ve - v_prev);
        }
        s_prev = sl, v_prev = ve, t_prev = t;
    }
    ck_assert_msg(!isnan(t_roll), "%dD: the ball never stopped slipping (slip velocity %g m/s at the end)", dim,
                  s_prev);
    double v[3], w[3];
    v_get(m, id, SX_BALL_VEL, v);
    v_get(m, id, SX_BALL_SPIN, w);
    const double v_end = v_dot(v, e, dim);
    double vperp[3] = {v[0] - v_end * e[0], v[1] - v_end * e[1], 0};
    const double eps = un / R;
    const double tol_t = dt + 2 * eps * t_star, tol_v = 2 * eps * v_star;
    printf("rolling %dD: t_roll %.6f s (exact %.6f s, rel err %.1e, tol %.1e), v at t_roll %.6f (exact %.6f, rel err "
           "%.1e), final v %.7f (rel err %.1e, tol %.1e); dt/t* = %.1e, Un/R = %.1e\n",
           dim, t_roll, t_star, t_roll / t_star - 1, tol_t / t_star, v_roll, v_star, v_roll / v_star - 1, v_end,
           v_end / v_star - 1, tol_v / v_star, dt / t_star, eps);
    ck_assert_msg(fabs(t_roll - t_star) <= tol_t, "%dD: pure rolling at t = %.9g s, expected %.9g s (tol %.3g s)", dim,
                  t_roll, t_star, tol_t);
    ck_assert_msg(fabs(v_roll - v_star) <= tol_v + V0 * mu * G * dt,
                  "%dD: velocity at the onset of rolling %.9g m/s, expected %.9g m/s", dim, v_roll, v_star);
    ck_assert_msg(fabs(v_end - v_star) <= tol_v, "%dD: final rolling velocity %.9g m/s, expected %.9g m/s (tol %.3g)",
                  dim, v_end, v_star, tol_v);
    ck_assert_msg(v_norm(vperp, 3) <= 1e-12 * V0, "%dD: the ball left its sliding direction (%g m/s across)", dim,
                  v_norm(vperp, 3));
    /* it did not bounce: the centre stayed at the equilibrium height */
    ck_assert_msg(zmax - zmin <= 1e-3 * un, "%dD: the ball moved vertically by %g m (overlap %g m)", dim, zmax - zmin,
                  un);
    sx_model_destroy(m);
}

START_TEST(rolling_2d) { check_rolling(2); }
END_TEST

START_TEST(rolling_3d) { check_rolling(3); }
END_TEST

int main(void)
{
    Suite *s = suite_create("rolling");
    V_TCASE(s, rolling_2d);
    V_TCASE(s, rolling_3d);
    return v_run(s);
}
