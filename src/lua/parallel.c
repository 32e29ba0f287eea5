/* Processes and MPI ranks, for work spread over cores and machines (the
 * calibration in lua/seixo/calibrate.lua):
 *
 *   seixo.cores()        the processors online
 *   seixo.executable()   the path of the running program (to start workers)
 *   seixo.rank(), seixo.ranks()   this process's MPI rank and the number of
 *                        ranks: 0 and 1 unless started under mpirun
 *   seixo.send(rank, text), seixo.receive([wait]) -> text, rank   MPI messages
 *
 * MPI is optional (meson finds it or not: SX_HAVE_MPI). A program started
 * by mpirun has OMPI_COMM_WORLD_SIZE (Open MPI) or PMI_SIZE (MPICH, Slurm)
 * in its environment; only then, and for two ranks or more, does
 * sx_lua_parallel_start call MPI_Init, so a plain `seixo script.lua` never
 * starts MPI. */
#define _GNU_SOURCE /* sched_getaffinity: the cores a rank may run on */
#include "bindings.h"
#include "seixo_lua.h"

#include <fcntl.h>
#include <limits.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

static int world_rank = 0, world_size = 1;

#ifdef SX_HAVE_MPI
#include <mpi.h>

static int node_size = 1; /* the ranks on this rank's machine */
static bool mpi_started;
static MPI_Comm fail_comm = MPI_COMM_NULL; /* the failing ranks' barrier (sx_lua_parallel_failing) alone */
static _Noreturn void abort_job(void);

enum { MESSAGE_TAG = 7, FAIL_TAG = 8, END_TAG = 9, WAIT_TAG = 10 };
enum { CALL_NAME = 96 }; /* a chunk's name holds the step and the time it ends at, and the model */
static void fail_heard(int n, MPI_Request *req);
static void fail_ended(void);
static bool await(int n, MPI_Request *req, const char *call);
static void say_wait(const char *call);
static const char *nobody_sends(void);
static void note_waits(void);
enum { WAIT_SAID_MS = 1000, STUCK_MS = 3000 }; /* say_wait, nobody_sends */

static double clock_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}
#endif

void sx_lua_parallel_start(int *argc, char ***argv)
{
#ifdef SX_HAVE_MPI
    /* one rank is a plain process (mpirun -np 1): its worker processes,
     * which inherit this environment, must not start MPI either */
    const char *size = getenv("OMPI_COMM_WORLD_SIZE");
    if (!size) size = getenv("PMI_SIZE");
    if (!size || atoi(size) < 2) return;
    if (MPI_Init(argc, argv) != MPI_SUCCESS) return;
    mpi_started = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);
    MPI_Comm_dup(MPI_COMM_WORLD, &fail_comm);
    MPI_Comm node;
    if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) == MPI_SUCCESS) {
        MPI_Comm_size(node, &node_size);
        MPI_Comm_free(&node);
    }
    /* every rank runs the script: one writes to standard output, else each
     * line would come once per rank, whether from print, io.write, a shell
     * command or a plot on gnuplot's dumb terminal (errors, on standard
     * error, are every rank's) */
    if (world_rank > 0) {
        const int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            fflush(stdout);
            dup2(null, STDOUT_FILENO);
            close(null);
        }
    }
#else
    (void)argc;
    (void)argv;
#endif
}

void sx_lua_parallel_stop(int ok)
{
#ifdef SX_HAVE_MPI
    if (!mpi_started) return;
    /* a rank that ends while others are in a collective call would leave
     * them waiting: it ends only with the others */
    char err[512];
    if (ok && !sx_lua_parallel_same_call("the script's end", err, sizeof err)) sx_lua_parallel_fail(err);
    /* a rank that failed would leave the others waiting for its messages */
    if (!ok && world_size > 1) abort_job();
    note_waits(); /* the others' words on their waits, which this rank did not need */
    if (fail_comm != MPI_COMM_NULL) MPI_Comm_free(&fail_comm);
    MPI_Finalize();
    mpi_started = false;
#else
    (void)ok;
#endif
}

void sx_lua_parallel_check_threads(int threads)
{
#ifdef SX_HAVE_MPI
    /* OpenMP's threads wait for work by spinning: with more threads than
     * the cores a rank may run on (mpirun binds each of 2 ranks to a core
     * by default), or more ranks times threads on a machine than its
     * cores, the waiting threads take the cores the working ones need (2
     * ranks of 2 threads on 2 cores ran a test scene 10 to 20 times slower
     * than with passive waiting). The runtime reads its policy once,
     * before main: too late to set it here, so say it, once, from rank 0. */
    static bool said;
    const char *policy = getenv("OMP_WAIT_POLICY");
    if (said || !mpi_started || threads < 2 || world_rank != 0) return;
    if (policy && strcasecmp(policy, "passive") == 0) return;
    const long cores = sysconf(_SC_NPROCESSORS_ONLN);
    cpu_set_t set;
    const int mine = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : (int)cores;
    if (threads <= mine && (long)node_size * threads <= cores) return;
    said = true;
    if (threads > mine)
        fprintf(stderr,
                "seixo: %d threads on the %d core%s this rank may run on (mpirun binds ranks to cores: "
                "--bind-to none, or --map-by ...:PE=%d): OpenMP's waits spin, many times slower; bind it to "
                "more cores, run fewer threads, or set OMP_WAIT_POLICY=passive\n",
                threads, mine, mine == 1 ? "" : "s", threads);
    else
        fprintf(stderr,
                "seixo: %d ranks of %d threads on this machine's %ld cores: more threads than cores, whose "
                "OpenMP waits spin (many times slower); run fewer, or set OMP_WAIT_POLICY=passive\n",
                node_size, threads, cores);
#else
    (void)threads;
#endif
}

