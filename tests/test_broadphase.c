/* The broad phase (uniform grid + Verlet skin) and the contact store:
 * completeness against an O(N^2) search, deterministic order, contact
 * history carried across rebuilds, re-sorts and removals, and bounded
 * memory for sparse scenes.
 *
 * The step evaluates contacts at the positions x_n and then integrates to
 * x_{n+1}, so after a cycle the contact set is the one of the positions at
 * the start of the last step. The brute-force reference is therefore taken
 * at those positions (recorded before a final one-step cycle), with the
 * same arithmetic as the kernel, so the comparison is exact. */
#include "scenes.h"

#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ck_assert_cycle(m, n) \
    ck_assert_msg(sx_model_cycle((m), (n)) == SX_OK, "cycle failed: %s", sx_model_error(m))

typedef struct pair {
    int64_t a, b; /* ball ids (a < b), or ball id and wall id */
    int wall;
} pair;

static int pair_cmp(const void *pa, const void *pb)
{
    const pair *x = pa, *y = pb;
    if (x->wall != y->wall) return x->wall - y->wall;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    if (x->b != y->b) return x->b < y->b ? -1 : 1;
    return 0;
}

typedef struct pairs {
    pair *p;
    int64_t n, cap;
} pairs;

static void push(pairs *s, int64_t a, int64_t b, int wall)
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 256;
        s->p = realloc(s->p, (size_t)s->cap * sizeof *s->p);
        ck_assert_ptr_nonnull(s->p);
    }
    if (!wall && a > b) {
        const int64_t t = a;
        a = b, b = t;
    }
    s->p[s->n++] = (pair){a, b, wall};
}

static bool collect(const sx_contact_info *c, void *ud)
{
    push(ud, c->a, c->b, c->is_wall);
    return true;
}

/* A snapshot of the balls by id. */
typedef struct snap {
    int64_t n;
    int64_t *id;
    double *x, *r;
} snap;

static snap take(sx_model *m)
{
    snap s;
    s.n = sx_ball_count(m);
    s.id = malloc((size_t)s.n * sizeof *s.id);
    s.x = malloc((size_t)s.n * 3 * sizeof *s.x);
    s.r = malloc((size_t)s.n * sizeof *s.r);
    ck_assert(s.id && s.x && s.r);
    /* no ck_assert in per-ball loops: each passing one writes to Check's pipe */
    for (int64_t i = 0; i < s.n; i++) {
        s.id[i] = sx_ball_id_at(m, i);
        if (sx_ball_get_vec(m, s.id[i], SX_BALL_POS, s.x + 3 * i) || sx_ball_get(m, s.id[i], SX_BALL_RADIUS, s.r + i))
            ck_abort_msg("ball %lld: %s", (long long)s.id[i], sx_model_error(m));
    }
    return s;
}

static void drop(snap *s)
{
    free(s->id);
    free(s->x);
    free(s->r);
}

/* All touching pairs of the snapshot, O(N^2), with the kernel's arithmetic
 * (d^2 < (RA + RB)^2; ball-wall: signed distance to the plane < R). */
static pairs brute(sx_model *m, const snap *s)
{
    const int dim = sx_model_dim(m);
    pairs out = {0};
    for (int64_t i = 0; i < s->n; i++)
        for (int64_t j = i + 1; j < s->n; j++) {
            double d2 = 0;
            for (int k = 0; k < dim; k++) {
                const double dx = s->x[3 * j + k] - s->x[3 * i + k];
                d2 += dx * dx;
            }
            const double rsum = s->r[i] + s->r[j];
            if (d2 < rsum * rsum) push(&out, s->id[i], s->id[j], 0);
        }
    for (int64_t w = 0; w < sx_wall_count(m); w++) {
        sx_wall_def wd;
        const int64_t wid = sx_wall_id_at(m, w);
        ck_assert_int_eq(sx_wall_get(m, wid, &wd), SX_OK);
        ck_assert(wd.kind == SX_WALL_PLANE || wd.kind == SX_WALL_LINE);
        for (int64_t i = 0; i < s->n; i++) {
            double dist = 0;
            for (int k = 0; k < dim; k++) dist += (s->x[3 * i + k] - wd.point[k]) * wd.normal[k];
            if (dist < s->r[i]) push(&out, s->id[i], wid, 1);
        }
    }
    return out;
}

