/* Output series: snapshots for viewing, appended to one HDF5 file, with
 * an XDMF file beside it that ParaView (or VisIt) opens as a time series.
 *
 * Each snapshot is a group /snapshots/NNNNNN holding the balls as points
 * (always 3 components per vector, z = 0 in 2D, so viewers need no
 * special case), ball-ball contacts and bonds as line cells between ball
 * centres (connectivity into the balls' points), ball-wall contacts as
 * lines from the centre to the contact point, and walls as quadrilaterals
 * (3D) or segments (2D); an infinite wall is drawn across the balls'
 * bounding box; the crack log so far (with the bonds) as points, so a
 * viewer draws the crack map of each snapshot. Every block is named in the
 * XDMF (balls, contacts, wall_contacts, bonds, cracks, walls).
 *
 * Histories grow beside the snapshots: /histories/<name> holds extendable
 * datasets (history.c) to which each write appends the samples of steps
 * after the last one the file holds.
 *
 * Nothing is lost on a crash: the file is created under a temporary name
 * and renamed; each snapshot and the history rows are written, flushed and
 * synced before the `count`s of complete snapshots and rows are raised
 * (readers ignore what lies beyond them). The XDMF is never patched in
 * place: the new one (kept in memory, so no snapshot is read back) is
 * written and synced under a temporary name before the counts are raised,
 * and renamed over the old one right after, so it is always a complete
 * document and lists the snapshots the counts say are complete; only a
 * kill in the microseconds between the counts' write and the rename leaves
 * it one snapshot behind (seixo.xdmf and append mode rebuild it). The 1.8
 * file format keeps a file whose writer was killed openable. */
#include "io_internal.h"
#include "state.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct buf {
    char *p;
    size_t n, cap;
    bool oom;
} buf;

/* The XDMF's blocks: one temporal collection each, so that a reader shows
 * each block under its own name at every time (ParaView's XDMF Reader
 * suffixes "[k]" to a name that repeats, as the grids of one spatial
 * collection per snapshot did). */
enum { K_BALLS, K_CONTACTS, K_WALL_CONTACTS, K_BONDS, K_CRACKS, K_WALLS, K_MESHES, NKINDS };
static const char *const kind_names[NKINDS] = {"balls", "contacts", "wall_contacts", "bonds", "cracks", "walls", "meshes"};

/* The XDMF in memory: each block's grids so far, and the whole text. */
typedef struct xdoc {
    buf kind[NKINDS];
    buf out;
} xdoc;

/* A history the file holds: its complete rows and their last step. */
typedef struct held {
    char *name;
    int64_t rows, last;
} held;

struct sx_series {
    char *path;       /* the .h5 */
    char *xmf;        /* the .xmf beside it */
    char *base;       /* the .h5's name as the .xmf refers to it */
    hid_t file;
    int dim;
    unsigned fields;
    int compression;
    int64_t count;    /* complete snapshots */
    xdoc x;           /* the XDMF: a grid per block and complete snapshot */
    held *held;       /* histories met so far */
    int nheld, capheld;
};

static const struct {
    unsigned bit;
    const char *name;
} field_names[] = {
    {SX_OUT_ID, "id"},           {SX_OUT_RADIUS, "radius"},     {SX_OUT_VELOCITY, "velocity"},
    {SX_OUT_SPIN, "spin"},       {SX_OUT_FORCE, "force"},       {SX_OUT_MOMENT, "moment"},
    {SX_OUT_GROUP, "group"},     {SX_OUT_MATERIAL, "material"}, {SX_OUT_MASS, "mass"},
    {SX_OUT_CONTACTS, "contacts"}, {SX_OUT_BONDS, "bonds"},     {SX_OUT_WALLS, "walls"},
};
enum { NFIELDS = sizeof field_names / sizeof *field_names };

const char *sx_series_field_name(unsigned bit)
{
    for (int k = 0; k < NFIELDS; k++)
        if (field_names[k].bit == bit) return field_names[k].name;
    return NULL;
}

unsigned sx_series_field_bit(const char *name)
{
    for (int k = 0; k < NFIELDS; k++)
        if (strcmp(field_names[k].name, name) == 0) return field_names[k].bit;
    return 0;
}

int64_t sx_series_count(const sx_series *s) { return s->count; }
const char *sx_series_path(const sx_series *s) { return s->path; }

/* ------------------------------------------------------------ buffers */

