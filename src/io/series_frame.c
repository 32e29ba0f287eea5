/* One snapshot of an output series: the balls as points, contacts, bonds
 * and cracks as cells and points, walls and meshes as drawable cells (the
 * layout of docs/file-format.md, "Output series"). */
#include "series_internal.h"
#include "state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------- gathering */

/* Growable arrays of one snapshot's cells. */
typedef struct cells {
    int64_t n, cap, per_i, per_d;
    int32_t *conn;  /* per_i ints per cell */
    double *d;      /* per_d doubles per cell */
} cells;

static double *cells_push(cells *c, const int32_t *conn)
{
    if (c->n == c->cap) {
        const int64_t cap = c->cap ? 2 * c->cap : 1024;
        int32_t *q = realloc(c->conn, (size_t)(cap * c->per_i) * sizeof *q);
        if (!q) return NULL;
        c->conn = q;
        double *r = realloc(c->d, (size_t)(cap * c->per_d) * sizeof *r);
        if (!r) return NULL;
        c->d = r;
        c->cap = cap;
    }
    memcpy(c->conn + c->n * c->per_i, conn, (size_t)c->per_i * sizeof *conn);
    return c->d + c->n++ * c->per_d;
}

/* Per ball-ball contact: fn, shear(3), force(3), overlap, bond, a, b.
 * Per wall contact: points(6), fn, shear(3), force(3), wall.
 * Per bond: kind, fn, shear(3), moment(3), radius. */
enum { BB_D = 11, BW_D = 14, BD_D = 9 };

typedef struct gather {
    const sx_model *m;
    cells bb, bw, bd;
    bool oom;
} gather;

static bool collect(const sx_contact_info *ci, void *ud)
{
    gather *g = ud;
    const sx_model *m = g->m;
    double force[3];
    for (int k = 0; k < 3; k++) force[k] = ci->fn * ci->normal[k] + ci->shear[k];
    if (ci->is_wall) {
        const int64_t i = sx__ball_index(m, ci->a);
        const int32_t conn[2] = {(int32_t)(2 * g->bw.n), (int32_t)(2 * g->bw.n + 1)};
        double *d = cells_push(&g->bw, conn);
        if (!d) return !(g->oom = true);
        for (int k = 0; k < 3; k++) {
            d[k] = k < m->dim ? m->balls.x[i * m->dim + k] : 0;
            d[3 + k] = ci->point[k];
            d[7 + k] = ci->shear[k];
            d[10 + k] = force[k];
        }
        d[6] = ci->fn;
        d[13] = (double)ci->b;
        return true;
    }
    const int32_t conn[2] = {(int32_t)sx__ball_index(m, ci->a), (int32_t)sx__ball_index(m, ci->b)};
    double *d = cells_push(&g->bb, conn);
    if (!d) return !(g->oom = true);
    d[0] = ci->fn;
    for (int k = 0; k < 3; k++) d[1 + k] = ci->shear[k], d[4 + k] = force[k];
    d[7] = ci->overlap;
    d[8] = ci->bond;
    if (ci->bond) {
        double *e = cells_push(&g->bd, conn);
        if (!e) return !(g->oom = true);
        e[0] = ci->bond;
        e[1] = ci->pb_fn;
        for (int k = 0; k < 3; k++) e[2 + k] = ci->pb_fs[k];
        /* 2D: the moment is the scalar about z */
        for (int k = 0; k < 3; k++) e[5 + k] = m->dim == 3 ? ci->pb_moment[k] : (k == 2 ? ci->pb_moment[0] : 0);
        e[8] = ci->pb_radius;
    }
    return true;
}

/* Column k (of `per`) of the cells' doubles, `width` consecutive columns. */
static double *column(const cells *c, int k, int width)
{
    double *out = malloc((size_t)(c->n > 0 ? c->n : 1) * (size_t)width * sizeof *out);
    if (!out) return NULL;
    for (int64_t i = 0; i < c->n; i++)
        for (int j = 0; j < width; j++) out[i * width + j] = c->d[i * c->per_d + k + j];
    return out;
}

