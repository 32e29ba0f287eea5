/* Cycling: m:cycle(n), m:solve{ratio=, steps=, time=}, and the callbacks
 * m:on(point, fn, {every=}) / m:off(id) they run.
 *
 * The core steps without ever calling Lua: a run cycles the core in
 * chunks that end at the next step where something is due (a callback, a
 * history sample, a ratio check, a progress refresh), and runs the Lua side
 * between chunks, when the core is not locked. Everything is keyed to the
 * model's absolute step count, so m:cycle(100) twice does exactly what
 * m:cycle(200) does, callbacks and histories included.
 *
 * Event handlers (m:on("bond_break", fn), ...) are in events.c; their
 * events are delivered after each chunk, before the callbacks.
 *
 * A callback with every = N runs at the step boundaries s with s % N == 0:
 * "after" (alias "cycle") once the step s is taken, "before" when the step
 * s + 1 is about to be taken. At one boundary the "after" callbacks run
 * first, then the histories are recorded, then the "before" callbacks. Ball
 * and wall removals a callback asks for are queued and applied when it
 * returns.
 *
 * Interrupts: a SIGINT handler cannot know the models, so each run lists
 * itself in a small static registry that sx_lua_interrupt_all() walks; it
 * flags every listed run and interrupts its core cycle. A listed run is
 * always alive: its record is a to-be-closed value of the running C frame,
 * unlisted when the frame returns or unwinds. The same close resets the
 * model's running state, so an error anywhere (in the core, a callback, an
 * interrupt) leaves the model usable. That holds only if the close itself
 * runs: the executable's interrupt hook must never raise on entering a C
 * function (a __close is one), which is why it waits for Lua code (main.c).
 * Long C work outside the core's cycle (generation) opens a run too and
 * polls it, so a Ctrl-C stops it as promptly as a cycle. */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bindings.h"
#include "seixo_lua.h"

enum { MAX_RUNS = 16 };  // models cycling inside each other's callbacks, at most
_Static_assert(ATOMIC_POINTER_LOCK_FREE == 2 && ATOMIC_INT_LOCK_FREE == 2,
               "a signal handler may only touch lock-free atomics");

/* ------------------------------------------------------------ progress */

static const char progress_key[] = "seixo.progress", progress_every_key[] = "seixo.progress_every";

void sx_lua_set_progress(lua_State *L, int on)
{
    if (on == SX_PROGRESS_LOG)
        lua_pushliteral(L, "log");
    else
        lua_pushboolean(L, on);
    lua_setfield(L, LUA_REGISTRYINDEX, progress_key);
}

int sx_lua_progress_mode(lua_State *L)
{
    const int t = lua_getfield(L, LUA_REGISTRYINDEX, progress_key);
    const int mode = t == LUA_TSTRING ? SX_PROGRESS_LOG : lua_toboolean(L, -1) ? SX_PROGRESS_TERMINAL : SX_PROGRESS_OFF;
    lua_pop(L, 1);
    return mode;
}

