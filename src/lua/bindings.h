/* Private declarations shared by the binding files of the `seixo` Lua module.
 *
 * Objects: a model userdata owns one sx_model (model.c) and a Lua table of
 * the state that lives on the Lua side (group names, user extras,
 * callbacks, histories, queued removals); balls, walls and contacts are
 * handles (util.c): an id, with the model userdata as their uservalue so
 * the model outlives them. No core pointer is ever given to Lua.
 *
 * Model methods come from several files: each exports a luaL_Reg array of
 * model methods below, and seixo_lua.c installs every array listed in its
 * table. A new binding file adds its array here and one line there.
 *
 * Vectors are Lua arrays of `n` numbers, n the model's dimension; a
 * rotational quantity of a 2D model (spin, moment) has one component and is
 * a plain number, so the vector helpers treat n == 1 as a number. */
#pragma once

#include <lauxlib.h>
#include <lua.h>
#include <stdbool.h>
#include <stdint.h>

#include "seixo.h"

/* pi to double precision (M_PI is not C11) */
#define SX_LUA_PI 3.14159265358979323846

/// Components of a rotational vector (spin, moment): 3 in 3D, 1 (about z) in 2D.
static inline int sx_lua_rdim(int dim) { return dim == 3 ? 3 : 1; }

/* ------------------------------------------------ model methods by file */

extern const luaL_Reg sx_lua_model_methods[];     ///< model.c: materials, time, timestep, gravity, energy, summary
extern const luaL_Reg sx_lua_run_methods[];       ///< run.c: cycle, solve, on, off
extern const luaL_Reg sx_lua_balls_methods[];     ///< balls.c: ball, balls, ball_count
extern const luaL_Reg sx_lua_walls_methods[];     ///< walls.c: wall, walls, wall_count
extern const luaL_Reg sx_lua_contacts_methods[];  ///< contacts.c: contacts
extern const luaL_Reg sx_lua_groups_methods[];    ///< groups.c: group, groups, set, sum, mean, count, remove
extern const luaL_Reg sx_lua_history_methods[];   ///< history.c: history, histories, history_csv
extern const luaL_Reg sx_lua_generate_methods[];  ///< generate.c: generate
extern const luaL_Reg sx_lua_lab_methods[];       ///< lab.c: measure
/// lab.c: adds servo, load, radius, set_radial_vel to the wall class (after walls are registered).
void sx_lua_lab_register(lua_State *L);
extern const luaL_Reg sx_lua_bonds_methods[];     ///< bonds.c: bond, bond_count, cracks, crack_count, track_energy
extern const luaL_Reg sx_lua_clumps_methods[];    ///< clumps.c: clump_template(s), clump, clumps, clump_count
extern const luaL_Reg sx_lua_disp_methods[];      ///< disp.c: reset_disp
extern const luaL_Reg sx_lua_joints_methods[];    ///< joints.c: joint, joints
/// disp.c: records a reference position for each ball that has none, once m:reset_disp made the table.
void sx_lua_disp_fill(lua_State *L, int model);
/// disp.c: pushes b.disp of ball id, the handle at index 1 (an error before any m:reset_disp).
int sx_lua_ball_disp(lua_State *L, const sx_model *m, int64_t id);

