/* The model: creation and material validation, cycling and time, the
 * automatic timestep, interruption from another thread, memory accounting,
 * the stage profile and energies. */
#include "scenes.h"

#include <check.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#define PI 3.14159265358979323846

#define ck_assert_cycle(m, n) \
    ck_assert_msg(sx_model_cycle((m), (n)) == SX_OK, "cycle failed: %s", sx_model_error(m))

#define ck_assert_msg_has(m, needle)                                                          \
    ck_assert_msg(strstr(sx_model_error(m), (needle)) != NULL, "message '%s' does not mention '%s'", \
                  sx_model_error(m), (needle))

#define ck_assert_rel(a, b, rel)                                                                         \
    do {                                                                                                 \
        const double a_ = (a), b_ = (b);                                                                 \
        ck_assert_msg(fabs(a_ - b_) <= (rel) * fabs(b_), "%s = %.17g, expected %.17g (rel. error %.3g > %g)", \
                      #a, a_, b_, fabs(a_ - b_) / fabs(b_), (double)(rel));                              \
    } while (0)

/* ------------------------------------------------------------ creation */

static void refuse(const sx_model_def *d, const char *needle)
{
    char err[256] = "";
    sx_model *m = sx_model_create(d, err, sizeof err);
    ck_assert_msg(m == NULL, "a bad definition was accepted (expected an error about %s)", needle);
    ck_assert_msg(strstr(err, needle) != NULL, "message '%s' does not mention '%s'", err, needle);
    ck_assert_ptr_null(sx_model_create(d, NULL, 0)); /* no buffer: still refused, no crash */
}

START_TEST(create_validation)
{
    sx_model_def d = sx_model_default_def();
    const int dims[] = {4, 1, 0, -3};
    for (int k = 0; k < 4; k++) {
        d.dim = dims[k];
        refuse(&d, "dim");
    }
    d = sx_model_default_def();
    const double dts[] = {-1e-6, NAN, INFINITY};
    for (int k = 0; k < 3; k++) {
        d.timestep = dts[k];
        refuse(&d, "timestep");
    }
    d = sx_model_default_def();
    for (int c = 0; c < 3; c++) {
        d.gravity[c] = NAN;
        refuse(&d, "gravity");
        d.gravity[c] = INFINITY;
        refuse(&d, "gravity");
        d.gravity[c] = 0;
    }
    d = sx_model_default_def();
    d.dim = 2;
    d.gravity[1] = -9.81;
    d.gravity[2] = -1.0;
    refuse(&d, "z gravity");
    d = sx_model_default_def();
    d.timestep_safety = 0;
    refuse(&d, "safety");
    d.timestep_safety = 1.5;
    refuse(&d, "safety");
    d = sx_model_default_def();
    d.skin = -1e-3;
    refuse(&d, "skin");
    /* the defaults, and a valid 2D model */
    d = sx_model_default_def();
    ck_assert_int_eq(d.dim, 3);
    ck_assert_double_eq(d.timestep, 0);
    ck_assert_double_eq(d.timestep_safety, 0.8);
    for (int dim = 2; dim <= 3; dim++) {
        d.dim = dim;
        d.gravity[0] = 0.5;
        d.gravity[1] = -9.81;
        d.gravity[2] = dim == 3 ? 1.0 : 0;
        char err[128];
        sx_model *m = sx_model_create(&d, err, sizeof err);
        ck_assert_ptr_nonnull(m);
        ck_assert_int_eq(sx_model_dim(m), dim);
        double g[3];
        sx_model_gravity(m, g);
        for (int k = 0; k < 3; k++) ck_assert_double_eq(g[k], d.gravity[k]);
        ck_assert_str_eq(sx_model_error(m), "");
        ck_assert_double_eq(sx_model_time(m), 0);
        ck_assert_int_eq(sx_model_step_count(m), 0);
        const double bad[3] = {0, NAN, 0};
        ck_assert_int_eq(sx_model_set_gravity(m, bad), SX_EINVAL);
        ck_assert_msg_has(m, "gravity");
        sx_model_gravity(m, g);
        ck_assert_double_eq(g[1], -9.81);
        sx_model_destroy(m);
    }
    sx_model_destroy(NULL);
}
END_TEST

START_TEST(material_validation)
{
    sx_model *m = scene_model(3, NULL, 0, 1e6, 0.5, 1000);
    const int before = sx_material_count(m);
    sx_material_def d;
#define BAD(member, value, needle)                                              \
    do {                                                                        \
        d = sx_material_default_def();                                          \
        d.member = (value);                                                     \
        ck_assert_int_eq(sx_material_set(m, "rock", &d, NULL), SX_EINVAL);      \
        ck_assert_msg_has(m, needle);                                           \
        ck_assert_msg_has(m, "rock");                                           \
    } while (0)
    BAD(density, 0.0, "density");
    BAD(density, -2650.0, "density");
    BAD(density, NAN, "density");
    BAD(kn, 0.0, "kn");
    BAD(kn, -1e8, "kn");
    BAD(kn, INFINITY, "kn");
    BAD(ks, -1.0, "ks");
    BAD(damping, 1.0, "damping");
    BAD(damping, 1.5, "damping");
    BAD(damping, -0.1, "damping");
    BAD(friction, -0.1, "friction");
    BAD(friction, NAN, "friction");
    BAD(viscous_normal, -0.1, "viscous_normal");
    BAD(viscous_shear, -0.1, "viscous_shear");
#undef BAD
    ck_assert_int_eq(sx_material_count(m), before);
    ck_assert_int_eq(sx_material_find(m, "rock"), -1);
    d = sx_material_default_def();
    ck_assert_int_eq(sx_material_set(m, "", &d, NULL), SX_EINVAL);
    ck_assert_msg_has(m, "name");
    char longname[200];
    memset(longname, 'x', sizeof longname - 1);
    longname[sizeof longname - 1] = 0;
    ck_assert_int_eq(sx_material_set(m, longname, &d, NULL), SX_EINVAL);
    ck_assert_msg_has(m, "name");
    /* a good one, then its redefinition keeps its index */
    int i1, i2;
    d.friction = 0.0; /* the edges of the valid ranges */
    d.ks = 0.0;
    d.damping = 0.0;
    ck_assert_int_eq(sx_material_set(m, "rock", &d, &i1), SX_OK);
    ck_assert_int_eq(sx_material_count(m), before + 1);
    d.damping = 0.7;
    ck_assert_int_eq(sx_material_set(m, "rock", &d, &i2), SX_OK);
    ck_assert_int_eq(i1, i2);
    ck_assert_int_eq(sx_material_count(m), before + 1);
    ck_assert_str_eq(sx_material_name(m, i1), "rock");
    ck_assert_ptr_null(sx_material_name(m, 99));
    sx_material_def got;
    ck_assert_int_eq(sx_material_get(m, i1, &got), SX_OK);
    ck_assert_double_eq(got.damping, 0.7);
    ck_assert_int_eq(sx_material_get(m, 99, &got), SX_ENOTFOUND);
    sx_model_destroy(m);
}
END_TEST

/* ------------------------------------------------------- cycle and time */

START_TEST(cycle_arguments)
{
    const int dim = _i;
    const double g[3] = {0, -9.81, 0};
    sx_model *m = scene_model(dim, g, 1e-4, 1e6, 0.5, 1000);
    const double x[3] = {0, 1, 0}, v[3] = {0.3, 0, 0};
    scene_ball(m, x, v, 0.1);
    ck_assert_cycle(m, 3);
    const uint64_t h = sx_model_state_hash(m);
    const double t = sx_model_time(m);
    ck_assert_int_eq(sx_model_cycle(m, -1), SX_EINVAL);
    ck_assert_msg_has(m, "-1");
    ck_assert_int_eq(sx_model_cycle(m, INT64_MIN), SX_EINVAL);
    ck_assert_uint_eq(sx_model_state_hash(m), h);
    ck_assert_cycle(m, 0); /* a no-op */
    ck_assert_uint_eq(sx_model_state_hash(m), h);
    ck_assert_double_eq(sx_model_time(m), t);
    ck_assert_int_eq(sx_model_step_count(m), 3);
    /* a successful cycle clears the last error */
    ck_assert_int_eq(sx_model_cycle(m, -1), SX_EINVAL);
    ck_assert_cycle(m, 1);
    ck_assert_str_eq(sx_model_error(m), "");
    sx_model_destroy(m);
}
END_TEST

/* sx_model_cycle_until: no step once the time is reached (none when it is
 * already), the first step past it, NaN refused. */
START_TEST(cycle_until_time)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-4, 1e6, 0.5, 1000);
    scene_ball(m, (const double[3]){0, 0, 0}, NULL, 0.1);
    ck_assert_int_eq(sx_model_cycle_until(m, 1000, 0.0123, 0), SX_OK);
    ck_assert_int_eq(sx_model_step_count(m), 123); /* 0.0123 within the rounding of 123 sums */
    ck_assert_int_eq(sx_model_cycle_until(m, 1000, 0.0123, 0), SX_OK);
    ck_assert_int_eq(sx_model_step_count(m), 123); /* reached: no step */
    ck_assert_int_eq(sx_model_cycle_until(m, 5, 1.0, 123), SX_OK);
    ck_assert_int_eq(sx_model_step_count(m), 128); /* n stops it first */
    ck_assert_int_eq(sx_model_cycle_until(m, 1000, 0.01285, 123), SX_OK);
    ck_assert_int_eq(sx_model_step_count(m), 129); /* past 0.01285 by the first step after it */
    ck_assert_int_eq(sx_model_cycle_until(m, 1, NAN, 0), SX_EINVAL);
    ck_assert_msg_has(m, "not a number");
    ck_assert_int_eq(sx_model_step_count(m), 129);
    sx_model_destroy(m);
}
END_TEST

