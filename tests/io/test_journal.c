/* The journal under files appended in place (src/io/journal.c), at the
 * level of its file driver: what reads back between flushes, which journal
 * an open applies, and which it must refuse or ignore. */
#include "io_scenes.h"

#include <fcntl.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "h5util.h"

static H5FD_t *open_driver(const char *path, unsigned flags)
{
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    ck_assert_int_ge(fapl, 0);
    ck_assert_int_ge(H5Pset_driver(fapl, sx_h5_journal_driver(), NULL), 0);
    H5FD_t *f = H5FDopen(path, flags, fapl, HADDR_UNDEF);
    H5Pclose(fapl);
    return f;
}

static void put(H5FD_t *f, haddr_t at, size_t n, char c)
{
    char b[256];
    ck_assert_uint_le(n, sizeof b);
    memset(b, c, n);
    ck_assert_int_ge(H5FDwrite(f, H5FD_MEM_DRAW, H5P_DEFAULT, at, n, b), 0);
}

/* byte i of [0, 200) as the writes below leave it */
static char wanted(int i)
{
    static const struct {
        int end;
        char c;
    } runs[] = {{40, 'a'}, {50, 'e'}, {60, 'd'}, {90, 'a'}, {120, 'b'}, {130, 'c'}, {150, 'b'}, {200, 'z'}};
    size_t k = 0;
    while (i >= runs[k].end) k++;
    return runs[k].c;
}

static void expect(H5FD_t *f, const char *when)
{
    char b[200];
    ck_assert_int_ge(H5FDread(f, H5FD_MEM_DRAW, H5P_DEFAULT, 0, sizeof b, b), 0);
    for (int i = 0; i < 200; i++)
        ck_assert_msg(b[i] == wanted(i), "%s: byte %d is '%c', not '%c'", when, i, b[i], wanted(i));
}

/* A write that straddles the end of the last flush, then a newer write to
 * its part beyond that end: the newer bytes win, before and after the
 * flush and after reopening; overlapping overwrites keep their order. */
START_TEST(straddling_write_keeps_newer)
{
    char path[512];
    io_path(path, sizeof path, "straddle.bin");
    remove(path);
    H5FD_t *f = open_driver(path, H5F_ACC_RDWR | H5F_ACC_CREAT | H5F_ACC_TRUNC);
    ck_assert_ptr_nonnull(f);
    ck_assert_int_ge(H5FDset_eoa(f, H5FD_MEM_DRAW, 100), 0);
    put(f, 0, 100, 'a');
    ck_assert_int_ge(H5FDflush(f, H5P_DEFAULT, false), 0); /* the file ends at 100 */
    ck_assert_int_ge(H5FDset_eoa(f, H5FD_MEM_DRAW, 200), 0);
    put(f, 90, 60, 'b');  /* 90..150: straddles 100 */
    put(f, 120, 10, 'c'); /* beyond 100: newer than the 'b's there */
    put(f, 150, 50, 'z');
    put(f, 40, 20, 'd'); /* two overwrites of the same bytes: the later wins */
    put(f, 40, 10, 'e');
    expect(f, "before the flush");
    ck_assert_int_ge(H5FDflush(f, H5P_DEFAULT, false), 0);
    expect(f, "after the flush");
    ck_assert_int_ge(H5FDclose(f), 0);
    f = open_driver(path, H5F_ACC_RDONLY);
    ck_assert_ptr_nonnull(f);
    ck_assert_int_ge(H5FDset_eoa(f, H5FD_MEM_DRAW, 200), 0);
    expect(f, "reopened");
    ck_assert_int_ge(H5FDclose(f), 0);
    remove(path);
}
END_TEST

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 1099511628211ULL;
    return h;
}

/* A complete journal beside path (the format docs/file-format.md gives)
 * that zeroes the file's first 8 bytes: the superblock's signature. */
static void write_journal(const char *path)
{
    char name[600];
    snprintf(name, sizeof name, "%s.journal", path);
    unsigned char b[256];
    size_t n = 0;
    memcpy(b, "SXJOURN1", 8), n += 8;
    const uint64_t head[2] = {0, 8};
    memcpy(b + n, head, sizeof head), n += sizeof head;
    memset(b + n, 0, 8), n += 8;
    const uint64_t tail[2] = {1, UINT64_MAX};
    memcpy(b + n, tail, sizeof tail), n += sizeof tail;
    const uint64_t h = fnv(1469598103934665603ULL, b, n);
    memcpy(b + n, &h, sizeof h), n += sizeof h;
    memcpy(b + n, "SXJEND01", 8), n += 8;
    FILE *out = fopen(name, "wb");
    ck_assert_ptr_nonnull(out);
    ck_assert_uint_eq(fwrite(b, 1, n, out), n);
    ck_assert_int_eq(fclose(out), 0);
}

