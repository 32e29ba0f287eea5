/* sx-bench: the SC-bed benchmark scene of ../shared/BENCH.md, built with the
 * public C API and timed.
 *
 *   sx-bench [N | nx ny nz] [--2d] [--threads T] [--steps S] [--warmup W] [--dump FILE]
 *
 * The scene: a simple cubic lattice of spheres (R = 0.01 m, density 2500)
 * at spacing 2R - 1e-5 m, so every lattice neighbour pair overlaps by 10 um
 * at step 0, with a deterministic lateral perturbation of +-2 um; an open
 * box of five planes; gravity -9.81 along z; linear springs kn = ks = 2e5
 * N/m per ball and per wall (springs in series: 1e5 N/m per contact),
 * friction 0.5, a normal dashpot and no shear dashpot; fixed timestep 1e-5 s,
 * skin 0.002 m. W untimed steps (default 10), then S timed ones (default 2000).
 *
 * seixo's dashpot is ratio-based (a critical-damping ratio, not an absolute
 * coefficient), so the ball-ball ratio 0.21545 (cn = 9.860 N s/m on the
 * reduced mass m/2) is used everywhere, as BENCH.md asks; on a ball-wall
 * contact the same ratio on the full mass gives cn = 13.94 N s/m where the
 * peers use 9.860. The run prints that.
 *
 * The 2D variant (--2d) puts the same number of disks in a square lattice
 * of nx*ny columns by nz layers, with three line walls; the disks' density
 * (per unit thickness) is chosen so that a disk weighs what a sphere weighs,
 * so the bed is loaded alike and the comparison is one of cost per step.
 *
 * The last line of the output is machine-readable, "SXBENCH key=value ...".
 * Contacts per ball counts each ball-ball contact for both its balls and
 * each ball-wall contact for its ball, (2 n_bb + n_bw) / N: that is how the
 * 5.94 of BENCH.md counts (the ball-ball contacts alone cannot exceed 5.72
 * on a 20 x 20 x 25 lattice). cpb_bb = 2 n_bb / N is printed as well.
 * Overlaps are ball-ball only, from sx_contact_each.
 */
#include "seixo.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

/* BENCH.md's scene constants */
#define RADIUS 0.01         /* m */
#define DELTA0 1e-5         /* m, initial overlap of lattice neighbours */
#define SPACING (2 * RADIUS - DELTA0)
#define PERTURB 2e-6        /* m, lateral perturbation amplitude */
#define DENSITY 2500.0      /* kg/m^3 */
#define K_BALL 2e5          /* N/m per ball and per wall: 1e5 per contact in series */
#define FRICTION 0.5
#define DASHPOT_RATIO 0.21545 /* critical-damping ratio of the ball-ball dashpot */
#define GRAVITY 9.81        /* m/s^2 */
#define TIMESTEP 1e-5       /* s */
#define SKIN 0.002          /* m */

typedef struct options {
    int nx, ny, nz;
    int dim;
    int threads;
    int64_t steps, warmup;
    const char *dump;
} options;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sx-bench [N | nx ny nz] [--2d] [--threads T] [--steps S] [--warmup W] [--dump FILE]\n"
            "  N            10000, 50000, 100000 or 400000 (BENCH.md's lattices; default 10000)\n"
            "  nx ny nz     any lattice (3D: nx x ny columns, nz layers)\n"
            "  --2d         the same number of disks: a 2D lattice of nx*ny columns by nz layers\n"
            "  --threads T  threads of the step (sx_model_set_threads; results do not depend on it)\n"
            "  --steps S    timed steps (default 2000); --warmup W untimed steps first (default 10)\n"
            "  --dump FILE  write the final state: id x y z vx vy vz wx wy wz radius mass\n");
}

static bool parse_int(const char *s, long long lo, long long hi, long long *out)
{
    char *end;
    const long long v = strtoll(s, &end, 10);
    if (end == s || *end || v < lo || v > hi) return false;
    *out = v;
    return true;
}

static bool size_of(long long n, options *o)
{
    static const int sizes[][4] = {
        {10000, 20, 20, 25}, {50000, 50, 40, 25}, {100000, 50, 80, 25}, {400000, 100, 160, 25}};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++)
        if (sizes[k][0] == n) {
            o->nx = sizes[k][1], o->ny = sizes[k][2], o->nz = sizes[k][3];
            return true;
        }
    return false;
}

