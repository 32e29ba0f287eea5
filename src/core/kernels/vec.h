/* Small vector helpers of the per-dimension kernels (kernels.c includes
 * this after defining D and RD). */
#pragma once

static inline double dot(const double *a, const double *b)
{
    double s = 0;
    for (int k = 0; k < D; k++) s += a[k] * b[k];
    return s;
}

/* w x r: the velocity of a point at arm r on a body spinning at w. */
static inline void spin_cross(const double *w, const double *r, double *out)
{
#if D == 3
    out[0] = w[1] * r[2] - w[2] * r[1];
    out[1] = w[2] * r[0] - w[0] * r[2];
    out[2] = w[0] * r[1] - w[1] * r[0];
#else
    out[0] = -w[0] * r[1];
    out[1] = w[0] * r[0];
#endif
}

/* r x F: the moment of F applied at arm r (2D: the scalar about z). */
static inline void moment_of(const double *r, const double *f, double *out)
{
#if D == 3
    out[0] = r[1] * f[2] - r[2] * f[1];
    out[1] = r[2] * f[0] - r[0] * f[2];
    out[2] = r[0] * f[1] - r[1] * f[0];
#else
    out[0] = r[0] * f[1] - r[1] * f[0];
#endif
}