START_TEST(time_user_timestep)
{
    const int dim = _i;
    /* a dyadic timestep: every partial sum is exact */
    sx_model *m = scene_model(dim, NULL, 0x1.0p-14, 1e6, 0.5, 1000);
    scene_ball(m, (const double[3]){0, 0, 0}, NULL, 0.1);
    ck_assert_double_eq(sx_model_timestep(m), 0x1.0p-14);
    ck_assert_cycle(m, 1000);
    ck_assert_int_eq(sx_model_step_count(m), 1000);
    ck_assert_double_eq(sx_model_time(m), 1000 * 0x1.0p-14);
    /* a general one: n dt within the rounding of n additions */
    ck_assert_int_eq(sx_model_set_timestep(m, 1e-4), SX_OK);
    ck_assert_double_eq(sx_model_timestep(m), 1e-4);
    const double t0 = sx_model_time(m);
    ck_assert_cycle(m, 777);
    ck_assert_cycle(m, 223);
    ck_assert_int_eq(sx_model_step_count(m), 2000);
    ck_assert_double_eq_tol(sx_model_time(m), t0 + 1000 * 1e-4, 1000 * DBL_EPSILON);
    /* refused timesteps leave it alone */
    ck_assert_int_eq(sx_model_set_timestep(m, -1e-4), SX_EINVAL);
    ck_assert_msg_has(m, "timestep");
    ck_assert_int_eq(sx_model_set_timestep(m, NAN), SX_EINVAL);
    ck_assert_int_eq(sx_model_set_timestep(m, INFINITY), SX_EINVAL);
    ck_assert_double_eq(sx_model_timestep(m), 1e-4);
    sx_model_destroy(m);
}
END_TEST

/* --------------------------------------------------- automatic timestep */

static double mass_of(sx_model *m, int64_t id)
{
    double v;
    ck_assert_int_eq(sx_ball_get(m, id, SX_BALL_MASS, &v), SX_OK);
    return v;
}

static double inertia_of(sx_model *m, int64_t id)
{
    double v;
    ck_assert_int_eq(sx_ball_get(m, id, SX_BALL_INERTIA, &v), SX_OK);
    return v;
}