/* Functions of the seixo table beside the loader's own. */
extern const luaL_Reg sx_lua_optimize_functions[];  ///< optimize.c: seixo.optimize
extern const luaL_Reg sx_lua_parallel_functions[];  ///< parallel.c: cores, executable, rank, ranks, send, receive, decompose
/// parallel.c: decomposes m over the MPI ranks when MPI runs and seixo.decompose is on, its cycles
/// leaving the state scattered (sx_model_gather_lazily); true if it did.
bool sx_lua_parallel_decompose(sx_model *m);
/// parallel.c: under mpirun, says once (rank 0, on stderr) when `threads`
/// are more than the cores rank 0 may run on, or the ranks on its machine
/// times `threads` more than the machine's cores, and OpenMP's waits spin
/// (OMP_WAIT_POLICY not passive).
void sx_lua_parallel_check_threads(int threads);
/// parallel.c: a decomposed cycle failed on this rank: the message, then every rank stops.
_Noreturn void sx_lua_parallel_fail(const char *message);
/// parallel.c: whether this process writes the files of a model, `shared`
/// if it is decomposed over MPI ranks (sx_model_ranks > 1): then rank 0
/// writes for all (every rank holds the whole model between cycles).
bool sx_lua_parallel_writes(bool shared);
/// parallel.c: whether this process prints a warning about model m (or
/// one m has every rank alike): rank 0 alone for a model decomposed over
/// the MPI ranks, every process for its own.
bool sx_lua_parallel_says(const sx_model *m);
/// parallel.c: the outcome of a file's work, which rank 0 alone does for a
/// `shared` model, made every rank's: err (empty: it succeeded; every rank
/// passes the same size) and *count (if not NULL) go from rank 0 to all
/// ranks, which wait for it. True if the work failed. Not shared: only
/// reads err. A collective call: never from __gc, whose time differs between ranks.
bool sx_lua_parallel_outcome(bool shared, char *err, size_t size, int64_t *count);
/// parallel.c: ranks sharing files (seixo.decompose on), each having read
/// one itself (seixo.load): whether every rank succeeded; else err (size
/// bytes) becomes the lowest failing rank's on every rank. No rank returns
/// before every rank has read, so none removes or rewrites the file under
/// another's read. A collective call. Serially, or alone: ok.
bool sx_lua_parallel_all_read(bool ok, char *err, size_t size);
/// parallel.c: the start of each collective call of the Lua layer (what
/// names it: "m:save"): true if every rank is in a call of that name; else
/// false, with a message naming two ranks' calls in err (then every rank
/// of the check fails, and none waits for ever). True without MPI.
bool sx_lua_parallel_same_call(const char *what, char *err, size_t size);
/// parallel.c: sx_lua_parallel_same_call raising the message as a Lua error.
void sx_lua_parallel_check_call(lua_State *L, const char *what);
/// model.c: sx_lua_parallel_check_call for a call on model m, named
/// with the model's number after the first ("model 2: m:save").
void sx_lua_check_model_call(lua_State *L, const sx_model *m, const char *what);
/// model.c: numbers m, a model just decomposed: the next number, or that
/// of `was` (seixo.load's placeholder, not dereferenced), which it
/// forgets; m NULL: only forgets `was`.
void sx_lua_model_share(lua_State *L, const sx_model *was, const sx_model *m);
/// parallel.c: rank 0's v, on every rank (which all make the call and wait
/// for it); v itself without MPI or with one rank.
int64_t sx_lua_parallel_root_value(int64_t v);
/// parallel.c: under mpirun, rank 0's math.random seed and os.tmpname names on
/// every rank, and os.exit finalizing MPI.
void sx_lua_parallel_open(lua_State *L);
/// parallel.c: whether the ranks share models and files: MPI runs and
/// seixo.decompose is on (rank 0 then writes the files).
bool sx_lua_parallel_sharing(void);
/// rank_files.c: under mpirun, on a rank above 0, the script's files become
/// shadows while models are shared (rank 0 alone writes the real ones).
void sx_lua_rank_files_open(lua_State *L);
/// rank_files.c: the C closure's upvalue 1 (the function it wraps, Lua's
/// own) called with the first nargs arguments, its values returned; an
/// error is raised again with the script's place in front, as the script's
/// own call would have it.
int sx_lua_call_own(lua_State *L, int nargs);
/// rank_stdin.c: standard input read by rank 0 for every rank while the ranks share models.
void sx_lua_rank_stdin_open(lua_State *L);
/// rank_files.c: pushes and returns the path to read for the script's file
/// `path`: its shadow's on a rank above 0 that wrote it, else path itself.
const char *sx_lua_rank_file(lua_State *L, const char *path);
/// rank_files.c: removes this rank's folder of shadows (at exit, and when
/// the run fails, before mpirun's abort can kill the rank).
void sx_lua_rank_files_remove(void);
/* run.c: an interrupt answered by this process alone (an error raised
 * from a run or a call that is not a decomposed cycle): cleared, and
 * under mpirun counted for seixo.interrupts() beside the ranks' stops. */
void sx_lua_interrupt_answered(void);
/* parallel.c: the error a seixo call is raising on this rank (under
 * mpirun): named by the same-call check if the ranks then part. */
