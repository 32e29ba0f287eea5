/* Validation of the servo, cylinder and measurement entry points: every
 * out-of-range argument returns SX_EINVAL with a message naming the
 * argument, and leaves the model as it was; unknown ids give SX_ENOTFOUND. */
#include "lab.h"

static sx_model *model(int dim)
{
    sx_model *m = scene_model(dim, NULL, 1e-6, 1e8, 0.5, 2650);
    double x[3] = {0, 0, 0};
    x[dim - 1] = 0.05; /* clear of the walls at the origin */
    scene_ball(m, x, NULL, 0.01);
    return m;
}

START_TEST(servo_arguments)
{
    const int dim = _i;
    sx_model *m = model(dim);
    sx_wall_def w = sx_wall_default_def(dim);
    int64_t wid;
    LAB_OK(m, sx_wall_add(m, &w, &wid));
    const sx_servo_def ok = sx_servo_default_def();
    ck_assert_double_eq(ok.alpha, 0.5);
    ck_assert_double_eq(ok.area, 1);
    ck_assert_double_eq(ok.max_speed, 1);
    ck_assert_double_eq(ok.target, 0);
    const double bad_area[] = {0, -1, NAN, INFINITY};
    for (int k = 0; k < 4; k++) {
        sx_servo_def s = ok;
        s.area = bad_area[k];
        LAB_EINVAL(m, sx_wall_set_servo(m, wid, &s), "area");
    }
    const double bad_alpha[] = {0, -0.5, 1.0000001, 2, NAN};
    for (int k = 0; k < 5; k++) {
        sx_servo_def s = ok;
        s.alpha = bad_alpha[k];
        LAB_EINVAL(m, sx_wall_set_servo(m, wid, &s), "alpha");
    }
    const double bad_speed[] = {0, -1, NAN, INFINITY};
    for (int k = 0; k < 4; k++) {
        sx_servo_def s = ok;
        s.max_speed = bad_speed[k];
        LAB_EINVAL(m, sx_wall_set_servo(m, wid, &s), "max_speed");
    }
    const double bad_target[] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        sx_servo_def s = ok;
        s.target = bad_target[k];
        LAB_EINVAL(m, sx_wall_set_servo(m, wid, &s), "target");
    }
    /* the limits are allowed: alpha = 1 */
    sx_servo_def s = ok;
    s.alpha = 1;
    s.max_speed = 0.25;
    LAB_OK(m, sx_wall_set_servo(m, wid, &s));
    /* a refused redefinition keeps the servo in force: with no contact the wall approaches at 0.25 m/s */
    sx_servo_def bad = ok;
    bad.alpha = 3;
    LAB_EINVAL(m, sx_wall_set_servo(m, wid, &bad), "alpha");
    lab_cycle(m, 4);
    const sx_wall_def got = lab_wall(m, wid);
    LAB_NEAR(got.point[dim - 1], 4 * 0.25 * 1e-6, 1e-18);
    /* cleared: the wall is no longer driven (it keeps the velocity it had) */
    LAB_OK(m, sx_wall_clear_servo(m, wid));
    const double still[3] = {0, 0, 0};
    LAB_OK(m, sx_wall_set_vel(m, wid, still));
    lab_cycle(m, 4);
    ck_assert_double_eq(lab_wall(m, wid).point[dim - 1], got.point[dim - 1]);
    /* unknown walls */
    ck_assert_int_eq(sx_wall_set_servo(m, 99, &ok), SX_ENOTFOUND);
    ck_assert_msg(strstr(sx_model_error(m), "99") != NULL, "%s", sx_model_error(m));
    ck_assert_int_eq(sx_wall_clear_servo(m, 99), SX_ENOTFOUND);
    double f;
    int64_t n;
    ck_assert_int_eq(sx_wall_load(m, 99, &f, &n, NULL), SX_ENOTFOUND);
    ck_assert_int_eq(sx_wall_set_radial_vel(m, 99, 1.0), SX_ENOTFOUND);
    sx_model_destroy(m);
}
END_TEST

