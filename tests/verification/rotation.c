/* The shear force turns with the contact (4-7 ... 4-15).
 *
 * A touching pair carrying a shear force is moved as a rigid body, so the
 * contact-point velocity of B relative to A is zero and no increment
 * (4-16 ... 4-20) adds to the force: only the carried rotations act.
 * - Orbit: the pair turns about an axis normal to the contact at w; after a
 *   quarter turn the normal and the shear force must both have turned by
 *   90 degrees (4-14: F <- F + c x F, c = n_old x n), in 3D and in 2D.
 * - Twist (3D): both balls spin at w about the contact normal; 4-15 turns
 *   the shear force about n by the mean spin, a quarter turn in the same time.
 * The rotation F + c x F is first order: |F|^2 grows by (1 + |c|^2) per
 * step, so over N steps of angle h the magnitude grows by about N h^2 / 2
 * and the direction lags by O(N h^3): with h = 5e-5 rad both are below 1e-4.
 */
#include "verify.h"

typedef struct shear_probe {
    double fs[3], normal[3];
    int contacts;
} shear_probe;

static bool take(const sx_contact_info *ci, void *ud)
{
    shear_probe *p = ud;
    if (ci->is_wall) return true;
    for (int k = 0; k < 3; k++) p->fs[k] = ci->shear[k], p->normal[k] = ci->normal[k];
    p->contacts++;
    return true;
}

static shear_probe probe(const sx_model *m)
{
    shear_probe p = {{0, 0, 0}, {0, 0, 0}, 0};
    sx_contact_each(m, take, &p);
    V_CHECK(p.contacts == 1, "one contact expected, %d found", p.contacts);
    return p;
}

enum motion { ORBIT, TWIST };

static void quarter_turn(int dim, enum motion how)
{
    const double R = 0.01, dt = 1e-6, w = 50.0;
    sx_model *m = scene_model(dim, NULL, dt, 1e6, 10.0, 2500);
    const double pa[3] = {-R + 1e-5, 0, 0}, pb[3] = {R - 1e-5, 0, 0};
    const double va[3] = {0, -0.01, 0}, vb[3] = {0, 0.01, 0};
    const int64_t a = scene_ball(m, pa, va, R), b = scene_ball(m, pb, vb, R);
    v_step(m, 50); /* B slides along +y on A: a shear force along -y on B */
    const shear_probe s0 = probe(m);
    const double f0 = v_norm(s0.fs, dim);
    ck_assert_msg(f0 > 0 && fabs(s0.fs[1]) > 0.999 * f0, "a shear force along y to start with");

    const int64_t steps = (int64_t)floor(V_PI / 2 / (w * dt) + 0.5);
    const int64_t ids[2] = {a, b};
    /* the motion is imposed (fixed components), so the contact forces
     * cannot take the pair off its rigid motion */
    scene_impose(m, a, NULL, NULL);
    scene_impose(m, b, NULL, NULL);
    for (int64_t s = 0; s < steps; s++) {
        for (int e = 0; e < 2; e++) {
            double x[3], v[3] = {0, 0, 0}, spin[3] = {0, 0, 0};
            v_get(m, ids[e], SX_BALL_POS, x);
            if (how == ORBIT) { /* rigid rotation about z through the origin: v = w x x */
                v[0] = -w * x[1], v[1] = w * x[0];
                if (dim == 3) spin[2] = w;
                else spin[0] = w;
            } else { /* both spin about the current normal, from A's centre to B's */
                double xa[3], xb[3], n[3];
                v_get(m, a, SX_BALL_POS, xa);
                v_get(m, b, SX_BALL_POS, xb);
                for (int k = 0; k < 3; k++) n[k] = xb[k] - xa[k];
                v_unit(n, 3);
                for (int k = 0; k < 3; k++) spin[k] = w * n[k];
            }
            V_CHECK(sx_ball_set_vec(m, ids[e], SX_BALL_VEL, v) == SX_OK, "%s", sx_model_error(m));
            V_CHECK(sx_ball_set_vec(m, ids[e], SX_BALL_SPIN, spin) == SX_OK, "%s", sx_model_error(m));
        }
        v_step(m, 1);
    }
    const shear_probe s1 = probe(m);
    const double f1 = v_norm(s1.fs, dim);
    /* A turn by t about an axis e normal to F turns F into cos t F + sin t e x F:
     * for the orbit e = z and t the angle the normal turned (contacts are
     * reported from the last force evaluation, a step behind the positions);
     * for the twist e = the normal and t = w dt per step. */
    const double z[3] = {0, 0, 1};
    const double *e = how == ORBIT ? z : s0.normal;
    const double turn = how == ORBIT ? atan2(s0.normal[0] * s1.normal[1] - s0.normal[1] * s1.normal[0],
                                             v_dot(s0.normal, s1.normal, dim))
                                     : (double)steps * w * dt;
    const double exf[3] = {e[1] * s0.fs[2] - e[2] * s0.fs[1], e[2] * s0.fs[0] - e[0] * s0.fs[2],
                           e[0] * s0.fs[1] - e[1] * s0.fs[0]};
    double err[3];
    for (int k = 0; k < 3; k++) err[k] = s1.fs[k] - (cos(turn) * s0.fs[k] + sin(turn) * exf[k]);
    printf("%dD %s: turned %.6f rad; |Fs| %.6g -> %.6g N (relative change %.2e), direction error %.2e\n", dim,
           how == ORBIT ? "orbit" : "twist", turn, f0, f1, f1 / f0 - 1, v_norm(err, 3) / f0);
    ck_assert_msg(fabs(turn - V_PI / 2) < 1e-3, "the pair turned a quarter turn (%g rad)", turn);
    ck_assert_msg(fabs(f1 / f0 - 1) < 1e-4, "the magnitude is kept: %g -> %g", f0, f1);
    ck_assert_msg(v_norm(err, 3) < 1e-4 * f0, "the shear force turned with the contact");
    if (how == TWIST) /* a spin about the normal leaves the normal where it was */
        ck_assert_msg(v_dot(s0.normal, s1.normal, dim) > 1 - 1e-12, "the normal stayed");
    sx_model_destroy(m);
}

START_TEST(orbit_3d) { quarter_turn(3, ORBIT); }
END_TEST

START_TEST(orbit_2d) { quarter_turn(2, ORBIT); }
END_TEST

START_TEST(twist_3d) { quarter_turn(3, TWIST); }
END_TEST

int main(void)
{
    Suite *s = suite_create("rotation");
    V_TCASE(s, orbit_3d);
    V_TCASE(s, orbit_2d);
    V_TCASE(s, twist_3d);
    return v_run(s);
}
