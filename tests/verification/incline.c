/* Verification: a ball released on an inclined wall rolls or slips,
 * 2D (disk) and 3D (sphere).
 *
 * Closed form. On a slope of angle theta with friction mu, a ball with
 * I = k m R^2 (k = 2/5 sphere, 1/2 disk) rolls without slipping if the
 * friction it needs, f = m g sin(theta) k/(1+k), is at most mu m g cos(theta):
 *     tan(theta) <= mu (1+k)/k     (sphere: 3.5 mu; disk: 3 mu),
 * and then accelerates at a = g sin(theta)/(1+k) (5/7 g sin, 2/3 g sin);
 * above the threshold it slips with a = g (sin(theta) - mu cos(theta)) and
 * spins up at dw/dt = mu m g cos(theta) R / I.
 * Each dimension is tested at tan(theta) = 0.7 and 1.4 times the threshold.
 *
 * Model. The wall is tilted (its normal is not along an axis; gravity is
 * along -z / -y); the ball starts at rest at its equilibrium overlap
 * m g cos(theta)/Kn, the contact friction is the smaller of the ball's (0.3)
 * and the wall's (0.6), and a shear dashpot damps the vibration of the stuck
 * contact (it only acts while the contact does not slip).
 *
 * Error analysis. Slipping: the contact force is constant and leapfrog
 * integrates constant forces exactly; the only error is round-off in
 * Un = R - distance, relative eps R/Un ~ 1e-11: tolerance 1e-9 (the spin-up
 * has the lever arm R - Un/2: tolerance Un/R). Rolling:
 * m v R' + I w about the contact line obeys d/dt = m g sin(theta) R' exactly in
 * the discrete update; once the start-up vibration has decayed (here by
 * e^-100 or more) a = g sin(theta)/(1 + I/(m R'^2)) with R' = R - Un/2, i.e.
 * within Un/R of the closed form: tolerance 2 Un/R (~3e-5). The acceleration
 * is measured from the velocity at half and at the end of the run.
 */
#include "verify.h"

static const double R = 0.01, RHO = 2650, G = 9.81, MU_BALL = 0.3, MU_WALL = 0.6;

typedef struct incline_result {
    double a, a_exact, alpha, alpha_exact, slip_end, tol, tol_w;
} incline_result;