static void write_col(sx_h5 *h, hid_t g, const char *name, const cells *c, int k, int width, const char *units,
                      bool as_int)
{
    double *v = column(c, k, width);
    if (!v) {
        sx_h5_fail(h, "out of memory");
        return;
    }
    if (as_int) {
        int64_t *iv = malloc((size_t)(c->n > 0 ? c->n : 1) * (size_t)width * sizeof *iv);
        if (!iv) {
            sx_h5_fail(h, "out of memory");
        } else {
            for (int64_t i = 0; i < c->n * width; i++) iv[i] = (int64_t)v[i];
            sx_h5_write(h, g, name, H5T_NATIVE_INT64, H5T_STD_I64LE, iv, c->n, width, units);
        }
        free(iv);
    } else {
        sx_h5_write(h, g, name, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, v, c->n, width, units);
    }
    free(v);
}

/* A 3-component copy of a dim- (or rdim-) component per-ball array; a 2D
 * rotational scalar goes to z. */
static double *widen(const sx_model *m, const double *src, int per, bool rot)
{
    const int64_t n = m->balls.n;
    double *out = calloc((size_t)(n > 0 ? n : 1) * 3, sizeof *out);
    if (!out) return NULL;
    for (int64_t i = 0; i < n; i++) {
        if (rot && per == 1) out[i * 3 + 2] = src[i];
        else
            for (int k = 0; k < per; k++) out[i * 3 + k] = src[i * per + k];
    }
    return out;
}

static void write_vec(sx_h5 *h, hid_t g, const char *name, const sx_model *m, const double *src, int per, bool rot,
                      const char *units)
{
    double *v = widen(m, src, per, rot);
    if (!v) {
        sx_h5_fail(h, "out of memory");
        return;
    }
    sx_h5_write(h, g, name, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, v, m->balls.n, 3, units);
    free(v);
}

static void write_balls(sx_h5 *h, hid_t snapg, const sx_model *m, unsigned f)
{
    const sx_balls *b = &m->balls;
    const int64_t n = b->n;
    hid_t g = sx_h5_group(h, snapg, "balls");
    write_vec(h, g, "position", m, b->x, m->dim, false, "m");
    int32_t *vert = malloc((size_t)(n > 0 ? n : 1) * sizeof *vert);
    if (!vert) {
        sx_h5_fail(h, "out of memory");
    } else {
        for (int64_t i = 0; i < n; i++) vert[i] = (int32_t)i;
        sx_h5_write(h, g, "vertices", H5T_NATIVE_INT32, H5T_STD_I32LE, vert, n, 1, NULL);
        free(vert);
    }
    if (f & SX_OUT_VELOCITY) write_vec(h, g, "velocity", m, b->v, m->dim, false, "m/s");
    if (f & SX_OUT_SPIN) write_vec(h, g, "spin", m, b->w, m->rdim, true, "rad/s");
    if (f & SX_OUT_FORCE) write_vec(h, g, "force", m, b->f, m->dim, false, "N");
    if (f & SX_OUT_MOMENT) write_vec(h, g, "moment", m, b->t, m->rdim, true, "N m");
    if (f & SX_OUT_RADIUS) sx_h5_write(h, g, "radius", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, b->rad, n, 1, "m");
    if (f & SX_OUT_GROUP) { /* a store without groups: every ball in none (0) */
        int32_t *none = b->group ? NULL : calloc((size_t)(n > 0 ? n : 1), sizeof *none);
        if (!b->group && !none) sx_h5_fail(h, "out of memory");
        else sx_h5_write(h, g, "group", H5T_NATIVE_INT32, H5T_STD_I32LE, b->group ? b->group : none, n, 1, NULL);
        free(none);
    }
    if (f & (SX_OUT_ID | SX_OUT_MATERIAL | SX_OUT_MASS)) {
        int64_t *iv = malloc((size_t)(n > 0 ? n : 1) * sizeof *iv);
        double *dv = malloc((size_t)(n > 0 ? n : 1) * sizeof *dv);
        if (!iv || !dv) {
            sx_h5_fail(h, "out of memory");
        } else {
            if (f & SX_OUT_ID) {
                for (int64_t i = 0; i < n; i++) iv[i] = b->id[i];
                sx_h5_write(h, g, "id", H5T_NATIVE_INT64, H5T_STD_I64LE, iv, n, 1, NULL);
                if (b->clump) { /* clumps: each ball's clump id, 0 for a free ball, with the ids */
                    for (int64_t i = 0; i < n; i++) iv[i] = b->clump[i];
                    sx_h5_write(h, g, "clump", H5T_NATIVE_INT64, H5T_STD_I64LE, iv, n, 1, NULL);
                }
            }
            if (f & SX_OUT_MATERIAL) {
                int32_t *mv = (int32_t *)iv;
                for (int64_t i = 0; i < n; i++) mv[i] = b->mat[i];
                sx_h5_write(h, g, "material", H5T_NATIVE_INT32, H5T_STD_I32LE, mv, n, 1, NULL);
            }
            if (f & SX_OUT_MASS) {
                for (int64_t i = 0; i < n; i++) dv[i] = 1.0 / b->inv_mass[i];
                sx_h5_write(h, g, "mass", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, dv, n, 1, "kg");
            }
        }
        free(iv);
        free(dv);
    }
    sx_h5_close(g);
}