static void put(buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(buf *b, const char *fmt, ...)
{
    if (b->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        const int k = vsnprintf(b->p ? b->p + b->n : NULL, b->p ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0) {
            b->oom = true;
            return;
        }
        if (b->p && b->n + (size_t)k < b->cap) {
            b->n += (size_t)k;
            return;
        }
        size_t cap = b->cap ? 2 * b->cap : 4096;
        while (cap < b->n + (size_t)k + 1) cap *= 2;
        char *q = realloc(b->p, cap);
        if (!q) {
            b->oom = true;
            return;
        }
        b->p = q;
        b->cap = cap;
    }
}

/* ---------------------------------------------------------------- XDMF */

/* What the XDMF needs to know of a snapshot (stored as its attributes). */
typedef struct snap {
    double time;
    int64_t step, balls, contacts, wall_contacts, bonds, walls, cracks;
    int64_t wall_cells, wall_points; /* a cylinder is drawn with many cells */
    int64_t mesh_cells, mesh_points; /* mesh walls' triangles, a grid of their own */
    unsigned fields;
    int dim;
    bool clumps; /* the balls carry their clump ids (pebbles of a clump, 0 for free balls) */
} snap;

/* The whole document: the blocks that have grids, each a temporal collection. */
static bool xmf_compose(xdoc *d)
{
    buf *b = &d->out;
    b->n = 0;
    put(b, "<?xml version=\"1.0\" ?>\n"
           "<!-- seixo output series: the snapshots of the .h5 beside this file, for ParaView (its XDMF Reader) or "
           "VisIt; one temporal collection per block -->\n"
           "<Xdmf Version=\"2.0\">\n <Domain>\n");
    for (int k = 0; k < NKINDS; k++) {
        if (d->kind[k].oom) b->oom = true;
        if (!d->kind[k].n) continue;
        put(b, "  <Grid Name=\"%s\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", kind_names[k]);
        put(b, "%.*s", (int)d->kind[k].n, d->kind[k].p);
        put(b, "  </Grid>\n");
    }
    put(b, " </Domain>\n</Xdmf>\n");
    return !b->oom;
}

static void xdoc_free(xdoc *d)
{
    for (int k = 0; k < NKINDS; k++) free(d->kind[k].p);
    free(d->out.p);
}

static void xml_escaped(buf *b, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': put(b, "&amp;"); break;
        case '<': put(b, "&lt;"); break;
        case '>': put(b, "&gt;"); break;
        case '"': put(b, "&quot;"); break;
        default: put(b, "%c", *s);
        }
    }
}