START_TEST(cylinder_arguments)
{
    sx_model *m = model(3);
    sx_wall_def c = sx_wall_default_def(3);
    c.kind = SX_WALL_CYLINDER;
    c.radius = 0.1;
    c.height = 0.2;
    int64_t id = -7;
    const double bad_radius[] = {0, -0.1, NAN, INFINITY};
    for (int k = 0; k < 4; k++) {
        sx_wall_def w = c;
        w.radius = bad_radius[k];
        LAB_EINVAL(m, sx_wall_add(m, &w, &id), "radius");
    }
    const double bad_height[] = {-0.1, NAN, INFINITY};
    for (int k = 0; k < 3; k++) {
        sx_wall_def w = c;
        w.height = bad_height[k];
        LAB_EINVAL(m, sx_wall_add(m, &w, &id), "height");
    }
    sx_wall_def w = c;
    w.radial_vel = NAN;
    LAB_EINVAL(m, sx_wall_add(m, &w, &id), "radial");
    w = c;
    memset(w.normal, 0, sizeof w.normal);
    LAB_EINVAL(m, sx_wall_add(m, &w, &id), "axis");
    ck_assert_int_eq(id, -7);
    ck_assert_int_eq(sx_wall_count(m), 0);
    /* a valid cylinder; its radial velocity must be finite */
    LAB_OK(m, sx_wall_add(m, &c, &id));
    LAB_EINVAL(m, sx_wall_set_radial_vel(m, id, NAN), "finite");
    LAB_EINVAL(m, sx_wall_set_radial_vel(m, id, INFINITY), "finite");
    LAB_OK(m, sx_wall_set_radial_vel(m, id, -0.5));
    ck_assert_double_eq(lab_wall(m, id).radial_vel, -0.5);
    /* radial velocity of a plane */
    sx_wall_def p = sx_wall_default_def(3);
    int64_t pid;
    LAB_OK(m, sx_wall_add(m, &p, &pid));
    LAB_EINVAL(m, sx_wall_set_radial_vel(m, pid, 1.0), "not a cylinder");
    ck_assert_double_eq(lab_wall(m, pid).radial_vel, 0);
    sx_model_destroy(m);
    /* no cylinder in 2D */
    m = model(2);
    sx_wall_def c2 = sx_wall_default_def(2);
    c2.kind = SX_WALL_CYLINDER;
    c2.radius = 0.1;
    LAB_EINVAL(m, sx_wall_add(m, &c2, NULL), "2D");
    ck_assert_msg(strstr(sx_model_error(m), "kind") != NULL, "%s", sx_model_error(m));
    ck_assert_int_eq(sx_wall_count(m), 0);
    /* nor a radial velocity for a line */
    sx_wall_def l = sx_wall_default_def(2);
    int64_t lid;
    LAB_OK(m, sx_wall_add(m, &l, &lid));
    LAB_EINVAL(m, sx_wall_set_radial_vel(m, lid, 1.0), "not a cylinder");
    sx_model_destroy(m);
}
END_TEST

START_TEST(measure_arguments)
{
    const int dim = _i;
    sx_model *m = model(dim);
    lab_cycle(m, 1);
    sx_measurement out;
    sx_region r;
    memset(&r, 0, sizeof r);
    r.shape = SX_SHAPE_BOX;
    for (int k = 0; k < 3; k++) r.lo[k] = -1, r.hi[k] = 1;
    LAB_OK(m, sx_measure(m, &r, &out));
    ck_assert_int_eq(out.balls, 1);
    /* a zero box, along each axis; an inverted one */
    for (int k = 0; k < dim; k++) {
        sx_region z = r;
        z.hi[k] = z.lo[k];
        LAB_EINVAL(m, sx_measure(m, &z, &out), "box");
        z.hi[k] = z.lo[k] - 1;
        LAB_EINVAL(m, sx_measure(m, &z, &out), "box");
    }
    sx_region z = r;
    z.lo[0] = NAN;
    LAB_EINVAL(m, sx_measure(m, &z, &out), "box");
    /* spheres: negative, zero, NaN, infinite radius */
    sx_region s;
    memset(&s, 0, sizeof s);
    s.shape = SX_SHAPE_SPHERE;
    const double bad[] = {-1, 0, NAN, INFINITY};
    for (int k = 0; k < 4; k++) {
        s.radius = bad[k];
        LAB_EINVAL(m, sx_measure(m, &s, &out), "radius");
    }
    s.radius = 1;
    LAB_OK(m, sx_measure(m, &s, &out));
    LAB_NEAR(out.volume, dim == 3 ? 4.0 / 3.0 * LAB_PI : LAB_PI, 1e-15);
    sx_region u = r;
    u.shape = (sx_region_shape)9;
    LAB_EINVAL(m, sx_measure(m, &u, &out), "shape");
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("lab_validation");
    TCase *tc = tcase_create("validation");
    tcase_add_loop_test(tc, servo_arguments, 2, 4);
    tcase_add_test(tc, cylinder_arguments);
    tcase_add_loop_test(tc, measure_arguments, 2, 4);
    suite_add_tcase(s, tc);
    return lab_run(s);
}