void sx_lua_set_progress_every(lua_State *L, double seconds)
{
    lua_pushnumber(L, seconds);
    lua_setfield(L, LUA_REGISTRYINDEX, progress_every_key);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* On a terminal a line rewritten in place, after a second; in a log a line
 * every `every` seconds (10 by default), for runs that last that long. */
enum { PROGRESS_DELAY_MS = 1000, PROGRESS_EVERY_MS = 250, PROGRESS_LOG_EVERY_S = 10 };

/* A model decomposed over MPI ranks cuts its cycles into chunks that every
 * rank takes alike (rank 0's, whose clock sets them), of a line's interval
 * and at least PROGRESS_RANKS_S: each chunk costs the ranks a check that
 * they make the same call and a broadcast of its length (the chunks go on
 * from each other's scattered state, without a gather). */
enum { PROGRESS_RANKS_S = 1 };

typedef struct progress {
    int mode;              // SX_PROGRESS_*
    bool ranks;            // the model is decomposed over MPI ranks: chunks of rank 0, lines from rank 0
    bool shown;
    double start, last;    // wall-clock s
    double delay, every;   // s before the first line, s between lines
    int64_t step0;         // model step at the start
    int64_t chunk;         // steps per chunk, adapted to about 0.1 s
    const char *what;      // the call, which a log line names
} progress;

static void progress_start(lua_State *L, progress *p, const sx_model *m, const char *what, bool ranks)
{
    p->mode = sx_lua_progress_mode(L);
    p->ranks = ranks;
    p->shown = false;
    p->start = p->last = now();
    p->step0 = sx_model_step_count(m);
    p->chunk = 16;
    p->what = what;
    p->delay = PROGRESS_DELAY_MS * 1e-3;
    p->every = PROGRESS_EVERY_MS * 1e-3;
    if (p->mode == SX_PROGRESS_LOG) {
        lua_getfield(L, LUA_REGISTRYINDEX, progress_every_key);
        p->delay = p->every = lua_isnumber(L, -1) ? lua_tonumber(L, -1) : PROGRESS_LOG_EVERY_S;
        lua_pop(L, 1);
    }
}

/* One status line on stderr: steps, time, speed, and the ETA when `fraction` (of the run done) is known. */
static void progress_show(progress *p, const sx_model *m, int64_t total, double fraction, double ratio, double target)
{
    const double t = now();
    const int64_t done = sx_model_step_count(m) - p->step0;
    const double rate = done / (t - p->start > 0 ? t - p->start : 1e-9);
    /* aim the next chunk at 0.1 s of cycling (over ranks, at a line's interval, and no less than PROGRESS_RANKS_S) */
    double want = rate * (p->ranks ? fmax(p->every, PROGRESS_RANKS_S) : 0.1);
    /* at most 8 times the last: the first chunks' rate, over a few steps,
     * can be many times the run's, and one chunk would then take the rest
     * of the run without a line (seen under MPI on an idle host) */
    if (want > 8.0 * (double)p->chunk) want = 8.0 * (double)p->chunk;
    p->chunk = want < 1 ? 1 : want > 1e9 ? 1000000000 : (int64_t)want;
    if (!p->mode || t - p->start < p->delay || t - p->last < p->every) return;
    if (p->ranks && sx_lua_parallel_rank() > 0) return; /* one line per chunk, not one per rank */
    p->last = t;
    p->shown = true;
    char line[256];
    int k = 0;
    if (total > 0)
        k = snprintf(line, sizeof line, "step %lld of %lld", (long long)done, (long long)total);
    else
        k = snprintf(line, sizeof line, "step %lld", (long long)done);
    k += snprintf(line + k, sizeof line - (size_t)k, "  time %.4g s  %.0f steps/s", sx_model_time(m), rate);
    if (target > 0) k += snprintf(line + k, sizeof line - (size_t)k, "  ratio %.3g -> %.3g", ratio, target);
    if (fraction > 0 && fraction <= 1)
        snprintf(line + k, sizeof line - (size_t)k, "  ETA %.0f s", (t - p->start) * (1 - fraction) / fraction);
    if (p->mode == SX_PROGRESS_LOG)  // a plain line a log keeps: no carriage return, no escape code
        fprintf(stderr, "seixo: %s: %s\n", p->what, line);
    else
        fprintf(stderr, "\r%s\033[K", line);
    fflush(stderr);
}

static void progress_end(progress *p)
{
    if (!p->shown || p->mode != SX_PROGRESS_TERMINAL) return;
    fputs("\r\033[K", stderr);
    fflush(stderr);
    p->shown = false;
}

struct sx_lua_run {
    sx_model *m;
    sx_lua_model *ud;
    atomic_int interrupted;  // set by sx_lua_interrupt_all
    atomic_int in_lua;       // a user callback is running
    int slot;                // its place in runs[], -1 when not listed
    int saved_callback;      // ud->callback when the run started
    int model;               // the model's index on the stack
    const char *what;        // the Lua call, in messages ("m:solve")
    int64_t since;           // the model's step count when the run began
    bool open;               // not closed yet
    lua_State *thread;       // the thread it runs on, referenced while open (thread_ref)
    int thread_ref;
    progress progress;       // the progress line, cleared when the run ends
};
typedef sx_lua_run run;

static _Atomic(run *) runs[MAX_RUNS];
static atomic_int nruns;

/* A Ctrl-C no code has answered yet is the core's process-wide request:
 * long C work outside any run, the core's included, polls it. */
int sx_lua_interrupt_pending(void) { return sx_interrupt_pending(); }

void sx_lua_interrupt_clear(void) { sx_interrupt_clear(); }

/* Interrupts requested so far (seixo.interrupts): code that catches errors
 * to go on (lab.calibrate's runs) tells an interrupt from a failure. Under
 * mpirun those the ranks' cycles stopped on alike (sx_interrupts_agreed):
 * a signal reaches each rank at its own time, and the ranks must count
 * alike. */
static atomic_uint interrupts, answered_alone;

unsigned sx_lua_interrupt_count(void)
{
    return sx_lua_parallel_ranks() > 1 ? sx_interrupts_agreed() + atomic_load(&answered_alone) : atomic_load(&interrupts);
}

void sx_lua_interrupt_answered(void)
{
    if (sx_lua_parallel_ranks() > 1) atomic_fetch_add(&answered_alone, 1);
    sx_interrupt_clear();
}

/* Whether run r's thread died with it open (sx_lua_runs_reap closes it). */
static bool run_dead(const run *r)
{
    const int st = lua_status(r->thread);
    return st != LUA_OK && st != LUA_YIELD;
}

int sx_lua_interrupt_all(void)
{
    atomic_fetch_add(&interrupts, 1);
    sx_interrupt_request();
    const int n = atomic_load(&nruns);
    int live = 0;
    run *inner = NULL;
    for (int i = 0; i < n; i++) {
        run *r = atomic_load(&runs[i]);
        if (!r || run_dead(r)) continue; /* a failed coroutine's: no cycle to stop */
        atomic_store(&r->interrupted, 1);
        /* a decomposed model's cycle stops on the ranks' requests: this
         * one is counted already, and must count once */
        if (!r->ud->decomposed) sx_model_interrupt(r->m);
        live++, inner = r;
    }
    /* a callback running Lua code is stopped by the caller's hook */
    if (inner && atomic_load(&inner->in_lua)) return 0;
    return live;
}

static run *innermost(void)
{
    const int n = atomic_load(&nruns);
    return n > 0 ? atomic_load(&runs[n - 1]) : NULL;
}

/* Closes run r: unlists it, gives the model back, lets its thread go. */
static void run_release(lua_State *L, run *r)
{
    if (!r->open) return;
    r->open = false;
    progress_end(&r->progress);
    if (r->slot >= 0) {
        atomic_store(&runs[r->slot], NULL);
        /* the list ends at the innermost run still open (a dead one below it is reaped in place) */
        int n = atomic_load(&nruns);
        while (n > 0 && !atomic_load(&runs[n - 1])) n--;
        atomic_store(&nruns, n);
    }
    r->ud->running--;
    r->ud->callback = r->saved_callback;
    luaL_unref(L, LUA_REGISTRYINDEX, r->thread_ref);
}

/* __close of a run record (and __gc: at the Lua state's end one still open
 * unlists itself, so that a Ctrl-C cannot find it once freed). */
static int run_close(lua_State *L)
{
    run *r = lua_touserdata(L, 1);
    if (r) run_release(L, r);
    return 0;
}

/* Closes the runs whose thread died with them open: a coroutine that failed
 * inside a cycle keeps its to-be-closed values until coroutine.close,
 * which scripts seldom call (the model stayed cycling for good, 16 such
 * failures refused every model, and a Ctrl-C once the coroutine was
 * collected wrote to the freed record: a robustness hunt's findings). The
 * open run holds its thread (thread_ref), so its record is not collected
 * before this finds it. */
void sx_lua_runs_reap(lua_State *L)
{
    const int n = atomic_load(&nruns);
    for (int i = 0; i < n; i++) {
        run *r = atomic_load(&runs[i]);
        if (r && run_dead(r)) run_release(L, r);
    }
}

sx_lua_run *sx_lua_run_open(lua_State *L, int model, const char *what)
{
    model = lua_absindex(L, model);
    sx_lua_model *ud = sx_lua_modelud(L, model);
    sx_model *m = sx_lua_checkmodel_scattered(L, model); /* a lazy cycle goes on from its ranks' own balls */
    sx_lua_runs_reap(L);
    if (ud->running)
        luaL_error(L, "%s: the model is already cycling (a callback cannot cycle its own model)", what);
    run *r = lua_newuserdatauv(L, sizeof *r, 0);
    memset(r, 0, sizeof *r);
    r->m = m;
    r->ud = ud;
    r->model = model;
    r->slot = -1;
    r->what = what;
    r->since = sx_model_step_count(m);
    atomic_init(&r->interrupted, 0);
    atomic_init(&r->in_lua, 0);
    r->thread_ref = LUA_NOREF;
    lua_createtable(L, 0, 2);
    lua_pushcfunction(L, run_close);
    lua_setfield(L, -2, "__close");
    lua_pushcfunction(L, run_close);
    lua_setfield(L, -2, "__gc");
    lua_setmetatable(L, -2);
    /* to be closed before the model is taken, so that nothing can come between */
    lua_toclose(L, -1);
    r->thread = L;
    lua_pushthread(L);
    r->thread_ref = luaL_ref(L, LUA_REGISTRYINDEX);
    ud->running++;
    r->saved_callback = ud->callback;
    r->open = true;
    /* an unlisted run could not be interrupted: deeper nesting is refused */
    const int slot = atomic_load(&nruns);
    if (slot >= MAX_RUNS)
        luaL_error(L, "%s: more than %d models cycling inside each other's callbacks", what, MAX_RUNS);
    r->slot = slot;
    atomic_store(&runs[slot], r);
    atomic_store(&nruns, slot + 1);
    return r;
}

/* The Ctrl-C is answered: by the error raised now (a decomposed cycle's,
 * on every rank alike; else by this process alone). */
static void interrupted(lua_State *L, sx_lua_run *r)
{
    if (r && r->ud->decomposed) sx_interrupt_clear();
    else sx_lua_interrupt_answered();
    if (r) luaL_error(L, "interrupted at step %I", (lua_Integer)sx_model_step_count(r->m));
    luaL_error(L, "interrupted");
}

void sx_lua_run_poll(lua_State *L, sx_lua_run *r)
{
    /* under mpirun the work every rank does alike stops where the ranks
     * agree, in a decomposed cycle (sx_interrupts_agreed): a rank's own
     * signal would stop it alone */
    if (sx_lua_parallel_ranks() > 1 && (!r || r->ud->decomposed)) return;
    if ((r && atomic_load(&r->interrupted)) || sx_interrupt_pending()) interrupted(L, r);
}

/* A fixed timestep far below the critical one (a slip of units: 1e-9 s
 * for 1e-6 s) makes every run take that many times the steps it needs,
 * with no other sign: said once a model, after the first step since it was
 * set or balls were placed (rated then from the contacts the step built:
 * asked before, the rating would build outside the cycle). */
enum { TINY_TIMESTEP = 1000 };

static void check_timestep(lua_State *L, run *r)
{
    r->ud->timestep_unchecked = false;
    const double dt = sx_model_fixed_timestep(r->m);
    if (!(dt > 0) || sx_ball_count(r->m) == 0) return;
    /* the usual case settled by an upper bound of the estimate that needs
     * no memory (the estimate's contact sums take five doubles a ball, a
     * peak a fixed timestep's run would not otherwise reach), from what
     * every rank holds alike (the balls' radii, masses and materials) */
    if (!(dt * TINY_TIMESTEP < sx_model_critical_timestep_bound(r->m))) return;
    /* decomposed and scattered: the ranks' least rating, a collective call (every rank alike, as the model's calls are) */
    if (sx_model_scattered(r->m)) sx_lua_check_model_call(L, r->m, "m:cycle (critical timestep)");
    const double crit = sx_model_critical_timestep(r->m);
    if (crit > 0 && dt * TINY_TIMESTEP < crit)
        sx_lua_warn_once(L, r->model, "timestep",
                         "the timestep %g s is 1/%.0f of the critical estimate %g s: every run takes that many "
                         "times the steps it needs (m:set_timestep('auto') sets the automatic one)",
                         dt, crit / dt, crit);
}

/* Decomposed, a collective call: the caller has checked that every rank
 * makes it (sx_lua_parallel_check_call). The cycle leaves the state
 * scattered: what follows gathers it when it needs more than the walls
 * and the time (sx_lua_checkmodel). */
static void run_chunk(lua_State *L, sx_lua_run *r, int64_t n, double t_end)
{
    sx_lua_run_poll(L, r);
    const sx_status st = sx_model_cycle_until(r->m, n, t_end, r->since);
    /* an interrupt, and an error the ranks agreed on (an instability one
     * rank found, say), stop the ranks in step: every rank raises it, and
     * a script can catch it; after any other error they are out of step:
     * all stop, with the message */
    if (st != SX_OK && st != SX_EINTERRUPT && r->ud->decomposed && !sx_model_error_agreed(r->m)) {
        char msg[1024];
        luaL_where(L, 1); /* the script's line, which the serial run's error gives too */
        /* the first step since a placement failed: the placement is named,
         * as serially, from this rank's copy of the balls as placed */
        if (st == SX_EUNSTABLE && r->ud->unchecked && sx_lua_placement_overlap(L, r->ud, r->what, true))
            snprintf(msg, sizeof msg, "%s%s", lua_tostring(L, -2), lua_tostring(L, -1));
        else
            snprintf(msg, sizeof msg, "%s%s: %s", lua_tostring(L, -1), r->what, sx_lua_core_message(sx_model_error(r->m)));
        sx_lua_parallel_fail(msg);
    }
    if (st == SX_EINTERRUPT || (st == SX_OK && !r->ud->decomposed && atomic_load(&r->interrupted))) interrupted(L, r);
    /* the first step since balls or walls were placed (run_model takes it alone) */
    const bool placed = r->ud->unchecked;
    if (placed && (st == SX_OK || st == SX_EUNSTABLE)) sx_lua_check_placement(L, r->ud, r->what, st != SX_OK);
    sx_lua_check(L, r->m, st, r->what);
    if (placed || r->ud->timestep_unchecked) check_timestep(L, r);
}

void sx_lua_run_cycle(lua_State *L, sx_lua_run *r, int64_t n, double t_end)
{
    /* the first step since balls or walls were placed alone, as run_model
     * takes it: its check sweeps the balls as placed */
    if ((r->ud->unchecked || r->ud->timestep_unchecked) && n > 1) {
        run_chunk(L, r, 1, t_end);
        n--;
    }
    run_chunk(L, r, n, t_end);
    sx_lua_gather(L, r->m, "m"); /* for the caller's own reads and changes of the balls */
}

/* ------------------------------------------------------------ callbacks */

static const char *const point_names[] = {"after", "before", "cycle", NULL};
enum { POINT_AFTER, POINT_BEFORE };

/* Calls the function below its nargs arguments on behalf of the user, as a
 * callback of the model at `model`: removals are queued meanwhile and
 * applied after; a SIGINT stops the Lua code (see sx_lua_interrupt_all).
 * An error says it came from a callback, where that function is defined
 * and at which step: the error's own position may be in a helper far from
 * the m:on or m:history that registered it. */
void sx_lua_user_call(lua_State *L, int model, int nargs, int nres)
{
    model = lua_absindex(L, model);
    sx_lua_model *ud = sx_lua_modelud(L, model);
    lua_Debug fn;
    lua_pushvalue(L, -nargs - 1);
    lua_getinfo(L, ">S", &fn);
    run *r = innermost();
    const bool mine = r && r->ud == ud;
    ud->callback++;
    if (mine) atomic_store(&r->in_lua, 1);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    const int status = lua_pcall(L, nargs, nres, 0);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (mine) atomic_store(&r->in_lua, 0);
    /* the profile's callbacks stage: time spent in Lua on behalf of a cycle */
    if (mine && ud->m)
        sx_model_profile_add(ud->m, SX_STAGE_CALLBACKS,
                             (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    ud->callback--;
    /* what the callback queued is applied even when it failed */
    if (ud->callback == 0) sx_lua_apply_removals(L, model);
    if (status != LUA_OK) {
        /* a Ctrl-C that stopped the callback reads like one that stopped the cycle */
        if (mine && !r->ud->decomposed && atomic_load(&r->interrupted)) {
            sx_lua_interrupt_answered();
            luaL_error(L, "interrupted at step %I (in a callback)", (lua_Integer)sx_model_step_count(r->m));
        }
        if (lua_type(L, -1) == LUA_TSTRING && ud->m) {
            const lua_Integer step = (lua_Integer)sx_model_step_count(ud->m);
            const char *msg =
                fn.what[0] == 'C'
                    ? lua_pushfstring(L, "a callback (a C function) failed at step %I: %s", step, lua_tostring(L, -1))
                    : lua_pushfstring(L, "the callback defined at %s:%d failed at step %I: %s", fn.short_src,
                                      fn.linedefined, step, lua_tostring(L, -1));
            sx_lua_parallel_note_error(msg);
            luaL_error(L, "%s", msg);
        }
        lua_error(L);
    }
}

/* The smallest multiple of every that is > s. */
static int64_t next_multiple(int64_t s, int64_t every)
{
    const int64_t q = s / every + 1;
    return q > INT64_MAX / every ? INT64_MAX : q * every;
}

/* Runs the callbacks of `point` due at step s (registration order; a
 * callback added or removed by another is seen at the next boundary). */
static void fire(lua_State *L, int model, int point, int64_t s)
{
    sx_lua_state(L, model, "callbacks");
    const int t = lua_gettop(L);
    /* a snapshot of the list, as callbacks may change it */
    const lua_Integer n = (lua_Integer)lua_rawlen(L, t);
    lua_createtable(L, (int)n, 0);
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, t, i);
        lua_rawseti(L, t + 1, i);
    }
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, t + 1, i);
        const int e = lua_gettop(L);
        lua_getfield(L, e, "point");
        lua_getfield(L, e, "every");
        lua_getfield(L, e, "removed");
        const bool due = lua_tointeger(L, e + 1) == point && s % lua_tointeger(L, e + 2) == 0 && !lua_toboolean(L, e + 3);
        lua_settop(L, e);
        if (due) {
            lua_getfield(L, e, "fn");
            lua_pushvalue(L, model);
            sx_lua_user_call(L, model, 1, 0);
        }
        lua_settop(L, t + 1);
    }
    lua_settop(L, t - 1);
}