static void write_cells(sx_h5 *h, hid_t g, const cells *c)
{
    sx_h5_write(h, g, "connectivity", H5T_NATIVE_INT32, H5T_STD_I32LE, c->conn, c->n, (int)c->per_i, NULL);
}

/* Unit vectors u, v completing the unit normal n to a right-handed frame. */
static void frame(const double *n, double *u, double *v)
{
    const int a = fabs(n[0]) < fabs(n[1]) ? (fabs(n[0]) < fabs(n[2]) ? 0 : 2) : (fabs(n[1]) < fabs(n[2]) ? 1 : 2);
    double e[3] = {0, 0, 0};
    e[a] = 1;
    u[0] = n[1] * e[2] - n[2] * e[1], u[1] = n[2] * e[0] - n[0] * e[2], u[2] = n[0] * e[1] - n[1] * e[0];
    const double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int k = 0; k < 3; k++) u[k] /= lu;
    v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
}

/* Facets around a cylinder: a 32-gon is within 0.5 % of its radius. */
enum { CYL_SIDES = 32 };

/* Walls drawn as cells: the points, the cells' corners (per each) and what
 * each cell carries (its wall's id, a velocity, the wall's force). */
typedef struct drawn {
    double *pts, *vel, *frc;
    int32_t *conn;
    int64_t *ids;
} drawn;

static bool drawn_alloc(drawn *w, int64_t npts, int64_t ncells, int per)
{
    w->pts = calloc((size_t)(npts * 3 + 1), sizeof *w->pts);
    w->vel = calloc((size_t)(ncells * 3 + 1), sizeof *w->vel);
    w->frc = calloc((size_t)(ncells * 3 + 1), sizeof *w->frc);
    w->conn = calloc((size_t)(ncells * per + 1), sizeof *w->conn);
    w->ids = calloc((size_t)(ncells + 1), sizeof *w->ids);
    return w->pts && w->vel && w->frc && w->conn && w->ids;
}

/* Writes the cells into group `name` of the snapshot (or fails out of
 * memory when ok is false), then frees them. */
static void drawn_write(sx_h5 *h, hid_t snapg, const char *name, drawn *w, bool ok, int64_t npts, int64_t ncells,
                        int per)
{
    if (!ok) {
        sx_h5_fail(h, "out of memory");
    } else {
        hid_t g = sx_h5_group(h, snapg, name);
        sx_h5_write(h, g, "points", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, w->pts, npts, 3, "m");
        sx_h5_write(h, g, "connectivity", H5T_NATIVE_INT32, H5T_STD_I32LE, w->conn, ncells, per, NULL);
        sx_h5_write(h, g, "id", H5T_NATIVE_INT64, H5T_STD_I64LE, w->ids, ncells, 1, NULL);
        sx_h5_write(h, g, "velocity", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, w->vel, ncells, 3, "m/s");
        sx_h5_write(h, g, "force", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, w->frc, ncells, 3, "N");
        sx_h5_close(g);
    }
    free(w->pts);
    free(w->vel);
    free(w->frc);
    free(w->conn);
    free(w->ids);
}

/* Walls as drawable cells: a 3D plane as a square across the balls'
 * bounding box, a rectangle as itself, a cylinder as CYL_SIDES
 * quadrilaterals around its axis (from its first end over its height; an
 * infinite one across the box); a 2D line as a segment across the box, a
 * segment as itself. Every cell carries its wall's id, velocity and force. */
