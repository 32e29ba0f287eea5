/* Helpers shared by the clump suites (header-only, like verify.h). */
#pragma once

#include "verify.h"

#include <string.h>

/* A model with one linear material "rock" (kn = ks = k, friction mu,
 * density rho, local damping alpha) and gravity g along -dim (0: none). */
static inline sx_model *ct_model(int dim, double g, double k, double mu, double rho, double alpha)
{
    double grav[3] = {0, 0, 0};
    grav[dim - 1] = -g;
    sx_model_def def = sx_model_default_def();
    def.dim = dim;
    memcpy(def.gravity, grav, sizeof grav);
    char err[256];
    sx_model *m = sx_model_create(&def, err, sizeof err);
    ck_assert_msg(m != NULL, "%s", err);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = k, md.friction = mu, md.density = rho, md.damping = alpha;
    ck_assert_msg(sx_material_set(m, "rock", &md, NULL) == SX_OK, "%s", sx_model_error(m));
    return m;
}

/* A template from n pebbles (dim numbers per centre); returns its index. */
static inline int ct_template(sx_model *m, const char *name, const double *pos, const double *rad, int64_t n)
{
    sx_clump_template_def td = {pos, rad, n, 0};
    int t = -1;
    ck_assert_msg(sx_clump_template_add(m, name, &td, &t) == SX_OK, "%s", sx_model_error(m));
    return t;
}

/* A clump of template t at pos with orientation q (NULL: identity), vel and spin (NULL: 0). */
static inline int64_t ct_clump(sx_model *m, int t, const double *pos, const double *q, const double *vel,
                               const double *spin)
{
    sx_clump_def cd = sx_clump_default_def();
    cd.template_index = t;
    for (int k = 0; k < 3; k++) {
        cd.pos[k] = pos[k];
        cd.vel[k] = vel ? vel[k] : 0;
        cd.spin[k] = spin ? spin[k] : 0;
    }
    if (q) memcpy(cd.orientation, q, 4 * sizeof(double));
    int64_t id = 0;
    ck_assert_msg(sx_clump_add(m, &cd, &id) == SX_OK, "%s", sx_model_error(m));
    return id;
}

static inline void ct_vec(const sx_model *m, int64_t id, sx_clump_vec which, double out[3])
{
    V_CHECK(sx_clump_get_vec(m, id, which, out) == SX_OK, "%s", sx_model_error(m));
}

/* Relative difference |a - b| / scale. */
static inline double ct_rel(double a, double b, double scale) { return fabs(a - b) / scale; }
