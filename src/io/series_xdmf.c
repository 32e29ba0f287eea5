/* The XDMF beside an output series: kept in memory by the writer (one
 * temporal collection per block, a grid per complete snapshot) and written
 * whole, or rebuilt from the snapshots' attributes (seixo.xdmf, append). */
#include "series_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const kind_names[NKINDS] = {"balls", "contacts", "wall_contacts", "bonds", "cracks", "walls", "meshes"};

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

/* The whole document: the blocks that have grids, each a temporal collection. */
bool sx_io_xmf_compose(xdoc *d)
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

void sx_io_xdoc_free(xdoc *d)
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

void sx_io_xmf_step(xdoc *d, const char *base, int64_t k, const snap *s)
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

/* path with its .h5 / .hdf5 / .hdf extension replaced by .xmf (or .xmf appended). */
char *sx_io_xmf_path(const char *path)
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
bool sx_io_xmf_body(sx_h5 *h, xdoc *d, const char *base, hid_t file, int dim, int64_t count)
{
    for (int k = 0; k < NKINDS; k++) d->kind[k].n = 0;
    for (int64_t k = 0; k < count && !h->failed; k++) {
        snap s;
        if (read_snap(h, file, dim, k, &s)) sx_io_xmf_step(d, base, k, &s);
    }
    return !h->failed;
}

/* The whole document, written whole (temporary name, rename). */
bool sx_io_xmf_write(sx_h5 *h, const char *xmf, xdoc *d)
{
    return sx_io_xmf_compose(d) ? write_whole(h, xmf, d->out.p, d->out.n) : sx_h5_fail(h, "out of memory");
}

sx_status sx_series_write_xdmf(const char *h5path, char *err, size_t errlen)
{
    sx_h5 h;
    sx_h5_begin(&h, h5path ? h5path : "", err, errlen);
    int dim = 0, version = 0;
    hid_t f = h5path && *h5path ? sx_io_open(&h, h5path, false, "series", 0, &dim, &version) : -1;
    if (!h5path || !*h5path) sx_h5_fail(&h, "an empty path");
    int64_t count = 0;
    char *xmf = sx_io_xmf_path(h5path ? h5path : "");
    const char *slash = h5path ? strrchr(h5path, '/') : NULL;
    xdoc d;
    memset(&d, 0, sizeof d);
    if (f >= 0 && sx_h5_get_i64(&h, f, "/", "count", &count, 1, true)) {
        if (!xmf) sx_h5_fail(&h, "out of memory");
        else if (count < 0) sx_h5_fail(&h, "damaged: negative snapshot count");
        else if (sx_io_xmf_body(&h, &d, slash ? slash + 1 : h5path, f, dim, count)) sx_io_xmf_write(&h, xmf, &d);
    }
    sx_io_xdoc_free(&d);
    free(xmf);
    if (f >= 0) H5Fclose(f);
    const bool failed = h.failed;
    sx_h5_end(&h);
    return failed ? SX_EINVAL : SX_OK;
}
