/* Nothing is lost: a writer killed in the middle of a save leaves the
 * previous file intact (and loadable); a series whose writer is killed
 * still opens with every complete snapshot and every complete history
 * row, its XDMF is a complete document listing exactly the complete
 * snapshots, and it can be continued. The writers are child processes
 * killed with SIGKILL. */
/* pwrite and ftruncate below take the place of the C library's under their
 * own names, not the 64-bit aliases this macro selects; off_t is 64 bits
 * wide on the 64-bit systems the test runs on either way */
#undef _FILE_OFFSET_BITS
#include "io_scenes.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <hdf5.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* A big model quickly: balls on a lattice (no O(n^2) placement). */
static sx_model *lattice(int dim, int n)
{
    sx_model *m = scene_model(dim, NULL, 0, 1e6, 0.5, 2600);
    const int side = dim == 3 ? (int)ceil(cbrt((double)n)) : (int)ceil(sqrt((double)n));
    uint64_t s = 5;
    for (int i = 0; i < n; i++) {
        const double x[3] = {0.01 * (i % side), 0.01 * ((i / side) % side), dim == 3 ? 0.01 * (i / (side * side)) : 0};
        const double v[3] = {scene_rng_uniform(&s, -1, 1), scene_rng_uniform(&s, -1, 1), dim == 3 ? 0.5 : 0};
        sx_ball_def b = sx_ball_default_def();
        memcpy(b.pos, x, sizeof x);
        memcpy(b.vel, v, sizeof v);
        b.radius = 0.004;
        ck_assert_int_eq(sx_ball_add(m, &b, NULL), SX_OK);
    }
    return m;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void sleep_ms(long ms)
{
    struct timespec t = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

START_TEST(killed_save_keeps_previous)
{
    char path[512];
    io_path(path, sizeof path, "state.h5");
    sx_model *a = io_scene_granular(3, 40);
    io_cycle(a, 10);
    io_save(a, path);
    const uint64_t ha = sx_model_state_hash(a);
    sx_model_destroy(a);
    sx_model *big = lattice(3, 200000);
    const uint64_t hb = sx_model_state_hash(big);

    /* kill times from "before any save finished" to "after several", scaled
     * by how long a save takes here (sanitizers and valgrind are slower) */
    char timing[512];
    const double t0 = now();
    io_save(big, io_path(timing, sizeof timing, "timing.h5"));
    const double t_save = now() - t0;
    remove(timing);
    printf("  one save of %lld balls: %.0f ms\n", (long long)sx_ball_count(big), 1e3 * t_save);
    const long delays[] = {(long)(100 * t_save), (long)(600 * t_save), (long)(1500 * t_save), (long)(2500 * t_save),
                           (long)(4200 * t_save)};
    int saw_a = 0, saw_b = 0;
    for (size_t k = 0; k < sizeof delays / sizeof *delays; k++) {
        int go[2];
        ck_assert_int_eq(pipe(go), 0);
        const pid_t pid = fork();
        ck_assert_int_ge(pid, 0);
        if (pid == 0) { /* the writer: saves the big model again and again */
            close(go[0]);
            char c = 1, err[512];
            ck_assert_int_eq(write(go[1], &c, 1), 1);
            for (;;)
                if (sx_snapshot_save(big, path, NULL, err, sizeof err)) _exit(3);
        }
        close(go[1]);
        char c;
        ck_assert_int_eq(read(go[0], &c, 1), 1);
        close(go[0]);
        sleep_ms(delays[k]);
        kill(pid, SIGKILL);
        int status;
        waitpid(pid, &status, 0);
        ck_assert_msg(WIFSIGNALED(status), "the writer ended by itself (status %d)", status);
        sx_model *m = io_load(path, 3);
        const uint64_t h = sx_model_state_hash(m);
        ck_assert_msg(h == ha || h == hb, "killed after %ld ms: the file holds neither complete state", delays[k]);
        saw_a += h == ha, saw_b += h == hb;
        printf("  killed after %4ld ms: %s\n", delays[k], h == ha ? "the previous file" : "the completed save");
        fflush(stdout);
        sx_model_destroy(m);
    }
    ck_assert_msg(saw_a > 0 && saw_b > 0, "the kills did not cover both sides of a completed save");
    sx_model_destroy(big);
}
END_TEST

static int count_steps(const char *xmf)
{
    FILE *f = fopen(xmf, "rb");
    ck_assert_ptr_nonnull(f);
    char line[4096];
    int n = 0;
    bool closed = false;
    while (fgets(line, sizeof line, f)) {
        n += strstr(line, "/balls/vertices</DataItem>") != NULL; /* the balls' grid of each snapshot */
        closed = strstr(line, "</Xdmf>") != NULL;
    }
    fclose(f);
    ck_assert_msg(closed, "%s does not end with </Xdmf>", xmf);
    return n;
}

/* The history the writers append: one sample per write, at step 5 i,
 * whose value is a function of its step (so any row can be checked). */
static double hvalue(int64_t step) { return 0.5 * (double)step + 1.0 / (1.0 + (double)step); }

typedef struct hist_buf {
    sx_io_history h;
    int64_t steps[32768];
    double times[32768], values[32768];
} hist_buf;

static void hist_init(hist_buf *b)
{
    memset(b, 0, sizeof *b);
    b->h.name = "probe";
    b->h.every = 5;
    b->h.source = SX_IO_SOURCE_BUILTIN;
    b->h.builtin = "time";
    b->h.steps = b->steps, b->h.times = b->times, b->h.values = b->values;
}

static void hist_add(hist_buf *b, int64_t step)
{
    ck_assert_int_lt(b->h.n, 32768);
    b->steps[b->h.n] = step, b->times[b->h.n] = 1e-3 * (double)step, b->values[b->h.n] = hvalue(step);
    b->h.n++;
}

/* What the checks below are looking at, for their messages. */
static char checking[128];

/* The complete rows of the series' history: counted, increasing, each
 * value that of its step; returns them and the last step. */
static int64_t check_history(const char *path, int64_t *last)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    ck_assert(f >= 0);
    *last = -1;
    hid_t g = -1;
    if (H5Lexists(f, "/histories", H5P_DEFAULT) <= 0) {
        H5Fclose(f);
        return 0;
    }
    /* a history's group whose header a kill kept from the disk holds no
     * complete row (the caller compares the rows with the snapshots) */
    H5E_BEGIN_TRY { g = H5Gopen2(f, "/histories/probe", H5P_DEFAULT); } H5E_END_TRY;
    if (g < 0) {
        H5Fclose(f);
        return 0;
    }
    int64_t count = -1;
    hid_t a = H5Aopen(g, "count", H5P_DEFAULT);
    ck_assert(a >= 0 && H5Aread(a, H5T_NATIVE_INT64, &count) >= 0);
    H5Aclose(a);
    hid_t ds = H5Dopen2(g, "step", H5P_DEFAULT), dv = H5Dopen2(g, "value", H5P_DEFAULT);
    hid_t sp = H5Dget_space(ds);
    hsize_t rows = 0, maxr = 0;
    H5Sget_simple_extent_dims(sp, &rows, &maxr);
    ck_assert(maxr == H5S_UNLIMITED);
    ck_assert_msg(count >= 0 && (hsize_t)count <= rows, "count %lld of %llu rows", (long long)count,
                  (unsigned long long)rows);
    int64_t *st = malloc((rows + 1) * sizeof *st);
    double *v = malloc((rows + 1) * sizeof *v);
    ck_assert_msg(H5Dread(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, st) >= 0 &&
                      H5Dread(dv, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0,
                  "%sthe history's rows cannot be read", checking);
    for (int64_t i = 0; i < count; i++) {
        ck_assert_msg(st[i] == 5 * i, "row %lld has step %lld", (long long)i, (long long)st[i]);
        ck_assert(v[i] == hvalue(st[i]));
    }
    if (count > 0) *last = st[count - 1];
    free(st);
    free(v);
    H5Sclose(sp);
    H5Dclose(ds);
    H5Dclose(dv);
    H5Gclose(g);
    H5Fclose(f);
    return count;
}

/* Every dataset of every complete snapshot reads back. */
static void read_all(const char *path, int64_t count)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    ck_assert(f >= 0);
    for (int64_t k = 0; k < count; k++) {
        char name[64];
        const char *ds[] = {"balls/position", "balls/velocity", "balls/radius", "contacts/connectivity",
                            "walls/points"};
        for (size_t q = 0; q < sizeof ds / sizeof *ds; q++) {
            snprintf(name, sizeof name, "/snapshots/%06lld/%s", (long long)k, ds[q]);
            hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
            ck_assert_msg(d >= 0, "%s%s is missing", checking, name);
            hid_t s = H5Dget_space(d), t = H5Dget_type(d);
            const hssize_t np = H5Sget_simple_extent_npoints(s);
            void *buf = malloc((size_t)(np > 0 ? np : 1) * H5Tget_size(t));
            ck_assert_msg(np == 0 || H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0, "%s unreadable", name);
            free(buf);
            H5Tclose(t);
            H5Sclose(s);
            H5Dclose(d);
        }
    }
    H5Fclose(f);
}

START_TEST(killed_series_keeps_snapshots)
{
    char path[512], xmf[512];
    io_path(path, sizeof path, "series.h5");
    io_path(xmf, sizeof xmf, "series.xmf");
    const long delays[] = {30, 250, 700};
    for (size_t k = 0; k < sizeof delays / sizeof *delays; k++) {
        int go[2];
        ck_assert_int_eq(pipe(go), 0);
        const pid_t pid = fork();
        ck_assert_int_ge(pid, 0);
        if (pid == 0) {
            close(go[0]);
            sx_model *m = io_scene_granular(3, 60);
            sx_model *big = lattice(3, 50000);
            char err[512];
            sx_series_opts o;
            memset(&o, 0, sizeof o);
            o.fields = SX_OUT_DEFAULT | SX_OUT_MOMENT | SX_OUT_MASS | SX_OUT_MATERIAL;
            sx_series *s = sx_series_open(path, 3, &o, err, sizeof err);
            if (!s) _exit(3);
            static hist_buf hb;
            hist_init(&hb);
            char c = 1;
            ck_assert_int_eq(write(go[1], &c, 1), 1);
            for (int i = 0;; i++) {
                hist_add(&hb, 5 * i);
                if (sx_series_write(s, i % 2 ? big : m, &hb.h, 1, err, sizeof err)) _exit(4);
                sx_model_cycle(m, 5);
            }
        }
        close(go[1]);
        char c;
        ck_assert_int_eq(read(go[0], &c, 1), 1);
        close(go[0]);
        sleep_ms(delays[k]);
        kill(pid, SIGKILL);
        int status;
        waitpid(pid, &status, 0);
        ck_assert_msg(WIFSIGNALED(status), "the writer ended by itself (status %d)", status);
        char err[512];
        const int64_t count = sx_series_read_count(path, err, sizeof err);
        ck_assert_msg(count >= 0, "%s", err);
        read_all(path, count);
        const int steps = count_steps(xmf);
        int64_t last;
        const int64_t rows = check_history(path, &last);
        printf("  killed after %4ld ms: %lld complete snapshots, %d in the XDMF, %lld history rows\n", delays[k],
               (long long)count, steps, (long long)rows);
        fflush(stdout);
        ck_assert_int_eq(steps, count);
        /* a snapshot's rows are counted with it (one flush raises both) */
        ck_assert(rows == count || rows == count + 1 || rows == count - 1);
        /* the series continues where it stopped; its XDMF is rebuilt; the
         * history takes only the samples after its last complete row */
        sx_series_opts o;
        memset(&o, 0, sizeof o);
        o.append = true;
        sx_series *s = sx_series_open(path, 3, &o, err, sizeof err);
        ck_assert_msg(s, "%s", err);
        ck_assert_int_eq(sx_series_count(s), count);
        ck_assert_int_eq(count_steps(xmf), count);
        sx_model *m = io_scene_granular(3, 30);
        static hist_buf hb;
        hist_init(&hb);
        for (int64_t i = 0; i <= rows + 2; i++) hist_add(&hb, 5 * i);
        ck_assert_msg(sx_series_write(s, m, &hb.h, 1, err, sizeof err) == SX_OK, "%s", err);
        ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
        sx_model_destroy(m);
        ck_assert_int_eq(sx_series_read_count(path, err, sizeof err), count + 1);
        ck_assert_int_eq(count_steps(xmf), count + 1);
        ck_assert_int_eq(check_history(path, &last), rows + 3);
        ck_assert_int_eq(last, 5 * (rows + 2));
        read_all(path, count + 1);
        io_assert_no_handles();
    }
}
END_TEST

/* The object header of `object` in the file at path overwritten with
 * zeros, as when a writer is killed after the link to a new object reached
 * the disk (HDF5's cache may evict a group's header, with its new link,
 * before the new object's own header) and before the object did. */
static void zero_header(const char *path, const char *object)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    H5O_info_t oi;
    ck_assert(f >= 0 && H5Oget_info_by_name(f, object, &oi, H5P_DEFAULT) >= 0);
    H5Fclose(f);
    FILE *fp = fopen(path, "r+b");
    const char zeros[16] = {0};
    ck_assert(fp && fseek(fp, (long)oi.addr, SEEK_SET) == 0 && fwrite(zeros, 1, sizeof zeros, fp) == sizeof zeros);
    fclose(fp);
}