static int seixo_cores(lua_State *L)
{
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    lua_pushinteger(L, n > 0 ? n : 1);
    return 1;
}

static int seixo_executable(lua_State *L)
{
    char path[4096];
    const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
    if (n <= 0) return luaL_error(L, "seixo.executable: /proc/self/exe cannot be read");
    lua_pushlstring(L, path, (size_t)n);
    return 1;
}

static int seixo_rank(lua_State *L)
{
    lua_pushinteger(L, world_rank);
    return 1;
}

static int seixo_ranks(lua_State *L)
{
    lua_pushinteger(L, world_size);
    return 1;
}

/* seixo.barrier(): every rank waits until all are there (a no-op serially).
 * A shell command rank 0 ran alone (`if seixo.rank() == 0 then
 * os.execute(...) end`) has then written its files for the others to read. */
static int seixo_barrier(lua_State *L)
{
    sx_lua_parallel_check_call(L, "seixo.barrier");
    return 0;
}

static void check_ranks(lua_State *L, const char *fn)
{
    if (world_size < 2) luaL_error(L, "seixo.%s: one rank only (start the script with mpirun -np N)", fn);
}

static int seixo_send(lua_State *L)
{
    const lua_Integer to = luaL_checkinteger(L, 1);
    size_t len;
    const char *text = luaL_checklstring(L, 2, &len);
    check_ranks(L, "send");
    if (!(to >= 0 && to < world_size && to != world_rank))
        return luaL_argerror(L, 1,
                             lua_pushfstring(L, "another rank expected (0 to %d, not this one, %d), got %I",
                                             world_size - 1, world_rank, to));
    if (len > (size_t)0x7fffffff) return luaL_error(L, "seixo.send: message too long");
#ifdef SX_HAVE_MPI
    MPI_Send(text, (int)len, MPI_CHAR, (int)to, MESSAGE_TAG, MPI_COMM_WORLD);
#else
    (void)text;
#endif
    return 0;
}

/* The next message from any rank; with wait = false, nil when none has
 * come. The wait polls every
 * millisecond instead of blocking in MPI_Recv: Open MPI's blocking receive
 * spins on a core, which a rank waiting for a long evaluation would take
 * from the ranks doing the work. */