/* A DataItem naming a dataset of snapshot k. */
static void item(buf *b, const char *base, int64_t k, const char *ds, int64_t rows, int cols, const char *type,
                 int precision)
{
    if (cols > 1)
        put(b, "<DataItem Dimensions=\"%lld %d\" ", (long long)rows, cols);
    else
        put(b, "<DataItem Dimensions=\"%lld\" ", (long long)rows);
    put(b, "NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">", type, precision);
    xml_escaped(b, base);
    put(b, ":/snapshots/%06lld/%s</DataItem>", (long long)k, ds);
}

static void attribute(buf *b, const char *base, int64_t k, const char *name, const char *ds, int64_t rows, int cols,
                      const char *type, int precision, bool cell)
{
    put(b, "     <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"%s\">", name, cols == 3 ? "Vector" : "Scalar",
        cell ? "Cell" : "Node");
    item(b, base, k, ds, rows, cols, type, precision);
    put(b, "</Attribute>\n");
}

static void geometry(buf *b, const char *base, int64_t k, const char *ds, int64_t rows)
{
    put(b, "     <Geometry GeometryType=\"XYZ\">");
    item(b, base, k, ds, rows, 3, "Float", 8);
    put(b, "</Geometry>\n");
}

static void lines(buf *b, const char *base, int64_t k, const char *ds, int64_t cells, int nodes, const char *topo)
{
    put(b, "     <Topology TopologyType=\"%s\" NumberOfElements=\"%lld\"", topo, (long long)cells);
    if (strcmp(topo, "Quadrilateral") != 0 && strcmp(topo, "Triangle") != 0) put(b, " NodesPerElement=\"%d\"", nodes);
    put(b, ">");
    item(b, base, k, ds, cells, nodes, "Int", 4);
    put(b, "</Topology>\n");
}

/* A block's grid of one snapshot, opened: its step and time. */
static buf *grid_open(xdoc *d, int kind, const snap *s)
{
    buf *b = &d->kind[kind];
    put(b, "   <Grid Name=\"step %lld\" GridType=\"Uniform\">\n", (long long)s->step);
    put(b, "    <Time Value=\"%.17g\"/>\n", s->time);
    return b;
}

static void xmf_step(xdoc *d, const char *base, int64_t k, const snap *s)
{
    const unsigned f = s->fields;
    /* balls: points with their fields */
    buf *b = grid_open(d, K_BALLS, s);
    /* explicit vertices: the Xdmf3 readers make no cells of an implicit Polyvertex */
    lines(b, base, k, "balls/vertices", s->balls, 1, "Polyvertex");
    geometry(b, base, k, "balls/position", s->balls);
    if (f & SX_OUT_ID) attribute(b, base, k, "id", "balls/id", s->balls, 1, "Int", 8, false);
    if (f & SX_OUT_RADIUS) attribute(b, base, k, "radius", "balls/radius", s->balls, 1, "Float", 8, false);
    if (f & SX_OUT_VELOCITY) attribute(b, base, k, "velocity", "balls/velocity", s->balls, 3, "Float", 8, false);
    if (f & SX_OUT_SPIN) attribute(b, base, k, "spin", "balls/spin", s->balls, 3, "Float", 8, false);
    if (f & SX_OUT_FORCE) attribute(b, base, k, "force", "balls/force", s->balls, 3, "Float", 8, false);
    if (f & SX_OUT_MOMENT) attribute(b, base, k, "moment", "balls/moment", s->balls, 3, "Float", 8, false);
    if (f & SX_OUT_GROUP) attribute(b, base, k, "group", "balls/group", s->balls, 1, "Int", 4, false);
    if (f & SX_OUT_MATERIAL) attribute(b, base, k, "material", "balls/material", s->balls, 1, "Int", 4, false);
    if (f & SX_OUT_MASS) attribute(b, base, k, "mass", "balls/mass", s->balls, 1, "Float", 8, false);
    if (s->clumps) attribute(b, base, k, "clump", "balls/clump", s->balls, 1, "Int", 8, false);
    put(b, "   </Grid>\n");
    if ((f & SX_OUT_CONTACTS) && s->contacts > 0) {
        b = grid_open(d, K_CONTACTS, s);
        lines(b, base, k, "contacts/connectivity", s->contacts, 2, "Polyline");
        geometry(b, base, k, "balls/position", s->balls);
        attribute(b, base, k, "normal_force", "contacts/normal_force", s->contacts, 1, "Float", 8, true);
        attribute(b, base, k, "shear_force", "contacts/shear_force", s->contacts, 3, "Float", 8, true);
        attribute(b, base, k, "force", "contacts/force", s->contacts, 3, "Float", 8, true);
        attribute(b, base, k, "overlap", "contacts/overlap", s->contacts, 1, "Float", 8, true);
        attribute(b, base, k, "bond", "contacts/bond", s->contacts, 1, "Int", 8, true);
        put(b, "   </Grid>\n");
    }
    if ((f & SX_OUT_CONTACTS) && s->wall_contacts > 0) {
        b = grid_open(d, K_WALL_CONTACTS, s);
        lines(b, base, k, "wall_contacts/connectivity", s->wall_contacts, 2, "Polyline");
        geometry(b, base, k, "wall_contacts/points", 2 * s->wall_contacts);
        attribute(b, base, k, "normal_force", "wall_contacts/normal_force", s->wall_contacts, 1, "Float", 8, true);
        attribute(b, base, k, "shear_force", "wall_contacts/shear_force", s->wall_contacts, 3, "Float", 8, true);
        attribute(b, base, k, "force", "wall_contacts/force", s->wall_contacts, 3, "Float", 8, true);
        attribute(b, base, k, "wall", "wall_contacts/wall", s->wall_contacts, 1, "Int", 8, true);
        put(b, "   </Grid>\n");
    }
    if ((f & SX_OUT_BONDS) && s->bonds > 0) {
        b = grid_open(d, K_BONDS, s);
        lines(b, base, k, "bonds/connectivity", s->bonds, 2, "Polyline");
        geometry(b, base, k, "balls/position", s->balls);
        attribute(b, base, k, "kind", "bonds/kind", s->bonds, 1, "Int", 8, true);
        attribute(b, base, k, "normal_force", "bonds/normal_force", s->bonds, 1, "Float", 8, true);
        attribute(b, base, k, "shear_force", "bonds/shear_force", s->bonds, 3, "Float", 8, true);
        attribute(b, base, k, "moment", "bonds/moment", s->bonds, 3, "Float", 8, true);
        attribute(b, base, k, "radius", "bonds/radius", s->bonds, 1, "Float", 8, true);
        put(b, "   </Grid>\n");
    }
    if ((f & SX_OUT_BONDS) && s->cracks > 0) {  // the crack map: every bond broken so far, a point each
        b = grid_open(d, K_CRACKS, s);
        lines(b, base, k, "cracks/connectivity", s->cracks, 1, "Polyvertex");
        geometry(b, base, k, "cracks/position", s->cracks);
        attribute(b, base, k, "mode", "cracks/mode", s->cracks, 1, "Int", 8, false);
        attribute(b, base, k, "kind", "cracks/kind", s->cracks, 1, "Int", 8, false);
        attribute(b, base, k, "time", "cracks/time", s->cracks, 1, "Float", 8, false);
        attribute(b, base, k, "step", "cracks/step", s->cracks, 1, "Int", 8, false);
        put(b, "   </Grid>\n");
    }
    if ((f & SX_OUT_WALLS) && s->wall_cells > 0) {
        const bool quad = s->dim == 3; /* 3D: quadrilaterals */
        const int64_t c = s->wall_cells;
        b = grid_open(d, K_WALLS, s);
        lines(b, base, k, "walls/connectivity", c, quad ? 4 : 2, quad ? "Quadrilateral" : "Polyline");
        geometry(b, base, k, "walls/points", s->wall_points);
        attribute(b, base, k, "id", "walls/id", c, 1, "Int", 8, true);
        attribute(b, base, k, "velocity", "walls/velocity", c, 3, "Float", 8, true);
        attribute(b, base, k, "force", "walls/force", c, 3, "Float", 8, true);
        put(b, "   </Grid>\n");
    }
    if ((f & SX_OUT_WALLS) && s->mesh_cells > 0) {
        const int64_t c = s->mesh_cells;
        b = grid_open(d, K_MESHES, s);
        lines(b, base, k, "meshes/connectivity", c, 3, "Triangle");
        geometry(b, base, k, "meshes/points", s->mesh_points);
        attribute(b, base, k, "id", "meshes/id", c, 1, "Int", 8, true);
        attribute(b, base, k, "velocity", "meshes/velocity", c, 3, "Float", 8, true);
        attribute(b, base, k, "force", "meshes/force", c, 3, "Float", 8, true);
        put(b, "   </Grid>\n");
    }
}

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

static void write_snapshot(sx_h5 *h, hid_t snapg, const sx_model *m, unsigned f, snap *s)
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

/* -------------------------------------------------------- the series */

/* path with its .h5 / .hdf5 / .hdf extension replaced by .xmf (or .xmf appended). */
static char *xmf_path_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    size_t keep = strlen(path);
    if (dot && (!slash || dot > slash) &&
        (strcmp(dot, ".h5") == 0 || strcmp(dot, ".hdf5") == 0 || strcmp(dot, ".hdf") == 0))
        keep = (size_t)(dot - path);
    char *out = malloc(keep + 5);
    if (out) {
        memcpy(out, path, keep);
        memcpy(out + keep, ".xmf", 5);
    }
    return out;
}

