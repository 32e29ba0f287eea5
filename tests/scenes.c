#include "scenes.h"

#include <check.h>

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
