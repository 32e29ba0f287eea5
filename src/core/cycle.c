/* The step pipeline (sx_model_cycle): broad phase (when needed) ->
 * timestep (auto) -> contact forces -> law of motion -> walls and the
 * periodic cell -> time, with the stability guard every GUARD_STEPS steps
 * and the dimension-specific stages in kernels.c; each stage timed into
 * the profile. */
#include "joints.h"
#include "laws/law.h"
#include "model_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* How often the energy guard looks at an unforced system. */
enum { GUARD_STEPS = 64 };

/* ---------------------------------------------------------------- cycle */

/* A cylinder whose radius its radial velocity would take to 0 or below
 * within the step: an error before the step moves anything (the radius ran
 * through 0 unseen, and the model then saved could not be loaded). */
static sx_status check_radii(sx_model *m)
{
    for (int64_t i = 0; i < m->nwall; i++) {
        const sx_wall *w = &m->walls[i];
        if (w->def.kind != SX_WALL_CYLINDER || w->def.radial_vel >= 0) continue;
        if (!(w->def.radius + w->def.radial_vel * m->dt > 0))
            return sx__fail(m, SX_EINVAL,
                            "cylinder %lld: its radius %g m would reach %g m at step %lld (radial velocity %g m/s%s); a "
                            "radius must stay > 0: %s",
                            (long long)w->id, w->def.radius, w->def.radius + w->def.radial_vel * m->dt,
                            (long long)m->step + 1, w->def.radial_vel, w->servo_on ? ", its servo's" : "",
                            w->servo_on ? "its servo closes it on nothing to push; lower max_speed, or give it a "
                                          "specimen to meet"
                                        : "stop it first (w:set_radial_vel(0))");
    }
    return SX_OK;
}

static void move_walls(sx_model *m, double *max_wall)
{
    *max_wall = 0;
    for (int64_t i = 0; i < m->nwall; i++) {
        sx_wall *w = &m->walls[i];
        double s = 0;
        for (int k = 0; k < m->dim; k++) {
            w->def.point[k] += w->def.vel[k] * m->dt;
            s += w->def.vel[k] * w->def.vel[k];
        }
        w->moved += sqrt(s) * m->dt;
        if (w->def.kind == SX_WALL_CYLINDER) {
            w->def.radius += w->def.radial_vel * m->dt;
            w->moved += fabs(w->def.radial_vel) * m->dt;
        }
        if (w->mesh) { /* a moving mesh: the turn about its point, then its vertices */
            const double turned = sx__mesh_turn(w, m->dt);
            w->moved += turned;
            if (turned > 0 || s > 0) sx__mesh_pose(w);
        }
        if (w->moved > *max_wall) *max_wall = w->moved;
    }
}

double sx__now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Closes a stage that began at t0; returns the time, the next stage's start. */
static double stage_end(sx_model *m, sx_stage s, double t0)
{
    const double t = sx__now();
    m->prof.seconds[s] += t - t0;
    m->prof.calls[s]++;
    return t;
}

bool sx_model_time_reached(const sx_model *m, double t_end, int64_t since)
{
    /* each sum of a timestep in the run rounds by at most half an ulp of
     * the time (an ulp <= eps |t|), one more for t_end itself */
    const double sums = m->step > since ? (double)(m->step - since) : 0;
    const double rounding = (sums + 1) * DBL_EPSILON * fmax(fabs(m->time), fabs(t_end));
    return m->time >= t_end - fmin(rounding, 0.5 * m->dt_prev);
}

/* What a decomposed cycle cannot go on to from the state the last one
 * left scattered, each rank's own balls current: the check of bonded
 * pairs' contact-model rows (sx__cmodel_prepare), which reads every pair.
 * (A build takes what it reads, periodic space's too: step_build.) */
static bool whole_needed(const sx_model *m) { return m->ncmodel && m->bb.bond && m->bb.cmodel; }

/* A build at a step of a cycle (or at the start of a decomposed one that
 * goes on from a scattered state): decomposed, the serial build on every
 * rank from what it reads, then the new cut, to which the balls, pairs
 * and bonds move (dd_migrate.c). */