static char *dup_str(const char *s)
{
    const size_t n = strlen(s) + 1;
    char *p = malloc(n);
    if (p) memcpy(p, s, n);
    return p;
}

static bool read_snap(sx_h5 *h, hid_t file, int dim, int64_t k, snap *s)
{
    char name[48];
    snprintf(name, sizeof name, "/snapshots/%06lld", (long long)k);
    hid_t g = sx_h5_open_group(h, file, name, true);
    if (g < 0) return false;
    int64_t f = 0;
    memset(s, 0, sizeof *s);
    s->dim = dim;
    sx_h5_get_f64(h, g, name, "time", &s->time, 1, true);
    sx_h5_get_i64(h, g, name, "step", &s->step, 1, true);
    sx_h5_get_i64(h, g, name, "balls", &s->balls, 1, true);
    sx_h5_get_i64(h, g, name, "contacts", &s->contacts, 1, true);
    sx_h5_get_i64(h, g, name, "wall_contacts", &s->wall_contacts, 1, true);
    sx_h5_get_i64(h, g, name, "bonds", &s->bonds, 1, true);
    sx_h5_get_i64(h, g, name, "walls", &s->walls, 1, true);
    sx_h5_get_i64(h, g, name, "fields", &f, 1, true);
    s->fields = (unsigned)f;
    int64_t clumps = 0;
    sx_h5_get_i64(h, g, name, "clumps", &clumps, 1, false); /* absent before clumps, and without them */
    s->clumps = clumps != 0;
    /* a damaged count (INT64_MIN) overflowed the points below and went into the XDMF text */
    if (!h->failed && (s->walls < 0 || s->walls >= ((int64_t)1 << 40))) {
        sx_h5_close(g);
        return sx_h5_fail(h, "damaged: %s has %lld walls", name, (long long)s->walls);
    }
    /* format 1 drew one cell per wall, of 4 (3D) or 2 (2D) points */
    s->wall_cells = s->walls;
    s->wall_points = s->walls * (dim == 3 ? 4 : 2);
    sx_h5_get_i64(h, g, name, "wall_cells", &s->wall_cells, 1, false);
    sx_h5_get_i64(h, g, name, "wall_points", &s->wall_points, 1, false);
    sx_h5_get_i64(h, g, name, "cracks", &s->cracks, 1, false); /* absent before crack maps */
    sx_h5_get_i64(h, g, name, "mesh_cells", &s->mesh_cells, 1, false); /* absent without meshes */
    sx_h5_get_i64(h, g, name, "mesh_points", &s->mesh_points, 1, false);
    sx_h5_close(g);
    const int64_t counts[] = {s->balls, s->contacts, s->wall_contacts, s->bonds, s->wall_cells, s->wall_points,
                              s->cracks, s->mesh_cells, s->mesh_points};
    for (size_t i = 0; i < sizeof counts / sizeof *counts && !h->failed; i++)
        if (counts[i] < 0 || counts[i] >= ((int64_t)1 << 40))
            return sx_h5_fail(h, "damaged: %s has a step or count out of range (%lld)", name, (long long)counts[i]);
    return !h->failed;
}

/* Writes a whole file under a temporary name and renames it over path. */
static bool write_whole(sx_h5 *h, const char *path, const char *data, size_t n)
{
    char tmp[4096];
    if (!sx_h5_write_temp(h, path, data, n, tmp, sizeof tmp)) return false;
    if (!sx_h5_rename(h, tmp, path)) {
        remove(tmp);
        return false;
    }
    return true;
}

