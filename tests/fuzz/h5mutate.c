/* h5mutate: damages one dataset or attribute of an HDF5 file, for the file
 * fuzzer (tests/fuzz/files.lua).
 *   h5mutate list FILE                      the targets, one a line: "D path" or "A path@name"
 *   h5mutate apply IN OUT TARGET KIND SEED  OUT = IN with target TARGET (its line
 *                                           number in `list`, from 0, modulo their
 *                                           count) damaged by mutation KIND (modulo
 *                                           NKINDS); SEED picks the element
 * Prints what it did on one line ("<target>: <mutation>"); exit 0, 1 on an error.
 * The mutations: a value set to NaN, +inf, -inf, 0, -0, 1e300, a negative
 * value or a denormal (an integer: -1, INT64_MAX, INT64_MIN, 0, 2^31, -2);
 * the object deleted; one row fewer or more; another type (a float as an
 * integer, an integer as a float, a string as a number, a number as a
 * variable-length string); an attribute's string made variable-length (as
 * h5py writes it) or empty. */
#include <hdf5.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_TARGETS = 4096, NKINDS = 14 };

typedef struct target {
    char path[512];
    char attr[128]; /* empty: the dataset itself */
} target;

static target targets[MAX_TARGETS];
static int ntargets;

static herr_t add_attr(hid_t loc, const char *name, const H5A_info_t *info, void *ud)
{
    (void)loc;
    (void)info;
    const char *path = ud;
    if (ntargets < MAX_TARGETS) {
        snprintf(targets[ntargets].path, sizeof targets[0].path, "%s", path);
        snprintf(targets[ntargets].attr, sizeof targets[0].attr, "%s", name);
        ntargets++;
    }
    return 0;
}

static void add_object(hid_t f, const char *path)
{
    hid_t o = H5Oopen(f, path, H5P_DEFAULT);
    if (o < 0) return;
    if (H5Iget_type(o) == H5I_DATASET && ntargets < MAX_TARGETS) {
        snprintf(targets[ntargets].path, sizeof targets[0].path, "%s", path);
        targets[ntargets].attr[0] = 0;
        ntargets++;
    }
    H5Aiterate2(o, H5_INDEX_NAME, H5_ITER_INC, NULL, add_attr, (void *)path);
    H5Oclose(o);
}

static herr_t visit(hid_t g, const char *name, const H5L_info_t *info, void *ud)
{
    (void)g;
    (void)info;
    char path[512];
    snprintf(path, sizeof path, "/%s", name);
    add_object(*(hid_t *)ud, path);
    return 0;
}

static void list_targets(hid_t f)
{
    ntargets = 0;
    add_object(f, "/");
    H5Lvisit(f, H5_INDEX_NAME, H5_ITER_INC, visit, &f);
}

static int copy_file(const char *from, const char *to)
{
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    if (!a || !b) {
        if (a) fclose(a);
        if (b) fclose(b);
        return -1;
    }
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, a)) > 0) fwrite(buf, 1, n, b);
    fclose(a);
    return fclose(b);
}

static const double bad_double[] = {NAN, INFINITY, -INFINITY, 0.0, -0.0, 1e300, -1e-3, 4.9e-310};
static const long long bad_int[] = {-1, INT64_MAX, INT64_MIN, 0, 0, 2147483648LL, -2, 1};

/* The values of a dataset or attribute as doubles or integers; its element count. */
static hsize_t count_of(hid_t space)
{
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    return n > 0 ? (hsize_t)n : 0;
}

/* Sets element `at` of the numeric object (dataset when !attr) to bad value k. */
static const char *poke(hid_t obj, bool attr, int k, uint64_t at, char *what, size_t len)
{
    hid_t type = attr ? H5Aget_type(obj) : H5Dget_type(obj);
    hid_t space = attr ? H5Aget_space(obj) : H5Dget_space(obj);
    const H5T_class_t cls = H5Tget_class(type);
    const hsize_t n = count_of(space);
    const char *r = NULL;
    if ((cls == H5T_FLOAT || cls == H5T_INTEGER) && n > 0) {
        const bool fl = cls == H5T_FLOAT;
        const hid_t mem = fl ? H5T_NATIVE_DOUBLE : H5T_NATIVE_LLONG;
        void *buf = malloc(n * 8);
        if (buf && (attr ? H5Aread(obj, mem, buf) : H5Dread(obj, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf)) >= 0) {
            const hsize_t i = at % n;
            if (fl) {
                ((double *)buf)[i] = bad_double[k];
                snprintf(what, len, "element %llu = %g", (unsigned long long)i, bad_double[k]);
            } else {
                ((long long *)buf)[i] = bad_int[k];
                snprintf(what, len, "element %llu = %lld", (unsigned long long)i, bad_int[k]);
            }
            /* written through a conversion: out-of-range integers saturate */
            if ((attr ? H5Awrite(obj, mem, buf) : H5Dwrite(obj, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf)) >= 0) r = what;
            /* as one editing on purpose: else seixo's checksum refuses every
             * poked dataset before its values' checks are reached */
            if (r && !attr && H5Aexists(obj, "checksum") > 0) H5Adelete(obj, "checksum");
        }
        free(buf);
    }
    H5Sclose(space);
    H5Tclose(type);
    return r;
}