/* One step; the contacts it reports must be exactly the brute-force set of
 * the positions it started from. Returns the number of contacts. */
static int64_t step_and_compare(sx_model *m)
{
    snap s = take(m);
    ck_assert_cycle(m, 1);
    pairs want = brute(m, &s), got = {0};
    ck_assert(sx_contact_each(m, collect, &got));
    ck_assert_int_eq(sx_contact_count(m), got.n);
    if (want.n) qsort(want.p, (size_t)want.n, sizeof *want.p, pair_cmp);
    if (got.n) qsort(got.p, (size_t)got.n, sizeof *got.p, pair_cmp);
    for (int64_t i = 1; i < got.n; i++)
        if (pair_cmp(&got.p[i - 1], &got.p[i]) == 0)
            ck_abort_msg("contact %lld-%lld reported twice", (long long)got.p[i].a, (long long)got.p[i].b);
    /* report the first difference */
    int64_t i = 0, j = 0;
    while (i < want.n || j < got.n) {
        const int c = i == want.n ? 1 : j == got.n ? -1 : pair_cmp(&want.p[i], &got.p[j]);
        if (c != 0)
            ck_abort_msg("step %lld: %s contact %s%lld-%lld (%lld brute-force, %lld reported)",
                      (long long)sx_model_step_count(m), c < 0 ? "missing" : "spurious",
                      (c < 0 ? want.p[i].wall : got.p[j].wall) ? "ball-wall " : "",
                      (long long)(c < 0 ? want.p[i].a : got.p[j].a), (long long)(c < 0 ? want.p[i].b : got.p[j].b),
                      (long long)want.n, (long long)got.n);
        i++, j++;
    }
    const int64_t n = got.n;
    free(want.p);
    free(got.p);
    drop(&s);
    return n;
}

/* A polydisperse gas in a box: a few hundred balls, some overlapping, fast
 * enough that the Verlet list is rebuilt every few tens of steps. */
static sx_model *gas(int dim, uint64_t seed, bool walls)
{
    sx_model *m = scene_model(dim, NULL, 0, 1e6, 0.3, 2650);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.2, 0.2, 0.1};
    const double hi3[3] = {0.1, 0.1, 0.1};
    const double *h = dim == 3 ? hi3 : hi;
    if (walls) scene_box_walls(m, lo, h, 1e6, 0.3);
    const int64_t n = dim == 3 ? 300 : 400;
    scene_random_balls(m, n, lo, h, dim == 3 ? 0.004 : 0.002, dim == 3 ? 0.008 : 0.004, walls ? 0.5 : 0.05, 0.05,
                       seed, NULL);
    return m;
}

START_TEST(matches_brute_force)
{
    const int dim = _i;
    sx_model *m = gas(dim, 12345 + (uint64_t)dim, true);
    snap s0 = take(m);
    /* every step, so that a pair the Verlet list missed for a single step shows */
    const int steps = dim == 3 ? 5000 : 1000;
    int64_t total = step_and_compare(m);
    ck_assert_msg(total > 0, "the assembly should start with some overlaps"); /* none touch a wall yet */
    for (int c = 1; c < steps; c++) total += step_and_compare(m);
    /* the test means something only if there were contacts and the balls
     * travelled many skins (so the lists were rebuilt many times) */
    ck_assert_msg(total > 100, "only %lld contacts seen", (long long)total);
    snap s1 = take(m);
    double mean_r = 0, path = 0;
    for (int64_t i = 0; i < s0.n; i++) mean_r += s0.r[i] / (double)s0.n;
    for (int64_t i = 0; i < s1.n; i++)
        for (int64_t j = 0; j < s0.n; j++)
            if (s0.id[j] == s1.id[i]) {
                double d2 = 0;
                for (int k = 0; k < dim; k++) d2 += (s1.x[3 * i + k] - s0.x[3 * j + k]) * (s1.x[3 * i + k] - s0.x[3 * j + k]);
                path += sqrt(d2) / (double)s1.n;
            }
    ck_assert_msg(path > 10 * 0.2 * mean_r, "balls moved %g m on average, under ten skins", path);
    drop(&s0);
    drop(&s1);
    sx_model_destroy(m);
}
END_TEST