/* The XDMF of the first `count` snapshots of file, without its closing tags. */
static bool xmf_body(sx_h5 *h, xdoc *d, const char *base, hid_t file, int dim, int64_t count)
{
    for (int k = 0; k < NKINDS; k++) d->kind[k].n = 0;
    for (int64_t k = 0; k < count && !h->failed; k++) {
        snap s;
        if (read_snap(h, file, dim, k, &s)) xmf_step(d, base, k, &s);
    }
    return !h->failed;
}

/* The whole document, written whole (temporary name, rename). */
static bool xmf_write(sx_h5 *h, const char *xmf, xdoc *d)
{
    return xmf_compose(d) ? write_whole(h, xmf, d->out.p, d->out.n) : sx_h5_fail(h, "out of memory");
}

/* The file's descriptor (sec2 driver), or -1. */
static int file_fd(hid_t file)
{
    void *handle = NULL;
    return H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) >= 0 && handle ? *(int *)handle : -1;
}

/* H5Fflush writes a superblock recording the end of the space allocated so
 * far, while some of that space (metadata the same flush writes later, the
 * unused end of an aggregator block) is not yet on disk: a writer killed
 * during the flush would leave a file shorter than its superblock says,
 * which HDF5 refuses to open ("truncated file"). The file is first grown to
 * that end, so it is never shorter than any superblock a flush writes (the
 * flush trims it back to what is allocated when it completes). */
static bool flush_file(hid_t file)
{
    const int fd = file_fd(file);
    hsize_t size = 0;
    struct stat st;
    if (fd >= 0 && H5Fget_filesize(file, &size) >= 0 && fstat(fd, &st) == 0 && (hsize_t)st.st_size < size &&
        ftruncate(fd, (off_t)size) != 0)
        return false;
    return H5Fflush(file, H5F_SCOPE_LOCAL) >= 0;
}

static bool sync_file(hid_t file)
{
    if (!flush_file(file)) return false;
    const int fd = file_fd(file);
    if (fd >= 0) fsync(fd);
    return true;
}

static void fields_text(unsigned f, char *out, size_t len)
{
    out[0] = 0;
    size_t n = 0;
    for (int k = 0; k < NFIELDS; k++)
        if (f & field_names[k].bit) {
            const int w = snprintf(out + n, len - n, "%s%s", n ? " " : "", field_names[k].name);
            if (w < 0 || (size_t)w >= len - n) break;
            n += (size_t)w;
        }
}

/* A new, empty series file: written under a temporary name, then renamed. */
static bool create_file(sx_h5 *h, const char *path, int dim, const sx_series_opts *o, unsigned fields)
{
    char tmp[4096];
    if (!sx_h5_temp_name(path, tmp, sizeof tmp)) return sx_h5_fail(h, "the path is too long");
    hid_t fapl = sx_h5_fapl(false);
    hid_t fcpl = sx_h5_fcpl();
    hid_t f = fapl >= 0 && fcpl >= 0 ? H5Fcreate(tmp, H5F_ACC_EXCL, fcpl, fapl) : -1;
    if (f < 0) sx_h5_fail_h5(h, "cannot create a file in its folder");
    sx_h5_close(fapl);
    sx_h5_close(fcpl);
    if (f < 0) return false;
    char text[256];
    fields_text(fields, text, sizeof text);
    sx_io_write_provenance(h, f, "series", dim, o ? &o->provenance : NULL);
    sx_h5_attr_str(h, f, "fields", text);
    sx_h5_attr_int(h, f, "count", 0);
    sx_h5_close(sx_h5_group(h, f, "snapshots"));
    if (H5Fclose(f) < 0) sx_h5_fail_h5(h, "cannot complete the file");
    if (!h->failed) sx_h5_commit(h, tmp, path);
    if (h->failed) remove(tmp);
    return !h->failed;
}