/* The next step > s at which a callback or a history is due. */
static int64_t next_event(lua_State *L, int model, int64_t s)
{
    int64_t next = sx_lua_history_next(L, model, s);
    sx_lua_state(L, model, "callbacks");
    for (lua_Integer i = 1; lua_rawgeti(L, -1, i) == LUA_TTABLE; i++) {
        lua_getfield(L, -1, "every");
        const int64_t at = next_multiple(s, (int64_t)lua_tointeger(L, -1));
        if (at < next) next = at;
        lua_pop(L, 2);
    }
    lua_pop(L, 2);
    return next;
}

/* The next id of a callback or an event handler of the model at 1. */
static lua_Integer next_id(lua_State *L)
{
    sx_lua_state(L, 1, "next_callback");
    lua_rawgeti(L, -1, 1);
    const lua_Integer id = lua_tointeger(L, -1) + 1;
    lua_pop(L, 1);
    lua_pushinteger(L, id);
    lua_rawseti(L, -2, 1);
    lua_pop(L, 1);
    return id;
}

/* m:on(point, fn[, {every = N}]) -> id; m:on(event, fn[, {region =}]) -> id (events.c) */
static int model_on(lua_State *L)
{
    static const char *const keys[] = {"every", NULL};
    sx_lua_checkmodel_scattered(L, 1);
    if (lua_type(L, 2) == LUA_TSTRING && sx_lua_is_event(lua_tostring(L, 2))) return sx_lua_events_add(L, next_id(L));
    const char *name = luaL_checkstring(L, 2);
    const int point = sx_lua_find(name, point_names);
    if (point < 0) /* the points and the events, as every other list of choices says them */
        return luaL_argerror(L, 2, lua_pushfstring(L, "unknown point '%s' (valid: after, before, cycle; events: "
                                                      "bond_break, contact_create, contact_delete, ball_leave_region)",
                                                   name));
    luaL_checktype(L, 3, LUA_TFUNCTION);
    int64_t every = 1;
    if (!lua_isnoneornil(L, 4)) {
        sx_lua_checkkeys(L, 4, keys);
        sx_lua_optintfield(L, 4, "every", 1, INT64_MAX / 2, &every);
    }
    const lua_Integer id = next_id(L);
    sx_lua_state(L, 1, "callbacks");
    lua_createtable(L, 0, 5);
    lua_pushinteger(L, id);
    lua_setfield(L, -2, "id");
    lua_pushinteger(L, point == POINT_BEFORE ? POINT_BEFORE : POINT_AFTER);
    lua_setfield(L, -2, "point");
    lua_pushinteger(L, (lua_Integer)every);
    lua_setfield(L, -2, "every");
    lua_pushvalue(L, 3);
    lua_setfield(L, -2, "fn");
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
    lua_pushinteger(L, id);
    return 1;
}