/* Contacts reported after a cycle are those of the step's force evaluation:
 * positive overlap, compressive normal force Kn Un, and, with no applied load,
 * no gravity and no damping, the reported forces add up to each ball's force. */
typedef struct sums {
    sx_model *m;
    double *f; /* by dense index, dim components */
    int64_t bad;
    double worst;
} sums;

static bool add_force(const sx_contact_info *c, void *ud)
{
    sums *s = ud;
    const int dim = sx_model_dim(s->m);
    /* no dashpot here: the normal force is the linear spring's, 4-6 */
    if (!(c->overlap > 0) || !(c->fn > 0) || fabs(c->fn - c->kn * c->overlap) > 1e-12 * c->fn) {
        s->bad++;
        if (-c->overlap > s->worst) s->worst = -c->overlap;
    }
    double F[3];
    for (int k = 0; k < dim; k++) F[k] = c->fn * c->normal[k] + c->shear[k]; /* force on b */
    for (int64_t i = 0; i < sx_ball_count(s->m); i++) {
        const int64_t id = sx_ball_id_at(s->m, i);
        if (id == c->a)
            for (int k = 0; k < dim; k++) s->f[i * 3 + k] += c->is_wall ? F[k] : -F[k];
        if (!c->is_wall && id == c->b)
            for (int k = 0; k < dim; k++) s->f[i * 3 + k] += F[k];
    }
    return true;
}

START_TEST(reported_contacts_are_consistent)
{
    const int dim = _i;
    sx_model *m = gas(dim, 777 + (uint64_t)dim, true);
    int64_t checked = 0, bad = 0;
    double worst = 0, ferr = 0, fscale = 0;
    for (int c = 0; c < 20; c++) {
        ck_assert_cycle(m, 23);
        const int64_t n = sx_ball_count(m);
        sums s = {m, calloc((size_t)n * 3, sizeof(double)), 0, 0};
        ck_assert_ptr_nonnull(s.f);
        sx_contact_each(m, add_force, &s);
        for (int64_t i = 0; i < n; i++) {
            double f[3];
            sx_ball_get_vec(m, sx_ball_id_at(m, i), SX_BALL_FORCE, f);
            for (int k = 0; k < dim; k++) {
                ferr = fmax(ferr, fabs(f[k] - s.f[i * 3 + k]));
                fscale = fmax(fscale, fabs(f[k]));
            }
        }
        checked += sx_contact_count(m);
        bad += s.bad;
        worst = fmax(worst, s.worst);
        free(s.f);
    }
    ck_assert(checked > 50);
    ck_assert_msg(bad == 0, "%lld of %lld reported contacts have overlap <= 0 (down to %g m) or fn != Kn overlap",
                  (long long)bad, (long long)checked, -worst);
    ck_assert_msg(ferr <= 1e-9 * fscale, "reported contact forces differ from the balls' forces by %g N (scale %g N)",
                  ferr, fscale);
    sx_model_destroy(m);
}
END_TEST

/* Two identical models report identical contact sequences, bit for bit. */
typedef struct record {
    int64_t a, b;
    int wall;
    double fn, overlap, shear[3], normal[3];
} record;

typedef struct records {
    record *r;
    int64_t n, cap;
} records;

static bool keep(const sx_contact_info *c, void *ud)
{
    records *s = ud;
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 256;
        s->r = realloc(s->r, (size_t)s->cap * sizeof *s->r);
        ck_assert_ptr_nonnull(s->r);
    }
    record *r = &s->r[s->n++];
    memset(r, 0, sizeof *r);
    r->a = c->a, r->b = c->b, r->wall = c->is_wall, r->fn = c->fn, r->overlap = c->overlap;
    memcpy(r->shear, c->shear, sizeof r->shear);
    memcpy(r->normal, c->normal, sizeof r->normal);
    return true;
}