static void write_walls(sx_h5 *h, hid_t snapg, const sx_model *m, snap *sn)
{
    const int64_t nw = m->nwall;
    const int d = m->dim, per = d == 3 ? 4 : 2;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int64_t i = 0; i < m->balls.n; i++)
        for (int k = 0; k < d; k++) {
            const double x = m->balls.x[i * d + k], r = m->balls.rad[i];
            if (i == 0 || x - r < lo[k]) lo[k] = x - r;
            if (i == 0 || x + r > hi[k]) hi[k] = x + r;
        }
    double c[3], diag = 0;
    for (int k = 0; k < 3; k++) c[k] = 0.5 * (lo[k] + hi[k]), diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    const double half = diag > 0 ? 0.6 * sqrt(diag) : 1.0;
    int64_t ncells = 0, npts = 0;
    for (int64_t w = 0; w < nw; w++) {
        if (m->walls[w].mesh) continue; /* in write_meshes */
        const bool cyl = m->walls[w].def.kind == SX_WALL_CYLINDER;
        ncells += cyl ? CYL_SIDES : 1;
        npts += cyl ? 2 * CYL_SIDES : per;
    }
    drawn dw;
    const bool ok = drawn_alloc(&dw, npts, ncells, per);
    double *pts = dw.pts, *vel = dw.vel, *frc = dw.frc;
    int32_t *conn = dw.conn;
    int64_t *ids = dw.ids;
    int64_t cell = 0, pt = 0;
    for (int64_t w = 0; w < nw && ok; w++) {
        const sx_wall *wl = &m->walls[w];
        const sx_wall_def *def = &wl->def;
        double *p = pts + pt * 3;
        const int64_t first = cell;
        if (wl->mesh) continue;
        if (def->kind == SX_WALL_CYLINDER) {
            const double *n = def->normal;
            double u[3], v[3], t0 = 0, t1 = def->height;
            frame(n, u, v);
            if (!(def->height > 0)) { /* infinite: across the box, about the centre's projection */
                double t = 0;
                for (int k = 0; k < 3; k++) t += (c[k] - def->point[k]) * n[k];
                t0 = t - half, t1 = t + half;
            }
            for (int j = 0; j < CYL_SIDES; j++) {
                const double a = 2 * SX_PI * j / CYL_SIDES, ca = cos(a), sa = sin(a);
                for (int k = 0; k < 3; k++) {
                    const double radial = def->radius * (ca * u[k] + sa * v[k]);
                    p[j * 3 + k] = def->point[k] + t0 * n[k] + radial;
                    p[(CYL_SIDES + j) * 3 + k] = def->point[k] + t1 * n[k] + radial;
                }
                const int32_t j1 = (int32_t)((j + 1) % CYL_SIDES), b = (int32_t)pt;
                int32_t *q = conn + (cell + j) * per;
                q[0] = b + j, q[1] = b + j1, q[2] = b + CYL_SIDES + j1, q[3] = b + CYL_SIDES + j;
            }
            cell += CYL_SIDES, pt += 2 * CYL_SIDES;
        } else {
            if (def->kind == SX_WALL_RECT || def->kind == SX_WALL_SEGMENT) {
                for (int k = 0; k < 3; k++) {
                    p[k] = def->point[k];
                    p[3 + k] = def->point[k] + def->edge1[k];
                    if (per == 4) {
                        p[6 + k] = def->point[k] + def->edge1[k] + def->edge2[k];
                        p[9 + k] = def->point[k] + def->edge2[k];
                    }
                }
            } else {
                /* the projection of the box's centre on the wall, and in-plane axes */
                const double *n = def->normal;
                double t = 0;
                for (int k = 0; k < d; k++) t += (c[k] - def->point[k]) * n[k];
                double o[3];
                for (int k = 0; k < 3; k++) o[k] = c[k] - t * (k < d ? n[k] : 0);
                if (d == 2) {
                    const double u[2] = {-n[1], n[0]};
                    for (int k = 0; k < 2; k++) p[k] = o[k] - half * u[k], p[3 + k] = o[k] + half * u[k];
                } else {
                    double u[3], v[3];
                    frame(n, u, v);
                    const double sg[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
                    for (int q = 0; q < 4; q++)
                        for (int k = 0; k < 3; k++) p[q * 3 + k] = o[k] + half * (sg[q][0] * u[k] + sg[q][1] * v[k]);
                }
            }
            for (int q = 0; q < per; q++) conn[cell * per + q] = (int32_t)(pt + q);
            cell++, pt += per;
        }
        for (int64_t e = first; e < cell; e++) {
            for (int k = 0; k < d; k++) vel[e * 3 + k] = def->vel[k], frc[e * 3 + k] = wl->force[k];
            ids[e] = wl->id;
        }
    }
    sn->wall_cells = ncells;
    sn->wall_points = npts;
    drawn_write(h, snapg, "walls", &dw, ok, npts, ncells, per);
}

