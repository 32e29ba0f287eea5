#include "scenes.h"

#include <check.h>
#include <stdlib.h>

int scene_run_suite(Suite *s)
{
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    const int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}

sx_model *scene_model(int dim, const double *gravity, double dt, double k, double mu, double rho)
{
    sx_model_def d = sx_model_default_def();
    d.dim = dim;
    d.timestep = dt;
    if (gravity)
        for (int i = 0; i < dim; i++) d.gravity[i] = gravity[i];
    char err[256];
    sx_model *m = sx_model_create(&d, err, sizeof err);
    ck_assert_msg(m != NULL, "%s", err);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = k;
    md.friction = mu;
    md.density = rho;
    ck_assert_msg(sx_material_set(m, "m", &md, NULL) == SX_OK, "%s", sx_model_error(m));
    return m;
}

int scene_material(sx_model *m) { return sx_material_find(m, "m"); }

int64_t scene_ball(sx_model *m, const double *pos, const double *vel, double radius)
{
    sx_ball_def b = sx_ball_default_def();
    for (int i = 0; i < sx_model_dim(m); i++) {
        b.pos[i] = pos[i];
        b.vel[i] = vel ? vel[i] : 0;
    }
    b.radius = radius;
    b.material = scene_material(m);
    int64_t id = 0;
    ck_assert_msg(sx_ball_add(m, &b, &id) == SX_OK, "%s", sx_model_error(m));
    return id;
}

/* ---- random assemblies ---- */

#include <math.h>

uint64_t scene_rng_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

double scene_rng_uniform(uint64_t *s, double lo, double hi)
{
    const double u = (double)(scene_rng_u64(s) >> 11) * 0x1.0p-53;
    return lo + (hi - lo) * u;
}

void scene_box_walls(sx_model *m, const double *lo, const double *hi, double k, double mu)
{
    const int dim = sx_model_dim(m);
    for (int axis = 0; axis < dim; axis++)
        for (int side = 0; side < 2; side++) {
            sx_wall_def w = sx_wall_default_def(dim);
            for (int k2 = 0; k2 < 3; k2++) w.normal[k2] = w.point[k2] = 0;
            w.point[axis] = side ? hi[axis] : lo[axis];
            w.normal[axis] = side ? -1.0 : 1.0;
            w.kn = w.ks = k;
            w.friction = mu;
            ck_assert_msg(sx_wall_add(m, &w, NULL) == SX_OK, "%s", sx_model_error(m));
        }
}

void scene_random_balls(sx_model *m, int64_t n, const double *lo, const double *hi, double rmin, double rmax,
                        double vmax, double max_overlap, uint64_t seed, int64_t *ids)
{
    const int dim = sx_model_dim(m);
    double *xs = malloc((size_t)(n > 0 ? n : 1) * 4 * sizeof(double));
    ck_assert_ptr_nonnull(xs);
    uint64_t s = seed;
    for (int64_t i = 0; i < n; i++) {
        double *x = xs + 4 * i;
        int tries = 0;
        for (;;) {
            ck_assert_msg(++tries < 100000, "scene_random_balls: the box is too crowded for %lld balls", (long long)n);
            x[3] = scene_rng_uniform(&s, rmin, rmax);
            for (int k = 0; k < dim; k++) x[k] = scene_rng_uniform(&s, lo[k] + x[3], hi[k] - x[3]);
            bool ok = true;
            for (int64_t j = 0; j < i && ok; j++) {
                const double *y = xs + 4 * j;
                double d2 = 0;
                for (int k = 0; k < dim; k++) d2 += (x[k] - y[k]) * (x[k] - y[k]);
                const double un = x[3] + y[3] - sqrt(d2);
                ok = un <= max_overlap * (x[3] < y[3] ? x[3] : y[3]);
            }
            if (ok) break;
        }
        double v[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++) v[k] = scene_rng_uniform(&s, -vmax, vmax);
        const int64_t id = scene_ball(m, x, v, x[3]);
        if (ids) ids[i] = id;
    }
    free(xs);
}

int scene_material_def(sx_model *m, const char *name, const sx_material_def *def)
{
    int index = -1;
    ck_assert_msg(sx_material_set(m, name, def, &index) == SX_OK, "%s", sx_model_error(m));
    return index;
}

int64_t scene_ball_full(sx_model *m, const double *pos, const double *vel, const double *spin, double radius,
                        int material)
{
    sx_ball_def b = sx_ball_default_def();
    const int dim = sx_model_dim(m), rdim = dim == 3 ? 3 : 1;
    for (int i = 0; i < dim; i++) {
        b.pos[i] = pos[i];
        b.vel[i] = vel ? vel[i] : 0;
    }
    for (int i = 0; i < rdim; i++) b.spin[i] = spin ? spin[i] : 0;
    b.radius = radius;
    b.material = material;
    int64_t id = 0;
    ck_assert_msg(sx_ball_add(m, &b, &id) == SX_OK, "%s", sx_model_error(m));
    return id;
}

int64_t scene_halfspace(sx_model *m, const double *point, const double *normal, double kn, double ks, double mu)
{
    const int dim = sx_model_dim(m);
    sx_wall_def w = sx_wall_default_def(dim);
    for (int i = 0; i < dim; i++) {
        w.point[i] = point[i];
        w.normal[i] = normal[i];
    }
    w.kn = kn;
    w.ks = ks;
    w.friction = mu;
    int64_t id = 0;
    ck_assert_msg(sx_wall_add(m, &w, &id) == SX_OK, "%s", sx_model_error(m));
    return id;
}

int64_t scene_ball_of(sx_model *m, int material, const double *pos, const double *vel, double radius)
{
    sx_ball_def b = sx_ball_default_def();
    for (int i = 0; i < sx_model_dim(m); i++) {
        b.pos[i] = pos[i];
        b.vel[i] = vel ? vel[i] : 0;
    }
    b.radius = radius;
    b.material = material;
    int64_t id = 0;
    ck_assert_msg(sx_ball_add(m, &b, &id) == SX_OK, "%s", sx_model_error(m));
    return id;
}

void scene_impose(sx_model *m, int64_t id, const double *vel, const double *spin)
{
    const double zero[3] = {0, 0, 0};
    ck_assert_msg(sx_ball_set_vec(m, id, SX_BALL_VEL, vel ? vel : zero) == SX_OK, "%s", sx_model_error(m));
    ck_assert_msg(sx_ball_set_vec(m, id, SX_BALL_SPIN, spin ? spin : zero) == SX_OK, "%s", sx_model_error(m));
    const unsigned all = sx_model_dim(m) == 3 ? (SX_FIX_VEL | SX_FIX_SPIN) : (SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ);
    ck_assert_msg(sx_ball_set_fixity(m, id, all) == SX_OK, "%s", sx_model_error(m));
}