START_TEST(deterministic_order)
{
    const int dim = _i;
    sx_model *m[2] = {gas(dim, 99, true), gas(dim, 99, true)};
    for (int round = 0; round < 3; round++) {
        records r[2] = {{0}, {0}};
        for (int k = 0; k < 2; k++) {
            ck_assert_cycle(m[k], 150);
            sx_contact_each(m[k], keep, &r[k]);
        }
        ck_assert(r[0].n > 0);
        ck_assert_int_eq(r[0].n, r[1].n);
        for (int64_t i = 0; i < r[0].n; i++)
            ck_assert_msg(memcmp(&r[0].r[i], &r[1].r[i], sizeof(record)) == 0, "contact %lld differs", (long long)i);
        ck_assert_uint_eq(sx_model_state_hash(m[0]), sx_model_state_hash(m[1]));
        free(r[0].r);
        free(r[1].r);
    }
    sx_model_destroy(m[0]);
    sx_model_destroy(m[1]);
}
END_TEST

static bool stop_now(const sx_contact_info *c, void *ud)
{
    (void)c;
    ++*(int64_t *)ud;
    return false;
}

START_TEST(each_stops_on_false)
{
    const int dim = _i;
    sx_model *m = gas(dim, 5, true);
    ck_assert_cycle(m, 50);
    ck_assert(sx_contact_count(m) > 1);
    int64_t calls = 0;
    ck_assert(!sx_contact_each(m, stop_now, &calls));
    ck_assert_int_eq(calls, 1);
    sx_model_destroy(m);
}
END_TEST

/* ------------------------------------------------ history across rebuilds */

/* Ball B is pressed obliquely against ball A and driven tangentially at a
 * fixed velocity (A fixed): a sticking contact whose shear force grows by
 * -Ks Vs dt every step (4-20). Four spectator balls sit far from both. */
enum { NSPEC = 4 };
static const double RB = 0.01, DT = 1e-6;

typedef struct duo {
    sx_model *m;
    int64_t a, b, spec[NSPEC];
} duo;

static duo make_duo(int dim)
{
    duo d;
    d.m = scene_model(dim, NULL, DT, 1e8, 0.5, 2650);
    /* spectators first, lower left, so they sort before the pair */
    for (int s = 0; s < NSPEC; s++) {
        const double x[3] = {-0.08 + 0.03 * s, -0.07, -0.05};
        d.spec[s] = scene_ball(d.m, x, NULL, RB);
    }
    /* B is added before A; A sits up and to the left of B, so whether A or B
     * comes first in the cell order depends on where the grid's rows fall */
    double n[3] = {-0.8660254037844386, 0.5, 0}, t[3] = {0.5, 0.8660254037844386, 0};
    if (dim == 3) {
        n[0] = -0.8, n[1] = 0.6, n[2] = 0;      /* |n| = 1 */
        t[0] = 0.36, t[1] = 0.48, t[2] = 0.8;   /* t . n = 0, |t| = 1 */
    }
    const double xb[3] = {0.04, 0.02, 0.01};
    double xa[3] = {0, 0, 0}, vb[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) {
        xa[k] = xb[k] + (2 * RB - 1e-4) * n[k];
        vb[k] = 0.01 * t[k];
    }
    d.b = scene_ball(d.m, xb, vb, RB);
    d.a = scene_ball(d.m, xa, NULL, RB);
    const unsigned all = dim == 3 ? SX_FIX_VEL | SX_FIX_SPIN : SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ;
    ck_assert_int_eq(sx_ball_set_fixity(d.m, d.a, all), SX_OK);
    ck_assert_int_eq(sx_ball_set_fixity(d.m, d.b, all), SX_OK);
    return d;
}

typedef struct shear_probe {
    int64_t a, b;
    double fs[3];
    int found;
} shear_probe;

static bool find_shear(const sx_contact_info *c, void *ud)
{
    shear_probe *p = ud;
    if (!c->is_wall && ((c->a == p->a && c->b == p->b) || (c->a == p->b && c->b == p->a))) {
        /* the shear force on A, whichever end the store calls b */
        const double sgn = c->b == p->a ? 1.0 : -1.0;
        for (int k = 0; k < 3; k++) p->fs[k] = sgn * c->shear[k];
        p->found++;
    }
    return true;
}