/* Removes entry `id` from the list `list` of the model at index 1; whether
 * there was one. An entry of an owner's (an output's) is removed only when
 * `owned`; m:off's raises. */
static bool remove_entry(lua_State *L, const char *list, lua_Integer id, bool owned)
{
    sx_lua_state(L, 1, list);
    const int t = lua_gettop(L);
    const lua_Integer n = (lua_Integer)lua_rawlen(L, t);
    for (lua_Integer i = 1; i <= n; i++) {
        lua_rawgeti(L, t, i);
        lua_getfield(L, -1, "id");
        const bool hit = lua_tointeger(L, -1) == id;
        lua_pop(L, 1);
        if (!hit) {
            lua_pop(L, 1);
            continue;
        }
        if (!owned && lua_getfield(L, -1, "owner") == LUA_TSTRING)
            luaL_error(L, "m:off: callback %I is %s, not the script's (its o:close() stops it)", id,
                       lua_tostring(L, -1));
        if (!owned) lua_pop(L, 1);
        lua_pushboolean(L, 1);
        lua_setfield(L, -2, "removed");  // a snapshot being fired skips it
        lua_pop(L, 1);
        for (lua_Integer j = i; j < n; j++) {
            lua_rawgeti(L, t, j + 1);
            lua_rawseti(L, t, j);
        }
        lua_pushnil(L);
        lua_rawseti(L, t, n);
        lua_settop(L, t - 1);
        return true;
    }
    lua_settop(L, t - 1);
    return false;
}

