/* sx-bench-clumps: the cost of a pebble-step against a ball-step.
 *
 *   sx-bench-clumps [nx ny nz] [--steps S] [--warmup W] [--threads T]
 *
 * The scene is the SC bed of sc_bed.c (../shared/BENCH.md): a simple cubic
 * lattice of spheres R = 0.01 m at spacing 2R - 1e-5 m (lattice neighbours
 * overlap by 10 um), density 2500, kn = ks = 2e5 N/m per ball and wall,
 * friction 0.5, a box of five planes, gravity, fixed timestep 1e-5 s. It
 * runs three times with the same spheres at the same places:
 *   balls      every sphere a ball;
 *   dumbbells  neighbours along x joined into clumps of 2 pebbles;
 *   cubes      2 x 2 x 2 blocks joined into clumps of 8 pebbles.
 * A clump's own pebbles do not touch, so the clumped scenes have fewer
 * contacts (the lattice bonds inside a clump are gone): the table gives
 * contacts per sphere (pairs, ball-ball and ball-wall, over spheres)
 * with the time per sphere-step, so the two effects can be told apart. nx, ny, nz must be even (default 20 20 24: 9600
 * spheres). W untimed steps (default 20), then S timed (default 1000) in
 * CPU time; the best of three timed runs is kept. */
#include "seixo.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define RADIUS 0.01
#define SPACING (2 * RADIUS - 1e-5)
#define DENSITY 2500.0
#define K 2e5
#define FRICTION 0.5
#define DASHPOT_RATIO 0.21545

static void die(const char *what, const sx_model *m)
{
    fprintf(stderr, "sx-bench-clumps: %s: %s\n", what, m ? sx_model_error(m) : "");
    exit(1);
}