void sx_lua_parallel_note_error(const char *message);
/// rank_files.c: the names this rank wrote, removed or renamed itself
/// while the ranks did not share files (seixo.decompose(false)), each with
/// its NUL, sorted, in a malloc'ed block of *len bytes (NULL: no memory);
/// forgets them.
char *sx_lua_rank_files_alone(lua_State *L, size_t *len);
/// rank_files.c: for each of the n NUL-ended names of names (len bytes),
/// whether it is on the disk now (1 or 0), in a malloc'ed array (NULL: no
/// memory).
char *sx_lua_rank_files_there(const char *names, size_t len, size_t n);
/// rank_files.c: a rank above 0 forgets its shadow of each name of names,
/// which is the disk's (there[i]: sx_lua_rank_files_there on rank 0) or
/// gone, as for rank 0.
void sx_lua_rank_files_settle(lua_State *L, const char *names, size_t len, const char *there);
/// parallel.c: under mpirun with more than one rank, while the models are
/// each rank's own (seixo.decompose(false)).
bool sx_lua_parallel_alone(void);
/// rank_files.c: rank 0 has written `path` for every rank (m:save): a rank
/// above 0 drops its shadow of it, reads the disk's file, and removes or
/// renames it as rank 0 did even if rank 0 got there first.
void sx_lua_rank_file_written(lua_State *L, const char *path);
/// rank_files.c: on a rank above 0 while the ranks share files, a new,
/// empty shadow, its name pushed and returned, for the rank to write what
/// rank 0 writes to a path (a file every rank can make alike, which the
/// script may then read or append to as rank 0 does, whenever rank 0 gets
/// there); NULL (nothing pushed, errno set) otherwise. Once written,
/// sx_lua_rank_shadow_take makes it stand for path (or the caller removes it).
const char *sx_lua_rank_shadow_new(lua_State *L);
void sx_lua_rank_shadow_take(lua_State *L, const char *path, const char *shadow);
extern const luaL_Reg sx_lua_periodic_methods[];  ///< periodic.c: periodic, cell_control, cell_stress
/// lab.c: pushes a dim x dim tensor as an array of rows.
void sx_lua_push_tensor(lua_State *L, const double t[3][3], int dim);

/* Classes other than the model's; each leaves nothing on the stack. */
void sx_lua_balls_register(lua_State *L);
void sx_lua_walls_register(lua_State *L);
void sx_lua_contacts_register(lua_State *L);
void sx_lua_clumps_register(lua_State *L);
/// io.c: adds m:save, m:vars, m:output to the model class and load, xdmf to
/// the module table on the top of the stack (call after both exist).
void sx_lua_io_register(lua_State *L);

/* ---------------------------------------------------------- model.c */

#define SX_LUA_MODEL "seixo.model"

/// The model userdata. Its uservalue is the state table (sx_lua_state).
typedef struct sx_lua_model {
    sx_model *m;           ///< NULL once closed
    int running;           ///< inside m:cycle / m:solve / a relaxation of m:generate
    int callback;          ///< depth of user callbacks being run (removals are queued while > 0)
    double overlap_limit;  ///< seixo.model{overlap_limit}: the largest overlap placed, a fraction of the radius
    bool unchecked;        ///< a ball or wall was added since the last placement check (geometry.c)
    bool timestep_unchecked; ///< the fixed timestep was set since the last check of it (run.c, sx_lua_check_timestep)
    int64_t fresh_lo, fresh_hi; ///< the ids of the balls m:generate made since that check, their overlaps among themselves its relaxation's, not checked (0, 0: none; ids are from 1)
    bool decomposed;       ///< its cycles run decomposed over the MPI ranks (parallel.c)
} sx_lua_model;

