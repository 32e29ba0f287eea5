/* The geometry of a ball against a mesh's facet (3D only): the closest
 * feature of the triangle, face, edge or vertex, with the distance and the
 * unit normal from the facet to the ball's centre. Used by the broad phase
 * (which facets to list), the wall contacts (mesh_rows), the timestep and
 * the energy. Part of the per-dimension unit kernels.c, which includes it;
 * not compiled alone. */
#if D == 3

enum { FACET_FACE, FACET_EDGE, FACET_VERTEX };

typedef struct facet_hit {
    double dist;     /* m, from the closest point to the centre (>= 0) */
    double n[3];     /* unit normal from the facet to the centre */
    double q[3];     /* the closest point */
    int kind;        /* FACET_FACE, FACET_EDGE or FACET_VERTEX */
    int32_t v0, v1;  /* the feature's vertices: an edge's, lower first; a vertex twice */
} facet_hit;

/* The point of facet t closest to x, by the triangle's Voronoi regions
 * (tested vertex, edge, face in turn). In the face region the distance is
 * the plane's, (x - a).n, as an infinite wall computes it, so a ball on
 * the face of a flat mesh feels what it feels on the plane, to the bit. */
static void facet_closest(const sx_mesh *s, int32_t t, const double *x, facet_hit *h)
{
    const int32_t *tv = s->tri + 3 * (int64_t)t;
    const double *a = s->x + 3 * (int64_t)tv[0], *b = s->x + 3 * (int64_t)tv[1], *c = s->x + 3 * (int64_t)tv[2];
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = x[k] - a[k];
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    int32_t e0 = -1, e1 = -1; /* the feature's two vertex numbers in the facet (0, 1, 2) */
    double s_on = 0;          /* an edge's parameter from e0 to e1 */
    for (int k = 0; k < 3; k++) bp[k] = x[k] - b[k], cp[k] = x[k] - c[k];
    const double d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
    const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d1 <= 0 && d2 <= 0) {
        e0 = e1 = 0;
    } else if (d3 >= 0 && d4 <= d3) {
        e0 = e1 = 1;
    } else if (d6 >= 0 && d5 <= d6) {
        e0 = e1 = 2;
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        e0 = 0, e1 = 1, s_on = d1 / (d1 - d3);
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        e0 = 0, e1 = 2, s_on = d2 / (d2 - d6);
    } else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        e0 = 1, e1 = 2, s_on = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    }
    if (e0 < 0) { /* the face: the plane's distance, on the side the centre is */
        const double *nf = s->nrm + 3 * (int64_t)t;
        const double sd = dot(ap, nf), sg = sd < 0 ? -1.0 : 1.0;
        h->kind = FACET_FACE;
        h->dist = sg * sd;
        for (int k = 0; k < 3; k++) h->n[k] = sg * nf[k], h->q[k] = x[k] - sd * nf[k];
        h->v0 = h->v1 = -1;
        return;
    }
    const double *p0 = s->x + 3 * (int64_t)tv[e0], *p1 = s->x + 3 * (int64_t)tv[e1];
    double r[3];
    for (int k = 0; k < 3; k++) h->q[k] = p0[k] + s_on * (p1[k] - p0[k]), r[k] = x[k] - h->q[k];
    h->kind = e0 == e1 ? FACET_VERTEX : FACET_EDGE;
    h->v0 = tv[e0] < tv[e1] ? tv[e0] : tv[e1];
    h->v1 = tv[e0] < tv[e1] ? tv[e1] : tv[e0];
    h->dist = sqrt(dot(r, r));
    if (h->dist > 0) {
        for (int k = 0; k < 3; k++) h->n[k] = r[k] / h->dist;
    } else { /* the centre on the edge or vertex: along the facet's normal */
        for (int k = 0; k < 3; k++) h->n[k] = s->nrm[3 * (int64_t)t + k];
    }
}

#endif