sx_series *sx_series_open(const char *path, int dim, const sx_series_opts *o, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, path ? path : "", err, errlen);
    sx_series *s = calloc(1, sizeof *s);
    if (s) s->file = -1;
    const unsigned fields = o && o->fields ? o->fields : SX_OUT_DEFAULT;
    if (!s) {
        sx_h5_fail(&h, "out of memory");
    } else if (!path || !*path) {
        sx_h5_fail(&h, "an empty path");
    } else if (dim != 2 && dim != 3) {
        sx_h5_fail(&h, "dim must be 2 or 3");
    } else if (!(s->path = dup_str(path)) || !(s->xmf = xmf_path_of(path))) {
        sx_h5_fail(&h, "out of memory");
    } else {
        const char *slash = strrchr(path, '/');
        s->base = dup_str(slash ? slash + 1 : path);
        s->dim = dim;
        s->fields = fields;
        s->compression = o && o->compression > 0 ? (o->compression > 9 ? 9 : o->compression) : 0;
        const bool append = o && o->append && access(path, F_OK) == 0;
        if (!s->base) {
            sx_h5_fail(&h, "out of memory");
        } else if (append) {
            int d = 0, version = 0;
            s->file = sx_io_open(&h, path, true, "series", dim, &d, &version);
            if (s->file >= 0) sx_h5_get_i64(&h, s->file, "/", "count", &s->count, 1, true);
            /* what is appended now follows this format: an older reader must refuse the file */
            if (s->file >= 0 && version < SX_IO_FORMAT_VERSION &&
                sx_h5_attr_int(&h, s->file, "format_version", SX_IO_FORMAT_VERSION) && !sync_file(s->file))
                sx_h5_fail_h5(&h, "cannot flush the series");
        } else if (create_file(&h, path, dim, o, fields)) {
            hid_t fapl = sx_h5_fapl(false);
            s->file = fapl >= 0 ? H5Fopen(path, H5F_ACC_RDWR, fapl) : -1;
            if (s->file < 0) sx_h5_fail_h5(&h, "cannot reopen the new series");
            sx_h5_close(fapl);
        }
        if (!h.failed && s->count < 0) sx_h5_fail(&h, "damaged: negative snapshot count");
        /* the XDMF of what the file holds now, kept in memory from here on */
        if (!h.failed && xmf_body(&h, &s->x, s->base, s->file, s->dim, s->count)) xmf_write(&h, s->xmf, &s->x);
    }
    const bool failed = h.failed;
    sx_h5_end(&h);
    if (failed) {
        sx_series_close(s, NULL, 0);
        return NULL;
    }
    return s;
}

/* ------------------------------------------------------------ recovery */

/* Links every link of a group but one into another group. */
typedef struct relink {
    hid_t to;
    const char *skip;
} relink;

static herr_t relink_one(hid_t g, const char *name, const H5L_info_t *info, void *ud)
{
    (void)info;
    const relink *r = ud;
    /* an object that cannot be read cannot be linked again: it stays
     * behind, with the group set aside */
    if (strcmp(name, r->skip) != 0) H5Lcreate_hard(g, name, r->to, name, H5P_DEFAULT, H5P_DEFAULT);
    return 0;
}

/* Removes the link `name` of the group `parent` (an absolute path of the
 * root), left by a write that failed or was killed. HDF5 deletes a link
 * only by reading its object (to lower the object's link count), which a
 * killed write may have left unreadable: its link reached the disk, its
 * header did not (the cache evicts a group's header, with its new link,
 * whenever it likes). Then the group is rebuilt without that link: a new
 * group links every other object (each readable, so nothing complete is
 * lost), is flushed, and takes the group's name; the old group is set
 * aside as <parent>-damaged-<n>, which no reader looks at. */
static bool drop_link(sx_h5 *h, hid_t file, const char *parent, const char *name)
{
    if (h->failed) return false;
    hid_t pg = H5Gopen2(file, parent, H5P_DEFAULT);
    if (pg < 0) return sx_h5_fail_h5(h, "damaged: cannot open the group %s", parent);
    bool ok = H5Lexists(pg, name, H5P_DEFAULT) <= 0 || H5Ldelete(pg, name, H5P_DEFAULT) >= 0;
    H5Eclear2(H5E_DEFAULT);
    if (!ok) {
        char aside[128];
        for (int n = 1; n < 1000 && (snprintf(aside, sizeof aside, "%s-damaged-%d", parent, n), true); n++)
            if (H5Lexists(file, aside, H5P_DEFAULT) <= 0) break;
        hid_t ng = H5Gcreate_anon(file, H5P_DEFAULT, H5P_DEFAULT);
        relink r = {ng, name};
        /* the new group on disk before any link to it */
        ok = ng >= 0 && H5Literate(pg, H5_INDEX_NAME, H5_ITER_INC, NULL, relink_one, &r) >= 0 && sync_file(file);
        H5Eclear2(H5E_DEFAULT);
        ok = ok && H5Lexists(file, aside, H5P_DEFAULT) <= 0 &&
             H5Lmove(file, parent, file, aside, H5P_DEFAULT, H5P_DEFAULT) >= 0;
        if (ok && H5Olink(ng, file, parent, H5P_DEFAULT, H5P_DEFAULT) < 0) {
            H5Lmove(file, aside, file, parent, H5P_DEFAULT, H5P_DEFAULT);
            ok = false;
        }
        if (!ok) sx_h5_fail_h5(h, "damaged: cannot remove %s/%s, left by an incomplete write", parent, name);
        sx_h5_close(ng);
    }
    sx_h5_close(pg);
    return ok;
}

/* ------------------------------------------------------ history rows */

/* A history being appended: its group, its entry in s->held and the rows
 * written beyond the file's count. */
typedef struct pending {
    hid_t g;
    int held;
    int64_t rows, last;
} pending;

/* The entry of s->held for the history group g named `name` (read from the
 * file the first time it is met); -1 on failure. */