/// seixo.models() -> {model, ...}: the open models, in order of creation.
int sx_lua_models(lua_State *L);
/// seixo.model{...}: the constructor.
int sx_lua_model_new(lua_State *L);
/// model.c: seixo.check_material({...}), m:material's checks without a model
int sx_lua_check_material(lua_State *L);
/// The executable's --threads N (seixo.threads), when set, on m (fn names
/// the call in the error of a bad value; m NULL: only that check); results
/// do not depend on it.
void sx_lua_model_threads(lua_State *L, sx_model *m, const char *fn);
/// Creates the model class with the methods of every array in `sets`
/// (NULL-terminated); leaves nothing on the stack.
void sx_lua_model_register(lua_State *L, const luaL_Reg *const sets[]);
/// The model of the model userdata at idx, or NULL if it has been closed;
/// decomposed, as its last cycle left it (see sx_lua_checkmodel).
sx_model *sx_lua_tomodel(lua_State *L, int idx);
/// Like sx_lua_tomodel, but a closed model is a Lua error, and a
/// decomposed model that its last cycle left scattered (each rank its own
/// balls: sx_model_gather_lazily) is gathered first (sx_lua_gather).
sx_model *sx_lua_checkmodel(lua_State *L, int idx);
/// Like sx_lua_checkmodel, without the gather: for the calls that read or
/// change only what every rank holds whole after a cycle (the walls, the
/// time and step, the counts of balls and walls) or that cycle the model.
sx_model *sx_lua_checkmodel_scattered(lua_State *L, int idx);
/// A scattered model's whole state on every rank: a collective call, so
/// the ranks first check that they all make it (naming the running
/// function as called on `self`, "m" or "b": m:save, b.pos); a failed
/// exchange stops every rank.
void sx_lua_gather(lua_State *L, sx_model *m, const char *self);
/// A scattered model's ball `id`: its motion from the rank that holds it
/// to every rank (sx_ball_fetch; every ball's after a few reads, then no
/// exchange until the next cycle), a collective call behind the same check
/// as sx_lua_gather.
void sx_lua_fetch_ball(lua_State *L, sx_model *m, const char *self, int64_t id);
/// Like sx_lua_checkmodel for a query that reads many balls' motion and
/// properties, but no pairs (a selection by region, a sum over the balls):
/// a scattered model's every ball's motion is shared first
/// (sx_model_share_motion), behind the same check as sx_lua_gather.
sx_model *sx_lua_checkmodel_motion(lua_State *L, int idx);
/// Like sx_lua_checkmodel for a query of the crack log alone (m:cracks(),
/// the bond_break events): a scattered model's ranks merge their cracks
/// (sx_model_share_cracks) behind the same check as sx_lua_gather.
sx_model *sx_lua_checkmodel_cracks(lua_State *L, int idx);
/// Whether a ball vector is part of its motion (a step's result, current
/// on its own rank alone in a scattered model), not an applied load.
static inline bool sx_lua_is_motion(sx_ball_vec which)
{
    return which != SX_BALL_APPLIED_FORCE && which != SX_BALL_APPLIED_MOMENT;
}
/// Like sx_lua_checkmodel for a query the core answers of a scattered
/// model with a small collective exchange of its own (the ranks' sums over
/// the rows they hold: sx_model_state_hash, sx_model_bond_counts,
/// sx_model_unbalanced_ratio, sx_model_energy, ...): behind the same-call
/// check, named `what`, without a gather.
sx_model *sx_lua_checkmodel_summed(lua_State *L, int idx, const char *what);
/// model.c: the unbalanced-force ratio behind sx_lua_checkmodel_summed, a
/// Lua error when the ranks could not sum it.
double sx_lua_ratio(lua_State *L, int idx, const char *what);
/// The userdata at idx (a Lua error if it is not a model, closed or not).
sx_lua_model *sx_lua_modelud(lua_State *L, int idx);
/// Pushes the table `field` of the state of the model userdata at idx,
/// creating it when absent.
void sx_lua_state(lua_State *L, int idx, const char *field);
/// Material for a new ball: the named one, or the model's only material.
/// Raises an argument error on `arg` naming the field `key` otherwise.
int sx_lua_material_arg(lua_State *L, const sx_model *m, int arg, const char *key, const char *name);

/* ---------------------------------------------------------- bonds.c */

/// Reads the material keys model (a law's name), every law's parameters, modulus,
/// stiffness_ratio into d and the `bond` sub-table into bpm (*has_bpm).
void sx_lua_material_extras(lua_State *L, int arg, sx_material_def *d, bool *has_bpm, sx_bpm_def *bpm);
/// bonds.c: pushes the `bond` table (the bond kinds' micro-parameters, from their registry) of material index
/// `material` and returns true, or pushes nothing and returns false when they are all zero.
bool sx_lua_push_bpm(lua_State *L, const sx_model *m, int material);
/// Appends the registry's law parameter keys (each once) to keys[0..n) and
/// ends the list with NULL; a list of `room` entries too small for them is
/// a Lua error (never keys dropped, then refused as unknown).
void sx_lua_law_keys(lua_State *L, const char **keys, int n, int room);

/* ------------------------------------------------ balls.c, walls.c */

extern const struct sx_lua_kind sx_lua_ball_kind, sx_lua_wall_kind;

/// Removes the n balls listed (each live, one listed twice goes once) in
/// one pass over the contacts, or queues them while a callback runs.
void sx_lua_remove_balls(lua_State *L, int model, const int64_t *ids, int64_t n, const char *what);
void sx_lua_remove_wall(lua_State *L, int model, int64_t id, const char *what);
/// How many removals a callback queued that are not applied yet.
lua_Integer sx_lua_removals_queued(lua_State *L, int model);
/// Applies the queued removals (when no callback runs).
void sx_lua_apply_removals(lua_State *L, int model);
/// A fixity value (nil, a word or an array of words) as a core mask;
/// errors start with `what` ("ball field 'fix'").
unsigned sx_lua_fixmask(lua_State *L, int dim, int idx, const char *what);
/// Pushes a core fixity mask as an array of component words ({"vx", "wz"}).
void sx_lua_pushfixmask(lua_State *L, unsigned mask);

/* ----------------------------------------------------------- clumps.c */

extern const struct sx_lua_kind sx_lua_clump_kind;
/// The clump template named by field `key` of the table at arg (required).
int sx_lua_template_arg(lua_State *L, const sx_model *m, int arg, const char *key);
/// Puts every pebble of clump id in group number `group`.
void sx_lua_clump_set_group(lua_State *L, sx_model *m, int64_t id, int32_t group);