/* CPU time of the process: on a machine shared with other jobs it measures
 * the work, where wall time would add the waits (with T threads it sums
 * their time, so compare runs of equal T). */
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The lattice site (i, j, k) as in sc_bed.c: the outer columns press the
 * side walls by half the lattice overlap; a deterministic lateral
 * perturbation of +-2 um (a simpler hash than sc_bed.c's). */
static void site(int i, int j, int k, double *x)
{
    const double p = 2e-6 * sin(12.9898 * i + 78.233 * j + 37.719 * k);
    x[0] = RADIUS - 0.5 * (2 * RADIUS - SPACING) + i * SPACING + p;
    x[1] = RADIUS - 0.5 * (2 * RADIUS - SPACING) + j * SPACING - p;
    x[2] = RADIUS + k * SPACING;
}

/* kind 0: balls, 1: dumbbells along x, 2: 2x2x2 cubes. */
static sx_model *scene(int kind, int nx, int ny, int nz, int threads)
{
    sx_model_def def = sx_model_default_def();
    def.dim = 3;
    def.gravity[2] = -9.81;
    def.timestep = 1e-5;
    def.skin = 0.002;
    char err[256];
    sx_model *m = sx_model_create(&def, err, sizeof err);
    if (!m) {
        fprintf(stderr, "sx-bench-clumps: %s\n", err);
        exit(1);
    }
    sx_model_set_threads(m, threads);
    sx_material_def md = sx_material_default_def();
    md.density = DENSITY, md.kn = md.ks = K, md.friction = FRICTION, md.viscous_normal = DASHPOT_RATIO;
    int mat;
    if (sx_material_set(m, "glass", &md, &mat)) die("material", m);
    /* an open box of five planes, as tight as sc_bed.c's */
    const double hi[2] = {nx * SPACING, ny * SPACING};
    const double normals[5][3] = {{0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    const double points[5][3] = {{0, 0, 0}, {0, 0, 0}, {hi[0], 0, 0}, {0, 0, 0}, {0, hi[1], 0}};
    for (int w = 0; w < 5; w++) {
        sx_wall_def wd = sx_wall_default_def(3);
        memcpy(wd.point, points[w], sizeof wd.point);
        memcpy(wd.normal, normals[w], sizeof wd.normal);
        wd.kn = wd.ks = K, wd.friction = FRICTION;
        if (sx_wall_add(m, &wd, NULL)) die("wall", m);
    }
    if (sx_ball_reserve(m, (int64_t)nx * ny * nz)) die("reserve", m);
    if (kind == 0) {
        for (int k = 0; k < nz; k++)
            for (int j = 0; j < ny; j++)
                for (int i = 0; i < nx; i++) {
                    sx_ball_def bd = sx_ball_default_def();
                    site(i, j, k, bd.pos);
                    bd.radius = RADIUS, bd.material = mat;
                    if (sx_ball_add(m, &bd, NULL)) die("ball", m);
                }
        return m;
    }
    /* one template per shape, its pebbles at lattice spacing; each clump
     * then placed at the centroid of its lattice sites (the lateral
     * perturbation, a rigid shift of a few um, is dropped inside a clump) */
    const int ex = 2, ey = kind == 2 ? 2 : 1, ez = kind == 2 ? 2 : 1, np = ex * ey * ez;
    double pos[24], rad[8];
    for (int c = 0; c < np; c++) {
        pos[3 * c] = (c % ex) * SPACING, pos[3 * c + 1] = (c / ex % ey) * SPACING, pos[3 * c + 2] = (c / (ex * ey)) * SPACING;
        rad[c] = RADIUS;
    }
    sx_clump_template_def td = {pos, rad, np, 0};
    int t;
    if (sx_clump_template_add(m, "block", &td, &t)) die("template", m);
    sx_clump_props p;
    sx_clump_template_props(m, t, &p);
    for (int k = 0; k < nz; k += ez)
        for (int j = 0; j < ny; j += ey)
            for (int i = 0; i < nx; i += ex) {
                sx_clump_def cd = sx_clump_default_def();
                cd.template_index = t, cd.material = mat;
                site(i, j, k, cd.pos);
                for (int d = 0; d < 3; d++) cd.pos[d] += p.centroid[d];
                if (sx_clump_add(m, &cd, NULL)) die("clump", m);
            }
    return m;
}

typedef struct result {
    double us_per_sphere_step;
    double contacts_per_sphere;
    int64_t bodies;
} result;

static result run(int kind, int nx, int ny, int nz, int threads, int warmup, int steps)
{
    result r = {INFINITY, 0, 0};
    for (int rep = 0; rep < 3; rep++) {
        sx_model *m = scene(kind, nx, ny, nz, threads);
        if (sx_model_cycle(m, warmup)) die("warm-up", m);
        const double t0 = now();
        if (sx_model_cycle(m, steps)) die("cycle", m);
        const double us = 1e6 * (now() - t0) / ((double)steps * (double)sx_ball_count(m));
        if (us < r.us_per_sphere_step) r.us_per_sphere_step = us;
        r.contacts_per_sphere = (double)sx_contact_count(m) / (double)sx_ball_count(m);
        r.bodies = kind ? sx_clump_count(m) : sx_ball_count(m);
        sx_model_destroy(m);
    }
    return r;
}

int main(int argc, char **argv)
{
    int n[3] = {20, 20, 24}, nn = 0, steps = 1000, warmup = 20, threads = 1;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--steps") == 0 && a + 1 < argc) steps = atoi(argv[++a]);
        else if (strcmp(argv[a], "--warmup") == 0 && a + 1 < argc) warmup = atoi(argv[++a]);
        else if (strcmp(argv[a], "--threads") == 0 && a + 1 < argc) threads = atoi(argv[++a]);
        else if (nn < 3) n[nn++] = atoi(argv[a]);
    }
    if (n[0] < 2 || n[1] < 2 || n[2] < 2 || n[0] % 2 || n[1] % 2 || n[2] % 2 || steps < 1 || warmup < 0 || threads < 1) {
        fprintf(stderr, "usage: sx-bench-clumps [nx ny nz (even)] [--steps S] [--warmup W] [--threads T]\n");
        return 2;
    }
    static const char *const names[3] = {"balls", "dumbbells (2 pebbles)", "cubes (8 pebbles)"};
    result r[3];
    for (int k = 0; k < 3; k++) r[k] = run(k, n[0], n[1], n[2], threads, warmup, steps);
    printf("SC bed %d x %d x %d = %d spheres, %d threads, %d steps (best of 3)\n", n[0], n[1], n[2],
           n[0] * n[1] * n[2], threads, steps);
    printf("%-24s %8s %14s %18s %12s\n", "scene", "bodies", "pairs/sphere", "us/sphere-step", "vs balls");
    for (int k = 0; k < 3; k++)
        printf("%-24s %8lld %14.3f %18.4f %12.3f\n", names[k], (long long)r[k].bodies, r[k].contacts_per_sphere,
               r[k].us_per_sphere_step, r[k].us_per_sphere_step / r[0].us_per_sphere_step);
    printf("SXBENCHCLUMPS ball_us=%.5f dumbbell_us=%.5f cube_us=%.5f dumbbell_ratio=%.4f cube_ratio=%.4f\n",
           r[0].us_per_sphere_step, r[1].us_per_sphere_step, r[2].us_per_sphere_step,
           r[1].us_per_sphere_step / r[0].us_per_sphere_step, r[2].us_per_sphere_step / r[0].us_per_sphere_step);
    return 0;
}