/* Replaces the dataset at path by one of `rows` rows (-1: as many) and
 * type `as` (-1 keep, 0 double, 1 int64, 2 vlen string), its old values
 * copied where they fit. */
static const char *remake_dataset(hid_t f, const char *path, long long rows, int as, char *what, size_t len)
{
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    if (d < 0) return NULL;
    hid_t type = H5Dget_type(d), space = H5Dget_space(d);
    const H5T_class_t cls = H5Tget_class(type);
    int rank = H5Sget_simple_extent_ndims(space);
    hsize_t dims[8] = {0}, ndims[8] = {0};
    if (rank < 0 || rank > 8) rank = 0;
    H5Sget_simple_extent_dims(space, dims, NULL);
    memcpy(ndims, dims, sizeof dims);
    if (rank == 0) {
        rank = 1;
        dims[0] = ndims[0] = 1;
    }
    if (rows >= 0) ndims[0] = (hsize_t)rows;
    hsize_t n = 1, nn = 1;
    for (int i = 0; i < rank; i++) n *= dims[i], nn *= ndims[i];
    const bool numeric = cls == H5T_FLOAT || cls == H5T_INTEGER;
    const int kind = as >= 0 ? as : cls == H5T_INTEGER ? 1 : 0;
    double *old = calloc(n + 1, sizeof *old), *fresh = calloc(nn + 1, sizeof *fresh);
    if (numeric) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, old);
    for (hsize_t i = 0; i < nn; i++) fresh[i] = n ? old[i < n ? i : n - 1] : 1;
    H5Sclose(space);
    H5Tclose(type);
    H5Dclose(d);
    H5Ldelete(f, path, H5P_DEFAULT);
    hid_t ns = H5Screate_simple(rank, ndims, NULL);
    hid_t nt = kind == 0 ? H5Tcopy(H5T_NATIVE_DOUBLE) : kind == 1 ? H5Tcopy(H5T_NATIVE_LLONG) : H5Tcopy(H5T_C_S1);
    if (kind == 2) H5Tset_size(nt, H5T_VARIABLE);
    hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    H5Pset_create_intermediate_group(lcpl, 1);
    hid_t nd = H5Dcreate2(f, path, nt, ns, lcpl, H5P_DEFAULT, H5P_DEFAULT);
    const char *r = NULL;
    if (nd >= 0) {
        herr_t st = 0;
        if (kind == 2) {
            const char **s = calloc(nn + 1, sizeof *s);
            for (hsize_t i = 0; i < nn; i++) s[i] = "junk";
            if (nn) st = H5Dwrite(nd, nt, H5S_ALL, H5S_ALL, H5P_DEFAULT, s);
            free(s);
        } else if (nn) {
            st = H5Dwrite(nd, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, fresh);
        }
        snprintf(what, len, "remade with %llu rows as %s", (unsigned long long)ndims[0],
                 kind == 0 ? "double" : kind == 1 ? "int64" : "strings");
        if (st >= 0) r = what;
        H5Dclose(nd);
    }
    H5Pclose(lcpl);
    H5Tclose(nt);
    H5Sclose(ns);
    free(old);
    free(fresh);
    return r;
}