static int parse(int argc, char **argv, options *o)
{
    *o = (options){.dim = 3, .threads = 1, .steps = 2000, .warmup = 10};
    size_of(10000, o);
    long long pos[3];
    int npos = 0;
    for (int a = 1; a < argc; a++) {
        const char *s = argv[a];
        long long v;
        if (!strcmp(s, "-h") || !strcmp(s, "--help")) {
            usage(stdout);
            exit(0);
        } else if (!strcmp(s, "--2d")) {
            o->dim = 2;
        } else if (!strcmp(s, "--threads") || !strcmp(s, "--steps") || !strcmp(s, "--warmup") ||
                   !strcmp(s, "--dump")) {
            if (a + 1 >= argc) {
                fprintf(stderr, "sx-bench: %s needs a value\n", s);
                return 2;
            }
            const char *val = argv[++a];
            if (!strcmp(s, "--dump")) {
                o->dump = val;
                continue;
            }
            if (!parse_int(val, !strcmp(s, "--warmup") ? 0 : 1, 1000000000, &v)) {
                fprintf(stderr, "sx-bench: bad value for %s: %s\n", s, val);
                return 2;
            }
            if (!strcmp(s, "--threads")) o->threads = (int)v;
            else if (!strcmp(s, "--steps")) o->steps = v;
            else o->warmup = v;
        } else if (s[0] == '-') {
            fprintf(stderr, "sx-bench: unknown option %s\n", s);
            usage(stderr);
            return 2;
        } else {
            if (npos == 3 || !parse_int(s, 1, 100000000, &pos[npos])) {
                fprintf(stderr, "sx-bench: bad size argument %s\n", s);
                usage(stderr);
                return 2;
            }
            npos++;
        }
    }
    if (npos == 1 && !size_of(pos[0], o)) {
        fprintf(stderr, "sx-bench: N must be 10000, 50000, 100000 or 400000 (or give nx ny nz)\n");
        return 2;
    }
    if (npos == 2) {
        fprintf(stderr, "sx-bench: give N or nx ny nz\n");
        return 2;
    }
    if (npos == 3) {
        if (pos[0] * pos[1] * pos[2] > 50000000) {
            fprintf(stderr, "sx-bench: lattice too large\n");
            return 2;
        }
        o->nx = (int)pos[0], o->ny = (int)pos[1], o->nz = (int)pos[2];
    }
    return 0;
}

static int fail(sx_model *m, const char *what, sx_status st)
{
    fprintf(stderr, "sx-bench: %s failed (status %d): %s\n", what, (int)st, m ? sx_model_error(m) : "");
    sx_model_destroy(m);
    return 1;
}

/* BENCH.md's lateral perturbation, a multiplicative hash of the lattice index. */
static double perturbation(uint64_t p, uint64_t mul, uint64_t add)
{
    const uint64_t u = (p * mul + add) & 0xffffffffULL;
    return PERTURB * (2.0 * ((double)u / 4294967296.0) - 1.0);
}

