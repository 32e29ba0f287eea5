/* Small vectors, quaternions and rotations of the clumps (clumps.c and the
 * clump_*.c files), shared with their per-dimension step
 * (kernels/clump_motion.c): static inline, so each unit keeps its own copy. */
#ifndef SX_CLUMP_MATH_H
#define SX_CLUMP_MATH_H

#include "clumps.h"
#include "model_internal.h"

#include <math.h>

static inline void cross3(const double *a, const double *b, double *out)
{
    const double o0 = a[1] * b[2] - a[2] * b[1], o1 = a[2] * b[0] - a[0] * b[2], o2 = a[0] * b[1] - a[1] * b[0];
    out[0] = o0, out[1] = o1, out[2] = o2;
}

/* a x b for dim-vectors: 3D the vector, 2D the scalar about z in out[0]. */
static inline void moment_arm(int d, const double *a, const double *b, double *out)
{
    if (d == 3) cross3(a, b, out);
    else out[0] = a[0] * b[1] - a[1] * b[0];
}

/* w x r: 2D w is the scalar spin about z. */
static inline void spin_arm(int d, const double *w, const double *r, double *out)
{
    if (d == 3) {
        cross3(w, r, out);
    } else {
        out[0] = -w[0] * r[1];
        out[1] = w[0] * r[0];
    }
}

/* Hamilton product a b of quaternions (w, x, y, z). */
static inline void qmul(const double *a, const double *b, double *out)
{
    const double w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    const double x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    const double y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    const double z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
    out[0] = w, out[1] = x, out[2] = y, out[3] = z;
}

static inline void qnormalize(double *q)
{
    const double s = 1.0 / sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; k++) q[k] *= s;
}

/* The rotation matrix (row-major) of a unit quaternion. */
static inline void qmatrix(const double *q, double *R)
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