void sx_lua_callback_own(lua_State *L, int model, lua_Integer id, const char *owner)
{
    model = lua_absindex(L, model);
    sx_lua_state(L, model, "callbacks");
    const int t = lua_gettop(L);
    for (lua_Integer i = 1; lua_rawgeti(L, t, i) == LUA_TTABLE; i++) {
        lua_getfield(L, -1, "id");
        const bool hit = lua_tointeger(L, -1) == id;
        lua_pop(L, 1);
        if (hit) {
            lua_pushstring(L, owner);
            lua_setfield(L, -2, "owner");
        }
        lua_pop(L, 1);
    }
    lua_settop(L, t - 1);
}

void sx_lua_callbacks_unsaved(lua_State *L, int model, int list)
{
    model = lua_absindex(L, model), list = lua_absindex(L, list);
    static const char *const lists[] = {"callbacks", "events"};
    for (int k = 0; k < 2; k++) {
        sx_lua_state(L, model, lists[k]);
        const int t = lua_gettop(L);
        for (lua_Integer i = 1; lua_rawgeti(L, t, i) == LUA_TTABLE; i++) {
            lua_getfield(L, -1, "id");
            const lua_Integer id = lua_tointeger(L, -1);
            if (lua_getfield(L, -2, "owner") == LUA_TNIL) {
                lua_pushfstring(L, "%s %I (m:on's function: give it again after a load)",
                                k ? "event handler" : "callback", id);
                lua_rawseti(L, list, (lua_Integer)lua_rawlen(L, list) + 1);
            }
            lua_pop(L, 3);
        }
        lua_settop(L, t - 1);
    }
}