static incline_result run_incline(int dim, double tan_theta, int expect_roll)
{
    const double theta = atan(tan_theta), phi = 0.7;
    const double kb = dim == 3 ? 1e6 : 1e8, kw = 4 * kb;
    int mat;
    sx_model *m = v_ball_model(dim, G, RHO, kb, MU_BALL, &mat);
    double g[3] = {0, 0, 0};
    g[dim - 1] = -G;
    double n[3] = {0, 0, 0};
    if (dim == 3)
        n[0] = sin(theta) * cos(phi), n[1] = sin(theta) * sin(phi), n[2] = cos(theta);
    else
        n[0] = -sin(theta), n[1] = cos(theta);
    const double p0[3] = {0.02, -0.01, 0.03};
    scene_halfspace(m, p0, n, kw, kw, MU_WALL);

    const double mass = dim == 3 ? RHO * 4.0 / 3.0 * V_PI * R * R * R : RHO * V_PI * R * R;
    const double k = dim == 3 ? 0.4 : 0.5, inertia = k * mass * R * R;
    const double Kn = kb * kw / (kb + kw), Ks = Kn, mu = fmin(MU_BALL, MU_WALL);
    const double un = mass * G * cos(theta) / Kn;
    /* downhill unit vector: gravity's part in the plane */
    double s[3];
    const double gn = v_dot(g, n, dim);
    for (int i = 0; i < 3; i++) s[i] = i < dim ? g[i] - gn * n[i] : 0;
    v_unit(s, dim);
    double pos[3] = {0, 0, 0};
    for (int i = 0; i < dim; i++) pos[i] = p0[i] + (R - un) * n[i];
    const int64_t id = scene_ball_full(m, pos, NULL, NULL, R, mat);
    const double threshold = mu * (1 + k) / k;
    ck_assert((tan_theta < threshold) == (expect_roll != 0));

    incline_result res = {0};
    if (expect_roll) {
        res.a_exact = G * sin(theta) / (1 + k);
        res.alpha_exact = res.a_exact / R;
        res.tol = res.tol_w = 2 * un / R;
    } else {
        res.a_exact = G * (sin(theta) - mu * cos(theta));
        res.alpha_exact = mu * mass * G * cos(theta) * R / inertia;
        res.tol = 1e-9;
        res.tol_w = un / R; /* the lever arm is R - Un/2 */
    }
    const double w_s = sqrt(Ks * (1 / mass + R * R / inertia));
    const double dt = 0.1 / w_s;
    ck_assert(sx_model_set_timestep(m, dt) == SX_OK);
    /* the start-up vibration decays as exp(-zeta w_s t), zeta = beta_s sqrt(1 + 1/k) >= 0.5 */
    const double T = 400 / w_s;
    const int64_t half = (int64_t)ceil(T / 2 / dt);
    double v1[3], w1[3], v2[3], w2[3], x[3];
    v_step(m, half);
    const double t1 = sx_model_time(m);
    v_get(m, id, SX_BALL_VEL, v1);
    v_get(m, id, SX_BALL_SPIN, w1);
    v_step(m, half);
    const double t2 = sx_model_time(m);
    v_get(m, id, SX_BALL_VEL, v2);
    v_get(m, id, SX_BALL_SPIN, w2);
    v_get(m, id, SX_BALL_POS, x);
    res.a = (v_dot(v2, s, dim) - v_dot(v1, s, dim)) / (t2 - t1);
    /* spin rate about the rolling axis: n x s (3D); 2D the scalar spin, rolling
     * downhill along s turns the ball about -(n x s)_z */
    double axis[3] = {0, 0, 0};
    if (dim == 3) {
        axis[0] = n[1] * s[2] - n[2] * s[1];
        axis[1] = n[2] * s[0] - n[0] * s[2];
        axis[2] = n[0] * s[1] - n[1] * s[0];
        res.alpha = (v_dot(w2, axis, 3) - v_dot(w1, axis, 3)) / (t2 - t1);
    } else {
        const double sz = n[0] * s[1] - n[1] * s[0];
        res.alpha = (w2[0] - w1[0]) * sz / (t2 - t1);
    }
    /* the ball stayed on the plane: distance R - Un */
    double r[3];
    for (int i = 0; i < dim; i++) r[i] = x[i] - p0[i];
    ck_assert_msg(fabs(v_dot(r, n, dim) - (R - un)) <= 1e-3 * un,
                  "%dD: the ball left the plane (distance %.9g, expected %.9g)", dim, v_dot(r, n, dim), R - un);
    /* the slip velocity of the contact point at the end */
    double slip[3] = {v2[0], v2[1], v2[2]}, arm[3];
    for (int i = 0; i < 3; i++) arm[i] = i < dim ? -(R - un / 2) * n[i] : 0;
    if (dim == 3) {
        slip[0] += w2[1] * arm[2] - w2[2] * arm[1];
        slip[1] += w2[2] * arm[0] - w2[0] * arm[2];
        slip[2] += w2[0] * arm[1] - w2[1] * arm[0];
    } else {
        slip[0] += -w2[0] * arm[1];
        slip[1] += w2[0] * arm[0];
    }
    res.slip_end = v_norm(slip, dim) / v_norm(v2, dim);
    sx_model_destroy(m);
    return res;
}

static void check_incline(int dim)
{
    const double k = dim == 3 ? 0.4 : 0.5, threshold = fmin(MU_BALL, MU_WALL) * (1 + k) / k;
    for (int roll = 1; roll >= 0; roll--) {
        const double tan_theta = (roll ? 0.7 : 1.4) * threshold;
        const incline_result r = run_incline(dim, tan_theta, roll);
        const double ea = r.a / r.a_exact - 1, ew = r.alpha / r.alpha_exact - 1;
        printf("incline %dD %s (tan theta = %.3f, threshold %.3f): a rel err %.1e (tol %.1e), spin-up rel err "
               "%.1e (tol %.1e), slip/v at the end %.1e\n",
               dim, roll ? "rolling" : "slipping", tan_theta, threshold, ea, r.tol, ew, r.tol_w, r.slip_end);
        ck_assert_msg(fabs(ea) <= r.tol,
                      "%dD %s at tan(theta) = %.4f: a = %.9g m/s^2, expected %.9g (rel err %.3e > %.1e)", dim,
                      roll ? "rolling" : "slipping", tan_theta, r.a, r.a_exact, ea, r.tol);
        ck_assert_msg(fabs(ew) <= r.tol_w,
                      "%dD %s at tan(theta) = %.4f: spin-up %.9g rad/s^2, expected %.9g (rel err %.3e > %.1e)", dim,
                      roll ? "rolling" : "slipping", tan_theta, r.alpha, r.alpha_exact, ew, r.tol_w);
        if (roll)
            ck_assert_msg(r.slip_end <= 1e-6, "%dD rolling: the contact still slips (slip/v = %.3e)", dim, r.slip_end);
        else
            ck_assert_msg(r.slip_end >= 0.1, "%dD slipping: the contact does not slip (slip/v = %.3e)", dim,
                          r.slip_end);
    }
}

START_TEST(incline_2d) { check_incline(2); }
END_TEST

START_TEST(incline_3d) { check_incline(3); }
END_TEST

int main(void)
{
    Suite *s = suite_create("incline");
    V_TCASE(s, incline_2d);
    V_TCASE(s, incline_3d);
    return v_run(s);
}