/* Mesh walls as their triangles, where they are; each cell carries its
 * wall's id and force and the surface velocity at the facet's centroid
 * (the translation and the spin about the mesh's point). */
static void write_meshes(sx_h5 *h, hid_t snapg, const sx_model *m, snap *sn)
{
    int64_t ncells = 0, npts = 0;
    for (int64_t w = 0; w < m->nwall; w++)
        if (m->walls[w].mesh) ncells += m->walls[w].mesh->nt, npts += m->walls[w].mesh->nv;
    sn->mesh_cells = ncells, sn->mesh_points = npts;
    if (!ncells) return;
    drawn dw;
    const bool ok = drawn_alloc(&dw, npts, ncells, 3);
    double *pts = dw.pts, *vel = dw.vel, *frc = dw.frc;
    int32_t *conn = dw.conn;
    int64_t *ids = dw.ids;
    int64_t cell = 0, pt = 0;
    for (int64_t w = 0; w < m->nwall && ok; w++) {
        const sx_wall *wl = &m->walls[w];
        const sx_mesh *s = wl->mesh;
        if (!s) continue;
        memcpy(pts + 3 * pt, s->x, (size_t)s->nv * 3 * sizeof *pts);
        for (int64_t t = 0; t < s->nt; t++, cell++) {
            double r[3];
            for (int k = 0; k < 3; k++) {
                conn[3 * cell + k] = (int32_t)(pt + s->tri[3 * t + k]);
                r[k] = (s->x[3 * s->tri[3 * t] + k] + s->x[3 * s->tri[3 * t + 1] + k] + s->x[3 * s->tri[3 * t + 2] + k]) / 3 -
                       wl->def.point[k];
            }
            const double *o = wl->def.spin;
            const double turn[3] = {o[1] * r[2] - o[2] * r[1], o[2] * r[0] - o[0] * r[2], o[0] * r[1] - o[1] * r[0]};
            for (int k = 0; k < 3; k++) vel[3 * cell + k] = wl->def.vel[k] + turn[k], frc[3 * cell + k] = wl->force[k];
            ids[cell] = wl->id;
        }
        pt += s->nv;
    }
    drawn_write(h, snapg, "meshes", &dw, ok, npts, ncells, 3);
}

/* The crack log so far as points (the bonds' field brings it): position,
 * mode (1 tension, 2 shear), kind (of bond), time and step of each break. */
enum { CR_D = 7 };

static void write_cracks(sx_h5 *h, hid_t snapg, const sx_model *m, snap *s)
{
    cells c = {.per_i = 1, .per_d = CR_D};
    for (int64_t i = 0; i < m->cracks.n; i++) {
        const sx_crack *e = &m->cracks.ev[i];
        const int32_t conn[1] = {(int32_t)i};
        double *d = cells_push(&c, conn);
        if (!d) {
            sx_h5_fail(h, "out of memory");
            break;
        }
        for (int k = 0; k < 3; k++) d[k] = k < m->dim ? e->pos[k] : 0;
        d[3] = e->mode, d[4] = e->kind, d[5] = e->time, d[6] = (double)e->step;
    }
    if (!h->failed) {
        s->cracks = c.n;
        hid_t g = sx_h5_group(h, snapg, "cracks");
        write_cells(h, g, &c);
        write_col(h, g, "position", &c, 0, 3, "m", false);
        write_col(h, g, "mode", &c, 3, 1, NULL, true);
        write_col(h, g, "kind", &c, 4, 1, NULL, true);
        write_col(h, g, "time", &c, 5, 1, "s", false);
        write_col(h, g, "step", &c, 6, 1, NULL, true);
        sx_h5_close(g);
    }
    free(c.conn);
    free(c.d);
}