static int seixo_receive(lua_State *L)
{
    const bool wait = lua_isnoneornil(L, 1) || lua_toboolean(L, 1);
    check_ranks(L, "receive");
#ifdef SX_HAVE_MPI
    MPI_Status st;
    int ready = 0;
    bool said = false;
    const double t0 = clock_ms();
    double stuck = -1; /* since when no rank can send, as the others say */
    for (;;) {
        MPI_Iprobe(MPI_ANY_SOURCE, MESSAGE_TAG, MPI_COMM_WORLD, &ready, &st);
        if (ready) break;
        fail_heard(0, NULL); /* the rank waited for (or polled for, as pool.hand_out does) may have failed */
        fail_ended();
        if (!wait) return 0;
        if (!said && clock_ms() - t0 > WAIT_SAID_MS) said = (say_wait("seixo.receive"), true);
        const char *why = nobody_sends();
        if (!why) stuck = -1;
        else if (stuck < 0) stuck = clock_ms();
        else if (clock_ms() - stuck > STUCK_MS) {
            if (said) say_wait(NULL); /* a script that catches the error goes on */
            return luaL_error(L, "seixo.receive: no message can come: %s", why);
        }
        const struct timespec ms = {0, 1000000};
        nanosleep(&ms, NULL);
    }
    if (said) say_wait(NULL);
    int len = 0;
    MPI_Get_count(&st, MPI_CHAR, &len);
    luaL_Buffer b;
    char *buf = luaL_buffinitsize(L, &b, (size_t)len + 1);
    MPI_Recv(buf, len, MPI_CHAR, st.MPI_SOURCE, MESSAGE_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    luaL_pushresultsize(&b, (size_t)len);
    lua_pushinteger(L, st.MPI_SOURCE);
    return 2;
#else
    (void)wait;
    return 0;
#endif
}

/* ------------------------------------------------- domain decomposition */

/* The models made while this is on run their cycles decomposed over the
 * ranks (seixo.decompose; lab.calibrate turns it off: its ranks run
 * models of their own). */
static bool decompose_on = true;

#ifdef SX_HAVE_MPI
enum { SHARE_TAG = 8 };

/* What rank `from` holds of span `want`: their intersection (may be empty). */
static sx_span meet(sx_span held, sx_span want)
{
    sx_span s = {held.lo > want.lo ? held.lo : want.lo, held.hi < want.hi ? held.hi : want.hi};
    if (s.hi < s.lo) s.hi = s.lo;
    return s;
}

/* sx_exchange.share over MPI: nonblocking sends of what this rank holds of
 * each other rank's needs, receives of what it needs from each holder,
 * straight into the array (the spans of one call never overlap). */
static bool mpi_share(void *ud, void *data, size_t size, const sx_span *own, const sx_span *need, int per)
{
    (void)ud;
    const int R = world_size, me = world_rank;
    MPI_Request *req = malloc((size_t)(2 * R * per) * sizeof *req);
    if (!req) return false;
    int nreq = 0;
    bool ok = true;
    char *base = data;
    for (int r = 0; r < R && ok; r++) {
        if (r == me) continue;
        for (int k = 0; k < per && ok; k++) {
            const sx_span out = meet(own[me], need[r * per + k]), in = meet(own[r], need[me * per + k]);
            const size_t nout = (size_t)(out.hi - out.lo) * size, nin = (size_t)(in.hi - in.lo) * size;
            if (nout > INT_MAX || nin > INT_MAX) ok = false; /* a message of more than 2 GB: not yet */
            if (ok && nout)
                MPI_Isend(base + (size_t)out.lo * size, (int)nout, MPI_BYTE, r, SHARE_TAG + k, MPI_COMM_WORLD,
                          &req[nreq++]);
            if (ok && nin)
                MPI_Irecv(base + (size_t)in.lo * size, (int)nin, MPI_BYTE, r, SHARE_TAG + k, MPI_COMM_WORLD,
                          &req[nreq++]);
        }
    }
    ok = await(nreq, req, NULL) && ok;
    free(req);
    return ok;
}

static bool mpi_max(void *ud, double *v)
{
    (void)ud;
    MPI_Request req;
    return MPI_Iallreduce(MPI_IN_PLACE, v, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD, &req) == MPI_SUCCESS &&
           await(1, &req, NULL);
}

static bool mpi_agree(void *ud, uint64_t v)
{
    (void)ud;
    uint64_t lo = v, hi = v;
    MPI_Request req[2];
    return MPI_Iallreduce(MPI_IN_PLACE, &lo, 1, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD, &req[0]) == MPI_SUCCESS &&
           MPI_Iallreduce(MPI_IN_PLACE, &hi, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD, &req[1]) == MPI_SUCCESS &&
           await(2, req, NULL) && lo == hi;
}
#endif

bool sx_lua_parallel_decompose(sx_model *m)
{
#ifdef SX_HAVE_MPI
    if (!mpi_started || !decompose_on) return false;
    const sx_exchange x = {world_rank, world_size, NULL, mpi_share, mpi_max, mpi_agree};
    if (sx_model_decompose(m, &x) != SX_OK) return false;
    /* a cycle leaves each rank its own balls; the calls that need more gather (sx_lua_checkmodel) */
    sx_model_gather_lazily(m, true);
    return true;
#else
    (void)m;
    return false;
#endif
}

/* An error in the script, or one that every rank finds in a cycle, fails
 * every rank alike: each would print the same message. A failing rank
 * enters a barrier of the failing ranks. Rank 0 reports at once (whoever
 * else fails says the same or keeps quiet), and waits on the barrier for
 * FAIL_WAIT_MS before its MPI_Abort (fail_wait), so that the others
 * failing alike remove their shadows first. A rank above 0 first tells
 * rank 0 its message (fail_tell): rank 0, waiting for the others (a
 * same-call check, a cycle's exchanges, seixo.receive: await), where a
 * rank failing alone leaves it, reports that message and ends the job
 * (fail_heard). Else the failing rank waits on the barrier too: when
 * every rank has come (all failed), rank 0 reports and it keeps quiet;
 * else this rank failed alone while rank 0 was elsewhere, or the others
 * fail that much later (then each reports), and it reports.
 * Then each ends the job (MPI_Abort); the ranks that keep quiet wait for
 * rank 0's. (A timer alone, ranks > 0 waiting for rank 0's MPI_Abort to
 * end them, failed under load: they outlived it.) */
enum { FAIL_WAIT_MS = 5000, FAIL_POLL_MS = 10 };

#ifdef SX_HAVE_MPI
static MPI_Request fail_req = MPI_REQUEST_NULL; /* this rank's entry in the failing ranks' barrier */
static bool fail_entered;                          /* once: a second entry would be another barrier */

/* Polls the failing ranks' barrier for up to FAIL_WAIT_MS: true once every
 * rank has come, or (a rank above 0) once rank 0 has said the job ends
 * (END_TAG: it reported, see abort_job); false at once when this rank is
 * not in the barrier, or when it completed already (MPI_Test then freed
 * the request). */
static bool fail_wait(void)
{
    int all = 0;
    const struct timespec poll = {0, FAIL_POLL_MS * 1000000L};
    for (int ms = 0; !all && fail_req != MPI_REQUEST_NULL && ms < FAIL_WAIT_MS; ms += FAIL_POLL_MS) {
        if (MPI_Test(&fail_req, &all, MPI_STATUS_IGNORE) != MPI_SUCCESS) return false;
        int ended = 0;
        if (!all && world_rank > 0 && MPI_Iprobe(0, END_TAG, fail_comm, &ended, MPI_STATUS_IGNORE) == MPI_SUCCESS &&
            ended)
            return true;
        if (!all) nanosleep(&poll, NULL);
    }
    return all;
}

/* This rank's entry in the failing ranks' barrier, once. */
static void fail_enter(void)
{
    if (!fail_entered && (fail_entered = true, MPI_Ibarrier(fail_comm, &fail_req) != MPI_SUCCESS))
        fail_req = MPI_REQUEST_NULL;
}

/* Ends the job after a failure. Rank 0, which reported at once, first
 * tells every other rank the job ends (END_TAG, tell_end: once, and as
 * soon as it takes a failure told, fail_heard): those waiting for the
 * others (await, seixo.receive: fail_ended) remove their shadows and come
 * to the barrier, as the ranks failing alike do, a failing rank's own
 * wait ends quiet (fail_wait), and rank 0 waits for them there (up to
 * FAIL_WAIT_MS for a rank that is busy). */
static void tell_end(void)
{
    static bool told;
    static char none;
    if (told || world_rank != 0 || fail_comm == MPI_COMM_NULL) return;
    told = true;
    for (int r = 1; r < world_size; r++) {
        MPI_Request req; /* never awaited: the job ends */
        if (MPI_Isend(&none, 0, MPI_CHAR, r, END_TAG, fail_comm, &req) == MPI_SUCCESS) MPI_Request_free(&req);
    }
}

static _Noreturn void abort_job(void)
{
    if (world_rank == 0 && fail_comm != MPI_COMM_NULL) {
        tell_end();
        fail_enter();
        fail_wait();
    }
    MPI_Abort(MPI_COMM_WORLD, 1);
    exit(1); /* MPI_Abort does not return */
}

/* A rank above 0 waiting for the others, whom rank 0 told that the job
 * ends (abort_job): its shadows removed, it comes to the failing ranks'
 * barrier and waits for rank 0's MPI_Abort. */
static void fail_ended(void)
{
    int ready = 0;
    if (!mpi_started || world_rank == 0 || fail_comm == MPI_COMM_NULL ||
        MPI_Iprobe(0, END_TAG, fail_comm, &ready, MPI_STATUS_IGNORE) != MPI_SUCCESS || !ready)
        return;
    sx_lua_rank_files_remove();
    fail_enter();
    fail_wait();
    const struct timespec wait = {FAIL_WAIT_MS / 1000, 0};
    nanosleep(&wait, NULL);
    MPI_Abort(MPI_COMM_WORLD, 1);
    exit(1);
}

/* A rank above 0 that fails tells rank 0 its message, once; the text
 * stays until the job ends (the send completes when rank 0 takes it). */
static void fail_tell(const char *message)
{
    static char *told;
    static MPI_Request req = MPI_REQUEST_NULL;
    if (world_rank == 0 || told || !message) return;
    if ((told = strdup(message))) MPI_Isend(told, (int)strlen(told) + 1, MPI_CHAR, 0, FAIL_TAG, fail_comm, &req);
}

/* Rank 0 in a wait that has not ended, for the requests req[n] (n 0: a
 * wait for a message, seixo.receive): takes a failure a rank told
 * (fail_tell), then reports it and ends the job (that rank removed its
 * shadows before it told) unless the wait ends within FAIL_GRACE_MS. A
 * rank that failed after this wait's partners had all come (failing
 * alike, a moment after; rank 0 goes on to meet the same error and report
 * it, the ranks failing alike wait for each other) lets it end: the
 * failure is kept for the next wait that does not end. */
enum { FAIL_GRACE_MS = 500 };
static char *heard; /* the failure told, once taken */
static int heard_from;

static void fail_heard(int n, MPI_Request *req)
{
    if (!mpi_started || world_rank != 0 || fail_comm == MPI_COMM_NULL) return;
    if (!heard) {
        int ready = 0, len = 0;
        MPI_Status st;
        if (MPI_Iprobe(MPI_ANY_SOURCE, FAIL_TAG, fail_comm, &ready, &st) != MPI_SUCCESS || !ready) return;
        MPI_Get_count(&st, MPI_CHAR, &len);
        static char lost[] = "failed (its message did not fit in memory)";
        char *text = malloc((size_t)len + 1); /* none: the message stays unread, the job ends */
        if (text) {
            MPI_Recv(text, len, MPI_CHAR, st.MPI_SOURCE, FAIL_TAG, fail_comm, MPI_STATUS_IGNORE);
            text[len] = '\0';
        }
        heard = text ? text : lost, heard_from = st.MPI_SOURCE;
        /* the job ends whatever follows (rank 0 reports this or its own
         * error): said now, the failing ranks' own waits end quiet */
        tell_end();
    }
    for (const double t0 = clock_ms(); n > 0 && clock_ms() - t0 < FAIL_GRACE_MS;) {
        int done = 0;
        if (MPI_Testall(n, req, &done, MPI_STATUSES_IGNORE) != MPI_SUCCESS) break;
        if (done) return; /* the caller's next test finds the requests done */
    }
    fprintf(stderr, "seixo: rank %d of %d: %s\n", heard_from, world_size, heard);
    fflush(stderr);
    abort_job();
}

/* A rank that waits long (WAIT_SAID_MS) in a call every rank makes
 * (await of a same-call check: it cannot end before every rank has come)
 * or in seixo.receive says so to the others (WAIT_TAG: the call's name),
 * and says when it goes on. A rank waiting in seixo.receive keeps what
 * they say (note_waits): when every other rank waits so, no message can
 * come, and once that has lasted STUCK_MS (a message sent just before its
 * sender began to wait is taken meanwhile) the receive fails, naming
 * their calls, instead of waiting for ever. */
static char *waits_in; /* per rank: the call it says it waits in ("" when it goes on) */

/* Sends to every other rank the call this rank waits in, or NULL when it
 * goes on. A message of CALL_NAME bytes, sent eagerly by MPI_Send (never
 * waiting for its receiver): a rank that never looks leaves it unread. */
static void say_wait(const char *call)
{
    char msg[CALL_NAME] = {0};
    if (call) snprintf(msg, sizeof msg, "%s", call);
    for (int r = 0; r < world_size; r++)
        if (r != world_rank) MPI_Send(msg, CALL_NAME, MPI_CHAR, r, WAIT_TAG, fail_comm);
}

/* Takes what the other ranks said of their waits, in the order they said it. */
static void note_waits(void)
{
    if (!waits_in && !(waits_in = calloc((size_t)world_size, CALL_NAME))) return;
    for (;;) {
        int ready = 0;
        MPI_Status st;
        if (MPI_Iprobe(MPI_ANY_SOURCE, WAIT_TAG, fail_comm, &ready, &st) != MPI_SUCCESS || !ready) return;
        char *to = waits_in + (size_t)st.MPI_SOURCE * CALL_NAME;
        MPI_Recv(to, CALL_NAME, MPI_CHAR, st.MPI_SOURCE, WAIT_TAG, fail_comm, MPI_STATUS_IGNORE);
        to[CALL_NAME - 1] = '\0';
    }
}

/* NULL while some other rank may send; else why none can (a static text). */
static const char *nobody_sends(void)
{
    note_waits();
    if (!waits_in) return NULL;
    static char why[512];
    int at = 0, named = 0;
    for (int r = 0; r < world_size; r++) {
        if (r == world_rank) continue;
        const char *call = waits_in + (size_t)r * CALL_NAME;
        if (!call[0]) return NULL;
        if (named++ < 2)
            at += snprintf(why + at, sizeof why - (size_t)at, "%srank %d waits in %s", at ? ", " : "", r, call);
    }
    if (named > 2) at += snprintf(why + at, sizeof why - (size_t)at, ", and %d more", named - 2);
    snprintf(why + at, sizeof why - (size_t)at, " (every rank must make the same calls: a receive that no send on "
                                               "another rank answers?)");
    return why;
}

/* Waits for the requests req[n], as MPI_Waitall, listening meanwhile
 * (every 64 tests, a probe): rank 0 for a rank that failed alone
 * (fail_heard), the others for rank 0's end of the job (fail_ended); a
 * wait in a call every rank makes (call, else NULL) long enough is said
 * to the others (say_wait). */
static bool await(int n, MPI_Request *req, const char *call)
{
    bool said = false;
    double t0 = -1;
    for (unsigned spin = 1;; spin++) {
        int done = 0;
        if (MPI_Testall(n, req, &done, MPI_STATUSES_IGNORE) != MPI_SUCCESS) return false;
        if (done) break;
        if (spin % 64 == 0) {
            fail_heard(n, req);
            fail_ended();
            if (call && !said) {
                if (t0 < 0) t0 = clock_ms();
                else if (clock_ms() - t0 > WAIT_SAID_MS) said = (say_wait(call), true);
            }
        }
    }
    if (said) say_wait(NULL);
    return true;
}
#endif

bool sx_lua_parallel_failing(const char *message)
{
    sx_lua_rank_files_remove(); /* the run ends: before rank 0's MPI_Abort can kill this rank */
#ifdef SX_HAVE_MPI
    if (!mpi_started || fail_comm == MPI_COMM_NULL) return true;
    fail_tell(message);
    fail_enter();
    if (world_rank == 0 || !fail_wait()) return true;
    /* rank 0 reports and its MPI_Abort ends this rank: an abort from here
     * could end rank 0 before it printed */
    const struct timespec wait = {FAIL_WAIT_MS / 1000, 0};
    nanosleep(&wait, NULL);
    return false;
#else
    (void)message;
    return true;
#endif
}

void sx_lua_parallel_line_end(bool failed, const char *message)
{
#ifdef SX_HAVE_MPI
    if (!mpi_started || world_size < 2) return;
    /* a same-call check (the same MPI operation as every collective call's:
     * a rank still in another call of the line meets this one there) */
    char err[512];
    if (sx_lua_parallel_same_call(failed ? "the end of a line that failed" : "the end of a line", err, sizeof err)) return;
    /* the ranks differ: a rank whose line failed ends the job with its
     * error; the others wait a moment for its message (rank 0) or the end
     * (fail_ended), then fail with the calls that differed (a rank still
     * inside its line, in a check this one left, hears nothing else) */
    if (failed) {
        char text[1024];
        snprintf(text, sizeof text, "%s (on some ranks only: they differ from the others now, and the session ends)",
                 message ? message : "(error object is not a string)");
        sx_lua_parallel_fail(text);
    }
    const double t0 = clock_ms(), wait = strstr(err, "that failed") ? FAIL_WAIT_MS : 2 * FAIL_GRACE_MS;
    const struct timespec ms = {0, 1000000};
    while (clock_ms() - t0 < wait) { /* a failing rank named: its message is on its way */
        fail_heard(0, NULL);
        fail_ended();
        nanosleep(&ms, NULL);
    }
    sx_lua_parallel_fail(err);
#else
    (void)failed;
    (void)message;
#endif
}

void sx_lua_parallel_fail(const char *message)
{
    if (sx_lua_parallel_failing(message)) {
        fprintf(stderr, "seixo: rank %d of %d: %s\n", world_rank, world_size, message);
        fflush(stderr);
    }
#ifdef SX_HAVE_MPI
    if (mpi_started) abort_job();
#endif
    exit(1);
}

int sx_lua_parallel_rank(void) { return world_rank; }
int sx_lua_parallel_ranks(void) { return world_size; }

/* Every rank must make the same calls, and a collective call that some
 * ranks skip (a save under `if seixo.rank() == 0`) would leave the ranks
 * that make it waiting for ever, or pair it with another collective of the
 * others. So each collective call of the Lua layer starts with this one:
 * the ranks' names for what they are doing, gathered (one MPI_Iallgather,
 * the same operation whatever call makes it, awaited by testing so that
 * rank 0 hears a rank that failed alone: fail_heard); when they differ,
 * every rank of the check fails with the message, which names two of
 * them. */
/* The last error a seixo call raised on this rank: when the ranks part
 * and their last errors differ (a rank caught one with pcall and went on,
 * the others did not raise it), the check's message names it. */
enum { LAST_ERROR = 240 };
static char last_error[LAST_ERROR];

void sx_lua_parallel_note_error(const char *message)
{
    if (world_size > 1 && message) snprintf(last_error, sizeof last_error, "%s", message);
}

#ifdef SX_HAVE_MPI
/* After calls that differ (every rank is here): the first rank, from
 * `first` on and round, whose last error is not every rank's, and that
 * error, appended to err. */
static void name_caught(char *err, size_t size, int first)
{
    char *errs = malloc((size_t)world_size * LAST_ERROR);
    if (!errs) return;
    if (MPI_Allgather(last_error, LAST_ERROR, MPI_CHAR, errs, LAST_ERROR, MPI_CHAR, MPI_COMM_WORLD) == MPI_SUCCESS)
        for (int k = 0; k < world_size; k++) {
            const int r = (first + k) % world_size;
            const char *e = errs + (size_t)r * LAST_ERROR;
            bool alone = false;
            for (int q = 0; q < world_size && !alone; q++) alone = memcmp(e, errs + (size_t)q * LAST_ERROR, LAST_ERROR) != 0;
            if (!e[0] || !alone) continue;
            const size_t at = strlen(err);
            snprintf(err + at, size - at, "; rank %d's last error, which not every rank raised (caught with pcall?): %.*s",
                     r, LAST_ERROR, e);
            break;
        }
    free(errs);
}
#endif

bool sx_lua_parallel_same_call(const char *what, char *err, size_t size)
{
#ifdef SX_HAVE_MPI
    if (!mpi_started || world_size < 2) return true;
    char mine[CALL_NAME] = {0};
    snprintf(mine, sizeof mine, "%s", what);
    char *all = malloc((size_t)world_size * CALL_NAME);
    if (!all) sx_lua_parallel_fail("out of memory to compare the ranks' calls");
    /* not blocking: rank 0 hears meanwhile whether the rank it waits for failed alone */
    MPI_Request req;
    if (MPI_Iallgather(mine, CALL_NAME, MPI_CHAR, all, CALL_NAME, MPI_CHAR, MPI_COMM_WORLD, &req) != MPI_SUCCESS ||
        !await(1, &req, what))
        sx_lua_parallel_fail("the ranks could not compare their calls");
    int other = 1;
    while (other < world_size && memcmp(all, all + (size_t)other * CALL_NAME, CALL_NAME) == 0) other++;
    if (other < world_size) {
        snprintf(err, size,
                 "%s: the ranks made different calls: rank 0 is in %.*s, rank %d in %.*s (every rank runs the "
                 "script and must make the same calls: one under `if seixo.rank() == 0`, after a decision "
                 "on the clock, or in a loop over pairs() of a table with string keys, whose order "
                 "differs between the ranks?)",
                 what, CALL_NAME, all, other, CALL_NAME, all + (size_t)other * CALL_NAME);
        name_caught(err, size, other);
    }
    free(all);
    return other >= world_size;
#else
    (void)what;
    (void)err;
    (void)size;
    return true;
#endif
}

void sx_lua_parallel_check_call(lua_State *L, const char *what)
{
    char err[1024];
    if (!sx_lua_parallel_same_call(what, err, sizeof err)) luaL_error(L, "%s", err);
}

int64_t sx_lua_parallel_root_value(int64_t v)
{
#ifdef SX_HAVE_MPI
    if (mpi_started && world_size > 1 && MPI_Bcast(&v, 1, MPI_INT64_T, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
        sx_lua_parallel_fail("the ranks could not share rank 0's value");
#endif
    return v;
}

char *sx_lua_parallel_root_text(const char *what, char *(*read)(void *ud, size_t *len, int *mark), void *ud,
                                size_t *len, int *mark)
{
    *len = 0;
#ifdef SX_HAVE_MPI
    if (mpi_started && world_size > 1) {
        char err[512];
        if (!sx_lua_parallel_same_call(what, err, sizeof err)) sx_lua_parallel_fail(err);
        char *text = world_rank == 0 ? read(ud, len, mark) : NULL;
        int64_t head[3] = {text != NULL, (int64_t)*len, *mark}; /* text or the end, its length, the mark */
        if (MPI_Bcast(head, 3, MPI_INT64_T, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
            sx_lua_parallel_fail("the ranks could not share rank 0's input");
        *len = (size_t)head[1], *mark = (int)head[2];
        if (!head[0]) return NULL;
        if (world_rank != 0 && !(text = malloc(*len + 1))) sx_lua_parallel_fail("out of memory for rank 0's input");
        for (size_t at = 0; at < *len;) { /* in pieces an int counts */
            const size_t piece = *len - at < INT_MAX ? *len - at : INT_MAX;
            if (MPI_Bcast(text + at, (int)piece, MPI_CHAR, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
                sx_lua_parallel_fail("the ranks could not share rank 0's input");
            at += piece;
        }
        if (world_rank != 0) text[*len] = '\0';
        return text;
    }
#else
    (void)what;
#endif
    return read(ud, len, mark);
}

bool sx_lua_parallel_writes(bool shared) { return !shared || world_rank == 0; }

bool sx_lua_parallel_says(const sx_model *m) { return sx_lua_parallel_writes(m && sx_model_ranks(m) > 1); }

bool sx_lua_parallel_sharing(void)
{
#ifdef SX_HAVE_MPI
    return mpi_started && decompose_on;
#else
    return false;
#endif
}

bool sx_lua_parallel_outcome(bool shared, char *err, size_t size, int64_t *count)
{
#ifdef SX_HAVE_MPI
    /* every rank passes the same size; a failed broadcast is a failure too */
    if (shared && mpi_started && size > 0 && size <= INT_MAX) {
        int64_t n = count ? *count : 0;
        if (MPI_Bcast(err, (int)size, MPI_CHAR, 0, MPI_COMM_WORLD) != MPI_SUCCESS ||
            MPI_Bcast(&n, 1, MPI_INT64_T, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
            snprintf(err, size, "rank %d of %d: the ranks failed to exchange a file's outcome", world_rank, world_size);
        err[size - 1] = '\0';
        if (count) *count = n;
    }
#else
    (void)shared;
    (void)count;
#endif
    return size > 0 && err[0] != '\0';
}

bool sx_lua_parallel_all_read(bool ok, char *err, size_t size)
{
#ifdef SX_HAVE_MPI
    if (!sx_lua_parallel_sharing() || world_size < 2 || size == 0 || size > INT_MAX) return ok;
    int first = ok ? world_size : world_rank, failed = world_size; /* the lowest failing rank */
    if (MPI_Allreduce(&first, &failed, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD) != MPI_SUCCESS) {
        snprintf(err, size, "rank %d of %d: the ranks failed to exchange a file's outcome", world_rank, world_size);
        return false;
    }
    if (failed == world_size) return true;
    if (failed != 0 && failed == world_rank) { /* named, as a rank's own trouble (a node without the file) */
        char mine[1024];
        snprintf(mine, sizeof mine, "%s", err);
        snprintf(err, size, "rank %d of %d: %s", world_rank, world_size, mine);
    }
    if (MPI_Bcast(err, (int)size, MPI_CHAR, failed, MPI_COMM_WORLD) != MPI_SUCCESS)
        snprintf(err, size, "rank %d of %d: the ranks failed to exchange a file's outcome", world_rank, world_size);
    err[size - 1] = '\0';
    return false;
#else
    (void)err;
    (void)size;
    return ok;
#endif
}

bool sx_lua_parallel_alone(void)
{
#ifdef SX_HAVE_MPI
    return mpi_started && world_size > 1 && !decompose_on;
#else
    return false;
#endif
}

/* The ranks share files again (seixo.decompose(true) after false): what
 * each wrote, removed or renamed itself meanwhile is the disk's on every
 * rank (a shadow of it from before is stale: a lab.series test's CSV that
 * another rank wrote). A collective call: the names' lengths, then the
 * names, to every rank. */
static void share_alone_writes(lua_State *L)
{
#ifdef SX_HAVE_MPI
    if (mpi_started && world_size > 1) sx_lua_parallel_check_call(L, "seixo.decompose(true)");
#endif
    size_t len;
    char *mine = sx_lua_rank_files_alone(L, &len);
    if (!mine) sx_lua_parallel_fail("seixo.decompose: out of memory for the names of the files this rank wrote");
#ifdef SX_HAVE_MPI
    if (mpi_started && world_size > 1) {
        static const char fail[] = "seixo.decompose: the ranks could not share the names of the files they wrote";
        int *count = malloc(2 * (size_t)world_size * sizeof *count);
        if (!count) sx_lua_parallel_fail(fail);
        const int n = len < INT_MAX ? (int)len : -1; /* every rank takes part, and all see a -1 */
        if (MPI_Allgather(&n, 1, MPI_INT, count, 1, MPI_INT, MPI_COMM_WORLD) != MPI_SUCCESS) sx_lua_parallel_fail(fail);
        size_t total = 0;
        for (int r = 0; r < world_size; r++) {
            if (count[r] < 0 || total + (size_t)count[r] >= INT_MAX) sx_lua_parallel_fail(fail);
            count[world_size + r] = (int)total; /* the displacements */
            total += (size_t)count[r];
        }
        char *all = malloc(total + 1);
        if (!all || MPI_Allgatherv(mine, n, MPI_CHAR, all, count, count + world_size, MPI_CHAR, MPI_COMM_WORLD) !=
                        MPI_SUCCESS)
            sx_lua_parallel_fail(fail);
        free(mine);
        free(count);
        mine = all, len = total;
    }
#endif
    /* what is on the disk now is rank 0's to say: a name written and then
     * removed is gone on every rank, as it is there */
    size_t n = 0;
    for (size_t at = 0; at < len; at += strlen(mine + at) + 1) n++;
    char *there = world_rank == 0 ? sx_lua_rank_files_there(mine, len, n) : malloc(n + 1);
    if (!there) sx_lua_parallel_fail("seixo.decompose: out of memory for the names of the files the ranks wrote");
#ifdef SX_HAVE_MPI
    if (mpi_started && world_size > 1 && n > 0 &&
        (n > INT_MAX || MPI_Bcast(there, (int)n, MPI_CHAR, 0, MPI_COMM_WORLD) != MPI_SUCCESS))
        sx_lua_parallel_fail("seixo.decompose: the ranks could not share which of their files are there");
#endif
    sx_lua_rank_files_settle(L, mine, len, there);
    free(there);
    free(mine);
}

/* seixo.decompose([on]) -> whether models made from now on are decomposed */
static int seixo_decompose(lua_State *L)
{
    if (!lua_isnoneornil(L, 1)) {
        luaL_checktype(L, 1, LUA_TBOOLEAN);
        const bool was = decompose_on;
        decompose_on = lua_toboolean(L, 1);
        if (decompose_on && !was) share_alone_writes(L);
    }
    lua_pushboolean(L, decompose_on);
    return 1;
}

#ifdef SX_HAVE_MPI
/* Every rank runs the script and must make the same calls, but Lua seeds
 * math.random at random in each process: a script placing balls with it
 * would build a different model on each rank (the first cycle stops them).
 * The ranks take rank 0's seed, two integers drawn from its own randomly
 * seeded generator, so such a script runs under mpirun as it does alone. */
static void same_random_seed(lua_State *L)
{
    if (lua_getglobal(L, "math") != LUA_TTABLE) { /* no math library: nothing to seed */
        lua_pop(L, 1);
        return;
    }
    int64_t seed[2] = {0, 0};
    if (world_rank == 0) {
        for (int k = 0; k < 2; k++) {
            lua_getfield(L, -1, "random");
            lua_pushinteger(L, 0); /* math.random(0): an integer of random bits */
            lua_call(L, 1, 1);
            seed[k] = (int64_t)lua_tointeger(L, -1);
            lua_pop(L, 1);
        }
    }
    if (MPI_Bcast(seed, 2, MPI_INT64_T, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
        sx_lua_parallel_fail("the ranks could not agree on math.random's seed");
    lua_getfield(L, -1, "randomseed");
    lua_pushinteger(L, (lua_Integer)seed[0]);
    lua_pushinteger(L, (lua_Integer)seed[1]);
    lua_call(L, 2, 0);
    lua_pop(L, 1);
}

/* os.tmpname under mpirun while models are decomposed: every rank runs the
 * script, and a path it makes with os.tmpname (m:save there, seixo.load
 * from there) must be the same path on every rank, as m:save writes from
 * rank 0 alone. Rank 0 makes the name (and the file), every rank gets it;
 * so every rank must call it alike, as it does everything that changes a
 * model. With seixo.decompose(false) (lab.calibrate: ranks on their own)
 * each rank makes its own. The upvalue is Lua's os.tmpname. */
static char *rank0_tmpname(void *ud, size_t *len, int *mark)
{
    lua_State *L = ud;
    lua_pushvalue(L, lua_upvalueindex(1)); /* (shared_tmpname's upvalue: its frame is running) */
    *mark = lua_pcall(L, 0, 1, 0);
    const char *text = lua_tolstring(L, -1, len);
    if (!text) {
        text = "os.tmpname: no name";
        *len = strlen(text);
    }
    char *copy = malloc(*len + 1);
    if (copy) memcpy(copy, text, *len + 1);
    lua_pop(L, 1);
    return copy;
}

static int shared_tmpname(lua_State *L)
{
    if (!decompose_on) {
        lua_pushvalue(L, lua_upvalueindex(1));
        lua_call(L, 0, 1);
        return 1;
    }
    /* rank 0's name, or its error (marked by its status) */
    size_t len;
    int status;
    char *name = sx_lua_parallel_root_text("os.tmpname", rank0_tmpname, L, &len, &status);
    if (!name) return luaL_error(L, "os.tmpname: out of memory");
    /* copied out before anything that may raise: the name is malloc'd */
    char copy[4096];
    const size_t n = len < sizeof copy ? len : sizeof copy - 1;
    memcpy(copy, name, n);
    free(name);
    lua_pushlstring(L, copy, n);
    if (status != LUA_OK) return lua_error(L);
    sx_lua_rank_file_written(L, lua_tostring(L, -1)); /* rank 0 made the file */
    return 1;
}

/* os.exit under mpirun: a rank that ends without MPI_Finalize is taken by
 * mpirun for one that failed, and the job fails even when every rank ends
 * with os.exit(0). Ending with success, every rank finalizes first, as at
 * the end of the script (each rank ends alike, as it makes every call); a
 * failure ends the job as before. The upvalue is Lua's os.exit. */
static int mpi_exit(lua_State *L)
{
    const bool ok = lua_isnoneornil(L, 1) ||
                    (lua_isboolean(L, 1) ? lua_toboolean(L, 1) : luaL_checkinteger(L, 1) == EXIT_SUCCESS);
    if (ok) sx_lua_parallel_stop(1);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    lua_call(L, lua_gettop(L) - 1, 0);
    return 0;
}

#endif

void sx_lua_parallel_open(lua_State *L)
{
#ifdef SX_HAVE_MPI
    if (!mpi_started || world_size < 2) return;
    same_random_seed(L);
    sx_lua_wrap(L, "os", "tmpname", shared_tmpname, 0);
    sx_lua_wrap(L, "os", "exit", mpi_exit, 0);
    /* rank 0's too: what it writes while the ranks do not share files is
     * noted for the others (share_alone_writes) */
    sx_lua_rank_files_open(L);
    sx_lua_rank_stdin_open(L);
#else
    (void)L;
#endif
}

const luaL_Reg sx_lua_parallel_functions[] = {
    {"cores", seixo_cores}, {"executable", seixo_executable}, {"rank", seixo_rank},
    {"ranks", seixo_ranks}, {"send", seixo_send},             {"receive", seixo_receive},
    {"decompose", seixo_decompose}, {"barrier", seixo_barrier},
    {NULL, NULL},
};