static sx_model *build(const options *o, int *material)
{
    char err[256];
    sx_model_def md = sx_model_default_def();
    md.dim = o->dim;
    md.gravity[o->dim - 1] = -GRAVITY;
    md.timestep = TIMESTEP;
    md.skin = SKIN;
    sx_model *m = sx_model_create(&md, err, sizeof err);
    if (!m) {
        fprintf(stderr, "sx-bench: %s\n", err);
        return NULL;
    }
    sx_material_def mat = sx_material_default_def();
    mat.model = SX_MODEL_LINEAR;
    /* 2D: a disk of unit thickness as heavy as the sphere, m = 4/3 pi R^3 rho */
    mat.density = o->dim == 3 ? DENSITY : DENSITY * 4.0 / 3.0 * RADIUS;
    mat.kn = mat.ks = K_BALL;
    mat.friction = FRICTION;
    mat.damping = 0;
    mat.viscous_normal = DASHPOT_RATIO;
    mat.viscous_shear = 0;
    sx_status st = sx_material_set(m, "bed", &mat, material);
    if (st) {
        fail(m, "material_set", st);
        return NULL;
    }
    const int64_t ncol = (int64_t)o->nx * o->ny; /* 2D: the columns in one row */
#ifdef SX_BENCH_HAVE_RESERVE
    if ((st = sx_ball_reserve(m, ncol * o->nz))) {
        fail(m, "ball_reserve", st);
        return NULL;
    }
#endif
    sx_ball_def bd = sx_ball_default_def();
    bd.radius = RADIUS;
    bd.material = *material;
    for (int64_t k = 0; k < o->nz; k++)
        for (int64_t j = 0; j < (o->dim == 3 ? o->ny : 1); j++)
            for (int64_t i = 0; i < (o->dim == 3 ? o->nx : ncol); i++) {
                const uint64_t p = (uint64_t)(o->dim == 3 ? i + o->nx * (j + o->ny * k) : i + ncol * k);
                const double dx = perturbation(p, 2654435761ULL, 12345ULL);
                const double dy = perturbation(p, 2246822519ULL, 3266489917ULL);
                memset(bd.pos, 0, sizeof bd.pos);
                bd.pos[0] = RADIUS - 0.5 * DELTA0 + (double)i * SPACING + dx;
                if (o->dim == 3) {
                    bd.pos[1] = RADIUS - 0.5 * DELTA0 + (double)j * SPACING + dy;
                    bd.pos[2] = RADIUS + (double)k * SPACING;
                } else {
                    bd.pos[1] = RADIUS + (double)k * SPACING;
                }
                int64_t id;
                if ((st = sx_ball_add(m, &bd, &id))) {
                    fail(m, "ball_add", st);
                    return NULL;
                }
                if (id != (int64_t)p + 1) { /* BENCH.md's ids: 1 + lattice index */
                    fprintf(stderr, "sx-bench: ball id %lld, expected %lld\n", (long long)id, (long long)p + 1);
                    sx_model_destroy(m);
                    return NULL;
                }
            }
    /* the open box: floor and four sides, normals towards the balls */
    const double lx = (double)(o->dim == 3 ? o->nx : ncol) * SPACING, ly = (double)o->ny * SPACING;
    const int up = o->dim - 1;
    double walls[5][2][3] = {{{0, 0, 0}, {0, 0, 0}},
                             {{0, 0, 0}, {1, 0, 0}},
                             {{lx, 0, 0}, {-1, 0, 0}},
                             {{0, 0, 0}, {0, 1, 0}},
                             {{0, ly, 0}, {0, -1, 0}}};
    walls[0][1][up] = 1;
    const int nwalls = o->dim == 3 ? 5 : 3;
    for (int w = 0; w < nwalls; w++) {
        sx_wall_def wd = sx_wall_default_def(o->dim);
        memcpy(wd.point, walls[w][0], sizeof wd.point);
        memcpy(wd.normal, walls[w][1], sizeof wd.normal);
        wd.kn = wd.ks = K_BALL;
        wd.friction = FRICTION;
        if ((st = sx_wall_add(m, &wd, NULL))) {
            fail(m, "wall_add", st);
            return NULL;
        }
    }
    return m;
}

typedef struct stats {
    int64_t bb, bw;
    double sum_overlap, max_overlap;
} stats;