/* ----------------------------------------------------------- groups.c */

/// The number of the named group of the model userdata at `model`:
/// created when `create`, else 0 when there is no such group.
int32_t sx_lua_group_id(lua_State *L, int model, const char *name, bool create);
/// Pushes the name of group number g (nil for 0).
void sx_lua_push_group_name(lua_State *L, int model, int32_t g);
/// Group slots of a ball, PFC's: slot 1 is the core's group (b.group), slots
/// 2 .. SX_LUA_SLOTS live in the model's Lua state.
enum { SX_LUA_SLOTS = 8 };
/// The group number of ball id in slot (1 .. SX_LUA_SLOTS) of the model userdata at `model`.
int32_t sx_lua_slot_group(lua_State *L, int model, const sx_model *m, int64_t id, int slot);
/// Puts ball id in group g (0: none) in slot; an error of `what` when the core refuses.
void sx_lua_set_slot_group(lua_State *L, int model, sx_model *m, int64_t id, int slot, int32_t g, const char *what);
/// The name of slot's table in the model's Lua state ("slot2" ...), NULL for slot 1 or out of range.
const char *sx_lua_slot_table(int slot);
/// Drops ball id from slots 2 and up (the ball was removed).
void sx_lua_slots_forget(lua_State *L, int model, int64_t id);
/// An order-free digest of slots 2 and up (ball id, slot, group number); 0 when they are empty.
uint64_t sx_lua_slots_digest(lua_State *L, int model);

/* ----------------------------------------------------------- region.c */

enum { SX_REGION_BOX, SX_REGION_SPHERE, SX_REGION_CYLINDER, SX_REGION_DISK, SX_REGION_POLYGON };

/// A region of space: 3D box, sphere, cylinder; 2D box, disk, polygon.
typedef struct sx_lua_region {
    int kind, dim;
    double lo[3], hi[3];  ///< box; the bounding box of every kind
    double c[3], r;       ///< sphere, disk: centre and radius; cylinder: first end centre and radius
    double axis[3], len;  ///< cylinder: unit axis from the first end to the second, length
    const double *poly;   ///< polygon: n (x, y) pairs, held by a userdata on the Lua stack
    int n;
    double volume;        ///< m^3 (2D: m^2, the area of a unit-thickness slice)
} sx_lua_region;

/// Reads the region table at idx ({box = {min, max}}, {sphere = {center =,
/// radius =}}, ...); errors are argument errors on `arg` naming `key`. May
/// leave one value (the polygon's storage) on the stack: call it with a
/// known top and restore it when the region is no longer used.
void sx_lua_region_read(lua_State *L, int idx, int dim, int arg, const char *key, sx_lua_region *g);
/// Whether a ball of radius r at x lies inside the region (r = 0: its centre).
bool sx_lua_region_contains(const sx_lua_region *g, const double *x, double r);

/* ------------------------------------------------- groups.c: filters */

/// Which balls a bulk operation applies to: a group, a region (by centre)
/// and a Lua predicate `where`, all optional.
typedef struct sx_lua_filter {
    int32_t group;       ///< 0: any
    int slot;            ///< the group slot the group is looked for in; 0: any (groups.c)
    bool has_region;
    sx_lua_region region;
    int where;           ///< stack index of the predicate, 0 for none
    int model;           ///< stack index of the model userdata
} sx_lua_filter;

/// The keys a filter reads, for the unknown-key check of a bulk call.
extern const char *const sx_lua_filter_keys[];
/// Reads the filter keys (group, region, where) of the table at arg (none
/// when arg is nil or absent). May push values: keep them until done.
void sx_lua_filter_read(lua_State *L, int model, int arg, sx_lua_filter *f);
/// Collects the ids of the balls that pass into a Lua-owned array pushed on
/// the stack; returns it, its length in *n. A scattered model is not
/// gathered: a region shares the balls' motion (sx_lua_checkmodel_motion),
/// and a predicate's reads fetch what they read.
int64_t *sx_lua_filter_ids(lua_State *L, const sx_lua_filter *f, int64_t *n);

/* -------------------------------------------------------- events.c */

/// Whether `name` is an event of m:on ("bond_break", "contact_create", ...).
bool sx_lua_is_event(const char *name);
/// m:on(event, fn[, opts]) for the model at 1 with the handler's id: pushes the id.
int sx_lua_events_add(lua_State *L, lua_Integer id);
/// Whether the model at `model` has handlers that need the run to go step by step.
bool sx_lua_events_per_step(lua_State *L, int model);
/// Whether the model at `model` has a bond_break handler (delivered at chunks' ends).
bool sx_lua_events_on_bonds(lua_State *L, int model);
/// Delivers the events of the steps since the last delivery to their handlers.
void sx_lua_events_deliver(lua_State *L, int model);