static sx_series *open_series(const char *path, bool append)
{
    sx_series_opts o;
    memset(&o, 0, sizeof o);
    o.append = append;
    char err[512];
    sx_series *s = sx_series_open(path, 3, &o, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    return s;
}

/* A series created anew under the name of one whose writer was killed in
 * a flush: the old file's journal is not applied to the new file. */
START_TEST(stale_journal_not_applied)
{
    char path[512], err[512];
    io_path(path, sizeof path, "stale.h5");
    ck_assert_int_eq(sx_series_close(open_series(path, false), err, sizeof err), SX_OK);
    /* the journal is one an open applies: appended to, the file is damaged */
    write_journal(path);
    ck_assert_int_lt(sx_series_read_count(path, err, sizeof err), 0);
    /* a new series of that name: the old journal must not reach it */
    ck_assert_int_eq(sx_series_close(open_series(path, false), err, sizeof err), SX_OK);
    write_journal(path);
    sx_series *s = open_series(path, false);
    ck_assert_int_eq(sx_series_count(s), 0);
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    ck_assert_msg(sx_series_read_count(path, err, sizeof err) == 0, "%s", err);
    char journal[600];
    snprintf(journal, sizeof journal, "%s.journal", path);
    ck_assert_int_ne(access(journal, F_OK), 0);
    /* an exclusive create that fails (the file exists) leaves its journal */
    write_journal(path);
    H5FD_t *f = open_driver(path, H5F_ACC_RDWR | H5F_ACC_CREAT | H5F_ACC_EXCL);
    ck_assert_ptr_null(f);
    H5Eclear2(H5E_DEFAULT);
    ck_assert_int_eq(access(journal, F_OK), 0);
    /* a truncating create drops it */
    f = open_driver(path, H5F_ACC_RDWR | H5F_ACC_CREAT | H5F_ACC_TRUNC);
    ck_assert_ptr_nonnull(f);
    ck_assert_int_ne(access(journal, F_OK), 0);
    ck_assert_int_ge(H5FDclose(f), 0);
    io_assert_no_handles();
}
END_TEST

/* A journal that cannot be read (here a folder of that name) may be a
 * complete one: the open fails, naming it, and leaves it in place. */
START_TEST(unreadable_journal_refused)
{
    char path[512], journal[600], err[512];
    io_path(path, sizeof path, "unreadable.h5");
    ck_assert_int_eq(sx_series_close(open_series(path, false), err, sizeof err), SX_OK);
    snprintf(journal, sizeof journal, "%s.journal", path);
    ck_assert_int_eq(mkdir(journal, 0755), 0);
    ck_assert_ptr_null(open_driver(path, H5F_ACC_RDONLY));
    H5Eclear2(H5E_DEFAULT);
    ck_assert_int_lt(sx_series_read_count(path, err, sizeof err), 0);
    ck_assert_msg(strstr(err, "journal") && strstr(err, "unreadable.h5"), "%s", err);
    struct stat st;
    ck_assert_int_eq(stat(journal, &st), 0);
    ck_assert(S_ISDIR(st.st_mode));
    ck_assert_int_eq(rmdir(journal), 0);
    ck_assert_msg(sx_series_read_count(path, err, sizeof err) == 0, "%s", err);
    io_assert_no_handles();
}
END_TEST

/* Bytes [0, 100) of the driver's file all c. */
static void expect_all(H5FD_t *f, char c, const char *when)
{
    char b[100];
    ck_assert_int_ge(H5FDread(f, H5FD_MEM_DRAW, H5P_DEFAULT, 0, sizeof b, b), 0);
    for (int i = 0; i < 100; i++) ck_assert_msg(b[i] == c, "%s: byte %d is '%c', not '%c'", when, i, b[i], c);
}

/* A flush that fails after its journal is complete (the file's writes
 * fail) leaves the journal, and no later flush rewrites it: the next open
 * applies it. Retried, a flush would rewrite the journal from its start,
 * and a kill then would leave a half-written file with no journal. */
START_TEST(failed_commit_keeps_journal)
{
    char path[512], journal[600];
    io_path(path, sizeof path, "failed.bin");
    snprintf(journal, sizeof journal, "%s.journal", path);
    remove(path);
    H5FD_t *f = open_driver(path, H5F_ACC_RDWR | H5F_ACC_CREAT | H5F_ACC_TRUNC);
    ck_assert_ptr_nonnull(f);
    ck_assert_int_ge(H5FDset_eoa(f, H5FD_MEM_DRAW, 100), 0);
    put(f, 0, 100, 'a');
    ck_assert_int_ge(H5FDflush(f, H5P_DEFAULT, false), 0);
    put(f, 0, 100, 'b'); /* an overwrite: journaled */
    /* the driver's descriptor made read-only: the file's writes fail */
    void *handle = NULL;
    ck_assert_int_ge(H5FDget_vfd_handle(f, H5P_DEFAULT, &handle), 0);
    const int fd = *(int *)handle, saved = dup(fd), ro = open(path, O_RDONLY);
    ck_assert_int_ge(saved, 0);
    ck_assert_int_ge(ro, 0);
    ck_assert_int_eq(dup2(ro, fd), fd);
    ck_assert_int_lt(H5FDflush(f, H5P_DEFAULT, false), 0);
    ck_assert_int_eq(access(journal, F_OK), 0);
    /* the descriptor back: still no flush succeeds, the journal stays */
    ck_assert_int_eq(dup2(saved, fd), fd);
    close(saved);
    close(ro);
    put(f, 0, 100, 'c');
    expect_all(f, 'c', "after the failed flush");
    ck_assert_int_lt(H5FDflush(f, H5P_DEFAULT, false), 0);
    ck_assert_int_lt(H5FDclose(f), 0);
    H5Eclear2(H5E_DEFAULT);
    ck_assert_int_eq(access(journal, F_OK), 0);
    /* the open completes the flush that failed */
    f = open_driver(path, H5F_ACC_RDONLY);
    ck_assert_ptr_nonnull(f);
    ck_assert_int_ne(access(journal, F_OK), 0);
    ck_assert_int_ge(H5FDset_eoa(f, H5FD_MEM_DRAW, 100), 0);
    expect_all(f, 'b', "reopened");
    ck_assert_int_ge(H5FDclose(f), 0);
    remove(path);
}
END_TEST

/* While HDF5 holds the file open (and locked), another open leaves its
 * journal alone: it may be its live writer's, half-written. */
START_TEST(journal_of_open_file_left_alone)
{
    char path[512], journal[600], err[512];
    io_path(path, sizeof path, "locked.h5");
    ck_assert_int_eq(sx_series_close(open_series(path, false), err, sizeof err), SX_OK);
    const hid_t held = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    ck_assert_int_ge(held, 0);
    write_journal(path);
    snprintf(journal, sizeof journal, "%s.journal", path);
    H5FD_t *f = open_driver(path, H5F_ACC_RDONLY);
    ck_assert_ptr_nonnull(f);
    ck_assert_int_ge(H5FDclose(f), 0);
    ck_assert_int_eq(access(journal, F_OK), 0);
    char sig[8];
    FILE *in = fopen(path, "rb");
    ck_assert_ptr_nonnull(in);
    ck_assert_uint_eq(fread(sig, 1, sizeof sig, in), sizeof sig);
    fclose(in);
    ck_assert_int_eq(memcmp(sig, "\211HDF\r\n\032\n", 8), 0);
    ck_assert_int_ge(H5Fclose(held), 0);
    ck_assert_int_eq(remove(journal), 0);
    io_assert_no_handles();
}
END_TEST

/* The driver claims no SWMR support: a reader in SWMR mode would read the
 * file while overwrites wait in the writer's memory. */
START_TEST(no_swmr)
{
    char path[512];
    io_path(path, sizeof path, "query.bin");
    H5FD_t *f = open_driver(path, H5F_ACC_RDWR | H5F_ACC_CREAT | H5F_ACC_TRUNC);
    ck_assert_ptr_nonnull(f);
    unsigned long flags = 0;
    ck_assert_int_ge(H5FDquery(f, &flags), 0);
    ck_assert_uint_eq(flags & H5FD_FEAT_SUPPORTS_SWMR_IO, 0);
    ck_assert_uint_ne(flags & H5FD_FEAT_POSIX_COMPAT_HANDLE, 0);
    ck_assert_int_ge(H5FDclose(f), 0);
    remove(path);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_journal");
    TCase *tc = tcase_create("journal");
    tcase_add_test(tc, straddling_write_keeps_newer);
    tcase_add_test(tc, stale_journal_not_applied);
    tcase_add_test(tc, unreadable_journal_refused);
    tcase_add_test(tc, failed_commit_keeps_journal);
    tcase_add_test(tc, journal_of_open_file_left_alone);
    tcase_add_test(tc, no_swmr);
    suite_add_tcase(s, tc);
    return io_run_suite(s);
}
