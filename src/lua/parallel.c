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
#include "bindings.h"
#include "seixo_lua.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int world_rank = 0, world_size = 1;

#ifdef SX_HAVE_MPI
#include <mpi.h>

static bool mpi_started;

enum { MESSAGE_TAG = 7 };
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
#else
    (void)argc;
    (void)argv;
#endif
}

void sx_lua_parallel_stop(int ok)
{
#ifdef SX_HAVE_MPI
    if (!mpi_started) return;
    /* a rank that failed would leave the others waiting for its messages */
    if (!ok && world_size > 1) MPI_Abort(MPI_COMM_WORLD, 1);
    MPI_Finalize();
    mpi_started = false;
#else
    (void)ok;
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
    luaL_argcheck(L, to >= 0 && to < world_size && to != world_rank, 1, "another rank expected");
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
    for (;;) {
        MPI_Iprobe(MPI_ANY_SOURCE, MESSAGE_TAG, MPI_COMM_WORLD, &ready, &st);
        if (ready) break;
        if (!wait) return 0;
        const struct timespec ms = {0, 1000000};
        nanosleep(&ms, NULL);
    }
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

const luaL_Reg sx_lua_parallel_functions[] = {
    {"cores", seixo_cores}, {"executable", seixo_executable}, {"rank", seixo_rank},
    {"ranks", seixo_ranks}, {"send", seixo_send},             {"receive", seixo_receive},
    {NULL, NULL},
};