/* A free ball is estimated as touching one entity with its own stiffnesses:
 * dt = safety min(sqrt(m / (kn + ks)), sqrt(I / (ks R^2))). */
START_TEST(auto_timestep_free_ball)
{
    const int dim = _i;
    const double ks_over_kn[] = {0.25, 1.0}; /* translation governs; rotation governs in 3D */
    for (int c = 0; c < 2; c++) {
        sx_model *m = scene_model(dim, NULL, 0, 1e8, 0.5, 2650);
        sx_material_def md = sx_material_default_def();
        md.kn = 1e8;
        md.ks = ks_over_kn[c] * 1e8;
        ck_assert_int_eq(sx_material_set(m, "m", &md, NULL), SX_OK);
        const double R = 0.01;
        const int64_t id = scene_ball(m, (const double[3]){0, 0, 0}, NULL, R);
        const double mass = mass_of(m, id), inertia = inertia_of(m, id);
        const double tr = sqrt(mass / (md.kn + md.ks)), rot = sqrt(inertia / (md.ks * R * R));
        const double crit = tr < rot ? tr : rot;
        if (c == 0) ck_assert(tr < rot);
        if (c == 1 && dim == 3) ck_assert(rot < tr);
        ck_assert_rel(sx_model_critical_timestep(m), crit, 4 * DBL_EPSILON);
        ck_assert_rel(sx_model_timestep(m), 0.8 * crit, 4 * DBL_EPSILON);
        /* the bound from the ball's own rating alone: its translation's, at least the estimate */
        ck_assert_rel(sx_model_critical_timestep_bound(m), tr, 4 * DBL_EPSILON);
        /* cycling uses it */
        ck_assert_cycle(m, 10);
        ck_assert_rel(sx_model_time(m), 10 * 0.8 * crit, 16 * DBL_EPSILON);
        /* a user value wins; 0 returns to the automatic one */
        ck_assert_int_eq(sx_model_set_timestep(m, 1e-7), SX_OK);
        ck_assert_double_eq(sx_model_timestep(m), 1e-7);
        ck_assert_int_eq(sx_model_set_timestep(m, 0), SX_OK);
        ck_assert_rel(sx_model_timestep(m), 0.8 * crit, 4 * DBL_EPSILON);
        sx_model_destroy(m);
    }
    /* the safety factor of the definition */
    sx_model_def d = sx_model_default_def();
    d.dim = dim;
    d.timestep_safety = 0.5;
    sx_model *m = sx_model_create(&d, NULL, 0);
    sx_material_def md = sx_material_default_def();
    int mat;
    ck_assert_int_eq(sx_material_set(m, "m", &md, &mat), SX_OK);
    sx_ball_def b = sx_ball_default_def();
    b.radius = 0.02;
    b.material = mat;
    int64_t id;
    ck_assert_int_eq(sx_ball_add(m, &b, &id), SX_OK);
    ck_assert_rel(sx_model_timestep(m), 0.5 * sx_model_critical_timestep(m), 4 * DBL_EPSILON);
    sx_model_destroy(m);
    /* nothing to estimate from */
    d.timestep_safety = 0.8;
    m = sx_model_create(&d, NULL, 0);
    ck_assert(isnan(sx_model_timestep(m)));
    ck_assert_msg_has(m, "timestep");
    sx_model_destroy(m);
}
END_TEST

/* In contact: k_tran = sum over contacts (Kn + Ks), k_rot = sum Ks R^2, the
 * contact stiffnesses springs in series (4-22/4-23). A ball with several
 * neighbours gets a smaller timestep than a free one. */
static void timestep_contacts(int dim, double ks)
{
    const double kn = 1e8, kw = 2e8, R = 0.01, un = 1e-4;
    sx_model *m = scene_model(dim, NULL, 0, kn, 0.5, 2650);
    sx_material_def md = sx_material_default_def();
    md.kn = kn;
    md.ks = ks;
    ck_assert_int_eq(sx_material_set(m, "m", &md, NULL), SX_OK);
    const int64_t lone = scene_ball(m, (const double[3]){5, 5, 5}, NULL, R);
    const double dt_free = 0.8 * fmin(sqrt(mass_of(m, lone) / (kn + ks)), sqrt(inertia_of(m, lone) / (ks * R * R)));
    ck_assert_rel(sx_model_timestep(m), dt_free, 4 * DBL_EPSILON);
    /* a centre ball with 2 dim neighbours, and a ball on a wall */
    const int64_t centre = scene_ball(m, (const double[3]){0, 0, 0}, NULL, R);
    int64_t nb[6];
    for (int k = 0; k < 2 * dim; k++) {
        double x[3] = {0, 0, 0};
        x[k / 2] = (k % 2 ? -1 : 1) * (2 * R - un);
        nb[k] = scene_ball(m, x, NULL, R);
    }
    sx_wall_def w = sx_wall_default_def(dim);
    w.point[dim - 1] = -1;
    w.kn = w.ks = kw;
    ck_assert_int_eq(sx_wall_add(m, &w, NULL), SX_OK);
    double xw[3] = {1, 1, 1};
    xw[dim - 1] = -1 + R - un;
    const int64_t onwall = scene_ball(m, xw, NULL, R);
    const double Kn = kn * kn / (2 * kn), Ks = ks * ks / (2 * ks);
    const double Knw = kn * kw / (kn + kw), Ksw = ks * kw / (ks + kw);
    const double mass = mass_of(m, centre), inertia = inertia_of(m, centre); /* all balls alike */
    const double nc = 2 * dim;
    double crit = fmin(sqrt(mass / (kn + ks)), sqrt(inertia / (ks * R * R)));                /* lone */
    crit = fmin(crit, fmin(sqrt(mass / (nc * (Kn + Ks))), sqrt(inertia / (nc * Ks * R * R)))); /* centre */
    crit = fmin(crit, fmin(sqrt(mass / (Kn + Ks)), sqrt(inertia / (Ks * R * R))));             /* neighbours */
    crit = fmin(crit, fmin(sqrt(mass / (Knw + Ksw)), sqrt(inertia / (Ksw * R * R))));          /* on the wall */
    ck_assert_rel(sx_model_critical_timestep(m), crit, 4 * DBL_EPSILON);
    ck_assert_rel(sx_model_timestep(m), 0.8 * crit, 4 * DBL_EPSILON);
    ck_assert(sx_model_timestep(m) < dt_free);
    /* the bound ignores the contacts (what makes it cheap): the lone ball's
     * translational rating, above the estimate they lower */
    ck_assert_rel(sx_model_critical_timestep_bound(m), sqrt(mass / (kn + ks)), 4 * DBL_EPSILON);
    ck_assert(sx_model_critical_timestep_bound(m) > crit);
    /* it is the centre ball that governs: its estimate alone, translational
     * or rotational as the stiffness ratio says */
    const double centre_tr = sqrt(mass / (nc * (Kn + Ks))), centre_rot = sqrt(inertia / (nc * Ks * R * R));
    ck_assert_rel(crit, ks < kn ? centre_tr : centre_rot, 1e-15);
    if (ks < kn)
        ck_assert(centre_tr < centre_rot);
    else
        ck_assert(centre_rot < centre_tr);
    /* separated again, the timestep goes back to the free estimate */
    for (int k = 0; k < 2 * dim; k++) {
        double x[3] = {0, 0, 0};
        x[k / 2] = (k % 2 ? -1 : 1) * 0.1;
        ck_assert_int_eq(sx_ball_set_vec(m, nb[k], SX_BALL_POS, x), SX_OK);
    }
    ck_assert_int_eq(sx_ball_remove(m, onwall), SX_OK);
    ck_assert_rel(sx_model_timestep(m), dt_free, 4 * DBL_EPSILON);
    sx_model_destroy(m);
}