void sx_io_frame_write(sx_h5 *h, hid_t snapg, const sx_model *m, unsigned f, snap *s)
{
    memset(s, 0, sizeof *s);
    s->time = m->time;
    s->step = m->step;
    s->balls = m->balls.n;
    s->fields = f;
    s->dim = m->dim;
    s->clumps = (f & SX_OUT_ID) && m->balls.clump;
    write_balls(h, snapg, m, f);
    if (f & (SX_OUT_CONTACTS | SX_OUT_BONDS)) {
        gather g = {.m = m};
        g.bb.per_i = g.bw.per_i = g.bd.per_i = 2;
        g.bb.per_d = BB_D, g.bw.per_d = BW_D, g.bd.per_d = BD_D;
        sx_contact_each(m, collect, &g);
        if (g.oom) {
            sx_h5_fail(h, "out of memory");
        } else {
            if (f & SX_OUT_CONTACTS) {
                s->contacts = g.bb.n;
                s->wall_contacts = g.bw.n;
                hid_t c = sx_h5_group(h, snapg, "contacts");
                write_cells(h, c, &g.bb);
                write_col(h, c, "normal_force", &g.bb, 0, 1, "N", false);
                write_col(h, c, "shear_force", &g.bb, 1, 3, "N", false);
                write_col(h, c, "force", &g.bb, 4, 3, "N", false);
                write_col(h, c, "overlap", &g.bb, 7, 1, "m", false);
                write_col(h, c, "bond", &g.bb, 8, 1, NULL, true);
                sx_h5_close(c);
                c = sx_h5_group(h, snapg, "wall_contacts");
                write_cells(h, c, &g.bw);
                double *pts = column(&g.bw, 0, 6); /* two points per contact */
                if (!pts) sx_h5_fail(h, "out of memory");
                else sx_h5_write(h, c, "points", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, pts, 2 * g.bw.n, 3, "m");
                free(pts);
                write_col(h, c, "normal_force", &g.bw, 6, 1, "N", false);
                write_col(h, c, "shear_force", &g.bw, 7, 3, "N", false);
                write_col(h, c, "force", &g.bw, 10, 3, "N", false);
                write_col(h, c, "wall", &g.bw, 13, 1, NULL, true);
                sx_h5_close(c);
            }
            if (f & SX_OUT_BONDS) {
                s->bonds = g.bd.n;
                hid_t c = sx_h5_group(h, snapg, "bonds");
                write_cells(h, c, &g.bd);
                write_col(h, c, "kind", &g.bd, 0, 1, NULL, true);
                write_col(h, c, "normal_force", &g.bd, 1, 1, "N", false);
                write_col(h, c, "shear_force", &g.bd, 2, 3, "N", false);
                write_col(h, c, "moment", &g.bd, 5, 3, "N m", false);
                write_col(h, c, "radius", &g.bd, 8, 1, "m", false);
                sx_h5_close(c);
            }
        }
        free(g.bb.conn), free(g.bb.d), free(g.bw.conn), free(g.bw.d), free(g.bd.conn), free(g.bd.d);
    }
    if ((f & SX_OUT_BONDS) && m->cracks.n > 0) write_cracks(h, snapg, m, s);
    if (f & SX_OUT_WALLS) {
        s->walls = m->nwall;
        write_walls(h, snapg, m, s);
        write_meshes(h, snapg, m, s);
    }
    sx_h5_attr_double(h, snapg, "time", s->time);
    sx_h5_attr_int(h, snapg, "step", s->step);
    sx_h5_attr_double(h, snapg, "timestep", m->dt);
    sx_h5_attr_int(h, snapg, "balls", s->balls);
    sx_h5_attr_int(h, snapg, "contacts", s->contacts);
    sx_h5_attr_int(h, snapg, "wall_contacts", s->wall_contacts);
    sx_h5_attr_int(h, snapg, "bonds", s->bonds);
    sx_h5_attr_int(h, snapg, "walls", s->walls);
    sx_h5_attr_int(h, snapg, "cracks", s->cracks);
    sx_h5_attr_int(h, snapg, "wall_cells", s->wall_cells);
    sx_h5_attr_int(h, snapg, "wall_points", s->wall_points);
    if (s->mesh_cells) {
        sx_h5_attr_int(h, snapg, "mesh_cells", s->mesh_cells);
        sx_h5_attr_int(h, snapg, "mesh_points", s->mesh_points);
    }
    sx_h5_attr_int(h, snapg, "fields", (int64_t)s->fields);
    if (s->clumps) sx_h5_attr_int(h, snapg, "clumps", 1);
}