void sx_lua_callback_remove(lua_State *L, int model, lua_Integer id)
{
    model = lua_absindex(L, model);
    lua_pushvalue(L, model);
    lua_insert(L, 1); /* remove_entry's model at index 1 */
    remove_entry(L, "callbacks", id, true);
    lua_remove(L, 1);
}

/* m:off(id): removes a callback or an event handler; true if there was one. */
static int model_off(lua_State *L)
{
    sx_lua_checkmodel_scattered(L, 1); /* also from a plot's __gc: no collective call */
    const lua_Integer id = luaL_checkinteger(L, 2);
    lua_pushboolean(L, remove_entry(L, "callbacks", id, false) || remove_entry(L, "events", id, false));
    return 1;
}

/* ------------------------------------------------------------- the run */

typedef struct limits {
    int64_t steps;   // at most this many steps (INT64_MAX: no limit)
    double time;     // stop once the model time reaches this (INFINITY: none)
    double ratio;    // stop once the unbalanced ratio is <= this (0: none)
    int64_t every;   // ratio check interval
} limits;

enum reason { BY_STEPS, BY_TIME, BY_RATIO };
static const char *const reason_names[] = {"steps", "time", "ratio"};

/* A ratio infinite this long (steps) in m:solve is said once a model. */
enum { INFINITE_RATIO_STEPS = 100000 };