START_TEST(auto_timestep_contacts)
{
    timestep_contacts(_i, 0.6e8); /* translation governs */
    timestep_contacts(_i, 2e8);   /* rotation governs */
}
END_TEST

/* ------------------------------------------------------------ interrupt */

typedef struct pester {
    sx_model *m;
    atomic_int done;
    atomic_int calls;
} pester;

static void *interrupter(void *ud)
{
    pester *p = ud;
    const struct timespec ms = {0, 2000000};
    while (!atomic_load(&p->done)) {
        nanosleep(&ms, NULL);
        if (atomic_load(&p->done)) break;
        sx_model_interrupt(p->m);
        atomic_fetch_add(&p->calls, 1);
    }
    return NULL;
}

/* A cycle clears the flag when it starts, so the interrupt must come while
 * it runs: a thread keeps interrupting until the cycle returns. */
START_TEST(interrupt_from_thread)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, 1000);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.2, 0.2, 0.2};
    scene_box_walls(m, lo, hi, 1e6, 0.5);
    scene_random_balls(m, 50, lo, hi, 0.005, 0.01, 0.1, 0.0, 3, NULL);
    pester p = {.m = m};
    atomic_init(&p.done, 0);
    atomic_init(&p.calls, 0);
    pthread_t th;
    ck_assert_int_eq(pthread_create(&th, NULL, interrupter, &p), 0);
    const sx_status st = sx_model_cycle(m, INT64_MAX);
    atomic_store(&p.done, 1);
    pthread_join(th, NULL);
    ck_assert_int_eq(st, SX_EINTERRUPT);
    ck_assert_msg_has(m, "interrupt");
    ck_assert(atomic_load(&p.calls) >= 1);
    /* usually some steps were taken, but an interrupt landing right after the
     * cycle cleared the flag stops it before its first step */
    const int64_t steps = sx_model_step_count(m);
    ck_assert(steps >= 0 && steps < INT64_MAX);
    ck_assert(fabs(sx_model_time(m) - (double)steps * 1e-5) <= (double)steps * 1e-5 * 1e-9);
    /* the model is consistent and usable afterwards */
    ck_assert_cycle(m, 10);
    ck_assert_int_eq(sx_model_step_count(m), steps + 10);
    ck_assert_int_eq(sx_ball_count(m), 50);
    const sx_energy e = sx_model_energy(m);
    ck_assert(isfinite(e.kinetic) && e.kinetic > 0);
    sx_model_destroy(m);
}
END_TEST

/* An interrupt asked for between cycles is cleared by the next cycle. */
START_TEST(interrupt_before_cycle_is_cleared)
{
    sx_model *m = scene_model(3, NULL, 1e-5, 1e6, 0.5, 1000);
    scene_ball(m, (const double[3]){0, 0, 0}, NULL, 0.1);
    sx_model_interrupt(m);
    ck_assert_cycle(m, 5);
    ck_assert_int_eq(sx_model_step_count(m), 5);
    sx_model_destroy(m);
}
END_TEST

/* A process-wide interrupt request (a Ctrl-C: sx_interrupt_request) stops
 * the core's long loops outside the steps, each leaving the model as it
 * was: the broad phase (in a cycle, and in m:bond's build), a clump
 * template's mass properties. The balls' order the build's sort changed
 * is put back, so a twin never interrupted runs on bit-identically. */
