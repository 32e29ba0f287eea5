/* Output series: what a snapshot holds (positions, fields, contacts and
 * bonds as lines into the balls' points, wall contacts, walls, a cylinder
 * as its surface), that the XDMF lists each snapshot and is rebuilt
 * identically from the file, that h5dump reads the file, field selection,
 * appending (to a format-1 series too), histories growing as extendable
 * datasets, and errors. */
#include "h5util.h"
#include "io_scenes.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    ck_assert_msg(f != NULL, "cannot open %s", path);
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    rewind(f);
    char *s = malloc((size_t)n + 1);
    ck_assert_uint_eq(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = 0;
    fclose(f);
    return s;
}

static int occurrences(const char *s, const char *what)
{
    int n = 0;
    for (const char *p = s; (p = strstr(p, what)); p += strlen(what)) n++;
    return n;
}

/* Reads a whole dataset of snapshot k as doubles; returns rows, cols in *cols. */
static double *read_ds(hid_t f, int64_t k, const char *ds, hsize_t *rows, hsize_t *cols)
{
    char name[128];
    snprintf(name, sizeof name, "/snapshots/%06lld/%s", (long long)k, ds);
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    ck_assert_msg(d >= 0, "%s is missing", name);
    hid_t s = H5Dget_space(d);
    hsize_t dims[2] = {0, 1};
    H5Sget_simple_extent_dims(s, dims, NULL);
    *rows = dims[0];
    *cols = H5Sget_simple_extent_ndims(s) == 2 ? dims[1] : 1;
    double *v = malloc((size_t)(*rows * *cols + 1) * sizeof *v);
    ck_assert(*rows == 0 || H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0);
    H5Sclose(s);
    H5Dclose(d);
    return v;
}

static bool count_contact(const sx_contact_info *ci, void *ud)
{
    int64_t *n = ud;
    n[ci->is_wall ? 1 : 0]++;
    if (ci->bond) n[2]++;
    return true;
}