static sx_status step_build(sx_model *m, const sx_kernels *k)
{
    sx_dd *dd = m->dd;
    sx_status st;
    if (m->cell && (st = sx__cell_check(m))) return sx__dd_agree_alike(m, st); /* the cell may have shrunk */
    if (dd && !sx__dd_build(m)) return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the state");
    if ((st = sx__check_skin(m))) return sx__dd_agree_alike(m, st); /* as at a cycle's start, however the run is cut */
    st = k->build(m);
    if (!st && dd && !sx__dd_plan(m)) st = SX_ENOMEM; /* the new slabs */
    if (st) return sx__build_failed(m, st);
    if (dd && !sx__dd_migrate(m)) /* balls, pairs and bonds to the ranks that now step them */
        return sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the state");
    return SX_OK;
}

sx_status sx__prepare_scattered(sx_model *m)
{
    sx_status st = sx__dd_agree_replicated(m);
    if (!st && whole_needed(m)) st = sx_model_gather(m);
    if (st) return st;
    if (!m->dd->scattered) return sx__dd_agree_alike(m, sx__prepare(m));
    if ((st = sx__prepare_laws(m))) return sx__dd_agree_alike(m, st);
    m->dd->active = true;
    if (m->build_needed && (st = step_build(m, sx__kernels(m)))) m->dd->active = false; /* as at a step */
    return st;
}

sx_status sx_model_gather(sx_model *m)
{
    if (!m->dd || !m->dd->scattered) return SX_OK;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "gather: the model is stepping");
    return sx__dd_whole(m, sx__kernels(m)->plan);
}

/* Decomposed, an instability a rank finds in its own part of the step
 * (its pairs, its wall blocks, its balls' or clumps' motion) is kept, the
 * first, and the rank goes on through the step's exchanges, moving
 * nothing more, to where the ranks agree on it (dd_agree.c). Any other
 * error (out of memory, an exchange that failed) may come before a
 * stage's own exchange: the rank stops there, out of step, as serially. */
static void keep(sx_model *m, sx_step_error *e, sx_status st, sx_fail_part part)
{
    e->st = st, e->part = part, e->order = m->dd->fail_order;
    memcpy(e->err, m->err, sizeof e->err);
    e->unstable = m->unstable;
}

/* After a part of the step that may fail on one rank: true to go on (no
 * error, or decomposed: an instability, or another error of the rank's
 * own part met after its exchanges, kept). */
static bool go_on(sx_model *m, sx_step_error *e, sx_status *st, sx_fail_part part)
{
    if (!*st) return true;
    if (!m->dd || (*st != SX_EUNSTABLE && !m->dd->own_error)) return false;
    m->dd->own_error = false;
    if (!e->st) keep(m, e, *st, part);
    m->dd->failed = true;
    *st = SX_OK;
    return true;
}

/* Where every rank stops together (an error all decide alike, st, or the
 * displacements' exchange telling of a rank's), decomposed: the error the
 * ranks agree on, from this rank's kept one or st. */
static sx_status stop_together(sx_model *m, sx_step_error *e, sx_status st, sx_fail_part part)
{
    if (!m->dd) return st;
    if (!e->st && st) keep(m, e, st, part);
    return sx__dd_agree_failure(m, e);
}

/* Decomposed, a stop before the step's energy chain (a cylinder's radius,
 * the cell's rates): the serial step has added its contacts' and walls'
 * energy sums by then, and none of the law of motion, which has not run
 * (the blocks' terms are the last step's): the chain of those sums. */
static sx_status stop_before_motion(sx_model *m, sx_step_error *e, sx_status st, sx_fail_part part)
{
    if (m->dd && m->track_energy) {
        for (int64_t b = 0; b < m->nblock; b++) m->blocks[b].damp_work = m->blocks[b].load_work = m->blocks[b].visc_work = 0;
        if (!sx__dd_energy(m))
            return sx__fail(m, SX_EINVAL, "cycle: the ranks could not sum the step's energies (out of memory?)");
    }
    return stop_together(m, e, st, part);
}