START_TEST(interrupt_request_stops_long_loops)
{
    const int dim = _i;
    sx_model *m[2];
    const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.1, 0.06}, g[3] = {0, -9.81, 0};
    for (int k = 0; k < 2; k++) {
        m[k] = scene_model(dim, g, 1e-5, 1e6, 0.5, 1000);
        scene_box_walls(m[k], lo, hi, 1e6, 0.5);
        /* packed enough that many balls touch from the start */
        scene_random_balls(m[k], dim == 3 ? 150 : 50, lo, hi, 0.004, 0.006, 1.0, 0.1, 3, NULL);
        ck_assert_cycle(m[k], 1000);
        /* a ball set where it is: the next cycle starts with a build */
        double x[3];
        const int64_t id = sx_ball_id_at(m[k], 0);
        ck_assert_int_eq(sx_ball_get_vec(m[k], id, SX_BALL_POS, x), SX_OK);
        ck_assert_int_eq(sx_ball_set_vec(m[k], id, SX_BALL_POS, x), SX_OK);
    }
    ck_assert_int_gt(sx_contact_count(m[0]), 0); /* a history to carry over */
    const uint64_t h = sx_model_state_hash(m[0]);
    sx_interrupt_request();
    ck_assert_int_eq(sx_model_cycle(m[0], 10), SX_EINTERRUPT);
    ck_assert_msg_has(m[0], "interrupted in the broad phase");
    ck_assert_int_eq(sx_model_step_count(m[0]), 1000);
    sx_bond_def b = sx_bond_default_def();
    b.kind = SX_BOND_CONTACT;
    b.gap = 1e-3;
    b.normal_strength = b.shear_strength = 1;
    int64_t count = -1;
    ck_assert_int_eq(sx_bond_install(m[0], &b, &count), SX_EINTERRUPT);
    ck_assert_int_eq(sx_bond_count(m[0]), 0);
    /* two overlapping pebbles */
    const double pos2[4] = {0, 0, 0.008, 0}, pos3[6] = {0, 0, 0, 0.008, 0, 0}, rad[2] = {0.005, 0.005};
    const sx_clump_template_def t = {dim == 3 ? pos3 : pos2, rad, 2, 0};
    ck_assert_int_eq(sx_clump_template_add(m[0], "pair", &t, NULL), SX_EINTERRUPT);
    ck_assert_msg_has(m[0], "interrupted (no template added)");
    ck_assert_int_eq(sx_clump_template_count(m[0]), 0);
    /* the request stays until answered */
    ck_assert(sx_interrupt_pending());
    sx_interrupt_clear();
    ck_assert(!sx_interrupt_pending());
    ck_assert_uint_eq(sx_model_state_hash(m[0]), h);
    int64_t moved = 0;
    for (int64_t i = 0; i < sx_ball_count(m[0]); i++) moved += sx_ball_id_at(m[0], i) != sx_ball_id_at(m[1], i);
    ck_assert_int_eq(moved, 0);
    for (int k = 0; k < 2; k++) ck_assert_cycle(m[k], 300);
    ck_assert_uint_eq(sx_model_state_hash(m[0]), sx_model_state_hash(m[1]));
    ck_assert_int_eq(sx_clump_template_add(m[0], "pair", &t, NULL), SX_OK);
    sx_model_destroy(m[0]);
    sx_model_destroy(m[1]);
}
END_TEST

/* --------------------------------------------------------------- memory */

START_TEST(bytes_grow_with_balls)
{
    const int dim = _i;
    sx_model *m = scene_model(dim, NULL, 1e-5, 1e6, 0.5, 1000);
    const size_t b0 = sx_model_bytes(m);
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    scene_random_balls(m, 100, lo, hi, 0.005, 0.01, 0.0, 0.0, 1, NULL);
    const size_t b1 = sx_model_bytes(m);
    const double lo2[3] = {2, 0, 0}, hi2[3] = {3, 1, 1}; /* apart from the first batch */
    scene_random_balls(m, 2000, lo2, hi2, 0.005, 0.01, 0.0, 0.0, 2, NULL);
    const size_t b2 = sx_model_bytes(m);
    ck_assert_msg(b0 < b1 && b1 < b2, "bytes %zu, %zu, %zu", b0, b1, b2);
    ck_assert_cycle(m, 2);
    const size_t b3 = sx_model_bytes(m);
    ck_assert(b3 >= b2);
    /* a few hundred bytes per ball, not kilobytes */
    ck_assert_msg(b3 < 2100 * 1024, "%zu bytes for 2100 balls", b3);
    sx_model_destroy(m);
}
END_TEST

/* sx_model_memory splits the tracked bytes by owner; its parts add up. */
START_TEST(memory_report)
{
    const int dim = _i;
    const double g[3] = {0, 0, 0};
    sx_model *m = scene_model(dim, g, 1e-5, 1e6, 0.5, 1000);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.2, 0.2, 0.2};
    const int64_t n = dim == 3 ? 400 : 100;
    scene_random_balls(m, n, lo, hi, 0.005, 0.01, 0.01, 0.2, 3, NULL);
    ck_assert_cycle(m, 5);
    const sx_memory r = sx_model_memory(m);
    ck_assert_uint_eq(r.total, sx_model_bytes(m));
    ck_assert_uint_eq(r.balls + r.contacts + r.bonds + r.work, r.total);
    ck_assert(r.peak >= r.total);
    ck_assert_int_eq(r.ball_count, n);
    ck_assert_int_eq(r.contact_count, sx_contact_count(m));
    ck_assert(r.pair_count >= r.contact_count && r.contact_count > 0);
    ck_assert(r.bytes_per_ball == (double)r.balls / (double)n);
    ck_assert(r.bytes_per_contact == (double)r.contacts / (double)r.contact_count);
    /* the state of a ball is at least position, velocity, spin, force, moment, radius, mass */
    ck_assert(r.bytes_per_ball >= (double)((4 * dim + 2 * (dim == 3 ? 3 : 1) + 2) * sizeof(double)));
    sx_model_destroy(m);
}
END_TEST

/* The stage timers: every step runs each of the step's stages once, the
 * broad phase runs once per build, and the stages together account for the
 * cycle's wall time (measured here around sx_model_cycle). No assertion on
 * speed. */
static double wall_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