static void shear_on_a(const duo *d, double *fs)
{
    shear_probe p = {d->a, d->b, {0, 0, 0}, 0};
    sx_contact_each(d->m, find_shear, &p);
    ck_assert_int_eq(p.found, 1);
    memcpy(fs, p.fs, sizeof p.fs);
}

static int64_t dense_index(sx_model *m, int64_t id)
{
    for (int64_t i = 0; i < sx_ball_count(m); i++)
        if (sx_ball_id_at(m, i) == id) return i;
    return -1;
}

/* The perturbed model's shear must follow the reference step for step,
 * and keep growing by the same increment across the disturbance. */
static void follow(duo *p, duo *q, int steps)
{
    const int dim = sx_model_dim(p->m);
    double prev[3], now[3], ref[3], inc0[3] = {0, 0, 0};
    shear_on_a(q, prev);
    for (int s = 0; s < steps; s++) {
        ck_assert_cycle(p->m, 1);
        ck_assert_cycle(q->m, 1);
        shear_on_a(p, now);
        shear_on_a(q, ref);
        double mag = 0;
        for (int k = 0; k < dim; k++) mag += ref[k] * ref[k];
        mag = sqrt(mag);
        for (int k = 0; k < dim; k++) {
            ck_assert_msg(fabs(now[k] - ref[k]) <= 1e-12 * mag, "step %d: shear %g != %g (reference)", s, now[k], ref[k]);
            const double inc = now[k] - prev[k];
            if (s == 0) inc0[k] = inc;
            ck_assert_msg(fabs(inc - inc0[k]) <= 1e-3 * fabs(inc0[k]) + 1e-9 * mag,
                          "step %d: shear jumped by %g (steady increment %g)", s, inc, inc0[k]);
        }
        memcpy(prev, now, sizeof now);
    }
}

START_TEST(history_survives_rebuild)
{
    const int dim = _i;
    /* find a jump of a spectator after which the re-sort puts A and B in the
     * other dense order, so the history transfer also crosses an a/b swap;
     * the jumps move the grid's lower corner, shifting its rows and columns */
    int swapped_at = -1, tried = 0;
    for (int j = 0; j < 56 && swapped_at < 0; j++, tried++) {
        const double jump[3] = {-0.05 - 0.006 * (j % 7), -0.095 - 0.005 * (j / 7), -0.08};
        duo p = make_duo(dim), q = make_duo(dim);
        ck_assert_cycle(p.m, 20);
        ck_assert_cycle(q.m, 20);
        double fs[3];
        shear_on_a(&p, fs);
        ck_assert(fabs(fs[0]) + fabs(fs[1]) > 0); /* the contact carries shear */
        const int64_t before = dense_index(p.m, p.a) < dense_index(p.m, p.b);
        /* the forced rebuild: a distant ball's position is set */
        ck_assert_int_eq(sx_ball_set_vec(p.m, p.spec[0], SX_BALL_POS, jump), SX_OK);
        follow(&p, &q, 20);
        if ((dense_index(p.m, p.a) < dense_index(p.m, p.b)) != before) swapped_at = j;
        sx_model_destroy(p.m);
        sx_model_destroy(q.m);
    }
    ck_assert_int_gt(tried, 0);
    ck_assert_msg(swapped_at >= 0, "no jump re-sorted the pair; the scene needs adjusting to exercise the swap");
}
END_TEST

START_TEST(history_survives_remove)
{
    const int dim = _i;
    duo p = make_duo(dim), q = make_duo(dim);
    ck_assert_cycle(p.m, 20);
    ck_assert_cycle(q.m, 20);
    const int64_t n = sx_ball_count(p.m);
    /* precondition: a spectator first and one of the pair last in the dense order */
    const int64_t first = sx_ball_id_at(p.m, 0), last = sx_ball_id_at(p.m, n - 1);
    ck_assert(first != p.a && first != p.b);
    ck_assert(last == p.a || last == p.b);
    const bool a_first = dense_index(p.m, p.a) < dense_index(p.m, p.b);
    /* removal swaps the last ball into the hole: the pair's ends swap order */
    ck_assert_int_eq(sx_ball_remove(p.m, first), SX_OK);
    ck_assert_int_eq(sx_ball_id_at(p.m, 0), last);
    ck_assert((dense_index(p.m, p.a) < dense_index(p.m, p.b)) != a_first);
    /* the history is there before any step ... */
    double fp[3], fq[3];
    shear_on_a(&p, fp);
    shear_on_a(&q, fq);
    for (int k = 0; k < dim; k++) ck_assert_double_eq(fp[k], fq[k]);
    /* ... and carries on */
    follow(&p, &q, 20);
    /* a second removal, of another spectator, after the rebuild */
    ck_assert_int_eq(sx_ball_remove(p.m, p.spec[2]), SX_OK);
    follow(&p, &q, 10);
    sx_model_destroy(p.m);
    sx_model_destroy(q.m);
}
END_TEST