static inline void mat_vec(const double *R, const double *v, double *out)
{
    for (int i = 0; i < 3; i++) out[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
}

static inline void mat_tvec(const double *R, const double *v, double *out)
{
    for (int i = 0; i < 3; i++) out[i] = R[i] * v[0] + R[3 + i] * v[1] + R[6 + i] * v[2];
}

/* The rotation (row-major 3x3) from the body frame to space. 2D: about z by the angle. */
static inline void body_rotation(const sx_model *m, int64_t c, double *R)
{
    const sx_clumps *C = m->clumps;
    if (m->dim == 3) {
        qmatrix(C->q + c * 4, R);
    } else {
        const double a = C->q[c], cs = cos(a), sn = sin(a);
        R[0] = cs, R[1] = -sn, R[2] = 0, R[3] = sn, R[4] = cs, R[5] = 0, R[6] = 0, R[7] = 0, R[8] = 1;
    }
}

/* 3D: the spin in space of angular momentum L, w = R I^-1 R^T L (principal moments I). */
static inline void spin_of(const double *R, const double *I, const double *L, double *w)
{
    double b[3];
    mat_tvec(R, L, b);
    for (int k = 0; k < 3; k++) b[k] /= I[k];
    mat_vec(R, b, w);
}

/* 3D: the angular momentum of spin w, L = R I R^T w. */
static inline void momentum_of(const double *R, const double *I, const double *w, double *L)
{
    double b[3];
    mat_tvec(R, w, b);
    for (int k = 0; k < 3; k++) b[k] *= I[k];
    mat_vec(R, b, L);
}

/* sin and cos of x. The drift's half-angles are w dt / 4 or w dt / 2,
 * small in any stable DEM run (w dt << 1, typically 1e-4 or less), where a
 * short Taylor series is exact to round-off and far cheaper than libm:
 * below 1e-3 the terms after x^5 (x^6) are under 1e-21 relative, below 0.1
 * those after x^9 (x^10) under 3e-19; larger angles go to libm. */
static inline void sin_cos(double x, double *s, double *c)
{
    const double x2 = x * x;
    if (x2 < 1e-6) {
        *s = x * (1 - x2 * (1.0 / 6) * (1 - x2 * (1.0 / 20)));
        *c = 1 - x2 * 0.5 * (1 - x2 * (1.0 / 12) * (1 - x2 * (1.0 / 30)));
    } else if (x2 < 1e-2) {
        *s = x * (1 - x2 * (1.0 / 6) * (1 - x2 * (1.0 / 20) * (1 - x2 * (1.0 / 42) * (1 - x2 * (1.0 / 72)))));
        *c = 1 - x2 * 0.5 * (1 - x2 * (1.0 / 12) * (1 - x2 * (1.0 / 30) * (1 - x2 * (1.0 / 56) * (1 - x2 * (1.0 / 90)))));
    } else {
        *s = sin(x);
        *c = cos(x);
    }
}

/* The drift of a torque-free body over dt (4-42 with M = 0): the symmetric
 * splitting of T = sum L_b,i^2 / (2 I_i) into rotations about the principal
 * axes (see the note atop kernels/clump_motion.c). Under the part T_a
 * alone w_a = L_b,a / I_a is constant and the body turns about its axis a
 * by phi = w_a tau: the orientation gains the body-axis rotation
 * (cos phi/2, sin phi/2 e_a) on the right, and L, fixed in space, turns by
 * -phi in body coordinates. R is the rotation of q at the start (the
 * kick's). */
/* One part of the splitting: the rotation about principal axis a (j, k the
 * two after it, cyclically) by the share `part` of dt. */
static inline __attribute__((always_inline)) void rotor_part(double *Lb, double *w, double *v, const double *h, int a,
                                                             int j, int k, double part)
{
    double sh, ch;
    sin_cos(Lb[a] * h[a] * part, &sh, &ch);
    const double c = ch * ch - sh * sh, sn = 2 * sh * ch; /* cos phi, sin phi */
    const double lj = Lb[j], lk = Lb[k];
    Lb[j] = c * lj + sn * lk;
    Lb[k] = c * lk - sn * lj;
    /* q (ch, sh e_a): the Hamilton product with a rotation about one axis */
    const double w0 = *w, va = v[a], vj = v[j], vk = v[k];
    *w = w0 * ch - va * sh;
    v[a] = va * ch + w0 * sh;
    v[j] = vj * ch + vk * sh;
    v[k] = vk * ch - vj * sh;
}

/* Always inlined: the clumps' step has two callers (serial, decomposed),
 * and left to itself the compiler stops inlining it into either. */
static inline __attribute__((always_inline)) void free_rotor(double *q, const double *R, const double *L,
                                                             const double *I, double dt)
{
    const double h[3] = {dt / I[0], dt / I[1], dt / I[2]};
    double Lb[3];
    mat_tvec(R, L, Lb);
    double w = q[0], v[3] = {q[1], q[2], q[3]};
    /* axes 0, 1, 2, 1, 0 by dt/4, dt/4, dt/2, dt/4, dt/4 (the axes spelled
     * out so that the parts' arithmetic stays in registers) */
    rotor_part(Lb, &w, v, h, 0, 1, 2, 0.25);
    rotor_part(Lb, &w, v, h, 1, 2, 0, 0.25);
    rotor_part(Lb, &w, v, h, 2, 0, 1, 0.5);
    rotor_part(Lb, &w, v, h, 1, 2, 0, 0.25);
    rotor_part(Lb, &w, v, h, 0, 1, 2, 0.25);
    q[0] = w, q[1] = v[0], q[2] = v[1], q[3] = v[2];
    qnormalize(q);
}

/* A spin imposed in space (every spin component fixed): the body turns by
 * |w| dt about w, a rotation on the left of the orientation. */
static inline void imposed_rotation(double *q, const double *w, double dt)
{
    const double n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (n == 0) return;
    const double half = 0.5 * n * dt, s = sin(half) / n;
    const double p[4] = {cos(half), s * w[0], s * w[1], s * w[2]};
    qmul(p, q, q);
    qnormalize(q);
}

#endif