START_TEST(profile_stages)
{
    const int dim = _i;
    const double g[3] = {0, dim == 2 ? -9.81 : 0, dim == 3 ? -9.81 : 0};
    sx_model *m = scene_model(dim, g, 2e-5, 1e6, 0.5, 1000);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.3, 0.3, 0.3};
    scene_box_walls(m, lo, hi, 1e6, 0.5);
    const int64_t n = dim == 3 ? 600 : 150;
    scene_random_balls(m, n, lo, hi, 0.005, 0.01, 0.5, 0.1, 5, NULL);
    sx_profile p = sx_model_profile(m);
    for (int s = 0; s < SX_STAGE_COUNT; s++) ck_assert(p.seconds[s] == 0 && p.calls[s] == 0);
    const double t0 = wall_now();
    for (int c = 0; c < 4; c++) ck_assert_cycle(m, 100);
    const double wall = wall_now() - t0;
    p = sx_model_profile(m);
    ck_assert_int_eq(p.steps, 400);
    ck_assert_int_eq(p.cycles, 4);
    ck_assert_int_eq(p.calls[SX_STAGE_BALL_CONTACTS], 400);
    ck_assert_int_eq(p.calls[SX_STAGE_WALL_CONTACTS], 400);
    ck_assert_int_eq(p.calls[SX_STAGE_INTEGRATION], 400);
    ck_assert_int_eq(p.calls[SX_STAGE_OTHER], 400);
    ck_assert_int_eq(p.calls[SX_STAGE_CALLBACKS], 0);
    /* balls thrown at 0.5 m/s use up the skin: the first build and some more */
    ck_assert_msg(p.calls[SX_STAGE_BROAD_PHASE] >= 2 && p.calls[SX_STAGE_BROAD_PHASE] <= 400, "%lld builds",
                  (long long)p.calls[SX_STAGE_BROAD_PHASE]);
    double sum = 0;
    for (int s = 0; s < SX_STAGE_COUNT; s++) {
        ck_assert(p.seconds[s] >= 0);
        sum += p.seconds[s];
    }
    ck_assert(p.seconds[SX_STAGE_BALL_CONTACTS] > 0 && p.seconds[SX_STAGE_INTEGRATION] > 0);
    /* the stages tile the cycle: what falls between two clock reads is a
     * few instructions per step; a busy machine may stretch either side */
    ck_assert_msg(sum <= p.cycle_seconds * (1 + 1e-9) && sum >= 0.9 * p.cycle_seconds,
                  "stages %.6f s, cycles %.6f s", sum, p.cycle_seconds);
    ck_assert_msg(p.cycle_seconds <= wall * (1 + 1e-9) && p.cycle_seconds >= 0.8 * wall - 1e-4,
                  "cycles %.6f s, measured around them %.6f s", p.cycle_seconds, wall);
    /* time reported from outside, as the Lua layer reports its callbacks */
    sx_model_profile_add(m, SX_STAGE_CALLBACKS, 0.25);
    sx_model_profile_add(m, SX_STAGE_CALLBACKS, 0.5);
    sx_model_profile_add(m, SX_STAGE_COUNT, 1.0); /* ignored */
    p = sx_model_profile(m);
    ck_assert_int_eq(p.calls[SX_STAGE_CALLBACKS], 2);
    ck_assert(p.seconds[SX_STAGE_CALLBACKS] == 0.75);
    char buf[1024];
    const int need = sx_profile_format(&p, n, buf, sizeof buf);
    ck_assert(need > 0 && (size_t)need < sizeof buf && strlen(buf) == (size_t)need);
    for (int s = 0; s < SX_STAGE_COUNT; s++) ck_assert_ptr_nonnull(strstr(buf, sx_stage_name((sx_stage)s)));
    ck_assert_int_eq(sx_profile_format(&p, n, buf, 10), need); /* truncated, still the full length */
    ck_assert_uint_eq(strlen(buf), 9);
    ck_assert_ptr_null(sx_stage_name(SX_STAGE_COUNT));
    sx_model_profile_reset(m);
    p = sx_model_profile(m);
    ck_assert(p.steps == 0 && p.cycle_seconds == 0 && p.calls[SX_STAGE_INTEGRATION] == 0);
    sx_model_destroy(m);
}
END_TEST

/* -------------------------------------------------------------- energies */

static double dot(const double *a, const double *b, int n)
{
    double s = 0;
    for (int k = 0; k < n; k++) s += a[k] * b[k];
    return s;
}

/* w x r (2D: w the scalar about z) */
static void spin_cross(int dim, const double *w, const double *r, double *out)
{
    if (dim == 3) {
        out[0] = w[1] * r[2] - w[2] * r[1];
        out[1] = w[2] * r[0] - w[0] * r[2];
        out[2] = w[0] * r[1] - w[1] * r[0];
    } else {
        out[0] = -w[0] * r[1];
        out[1] = w[0] * r[0];
        out[2] = 0;
    }
}

/* Two balls in an oblique contact and a third on a wall, all moving and
 * spinning at fixed rates (fixities), so after one step every term is known:
 * kinetic 1/2 m v^2 + 1/2 I w^2, gravitational -m g.(x - v dt/2), strain 1/2 Kn Un^2
 * + 1/2 |Fs|^2 / Ks with Fs = -Ks Vs dt from the first step (4-16 ... 4-20). */