/* What a killed add leaves, made on purpose (the kills above meet these
 * states only by chance): a series of 2 complete snapshots and 2 history
 * rows, then (0) the link /snapshots/000002 to a group whose header never
 * reached the disk, (1) that and a history met for the first time whose
 * group never reached the disk, (2) a complete snapshot 2 the count does
 * not include yet, (3) a snapshot 2 one of whose datasets' headers never
 * reached the disk (the group reads, its deletion does not). The series
 * continues: the next add succeeds, every complete snapshot and history
 * row is kept, and the XDMF lists exactly the complete snapshots. */
START_TEST(killed_add_recovers)
{
    char path[512], xmf[512], err[512];
    io_path(path, sizeof path, "left.h5");
    io_path(xmf, sizeof xmf, "left.xmf");
    sx_model *m = io_scene_granular(3, 40);
    static hist_buf hb;
    for (int k = 0; k < 4; k++) {
        hist_init(&hb);
        sx_series *s = sx_series_open(path, 3, NULL, err, sizeof err);
        ck_assert_msg(s, "%s", err);
        for (int i = 0; i < 2; i++) {
            hist_add(&hb, 5 * i);
            ck_assert_msg(sx_series_write(s, m, &hb.h, 1, err, sizeof err) == SX_OK, "%s", err);
        }
        if (k == 2 || k == 3) {
            /* the add of snapshot 2, stopped after its data was written */
            ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
            hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
            hid_t g = H5Gopen2(f, "/snapshots/000001", H5P_DEFAULT);
            ck_assert(H5Ocopy(g, ".", f, "/snapshots/000002", H5P_DEFAULT, H5P_DEFAULT) >= 0);
            H5Gclose(g);
            H5Fclose(f);
            if (k == 3) zero_header(path, "/snapshots/000002/balls/position");
        } else {
            ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
            hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
            H5Gclose(H5Gcreate2(f, "/snapshots/000002", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
            if (k == 1) H5Gclose(H5Gcreate2(f, "/histories/late", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
            H5Fclose(f);
            zero_header(path, "/snapshots/000002");
            if (k == 1) zero_header(path, "/histories/late");
        }
        ck_assert_int_eq(sx_series_read_count(path, err, sizeof err), 2);
        /* the series continues */
        sx_series_opts o;
        memset(&o, 0, sizeof o);
        o.append = true;
        s = sx_series_open(path, 3, &o, err, sizeof err);
        ck_assert_msg(s, "case %d: %s", k, err);
        static hist_buf late;
        hist_init(&late);
        late.h.name = "late";
        hist_add(&late, 0);
        hist_add(&late, 5);
        sx_io_history both[2] = {hb.h, late.h};
        hist_add(&hb, 10);
        both[0] = hb.h;
        ck_assert_msg(sx_series_write(s, m, both, 2, err, sizeof err) == SX_OK, "case %d: %s", k, err);
        ck_assert_msg(sx_series_write(s, m, both, 2, err, sizeof err) == SX_OK, "case %d: %s", k, err);
        ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
        ck_assert_int_eq(sx_series_read_count(path, err, sizeof err), 4);
        ck_assert_int_eq(count_steps(xmf), 4);
        read_all(path, 4);
        int64_t last;
        ck_assert_int_eq(check_history(path, &last), 3);
        ck_assert_int_eq(last, 10);
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        hid_t a = H5Aopen_by_name(f, "/histories/late", "count", H5P_DEFAULT, H5P_DEFAULT);
        int64_t late_rows = -1;
        ck_assert(a >= 0 && H5Aread(a, H5T_NATIVE_INT64, &late_rows) >= 0);
        H5Aclose(a);
        H5Fclose(f);
        ck_assert_int_eq(late_rows, 2);
        /* every snapshot loads as the series' reader (the XDMF) names it */
        ck_assert_int_eq(sx_series_write_xdmf(path, err, sizeof err), SX_OK);
        ck_assert_int_eq(count_steps(xmf), 4);
        io_assert_no_handles();
    }
    sx_model_destroy(m);
}
END_TEST


/* ------------------------------------------- every write, replayed */

/* The writes to a series file and to its journal (see src/io/journal.c),
 * recorded while armed: each pwrite (HDF5's sec2 driver and the journal
 * write only with pwrite), each ftruncate and the journal's removal, in
 * order, so that the files as a kill after any of them left them can be
 * rebuilt. The functions below take the place of the C library's for the
 * whole test (HDF5's calls included) and pass every call on. */
typedef enum { EV_WRITE, EV_TRUNCATE, EV_REMOVE } ev_kind;

typedef struct rec_event {
    bool journal; /* to the journal, else to the file */
    ev_kind kind;
    off_t at;     /* where the bytes go, or the new size */
    size_t n;
    char *bytes;
} rec_event;

static struct {
    bool armed;
    dev_t dev;
    ino_t ino;
    char journal[600];
    rec_event *ev;
    size_t nev, cap;
} rec;

/* 1: the series file, 2: its journal, 0: another file */
static int rec_which(int fd)
{
    struct stat st, js;
    if (!rec.armed || fstat(fd, &st) != 0) return 0;
    if (st.st_dev == rec.dev && st.st_ino == rec.ino) return 1;
    return stat(rec.journal, &js) == 0 && js.st_dev == st.st_dev && js.st_ino == st.st_ino ? 2 : 0;
}

static void rec_push(int which, ev_kind kind, off_t at, const void *bytes, size_t n)
{
    if (rec.nev == rec.cap) {
        rec.cap = rec.cap ? 2 * rec.cap : 256;
        rec.ev = realloc(rec.ev, rec.cap * sizeof *rec.ev);
        ck_assert(rec.ev);
    }
    rec_event *e = &rec.ev[rec.nev++];
    *e = (rec_event){which == 2, kind, at, n, NULL};
    if (n) {
        e->bytes = malloc(n);
        ck_assert(e->bytes);
        memcpy(e->bytes, bytes, n);
    }
}

/* exported, so that HDF5's and seixo's calls reach them (the build hides symbols) */
#define EXPORTED __attribute__((visibility("default")))

static ssize_t written(const char *name, int fd, const void *buf, size_t n, off_t at)
{
    ssize_t (*next)(int, const void *, size_t, off_t) = (ssize_t (*)(int, const void *, size_t, off_t))dlsym(RTLD_NEXT, name);
    const int which = rec_which(fd);
    const ssize_t w = next(fd, buf, n, at);
    if (w > 0 && which) rec_push(which, EV_WRITE, at, buf, (size_t)w);
    return w;
}

/* HDF5 calls pwrite and ftruncate; seixo, built for large files, pwrite64
 * and ftruncate64 */
EXPORTED ssize_t pwrite(int fd, const void *buf, size_t n, off_t at) { return written("pwrite", fd, buf, n, at); }
EXPORTED ssize_t pwrite64(int fd, const void *buf, size_t n, off_t at) { return written("pwrite64", fd, buf, n, at); }

static int truncated(const char *name, int fd, off_t size)
{
    int (*next)(int, off_t) = (int (*)(int, off_t))dlsym(RTLD_NEXT, name);
    const int which = rec_which(fd);
    const int r = next(fd, size);
    if (r == 0 && which) rec_push(which, EV_TRUNCATE, size, NULL, 0);
    return r;
}

EXPORTED int ftruncate(int fd, off_t size) { return truncated("ftruncate", fd, size); }
EXPORTED int ftruncate64(int fd, off_t size) { return truncated("ftruncate64", fd, size); }

EXPORTED int unlink(const char *path)
{
    static int (*next)(const char *);
    if (!next) next = (int (*)(const char *))dlsym(RTLD_NEXT, "unlink");
    const int r = next(path);
    if (r == 0 && rec.armed && strcmp(path, rec.journal) == 0) rec_push(2, EV_REMOVE, 0, NULL, 0);
    return r;
}

static char *read_whole(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    ck_assert(f && fseek(f, 0, SEEK_END) == 0);
    *n = (size_t)ftell(f);
    rewind(f);
    char *b = malloc(*n + 1);
    ck_assert(b && fread(b, 1, *n, f) == *n);
    fclose(f);
    return b;
}

/* The series file at `to` as it was when the recording started (base, n
 * bytes) with the first k recorded events applied, and its journal beside
 * it when one was being written or left. */
static void rebuild(const char *to, const char *base, size_t n, size_t k)
{
    char journal[600];
    snprintf(journal, sizeof journal, "%s.journal", to);
    const int fd = open(to, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ck_assert(fd >= 0 && write(fd, base, n) == (ssize_t)n);
    remove(journal);
    int jfd = -1;
    for (size_t i = 0; i < k; i++) {
        const rec_event *e = &rec.ev[i];
        if (e->journal && e->kind == EV_REMOVE) {
            if (jfd >= 0) close(jfd);
            jfd = -1;
            remove(journal);
            continue;
        }
        if (e->journal && jfd < 0) ck_assert((jfd = open(journal, O_WRONLY | O_CREAT | O_TRUNC, 0644)) >= 0);
        const int to_fd = e->journal ? jfd : fd;
        if (e->kind == EV_WRITE) ck_assert((size_t)pwrite(to_fd, e->bytes, e->n, e->at) == e->n);
        else ck_assert(ftruncate(to_fd, e->at) == 0);
    }
    if (jfd >= 0) close(jfd);
    close(fd);
}

/* A series written one snapshot (and 400 history rows) at a time; during
 * each add every write to the file and its journal is recorded, and the
 * files are rebuilt as a kill after each of those writes would have left
 * them: every rebuilt file opens (through seixo, which completes or drops
 * the journal), holds every snapshot and history row complete before the
 * add (and, once its counts were written, the new ones), and each of them
 * reads back. The twelve adds take the file through the growths that
 * HDF5 makes by rewriting a parent in place: /snapshots' header extended
 * and its links moved to a separate index after eight, the histories'
 * chunk indices split. Without the journal this failed at the second add
 * (HDF5 shrank the file before writing the superblock that records its
 * smaller end: "truncated file") and, that avoided, at the fifth
 * (/snapshots' header rewritten to point at a new piece not yet written). */
START_TEST(kill_after_every_write)
{
    char path[512], copy[512], err[512];
    io_path(path, sizeof path, "replayed.h5");
    io_path(copy, sizeof copy, "rebuilt.h5");
    sx_model *m = io_scene_granular(3, 30);
    static hist_buf hb;
    hist_init(&hb);
    sx_series *s = sx_series_open(path, 3, NULL, err, sizeof err);
    ck_assert_msg(s, "%s", err);
    size_t states = 0;
    /* SX_REPLAY_ADDS=N replays N adds (a longer check than the suite's) */
    const int adds = getenv("SX_REPLAY_ADDS") ? atoi(getenv("SX_REPLAY_ADDS")) : 12, per = 400;
    for (int k = 0; k < adds; k++) {
        struct stat st;
        ck_assert(stat(path, &st) == 0);
        size_t n;
        char *base = read_whole(path, &n);
        snprintf(rec.journal, sizeof rec.journal, "%s.journal", path);
        rec.dev = st.st_dev, rec.ino = st.st_ino, rec.nev = 0, rec.armed = true;
        for (int j = 0; j < per; j++) hist_add(&hb, 5 * ((int64_t)k * per + j));
        ck_assert_msg(sx_series_write(s, m, &hb.h, 1, err, sizeof err) == SX_OK, "%s", err);
        rec.armed = false;
        ck_assert_int_gt(rec.nev, 0);
        for (size_t i = 0; i <= rec.nev; i++) {
            rebuild(copy, base, n, i);
            const int64_t count = sx_series_read_count(copy, err, sizeof err);
            ck_assert_msg(count == k || count == k + 1, "add %d, after write %zu of %zu: count %lld (%s)", k, i,
                          rec.nev, (long long)count, err);
            snprintf(checking, sizeof checking, "add %d, after write %zu of %zu: ", k, i, rec.nev);
            read_all(copy, count);
            int64_t last;
            const int64_t rows = check_history(copy, &last);
            checking[0] = 0;
            /* one flush raises both counts: either may reach the disk first */
            ck_assert_msg(rows == (int64_t)k * per || rows == (int64_t)(k + 1) * per,
                          "add %d, after write %zu: %lld history rows", k, i, (long long)rows);
            states++;
        }
        /* the last rebuilt file is the file */
        size_t nb;
        char *now_bytes = read_whole(path, &nb);
        char *rebuilt = read_whole(copy, &n);
        size_t d = 0;
        while (d < n && d < nb && now_bytes[d] == rebuilt[d]) d++;
        ck_assert_msg(nb == n && d == n, "add %d: the file has %zu bytes, the rebuilt one %zu, first difference at %zu", k, nb, n, d);
        free(now_bytes);
        free(rebuilt);
        free(base);
        for (size_t i = 0; i < rec.nev; i++) free(rec.ev[i].bytes);
        io_cycle(m, 5);
    }
    ck_assert_int_eq(sx_series_close(s, err, sizeof err), SX_OK);
    printf("  %zu files rebuilt as a kill after each write left them: every complete snapshot read back\n", states);
    free(rec.ev);
    rec.ev = NULL, rec.cap = 0;
    sx_model_destroy(m);
    io_assert_no_handles();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_atomic");
    TCase *tc = tcase_create("atomic");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, killed_save_keeps_previous);
    tcase_add_test(tc, killed_series_keeps_snapshots);
    suite_add_tcase(s, tc);
    TCase *recovery = tcase_create("recovery");
    /* the replay's time is mostly its writer's syncs: the disk's, not the CPU's */
    tcase_set_timeout(recovery, 900);
    tcase_add_test(recovery, killed_add_recovers);
    tcase_add_test(recovery, kill_after_every_write);
    suite_add_tcase(s, recovery);
    return io_run_suite(s);
}
