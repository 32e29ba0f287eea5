/* How fast snapshots and series are written and read, and how large they
 * are per ball: a 3D assembly of 100k balls on a slightly overlapping
 * lattice (about 3 contacts per ball, every one bonded), after a
 * few steps so every store holds history.
 *     build/tests/io/io_bench [balls] [folder]
 * Times include the flush to disk (fsync) of a save; reads are from the
 * page cache (a file just written). */
#include "seixo.h"
#include "seixo_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double size_of(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 ? (double)st.st_size : 0;
}

static void die(const char *what, const char *err)
{
    fprintf(stderr, "%s: %s\n", what, err);
    exit(1);
}

int main(int argc, char **argv)
{
    const int n = argc > 1 ? atoi(argv[1]) : 100000;
    const char *dir = argc > 2 ? argv[2] : "/tmp";
    char err[1024], snap[512], snapz[512], series[512], seriesz[512];
    snprintf(snap, sizeof snap, "%s/bench_snapshot.h5", dir);
    snprintf(snapz, sizeof snapz, "%s/bench_snapshot_z.h5", dir);
    snprintf(series, sizeof series, "%s/bench_series.h5", dir);
    snprintf(seriesz, sizeof seriesz, "%s/bench_series_z.h5", dir);

    sx_model_def d = sx_model_default_def();
    d.gravity[2] = -9.81;
    sx_model *m = sx_model_create(&d, err, sizeof err);
    sx_material_def md = sx_material_default_def();
    md.kn = md.ks = 1e6;
    md.damping = 0.7;
    int mat;
    sx_material_set(m, "rock", &md, &mat);
    sx_bpm_def bpm;
    memset(&bpm, 0, sizeof bpm);
    bpm.radius_multiplier = 1, bpm.modulus = 1e7, bpm.stiffness_ratio = 2, bpm.tensile_strength = 1e9,
    bpm.cohesion = 1e9;
    sx_material_set_bpm(m, mat, &bpm);
    const int side = (int)ceil(cbrt((double)n));
    const double r = 0.001, a = 2 * r * 0.999;
    sx_ball_reserve(m, n);
    for (int i = 0; i < n; i++) {
        sx_ball_def b = sx_ball_default_def();
        b.pos[0] = a * (i % side), b.pos[1] = a * ((i / side) % side), b.pos[2] = a * (i / (side * side));
        b.radius = r * (1 - 0.0001 * (i % 7));
        b.material = mat;
        if (sx_ball_add(m, &b, NULL)) die("ball", sx_model_error(m));
    }
    sx_bond_def bd = sx_bond_default_def();
    bd.gap = 0;
    bd.material_a = mat;
    int64_t nb = 0;
    if (sx_bond_install(m, &bd, &nb)) die("bond", sx_model_error(m));
    if (sx_model_cycle(m, 20)) die("cycle", sx_model_error(m));
    printf("model: %d balls, %lld contacts, %lld bonds, %.1f MB in memory\n", n, (long long)sx_contact_count(m),
           (long long)sx_bond_count(m), sx_model_bytes(m) / 1e6);

    const char *paths[2] = {snap, snapz};
    for (int z = 0; z < 2; z++) {
        sx_snapshot_opts o;
        memset(&o, 0, sizeof o);
        o.compression = z ? 4 : 0;
        double t0 = now();
        if (sx_snapshot_save(m, paths[z], &o, err, sizeof err)) die("save", err);
        const double tw = now() - t0, bytes = size_of(paths[z]);
        t0 = now();
        sx_model *c = sx_snapshot_load(paths[z], 3, NULL, err, sizeof err);
        const double tr = now() - t0;
        if (!c) die("load", err);
        if (sx_model_state_hash(c) != sx_model_state_hash(m)) die("load", "the state differs");
        sx_model_destroy(c);
        printf("snapshot%s: %.1f MB (%.0f bytes/ball); save %.3f s (%.0f MB/s, fsync included), load %.3f s "
               "(%.0f MB/s)\n",
               z ? " (deflate 4)" : "", bytes / 1e6, bytes / n, tw, bytes / 1e6 / tw, tr, bytes / 1e6 / tr);
    }
    const char *spaths[2] = {series, seriesz};
    for (int z = 0; z < 2; z++) {
        sx_series_opts o;
        memset(&o, 0, sizeof o);
        o.compression = z ? 4 : 0;
        sx_series *s = sx_series_open(spaths[z], 3, &o, err, sizeof err);
        if (!s) die("series", err);
        const int k = 5;
        const double t0 = now();
        for (int i = 0; i < k; i++)
            if (sx_series_write(s, m, NULL, 0, err, sizeof err)) die("series write", err);
        const double tw = (now() - t0) / k;
        sx_series_close(s, err, sizeof err);
        const double bytes = size_of(spaths[z]) / k;
        printf("series snapshot (default fields%s): %.1f MB (%.0f bytes/ball), write %.3f s (%.0f MB/s, fsync "
               "included)\n",
               z ? ", deflate 4" : "", bytes / 1e6, bytes / n, tw, bytes / 1e6 / tw);
    }
    remove(snap), remove(snapz), remove(series), remove(seriesz);
    char xmf[600];
    snprintf(xmf, sizeof xmf, "%s/bench_series.xmf", dir);
    remove(xmf);
    snprintf(xmf, sizeof xmf, "%s/bench_series_z.xmf", dir);
    remove(xmf);
    sx_model_destroy(m);
    return 0;
}