START_TEST(energy_by_hand)
{
    const int dim = _i, rd = dim == 3 ? 3 : 1;
    const double g[3] = {0.7, -9.81, dim == 3 ? 0.3 : 0};
    const double dt = 1e-6, k = 1e8, R = 0.01;
    sx_model *m = scene_model(dim, g, dt, k, 0.5, 2650);
    sx_wall_def wd = sx_wall_default_def(dim);
    ck_assert_int_eq(sx_wall_add(m, &wd, NULL), SX_OK);
    double n0[3] = {0.6, 0.8, 0};
    if (dim == 3) n0[0] = 0.48, n0[1] = 0.6, n0[2] = 0.64;
    const double xa[3] = {0.1, 0.2, 0.3};
    double xb[3] = {0, 0, 0}, xc[3] = {0.5, 0.5, 0.5};
    for (int c = 0; c < dim; c++) xb[c] = xa[c] + (2 * R - 1e-4) * n0[c];
    xc[dim - 1] = R - 2e-4;
    const double *x0[3] = {xa, xb, xc};
    const double v[3][3] = {{0.1, -0.2, 0.05}, {-0.3, 0.1, 0.2}, {0.05, 0.0, 0.0}};
    const double w[3][3] = {{2.0, -1.0, 0.5}, {-3.0, 0.5, 1.5}, {0.0, 0.0, 0.0}};
    int64_t id[3];
    double mass[3], inertia[3];
    for (int i = 0; i < 3; i++) {
        double vi[3] = {v[i][0], v[i][1], v[i][2]};
        if (i == 2) vi[dim - 1] = 0; /* the wall ball slides, its overlap stays */
        id[i] = scene_ball(m, x0[i], vi, R);
        ck_assert_int_eq(sx_ball_set_vec(m, id[i], SX_BALL_SPIN, w[i]), SX_OK);
        ck_assert_int_eq(sx_ball_set_fixity(m, id[i], dim == 3 ? SX_FIX_VEL | SX_FIX_SPIN : SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ),
                         SX_OK);
        mass[i] = mass_of(m, id[i]);
        inertia[i] = inertia_of(m, id[i]);
    }
    ck_assert_cycle(m, 1);
    const sx_energy e = sx_model_energy(m);
    /* kinetic, and gravitational at the velocities' time: half a step
     * before the new positions x0 + v dt */
    double ek = 0, eg = 0;
    for (int i = 0; i < 3; i++) {
        double vi[3], wi[3], xi[3], xm[3] = {0, 0, 0};
        ck_assert_int_eq(sx_ball_get_vec(m, id[i], SX_BALL_VEL, vi), SX_OK);
        ck_assert_int_eq(sx_ball_get_vec(m, id[i], SX_BALL_SPIN, wi), SX_OK);
        ck_assert_int_eq(sx_ball_get_vec(m, id[i], SX_BALL_POS, xi), SX_OK);
        for (int c = 0; c < dim; c++) ck_assert_double_eq_tol(xi[c], x0[i][c] + vi[c] * dt, 1e-15);
        ek += 0.5 * mass[i] * dot(vi, vi, dim) + 0.5 * inertia[i] * dot(wi, wi, rd);
        for (int c = 0; c < dim; c++) xm[c] = xi[c] - 0.5 * dt * vi[c];
        eg -= mass[i] * dot(g, xm, dim);
    }
    ck_assert_rel(e.kinetic, ek, 1e-14);
    ck_assert_rel(e.gravitational, eg, 1e-14);
    /* the shear of the first step, at the start positions (4-16, 4-17, 4-20) */
    const double Kn = k / 2, Ks = k / 2;
    double d0 = 0, nn[3] = {0, 0, 0};
    for (int c = 0; c < dim; c++) d0 += (xb[c] - xa[c]) * (xb[c] - xa[c]);
    d0 = sqrt(d0);
    for (int c = 0; c < dim; c++) nn[c] = (xb[c] - xa[c]) / d0;
    const double un0 = 2 * R - d0;
    double ra[3] = {0, 0, 0}, rb[3] = {0, 0, 0}, va[3], vb[3], vc[3] = {0, 0, 0};
    for (int c = 0; c < dim; c++) {
        ra[c] = (R - 0.5 * un0) * nn[c];
        rb[c] = -(R - 0.5 * un0) * nn[c];
    }
    spin_cross(dim, w[0], ra, va);
    spin_cross(dim, w[1], rb, vb);
    for (int c = 0; c < dim; c++) vc[c] = (v[1][c] + vb[c]) - (v[0][c] + va[c]);
    const double vn = dot(vc, nn, dim);
    double fs2 = 0;
    for (int c = 0; c < dim; c++) {
        const double fs = -Ks * (vc[c] - vn * nn[c]) * dt;
        fs2 += fs * fs;
    }
    ck_assert(sqrt(fs2) < 0.5 * Kn * un0); /* sticking */
    ck_assert(fs2 > 0);
    /* the wall ball: contact point velocity v + w x rb with rb = -(R - Un/2) n */
    const double unw = 2e-4;
    double nw[3] = {0, 0, 0}, rw[3] = {0, 0, 0}, vw[3];
    nw[dim - 1] = 1;
    for (int c = 0; c < dim; c++) rw[c] = -(R - 0.5 * unw) * nw[c];
    spin_cross(dim, w[2], rw, vw);
    double fsw2 = 0;
    {
        double vcw[3] = {0, 0, 0};
        for (int c = 0; c < dim; c++) vcw[c] = (c == dim - 1 ? 0 : v[2][c]) + vw[c];
        const double vnw = dot(vcw, nw, dim);
        for (int c = 0; c < dim; c++) {
            const double fs = -Ks * (vcw[c] - vnw * nw[c]) * dt; /* kw = kn: Ks = k/2 too */
            fsw2 += fs * fs;
        }
    }
    /* overlaps now, after the step */
    double xa1[3], xb1[3], xc1[3];
    sx_ball_get_vec(m, id[0], SX_BALL_POS, xa1);
    sx_ball_get_vec(m, id[1], SX_BALL_POS, xb1);
    sx_ball_get_vec(m, id[2], SX_BALL_POS, xc1);
    double d1 = 0;
    for (int c = 0; c < dim; c++) d1 += (xb1[c] - xa1[c]) * (xb1[c] - xa1[c]);
    const double un1 = 2 * R - sqrt(d1), unw1 = R - xc1[dim - 1];
    ck_assert(un1 > 0 && unw1 > 0);
    const double es = 0.5 * Kn * un1 * un1 + 0.5 * fs2 / Ks + 0.5 * Kn * unw1 * unw1 + 0.5 * fsw2 / Ks;
    ck_assert_rel(e.strain, es, 1e-12);
    /* the shear part is not negligible in the check */
    ck_assert(0.5 * (fs2 + fsw2) / Ks > 1e-6 * es);
    sx_model_destroy(m);
}
END_TEST

/* The energies are those of the current state: an overlap made by adding or
 * moving balls stores strain before any step has seen it (no shear yet). */