static sx_status cycle_steps(sx_model *m, int64_t n, double t_end, int64_t since)
{
    for (int k = 0; k < m->dim; k++)
        if (!(fabs(m->gravity[k]) < SX_GRAVITY_MAX)) /* a file's from before the limit */
            return sx__dd_agree_alike(
                m, sx__fail(m, SX_EINVAL,
                            "cycle: gravity component %g is beyond 1e100 m/s^2; set a smaller one (m:set_gravity)",
                            m->gravity[k]));
    if (m->dd) m->dd->failed = false, m->dd->fail_order = 0, m->dd->own_error = false;
    double t = sx__now();
    const int64_t builds = m->builds;
    sx_status st = SX_OK;
    /* decomposed and scattered: the ranks agree on what they hold whole
     * before any of them gathers (a wall moved on one rank alone would
     * otherwise leave it gathering while the others resume) */
    const sx_kernels *k = sx__kernels(m);
    if (m->dd && m->dd->scattered) st = sx__prepare_scattered(m);
    else st = sx__dd_agree_alike(m, sx__prepare(m)); /* the whole model, on every rank alike */
    /* the last cycle's plan goes on (nothing but the walls and settings
     * changed since: a caller that changes more gathers first), the
     * timestep rated rank by rank */
    const bool resume = !st && m->dd && m->dd->active;
    if (resume) m->prof.resumed++;
    if (m->builds != builds) t = stage_end(m, SX_STAGE_BROAD_PHASE, t);
    if (st) return st;
    if ((st = sx__update_timestep(m))) { /* every rank here alike, its estimate the ranks' least */
        if (resume) m->dd->active = false;
        return sx__dd_agree_alike(m, st);
    }
    if (m->dd && !resume && (st = sx__dd_begin(m))) return st; /* decomposed: each rank its slab (decompose.c) */
    sx_dd *dd = m->dd;
    sx_step_error kept = {.st = SX_OK};
    m->locked = true;
    /* the energy baseline is taken when the user has changed the system, not
     * at every call: a script cycling one step at a time is guarded too. A
     * mesh's overlaps are those its contact pass kept (kernels/queries.c),
     * stale after a placement or a move until a step has run: with meshes,
     * the baseline is taken after the first step (a ball placed 1 % into a
     * mesh floor tripped the guard 64 steps later, its strain "grown") */
    const bool baseline_after_step = m->guard_dirty && m->mesh_pairs;
    if (m->guard_dirty && !baseline_after_step && (st = sx__guard_start(m, false))) {
        m->locked = false;
        if (dd) dd->active = false;
        return st;
    }
    m->guard_dirty = baseline_after_step;
    double other = sx__now() - t; /* the stages outside the four of the step, summed over the steps */
    for (int64_t s = 0; s < n; s++) {
        if (sx_model_time_reached(m, t_end, since)) break; /* the time is global: every rank stops here */
        t = sx__now();
        bool stop = false; /* decomposed: where the ranks agree (sx__dd_stop) */
        if (dd && !sx__dd_stop(m, &stop)) {
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange their interrupts");
            break;
        }
        if (dd ? stop : sx__interrupted(m)) {
            st = sx__fail(m, SX_EINTERRUPT, "interrupted at step %lld", (long long)m->step);
            break;
        }
        if (m->build_needed) {
            st = step_build(m, k);
            t = stage_end(m, SX_STAGE_BROAD_PHASE, t);
            if (st) break;
        }
        st = sx__dd_agree_alike(m, sx__update_timestep(m)); /* at the same step on every rank */
        double t1 = sx__now();
        other += t1 - t;
        if (st) break;
        if (dd && !sx__dd_halo(m)) {
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange ghosts");
            break;
        }
        const double t_own = dd ? sx__now() : 0; /* decomposed: this rank's computing, for its pace */
        st = k->contacts(m);
        t1 = stage_end(m, SX_STAGE_BALL_CONTACTS, t1);
        if (!go_on(m, &kept, &st, SX_FAIL_CONTACTS)) break;
        st = k->walls(m);
        t1 = stage_end(m, SX_STAGE_WALL_CONTACTS, t1);
        if (!go_on(m, &kept, &st, SX_FAIL_WALLS)) break;
        /* the walls' and the cell's motion of this step, decided before any
         * body moves, so that a refusal leaves the step undone: the servos'
         * speeds (from this step's wall loads), a cylinder's radius kept
         * above 0, the cell's rates (every rank decides them alike) */
        sx__walls_servo(m);
        if ((st = check_radii(m))) {
            st = stop_before_motion(m, &kept, st, SX_FAIL_RADII);
            break;
        }
        if (m->cell && (st = sx__cell_rate(m))) {
            st = stop_before_motion(m, &kept, st, SX_FAIL_CELL);
            break;
        }
        double max_disp = INFINITY, max_wall; /* infinite: this rank failed (decomposed) */
        if (!kept.st) st = k->integrate(m, &max_disp);
        go_on(m, &kept, &st, SX_FAIL_MOTION); /* serially an error stays in st, the step's end below */
        if (dd) dd->busy += sx__now() - t_own, dd->busy_work += (double)dd->planned;
        if (!st && dd && m->track_energy && !sx__dd_energy(m)) /* the step's energy sums, in the serial order */
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not sum the step's energies (out of memory?)");
        if (!st && m->clumps && dd && !sx__dd_pebbles(m, NULL, 0)) /* to the clumps' owners, who step them */
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the pebbles' forces");
        if (!st && m->clumps) { /* kernels/clump_motion.c: the bodies move their pebbles */
            st = k->clumps_step(m, &max_disp);
            go_on(m, &kept, &st, SX_FAIL_CLUMPS);
        }
        if (!st && m->clumps && dd && !sx__dd_placed(m)) /* the placed pebbles to their owners */
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange the pebbles' places");
        if (kept.st) max_disp = INFINITY;
        /* every rank decides the same rebuild (the largest of the ranks' own
         * balls' and pebbles' moves), and learns of a rank's error */
        if (!st && dd && !dd->x.max(dd->x.ud, &max_disp))
            st = sx__fail(m, SX_EINVAL, "cycle: the ranks could not exchange their displacements");
        if (!st && dd && !(max_disp < INFINITY)) st = stop_together(m, &kept, SX_OK, SX_FAIL_MOTION);
        t = stage_end(m, SX_STAGE_INTEGRATION, t1);
        if (st) break;
        move_walls(m, &max_wall);
        if (m->cell) sx__cell_move(m); /* periodic space: the cell deforms */
        m->time += m->dt;
        m->dt_prev = m->dt;
        m->step++;
        m->prof.steps++;
        m->prof.calls[SX_STAGE_OTHER]++;
        /* Verlet criterion: two balls may close the gap by twice the largest
         * displacement, a ball and a wall by both of their displacements. */
        if (2 * max_disp > m->skin || max_disp + max_wall > m->skin) m->build_needed = true;
        /* a ghost moves with its owner and with the cell vectors that shift it */
        if (m->cell && 2 * max_disp + m->cell->moved > m->skin) m->build_needed = true;
        if (baseline_after_step && s == 0) {
            if ((st = sx__guard_start(m, true))) break;
            m->guard_dirty = false;
        }
        /* decomposed: chained sums (kernels/queries.c), the same decision on every rank */
        if (m->step % GUARD_STEPS == 0 && (st = sx__guard_check(m)) == SX_EUNSTABLE)
            st = stop_together(m, &kept, st, SX_FAIL_GUARD);
        other += sx__now() - t;
        if (st) break;
    }
    m->prof.seconds[SX_STAGE_OTHER] += other;
    m->locked = false;
    /* the whole state on every rank again, or lazily not (an interrupt and
     * an error the ranks agreed on stop them in step, sx__dd_stop and
     * sx__dd_agree_failure; after any other error the ranks are out of
     * step, the state mixed: the caller stops them) */
    const bool in_step = dd && (!st || st == SX_EINTERRUPT || dd->agreed);
    if (in_step) {
        const sx_status end = sx__dd_end(m, k->plan);
        if (end) st = end, dd->agreed = false;
    }
    if (dd) dd->active = dd->failed = false;
    if (dd && !in_step) dd->scattered = true;
    return st;
}

sx_status sx_model_cycle(sx_model *m, int64_t n) { return sx_model_cycle_until(m, n, INFINITY, m->step); }

sx_status sx_model_cycle_until(sx_model *m, int64_t n, double t_end, int64_t since)
{
    if (m->dd && !m->locked) m->dd->agreed = false; /* the error this call returns is its own */
    if (m->locked) return sx__fail(m, SX_ELOCKED, "cycle: the model is already stepping");
    if (n < 0) return sx__fail(m, SX_EINVAL, "cycle: the number of steps must be >= 0 (got %lld)", (long long)n);
    if (isnan(t_end)) return sx__fail(m, SX_EINVAL, "cycle: the time to stop at is not a number");
    m->err[0] = 0;
    m->interrupt = 0;
    const double t0 = sx__now();
    const sx_status st = cycle_steps(m, n, t_end, since);
    m->prof.cycle_seconds += sx__now() - t0;
    m->prof.cycles++;
    return st;
}
