/* Measurement regions (DESIGN 1, "Measurement"): the average stress tensor,
 * porosity, coordination number and fabric of the balls whose centre lies
 * in a sphere (2D: circle) or a box, from the contacts of the last step.
 *
 * Stress (compression positive): sigma = -(1/V) sum over the balls inside,
 * over their contacts, of F (x_c - x) with F the contact force on the ball
 * (Love-Weber; for a ball-ball contact inside the region the two ends add up
 * to F_on_b (x_b - x_a)). Porosity counts the solid inside the region: each
 * ball's part in it (region_cut.c), a pebble its share of its clump's
 * volume in that proportion.
 *
 * Clumps: a pebble counts its share of its clump's volume (the union, so
 * overlaps are not counted twice), and its contacts' arms run from the
 * clump's centroid, not the pebble's centre: the body carries load between
 * its pebbles internally, and the arms from one point of the body count
 * that internal stress too (for a body in equilibrium the sum of F (x_c - x)
 * does not depend on the point). */
#include "model_internal.h"

#include <math.h>
#include <string.h>

typedef struct measure_ctx {
    const sx_model *m;
    const sx_region *r;
    sx_measurement *out;
    int64_t fabric_n;
} measure_ctx;

static bool inside(const sx_region *r, const double *x, int dim)
{
    if (r->shape == SX_SHAPE_SPHERE) {
        double d2 = 0;
        for (int k = 0; k < dim; k++) d2 += (x[k] - r->centre[k]) * (x[k] - r->centre[k]);
        return d2 <= r->radius * r->radius;
    }
    for (int k = 0; k < dim; k++)
        if (x[k] < r->lo[k] || x[k] > r->hi[k]) return false;
    return true;
}

/* Where ball i's contact arms start: its centre, or its clump's centroid (into buf). */
static const double *arm_origin(const sx_model *m, int64_t i, double *buf)
{
    if (!m->balls.clump || !m->balls.clump[i]) return m->balls.x + i * m->dim;
    double volume;
    sx__pebble_body(m, i, buf, &volume);
    return buf;
}

/* Adds -F (x_c - x) of one ball's side of a contact. */
static void add_stress(sx_measurement *out, int dim, const double *f, const double *xc, const double *x)
{
    for (int i = 0; i < dim; i++)
        for (int j = 0; j < dim; j++) out->stress[i][j] -= f[i] * (xc[j] - x[j]);
}

static bool visit(const sx_contact_info *ci, void *ud)
{
    measure_ctx *c = ud;
    const sx_model *m = c->m;
    const int dim = m->dim;
    /* the force on b (ball-wall: on the ball, which is `a`): the contact's
     * and, in parallel with it, its parallel bond's (4-32); the bond's moment
     * is a couple and adds nothing to the average stress */
    double f[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) f[k] = (ci->fn + ci->pb_fn) * ci->normal[k] + ci->shear[k] + ci->pb_fs[k];
    const int64_t ia = sx__ball_index(m, ci->a);
    const double *xa = m->balls.x + ia * dim;
    double ba[3], bb[3];
    if (ci->is_wall) {
        if (!inside(c->r, xa, dim)) return true;
        add_stress(c->out, dim, f, ci->point, arm_origin(m, ia, ba));
        return true;
    }
    const int64_t ib = sx__ball_index(m, ci->b);
    const double *xb = m->balls.x + ib * dim;
    const bool in_a = inside(c->r, xa, dim), in_b = inside(c->r, xb, dim);
    if (!in_a && !in_b) return true;
    double fa[3];
    for (int k = 0; k < 3; k++) fa[k] = -f[k];
    if (in_a) add_stress(c->out, dim, fa, ci->point, arm_origin(m, ia, ba));
    if (in_b) { /* periodic space: b's arm from its image that touches a */
        const double *o = arm_origin(m, ib, bb);
        double ob[3];
        for (int k = 0; k < dim; k++) ob[k] = o[k] + ci->shift[k];
        add_stress(c->out, dim, f, ci->point, ob);
    }
    c->out->contacts += in_a + in_b; /* contact ends inside: twice the contacts for the coordination */
    for (int i = 0; i < dim; i++)
        for (int j = 0; j < dim; j++) c->out->fabric[i][j] += ci->normal[i] * ci->normal[j];
    c->fabric_n++;
    return true;
}

sx_status sx_measure(sx_model *m, const sx_region *region, sx_measurement *out)
{
    const int dim = m->dim;
    memset(out, 0, sizeof *out);
    if (region->shape == SX_SHAPE_SPHERE) {
        if (!(region->radius > 0) || !isfinite(region->radius))
            return sx__fail(m, SX_EINVAL, "measure: the region's radius must be > 0 m (got %g)", region->radius);
        const double r = region->radius;
        out->volume = sx__ball_volume(dim, r);
    } else if (region->shape == SX_SHAPE_BOX) {
        out->volume = 1;
        for (int k = 0; k < dim; k++) {
            if (!(region->hi[k] > region->lo[k]))
                return sx__fail(m, SX_EINVAL, "measure: the box must have hi > lo in every direction");
            out->volume *= region->hi[k] - region->lo[k];
        }
    } else {
        return sx__fail(m, SX_EINVAL, "measure: unknown region shape %d", (int)region->shape);
    }
    const sx_balls *b = &m->balls;
    for (int64_t i = 0; i < b->n; i++) {
        const double r = b->rad[i], whole = sx__ball_volume(dim, r);
        const double cut = sx__region_cut(region, dim, b->x + i * dim, r); /* region_cut.c */
        if (cut > 0) {
            double v = whole, centre[3];
            if (b->clump && b->clump[i]) sx__pebble_body(m, i, centre, &v); /* its share of the union */
            out->solid += v * (cut / whole);
        }
        if (inside(region, b->x + i * dim, dim)) out->balls++;
    }
    measure_ctx c = {m, region, out, 0};
    sx_contact_each(m, visit, &c);
    for (int i = 0; i < dim; i++)
        for (int j = 0; j < dim; j++) {
            out->stress[i][j] /= out->volume;
            out->fabric[i][j] = c.fabric_n ? out->fabric[i][j] / (double)c.fabric_n : 0;
        }
    out->porosity = 1 - out->solid / out->volume;
    out->coordination = out->balls ? (double)out->contacts / (double)out->balls : 0;
    out->contacts = c.fabric_n;
    return SX_OK;
}