START_TEST(energy_of_new_overlaps)
{
    const int dim = _i;
    const double k = 1e8, R = 0.01, un = 2e-4;
    sx_model *m = scene_model(dim, NULL, 1e-6, k, 0.5, 2650);
    const int64_t a = scene_ball(m, (const double[3]){0, 0, 0}, NULL, R);
    scene_ball(m, (const double[3]){2 * R - un, 0, 0}, NULL, R);
    const double Kn = k / 2;
    ck_assert_rel(sx_model_energy(m).strain, 0.5 * Kn * un * un, 1e-12);
    /* after a step the pair has moved apart a little: Kn un^2 / 2 of the new overlap */
    ck_assert_cycle(m, 1);
    ck_assert(sx_model_energy(m).strain > 0);
    /* a ball moved onto another one */
    const int64_t c = scene_ball(m, (const double[3]){0.5, 0.5, 0.5}, NULL, R);
    ck_assert_cycle(m, 1);
    const double before = sx_model_energy(m).strain;
    double xa[3];
    ck_assert_int_eq(sx_ball_get_vec(m, a, SX_BALL_POS, xa), SX_OK);
    xa[1] -= 2 * R - un;
    ck_assert_int_eq(sx_ball_set_vec(m, c, SX_BALL_POS, xa), SX_OK);
    ck_assert_rel(sx_model_energy(m).strain, before + 0.5 * Kn * un * un, 1e-9);
    sx_model_destroy(m);
}
END_TEST

/* ------------------------------------------------------- empty models */

/* A model without balls (none yet, or all removed) cycles its walls with a
 * user timestep, and says why it cannot pick an automatic one. */
START_TEST(cycle_without_balls)
{
    const int dim = _i;
    for (int emptied = 0; emptied < 2; emptied++) {
        sx_model *m = scene_model(dim, NULL, 1e-3, 1e6, 0.5, 1000);
        sx_wall_def w = sx_wall_default_def(dim);
        w.vel[dim - 1] = 0.5;
        int64_t wid;
        ck_assert_int_eq(sx_wall_add(m, &w, &wid), SX_OK);
        if (emptied) {
            const int64_t id = scene_ball(m, (const double[3]){0, 5, 5}, NULL, 0.1);
            ck_assert_cycle(m, 2);
            ck_assert_int_eq(sx_ball_remove(m, id), SX_OK);
        }
        const double t0 = sx_model_time(m);
        ck_assert_cycle(m, 10);
        ck_assert_double_eq_tol(sx_model_time(m), t0 + 10e-3, 1e-15);
        sx_wall_def got;
        sx_wall_get(m, wid, &got);
        ck_assert_double_eq_tol(got.point[dim - 1], 0.5 * sx_model_time(m), 1e-15);
        ck_assert_int_eq(sx_contact_count(m), 0);
        ck_assert_int_eq(sx_model_set_timestep(m, 0), SX_OK);
        ck_assert_int_eq(sx_model_cycle(m, 1), SX_EINVAL);
        ck_assert_msg_has(m, "timestep");
        sx_model_destroy(m);
    }
}
END_TEST

/* A ball's state or load that no double can integrate (a force of
 * DBL_MAX, a velocity of 1e200 m/s: their squares overflow in the step) is
 * refused where it is set, naming the bound (issue 18: such a value used
 * to reach the step and stop it as "non-finite"); a large value within the
 * bound is taken and its step stays finite. */
START_TEST(non_finite_state_stops)
{
    const int dim = _i;
    for (int what = 0; what < 3; what++) {
        sx_model *m = scene_model(dim, NULL, 1e-3, 1e5, 0.5, 1000);
        const int64_t calm = scene_ball(m, (const double[3]){0, 0, 0}, NULL, 1e-3);
        const int64_t id = scene_ball(m, (const double[3]){1, 1, 1}, NULL, 1e-3);
        (void)calm;
        const sx_ball_vec field = what == 0 ? SX_BALL_APPLIED_FORCE : what == 1 ? SX_BALL_APPLIED_MOMENT : SX_BALL_VEL;
        const double huge[3] = {what == 2 ? 1e200 : DBL_MAX, 0, 0};
        ck_assert_int_eq(sx_ball_set_vec(m, id, field, huge), SX_EINVAL);
        ck_assert_msg_has(m, "below 1e100");
        if (what == 2) { /* 1e90 m/s: 1e87 m in a step, finite */
            ck_assert_int_eq(sx_ball_set_vec(m, id, SX_BALL_VEL, (const double[3]){1e90, 0, 0}), SX_OK);
            ck_assert_cycle(m, 3);
            double x[3];
            ck_assert_int_eq(sx_ball_get_vec(m, id, SX_BALL_POS, x), SX_OK);
            ck_assert(isfinite(x[0]) && x[0] > 1e87);
        }
        sx_model_destroy(m);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("model");
    TCase *tc = tcase_create("model");
    tcase_add_test(tc, create_validation);
    tcase_add_test(tc, material_validation);
    tcase_add_loop_test(tc, cycle_arguments, 2, 4);
    tcase_add_loop_test(tc, time_user_timestep, 2, 4);
    tcase_add_loop_test(tc, cycle_until_time, 2, 4);
    tcase_add_loop_test(tc, auto_timestep_free_ball, 2, 4);
    tcase_add_loop_test(tc, auto_timestep_contacts, 2, 4);
    tcase_add_loop_test(tc, bytes_grow_with_balls, 2, 4);
    tcase_add_loop_test(tc, memory_report, 2, 4);
    tcase_add_loop_test(tc, profile_stages, 2, 4);
    tcase_add_loop_test(tc, energy_by_hand, 2, 4);
    tcase_add_loop_test(tc, energy_of_new_overlaps, 2, 4);
    tcase_add_loop_test(tc, non_finite_state_stops, 2, 4);
    suite_add_tcase(s, tc);
    /* these could hang if the interrupt or an empty grid were mishandled */
    TCase *tq = tcase_create("bounded");
    tcase_set_timeout(tq, 20);
    tcase_add_loop_test(tq, interrupt_from_thread, 2, 4);
    tcase_add_test(tq, interrupt_before_cycle_is_cleared);
    tcase_add_loop_test(tq, interrupt_request_stops_long_loops, 2, 4);
    tcase_add_loop_test(tq, cycle_without_balls, 2, 4);
    suite_add_tcase(s, tq);
    return scene_run_suite(s);
}
