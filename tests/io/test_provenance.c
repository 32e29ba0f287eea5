/* What a file says about itself: provenance attributes (format, version,
 * commit, script and the SHA-256 of its text, seeds, dim, units, time,
 * step), SHA-256 itself against FIPS 180 examples, and value trees
 * (every kind, any bytes) round-tripping through a snapshot. */
#include "io_scenes.h"
#include "sha256.h"

#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

START_TEST(sha256_vectors)
{
    char hex[65];
    sx_sha256 s;
    sx_sha256_init(&s);
    sx_sha256_update(&s, "abc", 3);
    sx_sha256_hex(&s, hex);
    ck_assert_str_eq(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    sx_sha256_init(&s);
    sx_sha256_hex(&s, hex);
    ck_assert_str_eq(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    sx_sha256_init(&s);
    const char *two = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
    sx_sha256_update(&s, two, strlen(two));
    sx_sha256_hex(&s, hex);
    ck_assert_str_eq(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
    /* a million 'a', fed in uneven pieces */
    sx_sha256_init(&s);
    char a[1000];
    memset(a, 'a', sizeof a);
    for (int k = 0, left = 1000000; left > 0; k++) {
        const int n = left < 1 + (k * 37) % 1000 ? left : 1 + (k * 37) % 1000;
        sx_sha256_update(&s, a, (size_t)n);
        left -= n;
    }
    sx_sha256_hex(&s, hex);
    ck_assert_str_eq(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
    ck_assert(!sx_sha256_file("/nonexistent/file", hex));
    ck_assert_str_eq(hex, "");
}
END_TEST

static void attr_str(hid_t f, const char *name, char *out, size_t len)
{
    hid_t a = H5Aopen(f, name, H5P_DEFAULT);
    ck_assert_msg(a >= 0, "no attribute %s", name);
    hid_t t = H5Aget_type(a);
    const size_t n = H5Tget_size(t);
    ck_assert(n < len);
    memset(out, 0, len);
    ck_assert(H5Aread(a, t, out) >= 0);
    H5Tclose(t);
    H5Aclose(a);
}

START_TEST(provenance)
{
    char script[512], p[512], err[1024];
    io_path(script, sizeof script, "run.lua");
    FILE *f = fopen(script, "wb");
    fputs("local m = seixo.model{dim = 2}\n", f);
    fclose(f);
    sx_model *m = io_scene_granular(2, 20);
    io_cycle(m, 7);
    const int64_t seeds[] = {7, 4242};
    sx_snapshot_opts o;
    memset(&o, 0, sizeof o);
    o.provenance.script = script;
    o.provenance.seeds = seeds;
    o.provenance.nseeds = 2;
    ck_assert_int_eq(sx_snapshot_save(m, io_path(p, sizeof p, "prov.h5"), &o, err, sizeof err), SX_OK);

    hid_t h = H5Fopen(p, H5F_ACC_RDONLY, H5P_DEFAULT);
    char s[256], want[65];
    attr_str(h, "format", s, sizeof s);
    ck_assert_str_eq(s, "seixo");
    attr_str(h, "kind", s, sizeof s);
    ck_assert_str_eq(s, "snapshot");
    attr_str(h, "units", s, sizeof s);
    ck_assert_str_eq(s, "SI");
    attr_str(h, "seixo_version", s, sizeof s);
    ck_assert_str_eq(s, SX_VERSION);
    attr_str(h, "git_commit", s, sizeof s);
    ck_assert_str_eq(s, sx_io_git_commit());
    ck_assert(strlen(s) > 0);
    attr_str(h, "script", s, sizeof s);
    ck_assert_str_eq(s, script);
    attr_str(h, "script_sha256", s, sizeof s);
    ck_assert(sx_sha256_file(script, want));
    ck_assert_str_eq(s, want);
    attr_str(h, "created", s, sizeof s);
    ck_assert_int_eq(strlen(s), 20); /* 2026-01-02T03:04:05Z */
    int64_t v[2] = {0, 0};
    hid_t a = H5Aopen(h, "seeds", H5P_DEFAULT);
    ck_assert(H5Aread(a, H5T_NATIVE_INT64, v) >= 0);
    H5Aclose(a);
    ck_assert(v[0] == 7 && v[1] == 4242);
    a = H5Aopen(h, "dim", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_INT64, v);
    H5Aclose(a);
    ck_assert_int_eq(v[0], 2);
    a = H5Aopen(h, "step", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_INT64, v);
    H5Aclose(a);
    ck_assert_int_eq(v[0], 7);
    double t;
    a = H5Aopen(h, "time", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, &t);
    H5Aclose(a);
    ck_assert(t == sx_model_time(m));
    H5Fclose(h);

    sx_snapshot_info info;
    sx_model *b = sx_snapshot_load(p, 2, &info, err, sizeof err);
    ck_assert_msg(b, "%s", err);
    ck_assert_int_eq(info.format_version, SX_IO_FORMAT_VERSION);
    ck_assert_str_eq(info.script, script);
    ck_assert_str_eq(info.script_sha256, want);
    ck_assert_str_eq(info.git_commit, sx_io_git_commit());
    sx_snapshot_info_free(&info);
    sx_model_destroy(b);
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

START_TEST(trees)
{
    sx_io_named_tree in[2];
    memset(in, 0, sizeof in);
    snprintf(in[0].name, sizeof in[0].name, "vars");
    snprintf(in[1].name, sizeof in[1].name, "empty");
    sx_io_tree *t = &in[0].tree;
    const char bin[] = {'x', 0, (char)0xff, 'y'};
    sx_io_node n = {.parent = -1, .key_kind = SX_IO_STRING, .key_string = "n", .key_length = 1, .kind = SX_IO_NUMBER,
                    .number = -0.1};
    ck_assert_int_eq(sx_io_tree_add(t, &n), 0);
    n = (sx_io_node){.parent = -1, .key_kind = SX_IO_INTEGER, .key_integer = -3, .kind = SX_IO_INTEGER,
                     .integer = INT64_MIN};
    ck_assert_int_eq(sx_io_tree_add(t, &n), 1);
    n = (sx_io_node){.parent = -1, .key_kind = SX_IO_BOOLEAN, .key_integer = 1, .kind = SX_IO_TABLE};
    ck_assert_int_eq(sx_io_tree_add(t, &n), 2);
    n = (sx_io_node){.parent = 2, .key_kind = SX_IO_STRING, .key_string = (char *)bin, .key_length = 4,
                     .kind = SX_IO_STRING, .string = (char *)bin, .length = 4};
    ck_assert_int_eq(sx_io_tree_add(t, &n), 3);
    n = (sx_io_node){.parent = 2, .key_kind = SX_IO_NUMBER, .key_number = 0.5, .kind = SX_IO_BOOLEAN, .integer = 0};
    ck_assert_int_eq(sx_io_tree_add(t, &n), 4);

    sx_model *m = io_scene_granular(3, 10);
    char p[512], err[1024];
    sx_snapshot_opts o;
    memset(&o, 0, sizeof o);
    o.trees = in;
    o.ntrees = 2;
    o.compression = 9;
    ck_assert_int_eq(sx_snapshot_save(m, io_path(p, sizeof p, "trees.h5"), &o, err, sizeof err), SX_OK);
    sx_snapshot_info info;
    sx_model *b = sx_snapshot_load(p, 3, &info, err, sizeof err);
    ck_assert_msg(b, "%s", err);
    ck_assert_int_eq(info.ntrees, 2);
    const sx_io_tree *r = NULL;
    for (int k = 0; k < 2; k++)
        if (strcmp(info.trees[k].name, "vars") == 0) r = &info.trees[k].tree;
        else ck_assert_int_eq(info.trees[k].tree.n, 0);
    ck_assert_ptr_nonnull(r);
    ck_assert_int_eq(r->n, 5);
    ck_assert(r->node[0].number == -0.1 && r->node[0].kind == SX_IO_NUMBER);
    ck_assert(r->node[1].integer == INT64_MIN && r->node[1].key_integer == -3);
    ck_assert(r->node[2].kind == SX_IO_TABLE && r->node[2].key_kind == SX_IO_BOOLEAN);
    ck_assert(r->node[3].parent == 2 && r->node[3].length == 4 && memcmp(r->node[3].string, bin, 4) == 0);
    ck_assert(r->node[3].key_length == 4 && memcmp(r->node[3].key_string, bin, 4) == 0);
    ck_assert(r->node[4].key_number == 0.5 && r->node[4].kind == SX_IO_BOOLEAN);
    sx_snapshot_info_free(&info);
    sx_model_destroy(b);

    /* a child before its parent is damage */
    hid_t f = H5Fopen(p, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t d = H5Dopen2(f, "/lua/vars/parent", H5P_DEFAULT);
    int64_t parents[5] = {-1, -1, -1, 4, 2};
    ck_assert(H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, parents) >= 0);
    io_drop_checksum(d);
    H5Dclose(d);
    H5Fclose(f);
    ck_assert_ptr_null(sx_snapshot_load(p, 3, NULL, err, sizeof err));
    ck_assert_msg(strstr(err, "damaged: entry 3 of /lua/vars is inconsistent"), "%s", err);
    io_assert_no_handles();
    sx_io_tree_free(&in[0].tree);
    sx_model_destroy(m);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_provenance");
    TCase *tc = tcase_create("provenance");
    tcase_add_test(tc, sha256_vectors);
    tcase_add_test(tc, provenance);
    tcase_add_test(tc, trees);
    suite_add_tcase(s, tc);
    return io_run_suite(s);
}