static int held_of(sx_h5 *h, sx_series *s, hid_t g, const char *name, bool fresh)
{
    for (int i = 0; i < s->nheld; i++)
        if (strcmp(s->held[i].name, name) == 0) return i;
    if (s->nheld == s->capheld) {
        const int cap = s->capheld ? 2 * s->capheld : 8;
        held *q = realloc(s->held, (size_t)cap * sizeof *q);
        if (!q) return sx_h5_fail(h, "out of memory"), -1;
        s->held = q;
        s->capheld = cap;
    }
    held *e = &s->held[s->nheld];
    e->rows = 0;
    e->last = INT64_MIN;
    if (!(e->name = dup_str(name))) return sx_h5_fail(h, "out of memory"), -1;
    if (!fresh) {
        char where[320];
        snprintf(where, sizeof where, "/histories/%.300s", name);
        if (!sx_io_history_tail(h, g, where, &e->rows, &e->last)) {
            free(e->name);
            return -1;
        }
    }
    return s->nheld++;
}

/* Writes, beyond each history's complete rows, its samples of steps after
 * the last one the file holds; nothing is counted yet. */
static void hist_stage(sx_h5 *h, sx_series *s, const sx_io_history *x, int nh, pending *p)
{
    for (int i = 0; i < nh; i++) p[i].g = -1;
    if (nh <= 0 || h->failed) return;
    for (int i = 0; i < nh; i++) {
        if (!sx_io_history_valid(h, &x[i])) return;
        for (int j = 0; j < i; j++)
            if (strcmp(x[i].name, x[j].name) == 0) {
                sx_h5_fail(h, "two histories named '%s'", x[i].name);
                return;
            }
    }
    hid_t hg = sx_h5_group(h, s->file, "histories");
    /* a history whose group a killed write left unreadable (its link
     * reached the disk, its header did not) starts again: its rows went
     * with the header, and the model holds them all */
    for (int i = 0; i < nh && !h->failed; i++) {
        H5O_info_t oi;
        if (H5Lexists(hg, x[i].name, H5P_DEFAULT) > 0 && H5Oget_info_by_name(hg, x[i].name, &oi, H5P_DEFAULT) < 0) {
            sx_h5_close(hg);
            hg = drop_link(h, s->file, "/histories", x[i].name) ? sx_h5_group(h, s->file, "histories") : -1;
        }
    }
    for (int i = 0; i < nh && !h->failed; i++) {
        const sx_io_history *q = &x[i];
        const bool fresh = H5Lexists(hg, q->name, H5P_DEFAULT) <= 0;
        if (fresh) {
            H5G_info_t gi;
            /* rows are appended a few at a time: 8 KiB chunks */
            p[i].g = H5Gget_info(hg, &gi) < 0 ? (sx_h5_fail_h5(h, "damaged: cannot list /histories"), -1)
                                              : sx_io_history_create(h, hg, q, (int64_t)gi.nlinks, 1024);
        } else {
            p[i].g = sx_h5_open_group(h, hg, q->name, true);
        }
        if (p[i].g < 0) break;
        p[i].held = held_of(h, s, p[i].g, q->name, fresh);
        if (p[i].held < 0) break;
        const held *e = &s->held[p[i].held];
        /* the first sample after the file's last step (steps increase) */
        int64_t lo = 0, hi = q->n;
        while (lo < hi) {
            const int64_t mid = lo + (hi - lo) / 2;
            if (q->steps[mid] > e->last) hi = mid;
            else lo = mid + 1;
        }
        sx_io_history_put(h, p[i].g, q, lo, e->rows);
        p[i].rows = e->rows + (q->n - lo);
        p[i].last = q->n > lo ? q->steps[q->n - 1] : e->last;
    }
    sx_h5_close(hg);
}

static void hist_raise(sx_h5 *h, const pending *p, int nh)
{
    for (int i = 0; i < nh && !h->failed; i++) sx_h5_attr_int(h, p[i].g, "count", p[i].rows);
}

static void hist_commit(sx_series *s, const pending *p, int nh)
{
    for (int i = 0; i < nh; i++) s->held[p[i].held].rows = p[i].rows, s->held[p[i].held].last = p[i].last;
}

/* ---------------------------------------------------------- writing */

/* One write: a snapshot of m (none when NULL) and the histories' new
 * rows, in the order that keeps every reader consistent (see the top). */
