/* Output series: what a snapshot holds (positions, fields, contacts and
 * bonds as lines into the balls' points, wall contacts, walls), that the
 * XDMF lists each snapshot and is rebuilt identically from the file, that
 * h5dump reads the file, field selection, appending, and errors. */
#include "io_scenes.h"

#include <hdf5.h>
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
        ck_assert_msg(sx_series_write(s, m, err, sizeof err) == SX_OK, "%s", err);
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

    /* the XDMF names each snapshot, and rebuilding it from the file gives the same text */
    char *a = slurp(xmf);
    ck_assert_int_eq(occurrences(a, "<Time Value="), 3);
    ck_assert_int_eq(occurrences(a, "Name=\"balls\""), 3);
    ck_assert(occurrences(a, "Name=\"bonds\"") >= 1);
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
    ck_assert_int_eq(sx_series_write(s, m, err, sizeof err), SX_OK);
    /* a 3D model into a 2D series */
    sx_model *m3 = io_scene_granular(3, 20);
    ck_assert_int_ne(sx_series_write(s, m3, err, sizeof err), SX_OK);
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
    ck_assert_int_eq(sx_series_write(s, m, err, sizeof err), SX_OK);
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
    suite_add_tcase(s, tc);
    io_tmpdir();
    SRunner *r = srunner_create(s);
    srunner_run_all(r, CK_NORMAL);
    const int failed = srunner_ntests_failed(r);
    srunner_free(r);
    io_rmdir();
    return failed ? 1 : 0;
}