/* ------------------------------------------------------ geometry.c */

/// m:ball: a new ball at x of radius r behind a plane or line wall of the
/// model userdata at `model`, or overlapping one beyond the limit, is an error.
void sx_lua_check_ball_walls(lua_State *L, int model, const sx_model *m, const double *x, double r);
/// After the first step since balls or walls were added: an overlap of the
/// last step's contacts (of the balls as placed, when that step `failed`)
/// beyond the limit is an error (of the Lua call `what`) naming the two
/// entities. Clears ud->unchecked.
void sx_lua_check_placement(lua_State *L, sx_lua_model *ud, const char *what, bool failed);
/// geometry.c: the check of sx_lua_check_placement without a gather: of
/// the last step's contacts (sx_contact_deepest: a collective call on a
/// scattered model), or, when that step `failed`, of the balls as this
/// process holds them (a decomposed cycle that failed on this rank alone:
/// its copy of the other ranks' balls is as placed): true with the message
/// (without the script's place) pushed, or false. Clears ud->unchecked.
bool sx_lua_placement_overlap(lua_State *L, sx_lua_model *ud, const char *what, bool failed);
/// Pushes "file:line: " of the script's line a warning names: the
/// innermost outside seixo's Lua library (seixo.caller's where(), when the
/// library is loaded), else luaL_where(L, 1)'s.
void sx_lua_where(lua_State *L);
/// Warns on stderr (once per model and `what`) when v != 0 lies outside
/// [lo, hi] in magnitude, naming the unit expected, at sx_lua_where's line.
void sx_lua_check_range(lua_State *L, int model, const char *what, double v, double lo, double hi, const char *unit);
/// Warns once per model for `key` (the caller's line, then the message);
/// only rank 0 prints.
void sx_lua_warn_once(lua_State *L, int model, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* ----------------------------------------------------------- run.c */

/// A run of a model: while its record is open the model counts as cycling
/// and a Ctrl-C (sx_lua_interrupt_all) flags the run and stops its core cycle.
typedef struct sx_lua_run sx_lua_run;
/// Opens a run of the model userdata at `model` and pushes its record as a
/// to-be-closed value (closed when the calling C function returns or raises,
/// or by lua_settop below it). Refused while the model cycles (`what` names
/// the caller in the message).
sx_lua_run *sx_lua_run_open(lua_State *L, int model, const char *what);
/// Marks callback `id` of the model at `model` as owner's (an output's,
/// named in messages): m:off refuses it, and m:save does not list it.
void sx_lua_callback_own(lua_State *L, int model, lua_Integer id, const char *owner);
/// Appends to the table at `list` a line for each callback and event
/// handler of the script's (m:on) of the model at `model`: a snapshot
/// cannot keep a function.
void sx_lua_callbacks_unsaved(lua_State *L, int model, int list);
/// Removes callback `id` of the model at `model`, an owned one too.
void sx_lua_callback_remove(lua_State *L, int model, lua_Integer id);
/// Closes the runs whose thread (a coroutine) failed with them open.
void sx_lua_runs_reap(lua_State *L);
/// Cycles the core n steps in the run, without user callbacks, stopping
/// early at the first step that reaches model time t_end (INFINITY: none;
/// the rounding allowed counts the run's steps, sx_model_time_reached);
/// an interrupt ("interrupted at step N") or a failure is a Lua error;
/// decomposed, the whole state is on every rank after it (sx_lua_gather).
void sx_lua_run_cycle(lua_State *L, sx_lua_run *r, int64_t n, double t_end);
/// Raises "interrupted at step N" when the run was interrupted, and
/// "interrupted" when r is NULL and a Ctrl-C is pending: long C work (between
/// cycles, or outside any run) calls it so that a Ctrl-C stops it too.
void sx_lua_run_poll(lua_State *L, sx_lua_run *r);
/// Calls the function below its nargs arguments as a user callback of the
/// model at `model`: removals are queued while it runs and applied after.
void sx_lua_user_call(lua_State *L, int model, int nargs, int nres);
/// Records the histories due at the model's current step (history.c).
void sx_lua_history_record(lua_State *L, int model);
/// The smallest step > s at which a history is due, or INT64_MAX.
int64_t sx_lua_history_next(lua_State *L, int model, int64_t s);

/* ---------------------------------------------- history.c: files */

struct sx_io_history;
/// Pushes a userdata that holds the histories of the model at `model` as
/// C arrays for the I/O layer, to be closed (freed when the calling C
/// function returns or raises; the caller must not pop it before) and
/// returns them, *n of them: all, or those named in the array at `names`
/// (0: all); with `passed` (the index of a table name -> step, 0: none)
/// only the samples of later steps.
struct sx_io_history *sx_lua_histories_push(lua_State *L, int model, int names, int passed, int *n);
/// Adds histories read from the file `path` to the model at `model`; a
/// history of a function comes back detached. An unknown source is a Lua
/// error naming the file.
void sx_lua_histories_restore(lua_State *L, int model, const struct sx_io_history *h, int n, const char *path);

/* ----------------------------------------------------------- io.c */

/// Records a random seed a call of the model at `model` used (once per
/// seed, in order of first use): files list them as their provenance.
void sx_lua_record_seed(lua_State *L, int model, int64_t seed);

/* ----------------------------------------------------------- util.c */

/// The core's message without the core function's name it starts with.
const char *sx_lua_core_message(const char *msg);
/// Unless st is SX_OK, raises the model's message as one of the Lua call
/// `what` ("m:wall", "seixo.model"): "m:wall: the normal must not be zero".
void sx_lua_check(lua_State *L, const sx_model *m, sx_status st, const char *what);
/// Replaces the Lua library function lib.name by the C closure fn, whose
/// first upvalue is the function it replaces and the next `extra` ones the
/// values at the stack's top (popped); nothing when lib or name is missing.
void sx_lua_wrap(lua_State *L, const char *lib, const char *name, lua_CFunction fn, int extra);
/// The same for a field of an object of `kind` ("ball"), the field's name
/// at stack index 2 (getters, setters): "ball field 'radius': ...".
void sx_lua_checkfield(lua_State *L, const sx_model *m, sx_status st, const char *kind);

/// Index of s in the NULL-terminated list, or -1.
int sx_lua_find(const char *s, const char *const list[]);
/// Pushes "a, b, c" for a NULL-terminated list.
void sx_lua_pushlist(lua_State *L, const char *const list[]);
/// Argument `arg` must be a table whose keys are all in `keys`.
void sx_lua_checkkeys(lua_State *L, int arg, const char *const keys[]);
/// Like sx_lua_checkkeys, for a table at idx that is the field `field` of argument `arg`.
void sx_lua_checksubkeys(lua_State *L, int idx, int arg, const char *field, const char *const keys[]);

/// Reads the value at idx as n numbers (n <= 4) into out; returns NULL, or
/// pushes and returns a message saying what is wrong.
const char *sx_lua_tovec(lua_State *L, int idx, int n, double *out);
/// Pushes n components of v (a number when n == 1, else a seixo.vec).
void sx_lua_pushvec(lua_State *L, const double *v, int n);
/// vec.c: pushes a seixo.vec of n (1 to 4) components.
void sx_lua_pushnewvec(lua_State *L, const double *v, int n);
/// vec.c: turns the plain seixo.vec on the stack top into a read-only field
/// vector of kind.key (b.pos): setting a component is an error saying how
/// to set the field (writable) or that it is read-only. Other values stay.
void sx_lua_vec_seal(lua_State *L, const char *kind, const char *key, bool writable);
/// vec.c: pushes the plain array holding the components of the vector at idx
/// (a field vector's inner vector, else the value itself); returns its index.
int sx_lua_vec_array(lua_State *L, int idx);
/// vec.c: creates the seixo.vec class and adds seixo.vec to the module table on the stack top.
void sx_lua_vec_register(lua_State *L);
/// Sets field k of the table on the stack top to the number v.
void sx_lua_setnum(lua_State *L, const char *k, double v);
/// A value assigned to the field `field` of an object of `kind`: n numbers,
/// or an error naming both ("ball field 'vel': ...").
void sx_lua_checkvalue(lua_State *L, int idx, int n, double *out, const char *kind, const char *field);

/* Fields of the property table at `arg` (read raw; a bad value is an
 * argument error naming the field). The opt variants return false and leave
 * out untouched when the field is absent; the check variants require it. */
bool sx_lua_optvecfield(lua_State *L, int arg, const char *key, int n, double *out);
void sx_lua_checkvecfield(lua_State *L, int arg, const char *key, int n, double *out);
bool sx_lua_optnumfield(lua_State *L, int arg, const char *key, double *out);
double sx_lua_checknumfield(lua_State *L, int arg, const char *key);
/// An integer field in [lo, hi] (a float with an integer value is accepted).
bool sx_lua_optintfield(lua_State *L, int arg, const char *key, int64_t lo, int64_t hi, int64_t *out);
/// A finite number field in [lo, hi].
bool sx_lua_optrangefield(lua_State *L, int arg, const char *key, double lo, double hi, double *out);
/// A string field, or NULL when absent; valid while the table holds it.
const char *sx_lua_optstrfield(lua_State *L, int arg, const char *key);
/// A string field naming one of the NULL-terminated names: its index, or
/// dflt when absent; an unknown name lists the valid ones.
int sx_lua_optchoicefield(lua_State *L, int arg, const char *key, const char *const names[], int dflt);
/// luaL_checkstring for a name or a path: one with a zero byte in it is an
/// argument error (C would cut it there).
const char *sx_lua_checkname(lua_State *L, int arg);
/// Raises "bad argument #arg to 'f' (field 'key': msg)".
int sx_lua_fielderror(lua_State *L, int arg, const char *key, const char *msg);

/// Creates the class `tname` ("seixo.ball"): metamethods `meta`, and an
/// __index/__newindex pair that resolves `methods`, then the field `getters`
/// and `setters` (called directly with the stack object, key[, value]), and
/// errors on anything else naming `kind` ("ball") and the valid fields.
/// The metatable also holds __methods, __getters and __setters (the REPL
/// completes and help() documents from them). Leaves the methods table on
/// the stack.
void sx_lua_newclass(lua_State *L, const char *tname, const char *kind, const luaL_Reg meta[],
                     const luaL_Reg methods[], const luaL_Reg getters[], const luaL_Reg setters[]);

/// An object kind reached through handles (model, id): balls, walls.
typedef struct sx_lua_kind {
    const char *tname;                          ///< its class, "seixo.ball"
    const char *name;                           ///< its name in messages, "ball"
    bool (*exists)(const sx_model *, int64_t);  ///< whether an id is live
    const char *extras;                         ///< the model state's table of user extras, by id
    const char *const *shown;                   ///< the fields print(x) shows (NULL-terminated)
    /// Every rank holds the kind's state whole after a decomposed cycle (the
    /// walls): its handles do not gather a scattered model (sx_lua_checkmodel).
    bool replicated;
} sx_lua_kind;

/// Pushes a handle for the object `id` of the model userdata at `model`.
void sx_lua_pushhandle(lua_State *L, int model, const sx_lua_kind *k, int64_t id);
/// The id of the handle at idx and its model; a closed model or a removed
/// object is a Lua error.
sx_model *sx_lua_checkhandle(lua_State *L, int idx, const sx_lua_kind *k, int64_t *id);
/// The same without the gather: for a read of what every rank holds whole
/// after a decomposed cycle (a ball's radius, material, fixity, ...).
sx_model *sx_lua_checkhandle_whole(lua_State *L, int idx, const sx_lua_kind *k, int64_t *id);
/// Reads a handle of kind k of the model userdata at `model`, or an integer
/// id, at idx into *id: returns NULL, or pushes and returns what is wrong (a
/// handle of another model is refused, not read as a plain id).
const char *sx_lua_toid(lua_State *L, int idx, int model, const sx_lua_kind *k, int64_t *id);
/// __tostring of a handle: "seixo.ball 7 {pos = {0, 0, 0.1}, radius = 0.001, ...}"
/// (the kind's shown fields), or "seixo.ball 7 (removed)" / "(model closed)".
int sx_lua_handle_tostring(lua_State *L, const sx_lua_kind *k);
/// __eq of handles: the same class, model and id.
int sx_lua_handle_eq(lua_State *L);

/* User extras of the handle at index 1: a Lua table per object, dropped
 * when the object is removed. The field `extra` (read: the table, created
 * on first use; write: a table or nil) and the methods set_extra(key,
 * value), get_extra(key[, default]). */
int sx_lua_extra_table(lua_State *L, const sx_lua_kind *k);
int sx_lua_set_extra_table(lua_State *L, const sx_lua_kind *k);
int sx_lua_set_extra(lua_State *L, const sx_lua_kind *k);
int sx_lua_get_extra(lua_State *L, const sx_lua_kind *k);
/// Drops the extras of object `id` of the model userdata at `model`.
void sx_lua_forget_extras(lua_State *L, int model, const sx_lua_kind *k, int64_t id);

/// Pushes a generic-for iterator over the ids in the Lua array at `ids`
/// (which it takes over), stepped by `next` (see sx_lua_nexthandle).
void sx_lua_pushiterator_ids(lua_State *L, int model, int ids, lua_CFunction next);
/// Pushes a generic-for iterator over a snapshot of the object ids of the
/// model userdata at `model`, stepped by `next` (see sx_lua_nexthandle).
void sx_lua_pushiterator(lua_State *L, int model, int64_t (*count)(const sx_model *),
                         int64_t (*id_at)(const sx_model *, int64_t), lua_CFunction next);
/// The body of an iterator's `next`: pushes the handle of the next id of the
/// snapshot that is still live, or nil at the end.
int sx_lua_nexthandle(lua_State *L, const sx_lua_kind *k);