START_TEST(contents)
{
    const int dim = _i;
    sx_model *m = io_scene_bonded(dim);
    char path[512], xmf[512], err[1024];
    io_path(path, sizeof path, "out.h5");
    io_path(xmf, sizeof xmf, "out.xmf");
    sx_series_opts o;
    memset(&o, 0, sizeof o);
    o.fields = SX_OUT_DEFAULT | SX_OUT_MOMENT | SX_OUT_MASS | SX_OUT_MATERIAL;
    o.compression = 4;
    sx_series *s = sx_series_open(path, dim, &o, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    int64_t counts[3][3];
    for (int k = 0; k < 3; k++) {
        memset(counts[k], 0, sizeof counts[k]);
        sx_contact_each(m, count_contact, counts[k]);
        ck_assert_msg(sx_series_write(s, m, NULL, 0, err, sizeof err) == SX_OK, "%s", err);
        io_cycle(m, 40);
    }
    ck_assert_int_eq(sx_series_count(s), 3);
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    io_assert_no_handles();

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    ck_assert(f >= 0);
    hsize_t rows, cols;
    /* the last snapshot's positions are the model's before its last 40 steps: check the first */
    double *x = read_ds(f, 0, "balls/position", &rows, &cols);
    ck_assert_uint_eq(rows, (hsize_t)sx_ball_count(m));
    ck_assert_uint_eq(cols, 3);
    if (dim == 2)
        for (hsize_t i = 0; i < rows; i++) ck_assert(x[i * 3 + 2] == 0);
    free(x);
    const char *vec[] = {"balls/velocity", "balls/spin", "balls/force", "balls/moment"};
    for (int q = 0; q < 4; q++) {
        free(read_ds(f, 2, vec[q], &rows, &cols));
        ck_assert_uint_eq(cols, 3);
    }
    const char *sca[] = {"balls/id", "balls/radius", "balls/group", "balls/material", "balls/mass"};
    for (int q = 0; q < 5; q++) {
        free(read_ds(f, 2, sca[q], &rows, &cols));
        ck_assert_uint_eq(rows, (hsize_t)sx_ball_count(m));
    }
    for (int k = 0; k < 3; k++) {
        double *c = read_ds(f, k, "contacts/connectivity", &rows, &cols);
        ck_assert_int_eq((int64_t)rows, counts[k][0]);
        for (hsize_t i = 0; i < rows * cols; i++) ck_assert(c[i] >= 0 && c[i] < (double)sx_ball_count(m));
        free(c);
        free(read_ds(f, k, "contacts/force", &rows, &cols));
        ck_assert_int_eq((int64_t)rows, counts[k][0]);
        free(read_ds(f, k, "wall_contacts/points", &rows, &cols));
        ck_assert_int_eq((int64_t)rows, 2 * counts[k][1]);
        free(read_ds(f, k, "bonds/connectivity", &rows, &cols));
        ck_assert_int_eq((int64_t)rows, counts[k][2]);
        double *w = read_ds(f, k, "walls/points", &rows, &cols);
        ck_assert_int_eq((int64_t)rows, (dim == 3 ? 4 : 2) * sx_wall_count(m));
        free(w);
    }
    ck_assert(counts[0][2] > 0 && counts[0][1] >= 0);
    H5Fclose(f);

    /* the XDMF has a temporal collection per block, named, with a grid per
     * snapshot; rebuilding it from the file gives the same text */
    char *a = slurp(xmf);
    ck_assert_int_eq(occurrences(a, "<Grid Name=\"balls\" GridType=\"Collection\" CollectionType=\"Temporal\">"), 1);
    ck_assert_int_eq(occurrences(a, "/balls/vertices</DataItem>"), 3);
    ck_assert_int_eq(occurrences(a, "<Grid Name=\"step "), occurrences(a, "<Time Value="));
    ck_assert_int_eq(occurrences(a, "Name=\"bonds\""), 1);
    ck_assert(strstr(a, "out.h5:/snapshots/000002/balls/position"));
    ck_assert(strstr(a, dim == 3 ? "Quadrilateral" : "Polyline"));
    ck_assert_int_eq(sx_series_write_xdmf(path, err, sizeof err), SX_OK);
    char *b = slurp(xmf);
    ck_assert_str_eq(a, b);
    free(a);
    free(b);

    /* h5dump, when installed, reads the whole file */
    if (system("command -v h5dump > /dev/null 2>&1") == 0) {
        char cmd[700];
        snprintf(cmd, sizeof cmd, "h5dump '%s' > /dev/null", path);
        ck_assert_int_eq(system(cmd), 0);
    }
    sx_model_destroy(m);
}
END_TEST

START_TEST(fields_append_errors)
{
    char path[512], err[1024];
    io_path(path, sizeof path, "few.h5");
    sx_series_opts o;
    memset(&o, 0, sizeof o);
    o.fields = SX_OUT_RADIUS;
    sx_model *m = io_scene_granular(2, 40);
    sx_series *s = sx_series_open(path, 2, &o, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    ck_assert_int_eq(sx_series_write(s, m, NULL, 0, err, sizeof err), SX_OK);
    /* a 3D model into a 2D series */
    sx_model *m3 = io_scene_granular(3, 20);
    ck_assert_int_ne(sx_series_write(s, m3, NULL, 0, err, sizeof err), SX_OK);
    printf("  %s\n", err);
    fflush(stdout);
    ck_assert(strstr(err, path) && strstr(err, "2D"));
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    ck_assert(H5Lexists(f, "/snapshots/000000/balls/radius", H5P_DEFAULT) > 0);
    ck_assert(H5Lexists(f, "/snapshots/000000/balls/velocity", H5P_DEFAULT) == 0);
    ck_assert(H5Lexists(f, "/snapshots/000000/contacts", H5P_DEFAULT) == 0);
    H5Fclose(f);
    /* continued with other fields; a 3D continuation is refused */
    o.append = true;
    o.fields = SX_OUT_DEFAULT;
    ck_assert_ptr_null(sx_series_open(path, 3, &o, err, sizeof err));
    printf("  %s\n", err);
    fflush(stdout);
    s = sx_series_open(path, 2, &o, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    ck_assert_int_eq(sx_series_write(s, m, NULL, 0, err, sizeof err), SX_OK);
    ck_assert_int_eq(sx_series_count(s), 2);
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    char xmf[512];
    char *text = slurp(io_path(xmf, sizeof xmf, "few.xmf"));
    ck_assert_int_eq(occurrences(text, "Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\""), 1);
    free(text);
    /* a snapshot is not a series */
    io_save(m, path);
    ck_assert_ptr_null(sx_series_open(path, 2, &o, err, sizeof err));
    printf("  %s\n", err);
    fflush(stdout);
    ck_assert(strstr(err, "not a series"));
    ck_assert_ptr_null(sx_series_open("", 2, NULL, err, sizeof err));
    io_assert_no_handles();
    sx_model_destroy(m);
    sx_model_destroy(m3);
}
END_TEST

/* A cylinder is drawn as its surface: 32 quadrilaterals around its axis
 * over its height, every point at its radius; planes stay one square. */
START_TEST(cylinder_surface)
{
    sx_model *m = io_scene_servo(3);
    io_cycle(m, 50);
    sx_wall_def cyl;
    ck_assert_int_eq(sx_wall_get(m, sx_wall_id_at(m, 0), &cyl), SX_OK);
    ck_assert_int_eq(cyl.kind, SX_WALL_CYLINDER);
    char path[512], xmf[512], err[1024];
    io_path(path, sizeof path, "cyl.h5");
    io_path(xmf, sizeof xmf, "cyl.xmf");
    sx_series *s = sx_series_open(path, 3, NULL, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    ck_assert_msg(sx_series_write(s, m, NULL, 0, err, sizeof err) == SX_OK, "%s", err);
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    hsize_t rows, cols, crows, ccols, irows, icols;
    double *p = read_ds(f, 0, "walls/points", &rows, &cols);
    double *c = read_ds(f, 0, "walls/connectivity", &crows, &ccols);
    double *id = read_ds(f, 0, "walls/id", &irows, &icols);
    H5Fclose(f);
    ck_assert_uint_eq(rows, 64 + 4 + 4);
    ck_assert_uint_eq(crows, 32 + 1 + 1);
    ck_assert_uint_eq(ccols, 4);
    ck_assert_uint_eq(irows, crows);
    for (hsize_t i = 0; i < 64; i++) {
        const double r = hypot(p[i * 3] - cyl.point[0], p[i * 3 + 1] - cyl.point[1]);
        ck_assert_double_eq_tol(r, cyl.radius, 1e-12 * cyl.radius);
        const double z = p[i * 3 + 2] - cyl.point[2];
        ck_assert(fabs(z) < 1e-15 || fabs(z - cyl.height) < 1e-15);
    }
    for (hsize_t q = 0; q < 32; q++) {
        ck_assert(id[q] == (double)sx_wall_id_at(m, 0));
        for (int k = 0; k < 4; k++) ck_assert(c[q * 4 + k] >= 0 && c[q * 4 + k] < 64);
    }
    for (hsize_t q = 32; q < 34; q++)
        for (int k = 0; k < 4; k++) ck_assert(c[q * 4 + k] >= 64 && c[q * 4 + k] < 72);
    free(p);
    free(c);
    free(id);
    char *text = slurp(xmf);
    ck_assert(strstr(text, "<Topology TopologyType=\"Quadrilateral\" NumberOfElements=\"34\">"));
    ck_assert(strstr(text, "<DataItem Dimensions=\"72 3\""));
    free(text);
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

/* A history of k samples at steps 10, 20, ...: value = step^2 / 7. */
typedef struct hbuf {
    sx_io_history h;
    int64_t st[64];
    double t[64], v[64];
} hbuf;

static void hset(hbuf *b, const char *name, int64_t k)
{
    memset(b, 0, sizeof *b);
    b->h.name = (char *)name;
    b->h.every = 10;
    b->h.source = SX_IO_SOURCE_WALL;
    b->h.id = 3;
    b->h.field = "force";
    b->h.component = 1;
    b->h.steps = b->st, b->h.times = b->t, b->h.values = b->v;
    b->h.n = k;
    for (int64_t i = 0; i < k; i++) b->st[i] = 10 * (i + 1), b->t[i] = 1e-4 * (double)(i + 1), b->v[i] = (double)(b->st[i] * b->st[i]) / 7;
}

/* The rows of /histories/<name> up to its count (asserting the layout). */
static int64_t read_history(const char *path, const char *name, int64_t *st, double *v)
{
    /* the series may hold the file open: opened as its writer opens it
     * (close degree, file driver), HDF5 shares the open file */
    hid_t fapl = sx_h5_fapl(false);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    H5Pclose(fapl);
    ck_assert(f >= 0);
    char g[128];
    snprintf(g, sizeof g, "/histories/%s", name);
    hid_t q = H5Gopen2(f, g, H5P_DEFAULT);
    ck_assert_msg(q >= 0, "%s is missing", g);
    int64_t count;
    hid_t a = H5Aopen(q, "count", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_INT64, &count);
    H5Aclose(a);
    hid_t d = H5Dopen2(q, "step", H5P_DEFAULT), e = H5Dopen2(q, "value", H5P_DEFAULT);
    hid_t sp = H5Dget_space(d), pl = H5Dget_create_plist(d);
    hsize_t rows, max;
    H5Sget_simple_extent_dims(sp, &rows, &max);
    ck_assert(max == H5S_UNLIMITED);
    ck_assert_int_eq(H5Pget_layout(pl), H5D_CHUNKED);
    ck_assert_uint_eq(rows, (hsize_t)count);
    ck_assert(H5Dread(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, st) >= 0);
    ck_assert(H5Dread(e, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0);
    H5Pclose(pl);
    H5Sclose(sp);
    H5Dclose(d);
    H5Dclose(e);
    H5Gclose(q);
    H5Fclose(f);
    return count;
}

/* Histories grow with the series: each write appends the samples after
 * the last step the file holds (so passing more than new samples is
 * harmless), a write of histories alone too, and an appended series
 * continues them. */
START_TEST(histories_grow)
{
    sx_model *m = io_scene_granular(2, 30);
    char path[512], err[1024];
    io_path(path, sizeof path, "hist.h5");
    sx_series *s = sx_series_open(path, 2, NULL, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    hbuf a, b;
    hset(&a, "fy, wall \"3\"", 2);
    hset(&b, "ke", 0);
    b.h.source = SX_IO_SOURCE_BUILTIN, b.h.builtin = "kinetic", b.h.field = NULL;
    sx_io_history both[2];
    both[0] = a.h, both[1] = b.h;
    ck_assert_msg(sx_series_write(s, m, both, 2, err, sizeof err) == SX_OK, "%s", err);
    int64_t st[64];
    double v[64];
    ck_assert_int_eq(read_history(path, "fy, wall \"3\"", st, v), 2);
    ck_assert_int_eq(read_history(path, "ke", st, v), 0);
    /* all five samples given again: only the three new ones are appended */
    hset(&a, "fy, wall \"3\"", 5);
    ck_assert_msg(sx_series_write(s, m, &a.h, 1, err, sizeof err) == SX_OK, "%s", err);
    ck_assert_int_eq(read_history(path, "fy, wall \"3\"", st, v), 5);
    for (int i = 0; i < 5; i++) ck_assert(st[i] == 10 * (i + 1) && v[i] == (double)(st[i] * st[i]) / 7);
    /* only the new tail, without a snapshot */
    a.h.steps += 5, a.h.times += 5, a.h.values += 5, a.h.n = 0;
    hset(&b, "ke", 3);
    ck_assert_msg(sx_series_write_histories(s, &b.h, 1, err, sizeof err) == SX_OK, "%s", err);
    ck_assert_int_eq(sx_series_count(s), 2);
    ck_assert_int_eq(read_history(path, "ke", st, v), 3);
    /* a history named so it cannot name a group, and the same name twice */
    hset(&b, "a/b", 1);
    ck_assert_int_ne(sx_series_write_histories(s, &b.h, 1, err, sizeof err), SX_OK);
    ck_assert(strstr(err, "cannot name a group"));
    both[0] = a.h, both[1] = a.h;
    ck_assert_int_ne(sx_series_write_histories(s, both, 2, err, sizeof err), SX_OK);
    ck_assert(strstr(err, "two histories"));
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);

    sx_series_opts o;
    memset(&o, 0, sizeof o);
    o.append = true;
    s = sx_series_open(path, 2, &o, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    hset(&a, "fy, wall \"3\"", 8);
    ck_assert_msg(sx_series_write(s, m, &a.h, 1, err, sizeof err) == SX_OK, "%s", err);
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    ck_assert_int_eq(read_history(path, "fy, wall \"3\"", st, v), 8);
    for (int i = 0; i < 8; i++) ck_assert(st[i] == 10 * (i + 1));
    ck_assert_int_eq(sx_series_read_count(path, err, sizeof err), 3);
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

/* Appending to a series of format 1 (no wall cell counts in its snapshots)
 * keeps its XDMF right and marks the file format 2, which it now is. */
START_TEST(append_to_format1)
{
    sx_model *m = io_scene_granular(3, 30);
    char path[512], xmf[512], err[1024];
    io_path(path, sizeof path, "old.h5");
    io_path(xmf, sizeof xmf, "old.xmf");
    sx_series *s = sx_series_open(path, 3, NULL, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    ck_assert_msg(sx_series_write(s, m, NULL, 0, err, sizeof err) == SX_OK, "%s", err);
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    char *before = slurp(xmf);
    /* make it what format 1 wrote */
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    const int64_t one = 1;
    hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_INT64, &one);
    H5Aclose(a);
    hid_t g = H5Gopen2(f, "/snapshots/000000", H5P_DEFAULT);
    H5Adelete(g, "wall_cells");
    H5Adelete(g, "wall_points");
    H5Gclose(g);
    H5Fclose(f);
    ck_assert_int_eq(sx_series_write_xdmf(path, err, sizeof err), SX_OK);
    char *rebuilt = slurp(xmf);
    ck_assert_str_eq(before, rebuilt);
    sx_series_opts o;
    memset(&o, 0, sizeof o);
    o.append = true;
    s = sx_series_open(path, 3, &o, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    ck_assert_msg(sx_series_write(s, m, NULL, 0, err, sizeof err) == SX_OK, "%s", err);
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    char *after = slurp(xmf);
    ck_assert_int_eq(occurrences(after, "/balls/vertices</DataItem>"), 2);
    /* the old snapshot's balls grid is kept as it was written */
    const char *g0 = strstr(before, "   <Grid Name=\"step "), *g1 = g0 ? strstr(g0, "   </Grid>\n") : NULL;
    ck_assert(g0 && g1);
    char *grid = strndup(g0, (size_t)(g1 - g0));
    ck_assert(strstr(after, grid));
    free(grid);
    f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    int64_t v = 0;
    a = H5Aopen(f, "format_version", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_INT64, &v);
    H5Aclose(a);
    H5Fclose(f);
    ck_assert_int_eq(v, SX_IO_FORMAT_VERSION);
    free(before);
    free(rebuilt);
    free(after);
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

/* A snapshot's count attribute damaged to INT64_MIN (found by the file
 * fuzzer: UBSan's overflow in the XDMF writer's wall points) or to -1 is
 * an error naming the snapshot, not an XDMF with negative sizes. */
START_TEST(damaged_counts)
{
    static const char *const attrs[] = {"walls", "balls", "contacts"};
    static const int64_t bad[] = {INT64_MIN, -1, INT64_MAX};
    for (int a = 0; a < 3; a++) {
        sx_model *m = io_scene_bonded(3);
        char path[512], err[1024];
        io_path(path, sizeof path, "counts.h5");
        sx_series_opts o;
        memset(&o, 0, sizeof o);
        o.fields = SX_OUT_DEFAULT;
        sx_series *s = sx_series_open(path, 3, &o, err, sizeof err);
        ck_assert_msg(s, "%s", err);
        ck_assert_msg(sx_series_write(s, m, NULL, 0, err, sizeof err) == SX_OK, "%s", err);
        ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
        sx_model_destroy(m);
        hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT), g = H5Gopen2(f, "/snapshots/000000", H5P_DEFAULT);
        hid_t at = H5Aopen(g, attrs[a], H5P_DEFAULT);
        ck_assert(f >= 0 && g >= 0 && at >= 0);
        ck_assert(H5Awrite(at, H5T_NATIVE_INT64, &bad[a]) >= 0);
        H5Aclose(at);
        H5Gclose(g);
        H5Fclose(f);
        ck_assert_int_ne(sx_series_write_xdmf(path, err, sizeof err), SX_OK);
        ck_assert_msg(strstr(err, "damaged: /snapshots/000000 has") != NULL, "%s", err);
        io_assert_no_handles();
    }
}
END_TEST

START_TEST(field_names)
{
    for (unsigned bit = 1; bit <= SX_OUT_WALLS; bit <<= 1) {
        const char *name = sx_series_field_name(bit);
        ck_assert_ptr_nonnull(name);
        ck_assert_uint_eq(sx_series_field_bit(name), bit);
    }
    ck_assert_uint_eq(sx_series_field_bit("nonsense"), 0);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_series");
    TCase *tc = tcase_create("series");
    tcase_set_timeout(tc, 600);
    tcase_add_loop_test(tc, contents, 2, 4);
    tcase_add_test(tc, fields_append_errors);
    tcase_add_test(tc, field_names);
    tcase_add_test(tc, damaged_counts);
    tcase_add_test(tc, cylinder_surface);
    tcase_add_test(tc, histories_grow);
    tcase_add_test(tc, append_to_format1);
    suite_add_tcase(s, tc);
    return io_run_suite(s);
}