/* Replaces attribute name of obj by a string (vlen or fixed) or a double. */
static const char *remake_attr(hid_t obj, const char *name, int as, char *what, size_t len)
{
    char text[256] = "junk";
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0) return NULL;
    hid_t type = H5Aget_type(a);
    if (H5Tget_class(type) == H5T_STRING && !H5Tis_variable_str(type)) {
        const size_t size = H5Tget_size(type);
        if (size < sizeof text) {
            hid_t mem = H5Tcopy(type); /* its size, padding and character set */
            if (H5Aread(a, mem, text) < 0) snprintf(text, sizeof text, "junk");
            text[size] = 0;
            H5Tclose(mem);
        }
    }
    H5Tclose(type);
    H5Aclose(a);
    H5Adelete(obj, name);
    hid_t space = H5Screate(H5S_SCALAR), nt;
    herr_t st = -1;
    if (as == 0) { /* the same text as a variable-length string, as h5py writes it */
        nt = H5Tcopy(H5T_C_S1);
        H5Tset_size(nt, H5T_VARIABLE);
        H5Tset_cset(nt, H5T_CSET_UTF8);
        const char *p = text;
        hid_t na = H5Acreate2(obj, name, nt, space, H5P_DEFAULT, H5P_DEFAULT);
        if (na >= 0) st = H5Awrite(na, nt, &p), H5Aclose(na);
        snprintf(what, len, "variable-length string '%s'", text);
    } else if (as == 1) { /* an empty fixed string */
        nt = H5Tcopy(H5T_C_S1);
        H5Tset_size(nt, 1);
        hid_t na = H5Acreate2(obj, name, nt, space, H5P_DEFAULT, H5P_DEFAULT);
        if (na >= 0) st = H5Awrite(na, nt, ""), H5Aclose(na);
        snprintf(what, len, "empty string");
    } else { /* a number */
        nt = H5Tcopy(H5T_NATIVE_DOUBLE);
        const double v = 2.5;
        hid_t na = H5Acreate2(obj, name, nt, space, H5P_DEFAULT, H5P_DEFAULT);
        if (na >= 0) st = H5Awrite(na, nt, &v), H5Aclose(na);
        snprintf(what, len, "the number 2.5");
    }
    H5Tclose(nt);
    H5Sclose(space);
    return st >= 0 ? what : NULL;
}

static const char *mutate(hid_t f, const target *t, int kind, uint64_t seed, char *what, size_t len)
{
    if (t->attr[0]) {
        hid_t o = H5Oopen(f, t->path, H5P_DEFAULT);
        if (o < 0) return NULL;
        const char *r = NULL;
        if (kind < 8) {
            hid_t a = H5Aopen(o, t->attr, H5P_DEFAULT);
            if (a >= 0) {
                r = poke(a, true, kind, seed, what, len);
                H5Aclose(a);
            }
            if (!r) r = remake_attr(o, t->attr, (int)(seed % 3), what, len);
        } else if (kind == 8) {
            if (H5Adelete(o, t->attr) >= 0) {
                snprintf(what, len, "deleted");
                r = what;
            }
        } else {
            r = remake_attr(o, t->attr, kind % 3, what, len);
        }
        H5Oclose(o);
        return r;
    }
    if (kind < 8) {
        hid_t d = H5Dopen2(f, t->path, H5P_DEFAULT);
        const char *r = d >= 0 ? poke(d, false, kind, seed, what, len) : NULL;
        if (d >= 0) H5Dclose(d);
        return r ? r : remake_dataset(f, t->path, -1, 2, what, len);
    }
    switch (kind) {
    case 8: return H5Ldelete(f, t->path, H5P_DEFAULT) >= 0 ? (snprintf(what, len, "deleted"), what) : NULL;
    case 9: return remake_dataset(f, t->path, 0, -1, what, len);
    case 10: return remake_dataset(f, t->path, (long long)(seed % 3) + 1, -1, what, len);
    case 11: return remake_dataset(f, t->path, 100000, -1, what, len);
    case 12: return remake_dataset(f, t->path, -1, (int)(seed % 2), what, len);
    default: return remake_dataset(f, t->path, -1, 2, what, len);
    }
}

int main(int argc, char **argv)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    if (argc == 3 && strcmp(argv[1], "list") == 0) {
        hid_t f = H5Fopen(argv[2], H5F_ACC_RDONLY, H5P_DEFAULT);
        if (f < 0) return 1;
        list_targets(f);
        for (int i = 0; i < ntargets; i++)
            printf(targets[i].attr[0] ? "A %s@%s\n" : "D %s\n", targets[i].path, targets[i].attr);
        H5Fclose(f);
        return 0;
    }
    if (argc == 7 && strcmp(argv[1], "apply") == 0) {
        if (copy_file(argv[2], argv[3])) return 1;
        hid_t f = H5Fopen(argv[3], H5F_ACC_RDWR, H5P_DEFAULT);
        if (f < 0) return 1;
        list_targets(f);
        if (ntargets == 0) return 1;
        const target *t = &targets[strtoull(argv[4], NULL, 10) % (unsigned long long)ntargets];
        const int kind = (int)(strtoull(argv[5], NULL, 10) % NKINDS);
        char what[256];
        const char *r = mutate(f, t, kind, strtoull(argv[6], NULL, 10), what, sizeof what);
        printf("%s%s%s: %s\n", t->path, t->attr[0] ? "@" : "", t->attr, r ? r : "unchanged (no such mutation)");
        return H5Fclose(f) < 0;
    }
    fprintf(stderr, "usage: h5mutate list FILE | h5mutate apply IN OUT TARGET KIND SEED\n");
    return 1;
}