/* Steps between deliveries of bond_break events when no event needs every
 * step: a handler then acts at a multiple of it, whatever the machine. */
#define BOND_EVENT_STEPS 100

/* Runs the model at stack index 1 until a limit stops it: returns why,
 * and the last ratio measured (NaN when none was) in *ratio. */
static enum reason run_model(lua_State *L, const limits *lim, double *ratio, const char *what)
{
    run *r = sx_lua_run_open(L, 1, what);
    sx_model *m = r->m;
    const int top = lua_gettop(L);
    const int64_t start = r->since; /* the time limit's rounding, in the core too, counts from it */
    const double t0 = sx_model_time(m);
    progress *p = &r->progress;
    progress_start(L, p, m, what, r->ud->decomposed);
    sx_lua_disp_fill(L, 1);  // balls added since m:reset_disp are measured from here
    *ratio = NAN;
    int64_t since_finite = 0; /* the last ratio check that read a finite ratio */
    enum reason why = BY_STEPS;
    for (bool first = true;; first = false) {
        const int64_t s = sx_model_step_count(m);
        if (!first) {
            fire(L, 1, POINT_AFTER, s);
            sx_lua_history_record(L, 1);
        }
        sx_lua_apply_removals(L, 1);
        const int64_t taken = s - start;
        if (taken >= lim->steps) {
            why = BY_STEPS;
            break;
        }
        if (sx_model_time_reached(m, lim->time, start)) {
            why = BY_TIME;
            break;
        }
        if (lim->ratio > 0 && !first && taken % lim->every == 0) {
            *ratio = sx_lua_ratio(L, 1, "m:solve (ratio)");
            if (*ratio <= lim->ratio) {
                why = BY_RATIO;
                break;
            }
            /* no contact carries the forces (a free fall): the ratio cannot
             * fall, and a solve with no other limit would run for ever */
            if (isfinite(*ratio)) since_finite = taken;
            else if (taken - since_finite >= INFINITE_RATIO_STEPS)
                sx_lua_warn_once(L, 1, "infinite ratio",
                                 "%s: the unbalanced-force ratio has been infinite for %lld steps (no contact "
                                 "carries the balls' forces: a free fall?), so it cannot fall to %g; give steps = "
                                 "or time = to end the run",
                                 what, (long long)(taken - since_finite), lim->ratio);
        }
        sx_lua_run_poll(L, r);
        fire(L, 1, POINT_BEFORE, s);
        /* the next chunk: up to the first thing due */
        int64_t n = lim->steps - taken;
        const int64_t ev = next_event(L, 1, s) - s;
        if (ev < n) n = ev;
        if (lim->ratio > 0) {
            const int64_t k = lim->every - taken % lim->every;
            if (k < n) n = k;
        }
        /* a time limit cuts nothing here: the core stops at its first step past it */
        /* a bond_break handler runs at the chunk's end and may change the
         * model: the chunks then end at fixed steps, not where the progress
         * display's clock would end them */
        const bool fixed = sx_lua_events_on_bonds(L, 1);
        if (fixed) {
            const int64_t k = BOND_EVENT_STEPS - s % BOND_EVENT_STEPS;
            if (k < n) n = k;
        }
        /* a placement check follows the first step; contact and region events are per step */
        if (r->ud->unchecked || sx_lua_events_per_step(L, 1)) n = 1;
        if (p->ranks) { /* the ranks' clocks differ, and they must cut their cycles alike */
            /* first: every rank is here, none waits for ever, and every rank's
             * callbacks, histories, handlers and limits end the chunk at one
             * step (one registered under a branch on seixo.rank() would not) */
            char call[64] = "";
            if (n < INT64_MAX - s) snprintf(call, sizeof call, " to step %lld", (long long)(s + n));
            if (!isinf(lim->time))
                snprintf(call + strlen(call), sizeof call - strlen(call), " %s %.17g s", call[0] ? "or" : "to", lim->time);
            sx_lua_check_model_call(L, m, lua_pushfstring(L, "%s%s", what, call));
            lua_pop(L, 1);
            const int64_t chunk = sx_lua_parallel_root_value(!fixed && p->mode ? p->chunk : INT64_MAX);
            if (chunk < n) n = chunk;
        } else if (!fixed && p->mode && p->chunk < n) {
            n = p->chunk;
        }
        run_chunk(L, r, n, lim->time);
        sx_lua_events_deliver(L, 1);
        double fraction = -1;
        int64_t total = 0;
        if (lim->steps < INT64_MAX) {
            total = lim->steps;
            fraction = (double)(sx_model_step_count(m) - start) / (double)lim->steps;
        }
        if (!isinf(lim->time)) {
            const double f = (sx_model_time(m) - t0) / (lim->time - t0);
            if (f > fraction) fraction = f;
        }
        progress_show(p, m, total, fraction, *ratio, lim->ratio);
        lua_settop(L, top);
    }
    lua_settop(L, top - 1);  // closes the run
    return why;
}