static sx_status append(sx_series *s, const sx_model *m, const sx_io_history *x, int nh, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, s->path, err, errlen);
    h.compression = s->compression;
    pending *p = calloc((size_t)(nh > 0 ? nh : 0) + 1, sizeof *p);
    snap sn;
    char tmp[4096];
    bool have_tmp = false;
    size_t xat[NKINDS]; /* the blocks' lengths, to drop a failed snapshot's grids */
    for (int k = 0; k < NKINDS; k++) xat[k] = s->x.kind[k].n;
    if (!p) {
        sx_h5_fail(&h, "out of memory");
    } else if (m && m->dim != s->dim) {
        sx_h5_fail(&h, "the series holds %dD models, this one is %dD", s->dim, m->dim);
    } else if (s->file < 0) {
        sx_h5_fail(&h, "the series is closed");
    } else {
        if (m) {
            char name[48];
            snprintf(name, sizeof name, "/snapshots/%06lld", (long long)s->count);
            /* a group left by a write that failed or was killed is dropped */
            hid_t g = drop_link(&h, s->file, "/snapshots", name + strlen("/snapshots/"))
                          ? H5Gcreate2(s->file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                          : -1;
            if (g < 0) sx_h5_fail_h5(&h, "cannot add a snapshot");
            else write_snapshot(&h, g, m, s->fields, &sn);
            sx_h5_close(g);
        }
        hist_stage(&h, s, x, nh, p);
        /* 1. the data on disk before anything says it is complete */
        if (!h.failed && !sync_file(s->file)) sx_h5_fail_h5(&h, "cannot flush the snapshot");
        /* 2. the XDMF that lists it, on disk under a temporary name */
        if (m && !h.failed) {
            xmf_step(&s->x, s->base, s->count, &sn);
            if (!xmf_compose(&s->x)) sx_h5_fail(&h, "out of memory");
            else have_tmp = sx_h5_write_temp(&h, s->xmf, s->x.out.p, s->x.out.n, tmp, sizeof tmp);
        }
        /* 3. the counts, and at once 4. the XDMF renamed into place */
        if (!h.failed) {
            if (m) sx_h5_attr_int(&h, s->file, "count", s->count + 1);
            hist_raise(&h, p, nh);
            if (!h.failed && !flush_file(s->file)) sx_h5_fail_h5(&h, "cannot flush the counts");
        }
        if (!h.failed) {
            s->count += m ? 1 : 0;
            hist_commit(s, p, nh);
            if (have_tmp && sx_h5_rename(&h, tmp, s->xmf)) have_tmp = false;
            /* 5. the counts durable too */
            if (!sync_file(s->file)) sx_h5_fail_h5(&h, "cannot flush the counts");
        } else {
            for (int k = 0; k < NKINDS; k++) s->x.kind[k].n = xat[k];
        }
    }
    if (have_tmp) remove(tmp);
    for (int i = 0; p && i < nh; i++) sx_h5_close(p[i].g);
    free(p);
    const bool failed = h.failed;
    sx_h5_end(&h);
    return failed ? SX_EINVAL : SX_OK;
}

sx_status sx_series_write(sx_series *s, const sx_model *m, const sx_io_history *h, int nh, char *err,
                          size_t errlen)
{
    return append(s, m, h, nh, err, errlen);
}

sx_status sx_series_write_histories(sx_series *s, const sx_io_history *h, int nh, char *err, size_t errlen)
{
    return append(s, NULL, h, nh, err, errlen);
}

sx_status sx_series_close(sx_series *s, char *err, size_t errlen)
{
    if (!s) return SX_OK;
    sx_h5 h;
    sx_h5_begin(&h, s->path ? s->path : "", err, errlen);
    if (s->file >= 0 && H5Fclose(s->file) < 0) sx_h5_fail_h5(&h, "cannot close the series");
    const bool failed = h.failed;
    sx_h5_end(&h);
    for (int i = 0; i < s->nheld; i++) free(s->held[i].name);
    free(s->held);
    xdoc_free(&s->x);
    free(s->path);
    free(s->xmf);
    free(s->base);
    free(s);
    return failed ? SX_EINVAL : SX_OK;
}

sx_status sx_series_write_xdmf(const char *h5path, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, h5path ? h5path : "", err, errlen);
    int dim = 0, version = 0;
    hid_t f = h5path && *h5path ? sx_io_open(&h, h5path, false, "series", 0, &dim, &version) : -1;
    if (!h5path || !*h5path) sx_h5_fail(&h, "an empty path");
    int64_t count = 0;
    char *xmf = xmf_path_of(h5path ? h5path : "");
    const char *slash = h5path ? strrchr(h5path, '/') : NULL;
    xdoc d;
    memset(&d, 0, sizeof d);
    if (f >= 0 && sx_h5_get_i64(&h, f, "/", "count", &count, 1, true)) {
        if (!xmf) sx_h5_fail(&h, "out of memory");
        else if (count < 0) sx_h5_fail(&h, "damaged: negative snapshot count");
        else if (xmf_body(&h, &d, slash ? slash + 1 : h5path, f, dim, count)) xmf_write(&h, xmf, &d);
    }
    xdoc_free(&d);
    free(xmf);
    if (f >= 0) H5Fclose(f);
    const bool failed = h.failed;
    sx_h5_end(&h);
    return failed ? SX_EINVAL : SX_OK;
}

int64_t sx_series_read_count(const char *path, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, path ? path : "", err, errlen);
    int dim = 0, version = 0;
    int64_t count = -1;
    hid_t f = path && *path ? sx_io_open(&h, path, false, "series", 0, &dim, &version) : -1;
    if (f >= 0 && !sx_h5_get_i64(&h, f, "/", "count", &count, 1, true)) count = -1;
    if (f >= 0) H5Fclose(f);
    sx_h5_end(&h);
    return count;
}