/* Ball-wall history survives a rebuild triggered elsewhere too. */
START_TEST(wall_history_survives_rebuild)
{
    const int dim = _i;
    sx_model *m[2];
    int64_t id[2], far[2];
    for (int k = 0; k < 2; k++) {
        m[k] = scene_model(dim, NULL, DT, 1e8, 0.5, 2650);
        sx_wall_def w = sx_wall_default_def(dim);
        ck_assert_int_eq(sx_wall_add(m[k], &w, NULL), SX_OK);
        const double xf[3] = {0.5, 0.5, 0.5};
        far[k] = scene_ball(m[k], xf, NULL, RB);
        double x[3] = {0, 0, 0}, v[3] = {0.01, 0.005, 0};
        x[dim - 1] = RB - 1e-4;
        v[dim - 1] = 0;
        id[k] = scene_ball(m[k], x, v, RB);
        const unsigned all = dim == 3 ? SX_FIX_VEL | SX_FIX_SPIN : SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ;
        ck_assert_int_eq(sx_ball_set_fixity(m[k], id[k], all), SX_OK);
        ck_assert_cycle(m[k], 30);
    }
    const double jump[3] = {-0.3, 0.7, 0.4};
    ck_assert_int_eq(sx_ball_set_vec(m[0], far[0], SX_BALL_POS, jump), SX_OK);
    for (int s = 0; s < 10; s++) {
        double f[2][3];
        for (int k = 0; k < 2; k++) {
            ck_assert_cycle(m[k], 1);
            sx_ball_get_vec(m[k], id[k], SX_BALL_FORCE, f[k]);
        }
        ck_assert(fabs(f[1][0]) > 0);
        for (int c = 0; c < dim; c++) ck_assert_double_eq_tol(f[0][c], f[1][c], 1e-12 * fabs(f[1][dim - 1]));
    }
    sx_model_destroy(m[0]);
    sx_model_destroy(m[1]);
}
END_TEST

/* A ball very far from a cluster must not make the grid huge. */
START_TEST(sparse_scene_memory)
{
    const int dim = _i;
    size_t bytes[2];
    for (int k = 0; k < 2; k++) {
        sx_model *m = gas(dim, 4242, false); /* no walls: they are infinite */
        if (k) {
            const double x[3] = {1e6, -2e6, 3e6};
            scene_ball(m, x, NULL, 0.005);
        }
        ck_assert_cycle(m, 5);
        step_and_compare(m);
        ck_assert_cycle(m, 5);
        bytes[k] = sx_model_bytes(m);
        sx_model_destroy(m);
    }
    ck_assert_msg(bytes[1] < bytes[0] + bytes[0] / 2, "a far ball grew the model from %zu to %zu bytes", bytes[0],
                  bytes[1]);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("broadphase");
    TCase *tc = tcase_create("broadphase");
    tcase_add_loop_test(tc, matches_brute_force, 2, 4);
    tcase_add_loop_test(tc, reported_contacts_are_consistent, 2, 4);
    tcase_add_loop_test(tc, deterministic_order, 2, 4);
    tcase_add_loop_test(tc, each_stops_on_false, 2, 4);
    tcase_add_loop_test(tc, history_survives_rebuild, 2, 4);
    tcase_add_loop_test(tc, history_survives_remove, 2, 4);
    tcase_add_loop_test(tc, wall_history_survives_rebuild, 2, 4);
    tcase_add_loop_test(tc, sparse_scene_memory, 2, 4);
    suite_add_tcase(s, tc);
    return scene_run_suite(s);
}