static int model_cycle(lua_State *L)
{
    sx_lua_checkmodel_scattered(L, 1);
    const lua_Integer n = luaL_checkinteger(L, 2);
    luaL_argcheck(L, n >= 0, 2, "the number of steps must be >= 0");
    lua_settop(L, 1);
    const limits lim = {(int64_t)n, INFINITY, 0, 1};
    double ratio;
    run_model(L, &lim, &ratio, "m:cycle");
    return 0;
}

/* m:solve{ratio=, steps=, time=, every=} -> reason, ratio, steps taken */
static int model_solve(lua_State *L)
{
    static const char *const keys[] = {"ratio", "steps", "time", "every", NULL};
    sx_model *m = sx_lua_checkmodel_scattered(L, 1);
    limits lim = {INT64_MAX, INFINITY, 0, 100};
    if (!lua_isnoneornil(L, 2)) {
        sx_lua_checkkeys(L, 2, keys);
        double t;
        if (sx_lua_optnumfield(L, 2, "time", &t)) {
            if (!(t > 0 && t < INFINITY)) sx_lua_fielderror(L, 2, "time", "a duration > 0 s expected");
            lim.time = sx_model_time(m) + t;
        }
        if (sx_lua_optnumfield(L, 2, "ratio", &lim.ratio) && !(lim.ratio > 0 && lim.ratio < INFINITY))
            sx_lua_fielderror(L, 2, "ratio", "a ratio > 0 expected");
        sx_lua_optintfield(L, 2, "steps", 0, INT64_MAX / 2, &lim.steps);
        sx_lua_optintfield(L, 2, "every", 1, 1000000000, &lim.every);
    }
    if (lim.ratio == 0 && lim.steps == INT64_MAX && isinf(lim.time)) lim.ratio = 1e-5;  // PFC's default
    lua_settop(L, 1);
    const int64_t start = sx_model_step_count(m);
    double ratio;
    const enum reason why = run_model(L, &lim, &ratio, "m:solve");
    lua_pushstring(L, reason_names[why]);
    if (isnan(ratio)) ratio = sx_lua_ratio(L, 1, "m:solve (ratio)");
    lua_pushnumber(L, ratio);
    lua_pushinteger(L, (lua_Integer)(sx_model_step_count(m) - start));
    return 3;
}

const luaL_Reg sx_lua_run_methods[] = {
    {"cycle", model_cycle},
    {"solve", model_solve},
    {"on", model_on},
    {"off", model_off},
    {NULL, NULL},
};
