/* Damping by restitution: a material may give the coefficient of
 * restitution e of a normal impact (`restitution`, in (0, 1]) instead of
 * the normal dashpot's critical-damping ratio beta (`viscous_normal`); the
 * ratio that yields e is derived for the material's law, once, when the
 * material is set or loaded, and mixes like viscous_normal (the mean of
 * the two materials'; against a wall, the ball's own).
 *
 * The normal dashpot is c = 2 beta sqrt(m* kn), kn the secant stiffness
 * (Fn = kn Un), not clipped, so an impact at speed v obeys
 *   m* d'' = -kn(d) d - 2 beta sqrt(m* kn(d)) d'.
 * Linear (kn constant): a damped oscillator, e = exp(-beta pi / sqrt(1 -
 *   beta^2)), so beta = -ln e / sqrt(pi^2 + ln^2 e).
 * Hertz (kn = K sqrt(d), 4-25): with d = d* x, t = s d* / v and
 *   d* = (m* v^2 / K)^(2/5), the impact becomes
 *     x'' = -x^(3/2) - 2 beta x^(1/4) x',  x(0) = 0, x'(0) = 1,
 *   with no parameter left but beta: e = -x'(s_end) at the return to
 *   x = 0 depends on beta alone, whatever the speed, masses, radii or
 *   moduli (the dashpot of Tsuji et al. 1992, whose e was tabulated
 *   numerically; Antypov & Elliott 2011 give an approximate closed form).
 *   Here e(beta) is integrated (RK4, 2000 steps per unit of s: its error
 *   is below 1e-10) and inverted by bisection to 1e-12 in beta. */
#pragma once

#include "law.h"

#include <math.h>

/* e of the dimensionless Hertz impact with damping ratio beta. */
static inline double sx_restitution_hertz_e(double beta)
{
    const double h = 5e-4;
    double x = 0, v = 1;
#define SX_ACC_(x_, v_) (-(x_) * sqrt(fmax(x_, 0)) - 2 * beta * sqrt(sqrt(fmax(x_, 0))) * (v_))
    for (int step = 0; step < 400000; step++) {
        const double a1 = SX_ACC_(x, v);
        const double x2 = x + 0.5 * h * v, v2 = v + 0.5 * h * a1, a2 = SX_ACC_(x2, v2);
        const double x3 = x + 0.5 * h * v2, v3 = v + 0.5 * h * a2, a3 = SX_ACC_(x3, v3);
        const double x4 = x + h * v3, v4 = v + h * a3, a4 = SX_ACC_(x4, v4);
        const double xn = x + h / 6 * (v + 2 * v2 + 2 * v3 + v4), vn = v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
        if (xn <= 0 && step > 0) /* back at contact: the speed where x crosses 0, by linear interpolation */
            return -(v + (vn - v) * (x / (x - xn)));
        x = xn, v = vn;
    }
#undef SX_ACC_
    return 0; /* still in contact after 200 time units: overdamped to the precision wanted */
}

/* The damping ratio giving restitution e under law `law` (0 < e <= 1). */
static inline double sx_restitution_beta(int law, double e)
{
    if (e >= 1) return 0;
    const double ln = log(e);
    const double linear = -ln / sqrt(SX_PI * SX_PI + ln * ln);
    if (law != SX_MODEL_HERTZ) return linear;
    double lo = 0, hi = 2 * linear + 0.1;
    while (sx_restitution_hertz_e(hi) > e) lo = hi, hi *= 2;
    while (hi - lo > 1e-12 * hi) {
        const double mid = 0.5 * (lo + hi);
        if (sx_restitution_hertz_e(mid) > e) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

static inline double sx_law_restitution_derive(const sx_material_def *d)
{
    return d->restitution > 0 ? sx_restitution_beta((int)d->model, d->restitution) : d->viscous_normal;
}

static inline const char *sx_law_restitution_check(const sx_material_def *d)
{
    return d->restitution > 0 && d->viscous_normal > 0
               ? "give the normal damping either as restitution or as viscous_normal, not both"
               : NULL;
}

/* After the contact's law has set kn: beta, and the linear dashpot's factor with it. */
static inline void sx_law_restitution_mix(sx_pair_law *l, const sx_material *a, const sx_material *b, int self)
{
    if (!(a->def.restitution > 0) && !(b && b->def.restitution > 0)) return; /* viscous_normal's, as mixed */
    l->beta_n = b ? 0.5 * (a->derived[self] + b->derived[self]) : a->derived[self];
    l->dash_n = 4 * l->beta_n * l->beta_n * l->kn;
}

static inline const sx_law *sx_law_restitution(void)
{
    static const sx_law_param params[] = {
        {"restitution", "1", offsetof(sx_material_def, restitution), 0, 1, true, true,
         "restitution must be in (0, 1] (0: the normal dashpot from viscous_normal)"},
    };
    static const sx_law law = {
        .name = "restitution",
        .kind = SX_LAW_PART,
        .summary = "normal damping by the coefficient of restitution e, derived for the law (linear, Hertz)",
        .params = params,
        .nparams = 1,
        .mix = sx_law_restitution_mix,
        .derive = sx_law_restitution_derive,
        .check = sx_law_restitution_check,
    };
    return &law;
}