static bool gather(const sx_contact_info *c, void *ud)
{
    stats *s = ud;
    if (c->is_wall) {
        s->bw++;
        return true;
    }
    s->bb++;
    s->sum_overlap += c->overlap;
    if (c->overlap > s->max_overlap) s->max_overlap = c->overlap;
    return true;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    options o;
    const int bad = parse(argc, argv, &o);
    if (bad) return bad;
    const int64_t n = (int64_t)o.nx * o.ny * o.nz;

    int material;
    sx_model *m = build(&o, &material);
    if (!m) return 1;
    sx_status st = sx_model_set_threads(m, o.threads);
    if (st) return fail(m, "set_threads", st);
    const int threads_used = sx_model_threads(m);
    const double mass = DENSITY * 4.0 / 3.0 * 3.14159265358979323846 * RADIUS * RADIUS * RADIUS;
    const double mstar = 0.5 * mass, kc = 0.5 * K_BALL;
    printf("# SC-bed %dD: %lld balls (%d x %d x %d%s), dt %g s, skin %g m, %lld + %lld steps, "
           "threads requested %d, used %d\n",
           o.dim, (long long)n, o.nx, o.ny, o.nz, o.dim == 2 ? ", as nx*ny columns by nz layers" : "",
           TIMESTEP, SKIN, (long long)o.warmup, (long long)o.steps, o.threads, threads_used);
    printf("# dashpot: seixo's is ratio-based; critical-damping ratio %.5f on every contact: "
           "ball-ball cn = %.3f N s/m (reduced mass), ball-wall cn = %.3f N s/m (full mass; the peers' 9.860)\n",
           DASHPOT_RATIO, 2 * DASHPOT_RATIO * sqrt(mstar * kc), 2 * DASHPOT_RATIO * sqrt(mass * kc));

    st = sx_model_cycle(m, o.warmup);
    if (st) return fail(m, "warm-up cycle", st);
    sx_model_profile_reset(m);
    const double t0 = now();
    st = sx_model_cycle(m, o.steps);
    const double seconds = now() - t0;
    if (st) return fail(m, "timed cycle", st);

    /* the profile of the timed steps */
    const sx_profile prof = sx_model_profile(m);
    char table[2048];
    sx_profile_format(&prof, n, table, sizeof table);
    printf("# profile of the timed steps:\n");
    for (const char *line = table; *line;) {
        const char *end = strchr(line, '\n');
        const int len = end ? (int)(end - line) : (int)strlen(line);
        printf("#   %.*s\n", len, line);
        line += len + (end != NULL);
    }
    const sx_memory mem = sx_model_memory(m);
    printf("# memory: %.1f MB held (peak %.1f MB): balls %.1f B/ball, contacts %.1f B/contact (%lld pairs for %lld "
           "contacts), bonds %zu B, working storage %.1f B/ball\n",
           (double)mem.total / 1048576.0, (double)mem.peak / 1048576.0, mem.bytes_per_ball, mem.bytes_per_contact,
           (long long)mem.pair_count, (long long)mem.contact_count, mem.bonds, (double)mem.work / (double)n);

    stats s = {0};
    sx_contact_each(m, gather, &s);
    const sx_energy e = sx_model_energy(m);
    const int64_t count = sx_ball_count(m);
    const double lx = (double)(o.dim == 3 ? o.nx : (int64_t)o.nx * o.ny) * SPACING, ly = (double)o.ny * SPACING;
    const double top = 2.0 * (double)o.nz * SPACING; /* the box is open: twice the bed's height */
    int64_t outside = 0;
    FILE *dump = NULL;
    if (o.dump && !(dump = fopen(o.dump, "w"))) {
        fprintf(stderr, "sx-bench: cannot write %s\n", o.dump);
        sx_model_destroy(m);
        return 1;
    }
    if (dump) fprintf(dump, "# seixo SC-bed final state, %dD: id x y z vx vy vz wx wy wz radius mass\n", o.dim);
    for (int64_t i = 0; i < count; i++) {
        const int64_t id = sx_ball_id_at(m, i);
        double x[3] = {0}, v[3] = {0}, w[3] = {0}, r = 0, bm = 0;
        sx_ball_get_vec(m, id, SX_BALL_POS, x);
        sx_ball_get_vec(m, id, SX_BALL_VEL, v);
        sx_ball_get_vec(m, id, SX_BALL_SPIN, w);
        sx_ball_get(m, id, SX_BALL_RADIUS, &r);
        sx_ball_get(m, id, SX_BALL_MASS, &bm);
        const double h = x[o.dim - 1];
        bool in = isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && x[0] >= 0 && x[0] <= lx && h >= 0 && h <= top;
        if (o.dim == 3) in = in && x[1] >= 0 && x[1] <= ly;
        outside += !in;
        if (dump) {
            if (o.dim == 2) { /* 2D spin is the scalar about z, in component 0 */
                w[2] = w[0];
                w[0] = 0;
            }
            fprintf(dump, "%lld %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                    (long long)id, x[0], x[1], x[2], v[0], v[1], v[2], w[0], w[1], w[2], r, bm);
        }
    }
    if (dump) fclose(dump);

    const size_t bytes = sx_model_bytes(m);
    const int64_t contacts = s.bb + s.bw;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("SXBENCH code=seixo N=%lld dim=%d nx=%d ny=%d nz=%d threads_requested=%d threads=%d steps=%lld "
           "seconds=%.6f psps=%.6e contacts_per_ball=%.6f cpb_bb=%.6f bb_contacts=%lld bw_contacts=%lld "
           "mean_overlap=%.6e max_overlap=%.6e ke=%.6e lost=%lld outside=%lld model_bytes=%zu "
           "bytes_per_ball=%.1f bytes_per_contact=%.1f maxrss_kb=%ld hash=%016" PRIx64 " dashpot=ratio:%.5f "
           "ball_bytes_per_ball=%.1f contact_bytes_per_contact=%.1f model_peak=%zu "
           "t_broad=%.6f t_balls=%.6f t_walls=%.6f t_motion=%.6f t_other=%.6f\n",
           (long long)n, o.dim, o.nx, o.ny, o.nz, o.threads, threads_used, (long long)o.steps, seconds,
           (double)n * (double)o.steps / seconds, (double)(2 * s.bb + s.bw) / (double)n,
           (double)(2 * s.bb) / (double)n, (long long)s.bb, (long long)s.bw,
           s.bb ? s.sum_overlap / (double)s.bb : 0.0, s.max_overlap, e.kinetic, (long long)(n - count),
           (long long)outside, bytes, (double)bytes / (double)n, contacts ? (double)bytes / (double)contacts : 0.0,
           ru.ru_maxrss, sx_model_state_hash(m), DASHPOT_RATIO, mem.bytes_per_ball, mem.bytes_per_contact, mem.peak,
           prof.seconds[SX_STAGE_BROAD_PHASE], prof.seconds[SX_STAGE_BALL_CONTACTS],
           prof.seconds[SX_STAGE_WALL_CONTACTS], prof.seconds[SX_STAGE_INTEGRATION], prof.seconds[SX_STAGE_OTHER]);
    sx_model_destroy(m);
    return 0;
}
