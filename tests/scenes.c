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
