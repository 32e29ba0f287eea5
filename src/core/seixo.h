/* seixo — the public C API of the core library (libseixo).
 *
 * The core knows nothing of Lua or HDF5. Everything a user can get wrong is
 * reported through an sx_status and a message readable with
 * sx_model_error(); programming errors (NULL model) are asserts.
 *
 * Units are SI throughout. Vectors are double[3]; in a 2D model only the
 * first two components are read or written, and a spin or moment is the
 * scalar in component 0.
 */
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__)
#define SX_API __attribute__((visibility("default")))
#else
#define SX_API
#endif

#define SX_VERSION "0.1.0"

typedef struct sx_model sx_model;

typedef enum sx_status {
    SX_OK = 0,
    SX_EINVAL,      ///< an argument is out of range or inconsistent
    SX_ENOMEM,      ///< an allocation failed
    SX_ENOTFOUND,   ///< no ball, wall or material with that id/name
    SX_EUNSTABLE,   ///< the stability guard stopped the run
    SX_EINTERRUPT,  ///< interrupted (sx_model_interrupt, sx_interrupt_request)
    SX_ELOCKED,     ///< the model is stepping; the change is not allowed now
} sx_status;

/* ---------------------------------------------------------------- model */

typedef struct sx_model_def {
    int dim;                 ///< 2 (disks of unit thickness) or 3 (spheres)
    double gravity[3];       ///< m/s^2
    double timestep;         ///< s; 0 selects the automatic critical timestep
    double timestep_safety;  ///< fraction of the critical timestep (auto mode), default 0.8
    double skin;             ///< m; Verlet skin of the broad phase; 0 = 0.2 x the mean radius
} sx_model_def;

/// Defaults: dim 3, no gravity, automatic timestep with safety 0.8, automatic skin.
SX_API sx_model_def sx_model_default_def(void);

/// Creates a model. On failure returns NULL and writes a message into err.
SX_API sx_model *sx_model_create(const sx_model_def *def, char *err, size_t errlen);
SX_API void sx_model_destroy(sx_model *m);

/// The message of the last failed call on this model ("" if none).
SX_API const char *sx_model_error(const sx_model *m);

SX_API int sx_model_dim(const sx_model *m);
SX_API double sx_model_time(const sx_model *m);        ///< s
SX_API int64_t sx_model_step_count(const sx_model *m); ///< steps taken

/// The timestep the next step will use (s): the user's value, or the
/// automatic one computed from the current contacts. On a model a lazy
/// cycle left scattered, a collective call (the ranks' least rating).
SX_API double sx_model_timestep(sx_model *m);
/// The critical timestep estimate sqrt(m/k) over balls, without safety factor (s).
/// On a model a lazy cycle left scattered, a collective call (the ranks' least).
SX_API double sx_model_critical_timestep(sx_model *m);
/// Sets a fixed timestep (s > 0), or 0 to return to the automatic one.
SX_API sx_status sx_model_set_timestep(sx_model *m, double dt);
/// The fixed timestep set (s), or 0 when it is the automatic one: a read,
/// which (unlike sx_model_timestep) never prepares the model.
SX_API double sx_model_fixed_timestep(const sx_model *m);
/// An upper bound of sx_model_critical_timestep (s) from each ball's own
/// rating alone (a contact with a ball like itself, at rest): no contact
/// sums, so neither a build nor memory of a few doubles a ball.
SX_API double sx_model_critical_timestep_bound(sx_model *m);

SX_API void sx_model_gravity(const sx_model *m, double out[3]);
SX_API sx_status sx_model_set_gravity(sx_model *m, const double g[3]);

/// Advances the model n steps. Stops early with SX_EUNSTABLE (stability
/// guard) or SX_EINTERRUPT; the model stays consistent and inspectable.
SX_API sx_status sx_model_cycle(sx_model *m, int64_t n);
/// As sx_model_cycle, for a run begun at step count `since`, but takes no
/// step once the model time has reached t_end (sx_model_time_reached;
/// INFINITY: no limit; NaN is refused), so it stops after the first step
/// that reaches it, and takes none when it is reached already: where a run
/// with a time limit stops does not depend on how it is cut into cycles,
/// even when the automatic timestep changes inside one.
SX_API sx_status sx_model_cycle_until(sx_model *m, int64_t n, double t_end, int64_t since);
/// The model time has reached t_end, in a run begun at step count `since`:
/// it is at least t_end less the rounding that the run's sums of timesteps
/// can have accumulated (at most half the last step's timestep; none before
/// the model's first step). Without it, 1 s in steps of 1e-5 s took 100,001.
SX_API bool sx_model_time_reached(const sx_model *m, double t_end, int64_t since);

/// OpenMP threads used by the step (default 1). Results are bit-identical
/// for any thread count: work is split in chunks that depend only on the model.
SX_API sx_status sx_model_set_threads(sx_model *m, int threads);
SX_API int sx_model_threads(const sx_model *m);

/// Asks a running cycle to stop at the next step boundary (async-signal-safe).
SX_API void sx_model_interrupt(sx_model *m);

/// A process-wide interrupt request (a Ctrl-C; async-signal-safe): a
/// cycle stops at the next step boundary, as for sx_model_interrupt, and
/// every long loop of the core outside the steps (the broad phase of a
/// build, sx_bond_install's pair scan, a clump template's mass properties)
/// stops with SX_EINTERRUPT, leaving the model as it was before the call.
/// It stays pending until the code that reports the interruption clears it.
SX_API void sx_interrupt_request(void);
SX_API int sx_interrupt_pending(void);
SX_API void sx_interrupt_clear(void);
/// Decomposed cycles do not stop on a rank's own request: every 16 steps
/// the ranks share their unanswered requests (sx_interrupt_clear answers
/// a process's, as does a stop), and one on any rank stops the cycle on
/// every rank at that step, with SX_EINTERRUPT (the state as at any
/// cycle's end). sx_model_interrupt of a decomposed model is a request.
/// The stops so far (the same on every rank).
SX_API unsigned sx_interrupts_agreed(void);

/// PFC's mean unbalanced-force ratio: the mean over bodies (free balls and clumps) of |F + m g| (free
/// components) over the mean contact force magnitude; 0 when at rest with no
/// contacts, infinity when forces act but no contact carries any. Of a
/// decomposed model left scattered (sx_model_scattered), a collective call:
/// the ranks' sums over their own balls and contacts chained in the serial
/// order, the clumps' resultants from their owners (the serial bits); NAN
/// if the ranks could not exchange.
SX_API double sx_model_unbalanced_ratio(const sx_model *m);

/// A 64-bit hash of everything a restart restores, in a canonical form
/// (balls, contacts, bonds, cracks and clumps as digests summed in no
/// order, -0 as +0, what the next cycle derives first as derived;
/// docs/lua-api.md, m:hash(), lists it): equal hashes mean states that
/// continue bit-identically. Queries leave it as it is. Of a decomposed
/// model left scattered (sx_model_scattered) it is a collective call: each
/// rank hashes what it holds current and the ranks add their sums (0 if a
/// rank ran out of memory).
SX_API uint64_t sx_model_state_hash(const sx_model *m);

/// Domain decomposition (issue 16; docs/developer.md, "MPI domain
/// decomposition"). The core makes no MPI call: whoever runs the ranks
/// fills this table, and every rank holds the same model between cycles.
/// A span is a range [lo, hi) of a dense array.
typedef struct sx_span {
    int64_t lo, hi;
} sx_span;
typedef struct sx_exchange {
    int rank, ranks;        ///< this process and their number (>= 1)
    void *ud;               ///< passed to the functions
    /// Rank r holds elements own[r] of an array of `size`-byte elements
    /// (the same address range on every rank) and needs need[r * per + k],
    /// k < per: every rank sends what it holds of the others' needs and
    /// receives what it needs into data. False on failure.
    bool (*share)(void *ud, void *data, size_t size, const sx_span *own, const sx_span *need, int per);
    /// *v becomes the largest *v of all ranks. False on failure.
    bool (*max)(void *ud, double *v);
    /// True when every rank passed the same value.
    bool (*agree)(void *ud, uint64_t v);
} sx_exchange;

/// Cycles of m run decomposed over x's ranks (NULL or one rank: not
/// decomposed): each rank integrates a slab of the balls, cut again at
/// every build to balance the ranks' work, with ghost copies of its
/// neighbours' balls, and steps the clumps it owns; every cycle ends with
/// the whole state on every rank (or lazily, sx_model_gather_lazily),
/// bit-identical to a serial run's for any number of ranks. A model the
/// last cycle left scattered is gathered first. SX_EINVAL when x lacks a function or its rank is out
/// of range; SX_ELOCKED while m is stepping.
SX_API sx_status sx_model_decompose(sx_model *m, const sx_exchange *x);
/// The number of ranks m's cycles are decomposed over (1: not decomposed).
SX_API int sx_model_ranks(const sx_model *m);
/// Decomposed: whether a cycle ends with the whole state on every rank
/// (the default) or, lazily, with each rank's own balls, their pairs,
/// bonds and clumps current and the rest as the last gather left it
/// (scattered); the walls, their loads and resultants, the tracked
/// energies' sums and the time are whole either way. A scattered model's next cycle goes on
/// from where the last one stopped, without the exchange of the whole
/// state; the queries that say so answer a scattered model with exchanges
/// of their own (collective calls: the state hash, the ratio, the counts,
/// the energies, the timesteps, the deepest contact, sx_ball_fetch before a
/// ball's motion is read, sx_model_share_motion before many balls' are,
/// sx_model_share_cracks before the crack log is), and anything else that
/// reads or changes the balls, pairs, bonds or clumps must first call
/// sx_model_gather. Nothing when not decomposed.
SX_API void sx_model_gather_lazily(sx_model *m, bool lazily);
/// Whether the last cycle left m's state scattered (see above).
SX_API bool sx_model_scattered(const sx_model *m);
/// Decomposed: whether the last cycle's error is every rank's. An error a
/// rank meets in its own part of a step (an overlap deeper than a radius, a
/// non-finite motion), or one every rank meets alike (a cylinder's radius,
/// the energy guard), ends the cycle on every rank at the same step, with
/// the error the serial run would give and the state whole (or scattered,
/// lazily) as after any cycle: the caller can report it or go on. False
/// serially, and after an error that left the ranks out of step.
SX_API bool sx_model_error_agreed(const sx_model *m);
/// Makes the whole state current on every rank after a lazy cycle. A
/// collective call: every rank calls it at the same point. SX_OK at once
/// when not scattered; SX_ELOCKED while m is stepping; SX_EINVAL when the
/// ranks could not exchange. A cycle that failed leaves the state
/// scattered, and the ranks out of step: stop them rather than gather.
SX_API sx_status sx_model_gather(sx_model *m);

/// Bytes currently allocated by the model.
SX_API size_t sx_model_bytes(const sx_model *m);

/// Where the model's bytes are: the arrays at their capacities, by owner.
typedef struct sx_memory {
    size_t total;           ///< bytes held (sx_model_bytes), the parts below together
    size_t peak;            ///< the highest total so far
    size_t balls;           ///< per-ball arrays (state, properties, id map, the grid's cell of each ball)
    size_t contacts;        ///< the candidate pairs with their contact history (ball-ball and ball-wall)
    size_t bonds;           ///< the bond store and the crack log
    size_t work;            ///< the step's working storage: chunk buffers, blocks, grid cells, scratch, laws, walls
    int64_t ball_count;     ///< balls
    int64_t pair_count;     ///< candidate pairs stored (touching or within the skin)
    int64_t contact_count;  ///< touching pairs of the last step
    double bytes_per_ball;    ///< balls / ball_count
    double bytes_per_contact; ///< contacts / contact_count: what each contact costs, its candidates included
} sx_memory;

SX_API sx_memory sx_model_memory(const sx_model *m);

/* -------------------------------------------------------------- profile */

/// The stages of a step, timed by every sx_model_cycle (always on: a few
/// clock reads per step).
typedef enum sx_stage {
    SX_STAGE_BROAD_PHASE,   ///< grid, sorting, candidate pairs, history transfer (when the skin is used up)
    SX_STAGE_BALL_CONTACTS, ///< ball-ball contact forces
    SX_STAGE_WALL_CONTACTS, ///< ball-wall contact forces, and the sums of the ball-ball pass's buffers
    SX_STAGE_INTEGRATION,   ///< the law of motion
    SX_STAGE_CALLBACKS,     ///< time an embedding layer reports with sx_model_profile_add (Lua callbacks)
    SX_STAGE_OTHER,         ///< the rest of a cycle: timestep, servos, wall motion, stability guard
    SX_STAGE_COUNT
} sx_stage;

typedef struct sx_profile {
    double seconds[SX_STAGE_COUNT]; ///< s of wall-clock time spent in each stage
    int64_t calls[SX_STAGE_COUNT];  ///< how often each ran: once per step, the broad phase per build,
                                    ///< callbacks per sx_model_profile_add
    double cycle_seconds;           ///< s of wall-clock time inside sx_model_cycle (all stages but callbacks)
    int64_t cycles;                 ///< sx_model_cycle calls
    int64_t steps;                  ///< steps taken
    int64_t resumed;                ///< decomposed: cycles that went on from a scattered state (no gather)
    int64_t gathers;                ///< decomposed: exchanges of the whole state (a cycle's end, a gather
                                    ///< before a call that reads the balls, a build in periodic space)
    int64_t received;               ///< decomposed: bytes this rank received from the others
} sx_profile;

/// The profile accumulated since the model was created or last reset.
SX_API sx_profile sx_model_profile(const sx_model *m);
SX_API void sx_model_profile_reset(sx_model *m);
/// Adds time spent on the model's behalf outside the core (one call of the stage).
SX_API void sx_model_profile_add(sx_model *m, sx_stage stage, double seconds);
/// "broad phase", "ball contacts", ... (NULL for a bad stage).
SX_API const char *sx_stage_name(sx_stage stage);
/// Writes a table of the profile (seconds, share, calls, time per call per
/// stage; particle-steps per second) into buf like snprintf; balls is the
/// number of balls for the rate (0: none printed). Returns the length it needed.
SX_API int sx_profile_format(const sx_profile *p, int64_t balls, char *buf, size_t len);

/* ------------------------------------------------------------ materials */

typedef enum sx_contact_model {
    SX_MODEL_LINEAR = 0,  ///< linear springs kn, ks in series (4-22/4-23)
    SX_MODEL_HERTZ = 1,   ///< Hertz-Mindlin from shear_modulus and poisson (4-25 ... 4-29)
} sx_contact_model;

typedef struct sx_material_def {
    sx_contact_model model; ///< the contact law, a registry number (sx_law_find); two materials in
                            ///< contact must use the same law (refused when cycling otherwise)
    double density;         ///< kg/m^3 (> 0)
    double kn;              ///< N/m, normal stiffness of the ball (springs in series, 4-22)
    double ks;              ///< N/m, shear stiffness of the ball (4-23)
    double modulus;         ///< Pa, BPM contact modulus Ec (4-49): if > 0, kn = 2 Ec (2D) or
                            ///< 4 R Ec (3D) per ball and ks = kn / stiffness_ratio; kn, ks ignored
    double stiffness_ratio; ///< kn/ks for the BPM modulus (4-50), > 0
    double shear_modulus;   ///< Pa, Hertz G (> 0 for Hertz)
    double poisson;         ///< Hertz Poisson's ratio in [0, 0.5)
    double friction;        ///< Coulomb coefficient (>= 0); a contact uses the smaller (4-30)
    double damping;         ///< local (non-viscous) damping coefficient alpha in [0, 1)
    double viscous_normal;  ///< normal critical-damping ratio of the contact dashpot, >= 0
    double viscous_shear;   ///< shear critical-damping ratio of the contact dashpot, >= 0
    double restitution;     ///< coefficient of restitution e in (0, 1] of a normal impact: the normal
                            ///< dashpot's ratio is derived from it for the law (0: viscous_normal gives it)
    double rolling_friction;///< rolling resistance mu_r >= 0: rolling spring ks R^2, moment <= mu_r R Fn
                            ///< (0: none; a contact uses the smaller of its two)
    double total_shear;     ///< 1: Mindlin's total tangential form Fs = -ks Us (both materials of a
                            ///< contact); 0: the seed's incremental form (4-20)
    double hertz_mixing;    ///< Hertz, two different materials (or a ball and a wall's material):
                            ///< 0: the means of G and nu (4-27); 1: the literature's
                            ///< 1/E* = sum (1 - nu_i^2)/E_i, 1/G* = sum (2 - nu_i)/G_i (both ask)
    double mindlin_unloading; ///< 1: as the overlap shrinks the shear force shrinks with ks (Mindlin &
                              ///< Deresiewicz, Thornton; both materials of a contact); 0: not
} sx_material_def;

/// The units of the contact-law registry (src/core/laws/registry.h), numbered in its order:
/// the normal laws a material's `model` names (SX_MODEL_LINEAR, SX_MODEL_HERTZ are 0 and 1;
/// sx_law_is_model), then the parts every contact runs beside its law, switched on by their
/// parameters (restitution, ...). Their count, the name and a one-line summary of unit `law`
/// (NULL out of range), the number of a name (-1: none).
SX_API int sx_law_count(void);
SX_API bool sx_law_is_model(int law);
SX_API const char *sx_law_name(int law);
SX_API const char *sx_law_summary(int law);
SX_API int sx_law_find(const char *name);
/// The material parameters a unit reads (beside the common ones of sx_material_def): their
/// count, the k-th one's key (its unit into *unit if not NULL; NULL out of range), and its
/// field in a definition (NULL out of range).
SX_API int sx_law_param_count(int law);
SX_API const char *sx_law_param_name(int law, int k, const char **unit);
SX_API double *sx_law_param_value(sx_material_def *d, int law, int k);

/// Linear, density 2650, kn = ks = 1e8, friction 0.5, no damping, stiffness_ratio 1,
/// Hertz G = 29 GPa, nu = 0.15 (used only when model is Hertz).
SX_API sx_material_def sx_material_default_def(void);

/// Adds a material, or redefines it if the name exists (balls using it get
/// their mass and inertia recomputed). Writes its index (>= 0) to *out if out is not NULL.
SX_API sx_status sx_material_set(sx_model *m, const char *name, const sx_material_def *def, int *out);
/// Index of the named material, or -1.
SX_API int sx_material_find(const sx_model *m, const char *name);
SX_API int sx_material_count(const sx_model *m);
SX_API const char *sx_material_name(const sx_model *m, int index);
SX_API sx_status sx_material_get(const sx_model *m, int index, sx_material_def *out);

/// The contact-model table (PFC's contact model assignment table): each row
/// gives the ball-ball contacts it matches their own law and parameters,
/// in place of those their two materials mix. A row matches a pair of
/// groups (the balls' core group numbers, in either order), a pair of
/// materials (indices, in either order), or any pair (the default row). A
/// contact takes its row when it is created (its balls start touching, or
/// it is bonded): the newest row of a group pair that matches, else the
/// newest of a material pair, else the newest default row, else none (its
/// materials' law). A created contact keeps the row it took while it
/// lasts, whatever rows are added later. A row's `law` is read as a
/// material: the contact is the one two balls of that material would make
/// (linear springs in series, 4-22/4-23). Rows are never removed: a newer
/// row for the same match replaces the older one for new contacts only.
/// Ball-wall contacts are matched by the rows of a wall (the WALL kinds)
/// alone, by the same rules (a ball group's row, else a ball material's,
/// else any ball's, newest first; else the laws of ball and wall); a
/// wall row's law is read as a ball and a wall of its material would make
/// (as a wall of a material, walls.c).
typedef enum sx_cmodel_match {
    SX_CMODEL_DEFAULT = 0,        ///< any ball-ball pair no other row matches
    SX_CMODEL_GROUPS = 1,         ///< balls of groups a and b (0: no group)
    SX_CMODEL_MATERIALS = 2,      ///< balls of materials a and b
    SX_CMODEL_WALL_GROUP = 3,     ///< a ball of group a with wall id b
    SX_CMODEL_WALL_MATERIAL = 4,  ///< a ball of material a with wall id b
    SX_CMODEL_WALL = 5,           ///< any ball with wall id b (a unused, 0)
} sx_cmodel_match;

typedef struct sx_cmodel_def {
    sx_cmodel_match match;
    int32_t a, b;            ///< group numbers (>= 0) or material indices, unordered; for the WALL kinds a ball's and a wall id
    sx_material_def law;     ///< the law (its `model`) and its parameters, as a material's
} sx_cmodel_def;

/// Appends a row (named for reports, 1 to 63 characters); its number
/// (from 1) into *row if not NULL. SX_EINVAL on a bad match or law.
SX_API sx_status sx_cmodel_add(sx_model *m, const char *name, const sx_cmodel_def *def, int *row);
/// Rows in the table.
SX_API int sx_cmodel_count(const sx_model *m);
/// Row `row` (from 1) and its name; SX_ENOTFOUND out of range.
SX_API sx_status sx_cmodel_get(const sx_model *m, int row, sx_cmodel_def *def, const char **name);

/* ---------------------------------------------------------------- balls */

typedef struct sx_ball_def {
    double pos[3];    ///< m
    double vel[3];    ///< m/s
    double spin[3];   ///< rad/s (2D: spin[0])
    double radius;    ///< m (> 0)
    int material;     ///< material index
} sx_ball_def;

SX_API sx_ball_def sx_ball_default_def(void);

/// Adds a ball; its stable id (>= 1) is written to *id.
SX_API sx_status sx_ball_add(sx_model *m, const sx_ball_def *def, int64_t *id);
SX_API sx_status sx_ball_remove(sx_model *m, int64_t id);
/// Removes the n balls listed (an id listed twice is removed once) in one
/// pass over the contacts: O(balls + contacts) however many go. Their
/// contacts and bonds go with them; the other contacts keep their history.
/// All or nothing: an id that is not a ball fails with SX_ENOTFOUND and
/// removes none.
SX_API sx_status sx_ball_remove_many(sx_model *m, const int64_t *ids, int64_t n);
/// Makes room for `count` more balls at once (optional: saves memory and
/// copies when the number of balls to add is known).
SX_API sx_status sx_ball_reserve(sx_model *m, int64_t count);
SX_API int64_t sx_ball_count(const sx_model *m);
/// Id of the ball at dense index i (0 <= i < count); the order changes when
/// the broad phase re-sorts balls, ids never do.
SX_API int64_t sx_ball_id_at(const sx_model *m, int64_t i);
SX_API bool sx_ball_exists(const sx_model *m, int64_t id);

typedef enum sx_ball_vec {
    SX_BALL_POS,     ///< m
    SX_BALL_VEL,     ///< m/s
    SX_BALL_SPIN,    ///< rad/s
    SX_BALL_FORCE,   ///< N: contact forces plus applied force of the last step
    SX_BALL_MOMENT,  ///< N m: contact moments plus applied moment of the last step
    SX_BALL_APPLIED_FORCE,   ///< N, constant external force added every step
    SX_BALL_APPLIED_MOMENT,  ///< N m
} sx_ball_vec;

SX_API sx_status sx_ball_get_vec(const sx_model *m, int64_t id, sx_ball_vec which, double out[3]);
/// Ball id's unwrapped position, m: in periodic space its position in the
/// cell plus the cell vectors (the cell's now) it was brought back by since
/// it was placed, so that it moves on without jumps across the faces (the
/// position a displacement and the gravitational energy take); elsewhere
/// its position.
SX_API sx_status sx_ball_get_unwrapped(const sx_model *m, int64_t id, double out[3]);
/// A model a lazy cycle left scattered (sx_model_gather_lazily): ball id's
/// motion (position, velocity, spin, force, moment) from the rank that
/// holds it current to every rank, where sx_ball_get_vec then reads it as
/// after a gather (its other fields every rank holds whole). A collective
/// call; ranks that pass different ids get the whole state gathered
/// (sx_model_gather). The 17th call since the last cycle shares every
/// ball's motion instead, which then holds until the next cycle (no
/// exchange).
/// SX_OK at once when not scattered or no such ball; SX_ELOCKED while m
/// is stepping; SX_EINVAL when the ranks could not exchange.
SX_API sx_status sx_ball_fetch(sx_model *m, int64_t id);
/// Whether every ball's motion is current on this rank: not scattered, or
/// shared since the last cycle (sx_ball_fetch then exchanges nothing).
SX_API bool sx_model_motion_current(const sx_model *m);
/// A model a lazy cycle left scattered: every ball's motion (as
/// sx_ball_fetch's) from the ranks that hold it current to every rank, one
/// exchange that holds until the next cycle (for a query that reads many
/// balls: a selection by region, a sum over the balls). A collective call;
/// SX_OK at once when sx_model_motion_current; SX_ELOCKED while m is
/// stepping; SX_EINVAL when the ranks could not exchange.
SX_API sx_status sx_model_share_motion(sx_model *m);
/// Sets pos, vel, spin or an applied force/moment (force and moment of the
/// last step are results, not settable).
SX_API sx_status sx_ball_set_vec(sx_model *m, int64_t id, sx_ball_vec which, const double v[3]);

typedef enum sx_ball_scalar {
    SX_BALL_RADIUS,   ///< m (settable; mass and inertia follow from the density)
    SX_BALL_MASS,     ///< kg
    SX_BALL_INERTIA,  ///< kg m^2
    SX_BALL_DAMPING,  ///< local damping alpha (settable)
} sx_ball_scalar;

SX_API sx_status sx_ball_get(const sx_model *m, int64_t id, sx_ball_scalar which, double *out);
SX_API sx_status sx_ball_set(sx_model *m, int64_t id, sx_ball_scalar which, double value);
SX_API sx_status sx_ball_material(const sx_model *m, int64_t id, int *material);
SX_API sx_status sx_ball_set_material(sx_model *m, int64_t id, int material);

/// A user group number per ball (0 = no group); the Lua layer maps names to numbers.
SX_API sx_status sx_ball_group(const sx_model *m, int64_t id, int32_t *group);
SX_API sx_status sx_ball_set_group(sx_model *m, int64_t id, int32_t group);

/// Fixity bits: a fixed component keeps its velocity (or spin) whatever the force.
enum {
    SX_FIX_VX = 1 << 0, SX_FIX_VY = 1 << 1, SX_FIX_VZ = 1 << 2,
    SX_FIX_WX = 1 << 3, SX_FIX_WY = 1 << 4, SX_FIX_WZ = 1 << 5,
    SX_FIX_VEL = SX_FIX_VX | SX_FIX_VY | SX_FIX_VZ,
    SX_FIX_SPIN = SX_FIX_WX | SX_FIX_WY | SX_FIX_WZ,
};
/// In 2D only SX_FIX_VX, SX_FIX_VY and SX_FIX_WZ (the scalar spin, about z) apply.
SX_API sx_status sx_ball_fixity(const sx_model *m, int64_t id, unsigned *mask);
SX_API sx_status sx_ball_set_fixity(sx_model *m, int64_t id, unsigned mask);

/* ---------------------------------------------------------------- walls */

typedef enum sx_wall_kind {
    SX_WALL_PLANE,    ///< 3D infinite plane: point + normal; balls live on the normal's side
    SX_WALL_LINE,     ///< 2D infinite line: point + normal; balls live on the normal's side
    SX_WALL_RECT,     ///< 3D finite rectangle: corner + two edge vectors; two-sided
    SX_WALL_SEGMENT,  ///< 2D finite segment: two end points; two-sided
    SX_WALL_CYLINDER, ///< 3D cylinder: axis point + axis direction (normal), radius, height; balls inside
    SX_WALL_MESH,     ///< 3D triangle mesh (sx_wall_add_mesh): two-sided facets; moves at vel and spins at spin about point
} sx_wall_kind;

/// sx_wall_def.material: no material of the wall's own, or a rigid wall.
enum { SX_WALL_NO_MATERIAL = -1, SX_WALL_RIGID = -2 };

typedef struct sx_wall_def {
    sx_wall_kind kind;
    /// SX_WALL_NO_MATERIAL: the wall's kn, ks, friction below (and a Hertz ball's own G, nu
    /// with R-bar = R, 4-28). SX_WALL_RIGID: the wall does not deform (kn, ks ignored,
    /// friction kept): a linear contact has the ball's own kn, ks; a Hertz one is the
    /// literature's rigid plane, E* = E/(1 - nu^2), G* = G/(2 - nu), R* = R. Else the index
    /// of a material of the wall's own, of the balls' law, that replaces kn, ks and friction:
    /// the contact mixes it with the ball's as two balls' materials mix (4-22/4-23/4-30;
    /// Hertz 4-27 or the literature's rule, `hertz_mixing`), with R-bar = R. Not in the BPM
    /// modulus mode (a wall has no radius).
    int material;
    double point[3];   ///< plane/line: a point on it; rect: a corner; segment: first end
    double normal[3];  ///< plane/line: normal towards the balls (normalised on input)
    double edge1[3];   ///< rect: first edge from the corner; segment: second end minus first
    double edge2[3];   ///< rect: second edge from the corner (orthogonal to edge1)
    double vel[3];     ///< m/s, imposed translational velocity
    double spin[3];    ///< mesh: rad/s, imposed angular velocity about point (0 for the other kinds)
    double radius;     ///< cylinder: m, its radius (changes at radial_vel)
    double height;     ///< cylinder: m, its length along the axis from point (0: infinite)
    double radial_vel; ///< cylinder: m/s, rate of change of the radius (> 0 expands)
    double kn, ks;     ///< N/m, wall stiffnesses (in series with the ball's, 4-22)
    double friction;   ///< Coulomb coefficient; the contact uses the smaller of ball and wall
} sx_wall_def;

/// A plane at the origin with normal +z (2D: a line with normal +y), kn = ks = 1e8, friction 0.5,
/// no material (SX_WALL_NO_MATERIAL).
SX_API sx_wall_def sx_wall_default_def(int dim);

SX_API sx_status sx_wall_add(sx_model *m, const sx_wall_def *def, int64_t *id);
SX_API sx_status sx_wall_remove(sx_model *m, int64_t id);
SX_API int64_t sx_wall_count(const sx_model *m);
SX_API int64_t sx_wall_id_at(const sx_model *m, int64_t i);
SX_API bool sx_wall_exists(const sx_model *m, int64_t id);
/// The definition as it is now (point moved by the wall's motion).
SX_API sx_status sx_wall_get(const sx_model *m, int64_t id, sx_wall_def *out);
SX_API sx_status sx_wall_set_vel(sx_model *m, int64_t id, const double vel[3]);
/// Moves the wall so that its reference point (def.point: a plane's or
/// line's point, a rect's corner, a segment's first end, a cylinder's axis
/// point) is at p (m): a translation, the rest of the wall follows.
SX_API sx_status sx_wall_set_point(sx_model *m, int64_t id, const double p[3]);

typedef enum sx_wall_scalar {
    SX_WALL_KN,        ///< N/m, normal stiffness (> 0)
    SX_WALL_KS,        ///< N/m, shear stiffness (>= 0)
    SX_WALL_FRICTION,  ///< Coulomb coefficient (>= 0)
    SX_WALL_RADIUS,    ///< cylinder: m, its radius (> 0)
} sx_wall_scalar;

/// A triangle mesh for sx_wall_add_mesh: nv vertices (x, y, z in m) and nt
/// triangles (three 0-based vertex indices each). Vertices at exactly the
/// same coordinates are welded into one, so a triangle soup (an STL file)
/// gets the shared edges and vertices that contacts need.
typedef struct sx_mesh_def {
    const double *vertices; ///< 3 nv, m
    int64_t nv;
    const int32_t *triangles; ///< 3 nt vertex indices
    int64_t nt;
    /// false: a degenerate triangle (a repeated vertex or zero area) is an
    /// error naming it; true: such triangles are dropped and counted.
    bool repair;
} sx_mesh_def;

/// What sx_wall_add_mesh changed in the mesh it was given.
typedef struct sx_mesh_report {
    int64_t dropped;  ///< degenerate triangles dropped (repair only)
    int64_t flipped;  ///< triangles turned round to wind as their neighbours (always)
    int64_t welded;   ///< vertices merged into an identical one
    int64_t first_dropped, first_flipped; ///< the input index of the first of each (-1: none)
} sx_mesh_report;

/// Adds a triangle-mesh wall (3D only). def gives the point the mesh spins
/// about (def.point), its velocity and spin, kn, ks and friction (def.kind
/// is ignored). A ball touches a facet's face, an edge or a vertex; where
/// facets meet, one contact is kept (a face before the edges and vertices
/// it borders), and a contact's shear history passes to the facet that
/// takes it over, so a ball rolls across facets as on one surface.
/// report (may be NULL) says what was repaired.
SX_API sx_status sx_wall_add_mesh(sx_model *m, const sx_wall_def *def, const sx_mesh_def *mesh, int64_t *id,
                                  sx_mesh_report *report);
/// A mesh wall's vertex and triangle counts (after welding and repair).
SX_API sx_status sx_wall_mesh_size(const sx_model *m, int64_t id, int64_t *nv, int64_t *nt);
/// A mesh wall's vertices where they are now (3 nv doubles, m) and its
/// triangles (3 nt indices); either may be NULL.
SX_API sx_status sx_wall_mesh_get(const sx_model *m, int64_t id, double *vertices, int32_t *triangles);
/// A mesh wall's angular velocity about its point (rad/s).
SX_API sx_status sx_wall_set_spin(sx_model *m, int64_t id, const double spin[3]);

/// Sets a stiffness, the friction or a cylinder's radius; the next step
/// (and its timestep) uses the new value.
SX_API sx_status sx_wall_set(sx_model *m, int64_t id, sx_wall_scalar which, double value);
/// Gives a wall its own material (an index), none (SX_WALL_NO_MATERIAL) or makes it rigid
/// (SX_WALL_RIGID); the next step uses it. See sx_wall_def.
SX_API sx_status sx_wall_set_material(sx_model *m, int64_t id, int material);
/// Cylinder: the rate of change of its radius (m/s, > 0 expands).
SX_API sx_status sx_wall_set_radial_vel(sx_model *m, int64_t id, double radial_vel);
/// Resultant force (N) of the balls on the wall in the last step, and its
/// moment (N m) about the wall's reference point (def.point; rect: its centre).
SX_API sx_status sx_wall_force(const sx_model *m, int64_t id, double force[3], double moment[3]);

/// PFC's servo: every step the wall's normal velocity is set to
/// G (sigma - target), G = alpha A / (kn Nc dt), sigma = (sum of the normal
/// contact forces on the wall) / A, kn the mean normal contact stiffness and
/// Nc the number of contacts of the wall; positive moves the wall away from
/// the balls (a cylinder expands). With no contact the wall approaches at max_speed.
typedef struct sx_servo_def {
    double target;     ///< Pa (2D: N/m, per unit thickness), compression positive
    double area;       ///< m^2 (2D: m) the load acts on; update it as the specimen deforms
    double alpha;      ///< gain factor, 0 < alpha <= 1 (PFC: 0.5)
    double max_speed;  ///< m/s, bound on the wall speed (> 0)
} sx_servo_def;

SX_API sx_servo_def sx_servo_default_def(void); ///< alpha 0.5, no target, area 1, max_speed 1
/// Puts a wall under servo control (plane, line, rect, segment, cylinder).
SX_API sx_status sx_wall_set_servo(sx_model *m, int64_t id, const sx_servo_def *def);
SX_API sx_status sx_wall_clear_servo(sx_model *m, int64_t id);
/// The servo's inputs after the last step, for a servo written in a script:
/// the sum of the normal contact forces on the wall (N), its contact count
/// and the mean normal stiffness of those contacts (N/m, 0 without contacts).
SX_API sx_status sx_wall_load(const sx_model *m, int64_t id, double *normal_force, int64_t *contacts, double *kn);

/* ------------------------------------------------------------- contacts */

/// Number of ball-ball and ball-wall contacts of the last step's force
/// evaluation. Of a decomposed model left scattered (sx_model_scattered), a
/// collective call: each rank counts its own pairs' and the ranks add them
/// (-1: they could not exchange).
SX_API int64_t sx_contact_count(const sx_model *m);

typedef struct sx_contact_info {
    int64_t a, b;        ///< ball ids (b is a wall id when is_wall)
    bool is_wall;
    double normal[3];    ///< unit normal from a to b (ball-wall: from the wall to the ball)
    double point[3];     ///< contact point, m (4-4)
    double overlap;      ///< m (4-3)
    double fn;           ///< N, normal force incl. its dashpot (compression positive)
    double shear[3];     ///< N, elastic shear force on b (the shear dashpot is not included)
    double kn, ks;       ///< N/m, contact stiffnesses (Hertz: secant normal, current shear)
    unsigned bond;       ///< SX_BOND_* bits intact on this contact (0: unbonded)
    double pb_fn;        ///< N, parallel-bond (or flat-joint face) normal force (compression positive)
    double pb_fs[3];     ///< N, parallel-bond (or flat-joint face) shear force on b
    double pb_moment[3]; ///< N m, parallel-bond (or face) moment on b about the contact point (2D: [0])
    double pb_radius;    ///< m, parallel-bond radius (4-53), or the flat joint's face radius
    int64_t joint;       ///< the smooth joint (1-based, sx_joint_add) whose law the contact takes; 0: none
    double shift[3];     ///< m, periodic space: the period b is seen through (b's image at
                         ///< its centre + shift touches a); 0 for a contact inside the cell
    int cmodel;          ///< the contact-model row it took (from 1; 0: its materials' law)
} sx_contact_info;

/// Calls fn for every contact of the last step's force evaluation (bonded
/// pairs included, whatever their gap), in the store's deterministic order:
/// the forces the balls felt in that step.
/// Stops and returns false when fn returns false.
SX_API bool sx_contact_each(const sx_model *m, bool (*fn)(const sx_contact_info *, void *), void *ud);

/// A contact's overlap relative to the smaller radius of its balls (a
/// ball-wall contact's: its ball's radius).
typedef struct sx_overlap {
    double ratio;    ///< overlap / radius; 0 when nothing overlaps
    double overlap;  ///< m
    double radius;   ///< m
    int64_t a, b;    ///< ball ids (b is a wall id when is_wall)
    bool is_wall;
} sx_overlap;
/// The contact with the deepest overlap relative to its smaller radius, the
/// first in sx_contact_each's order on a tie, passing over the ball-ball
/// contacts whose two ids both lie in [skip_lo, skip_hi] (balls placed
/// together, whose overlaps are theirs to remove). Of a model left
/// scattered (sx_model_scattered), a collective call: each rank scans the
/// contacts of its own balls and every rank compares the ranks' deepest in
/// the serial order, the serial answer. False: the ranks could not exchange.
SX_API bool sx_contact_deepest(const sx_model *m, int64_t skip_lo, int64_t skip_hi, sx_overlap *out);

/* ---------------------------------------------------------------- bonds */

typedef enum sx_bond_kind {
    SX_BOND_CONTACT = 1,   ///< contact bond: normal and shear strengths as forces (4.3.5)
    SX_BOND_PARALLEL = 2,  ///< parallel bond: a cement disk/beam (4-32 ... 4-39)
    SX_BOND_FLATJOINT = 4, ///< flat joint (Potyondy 2012): a face of bonded/unbonded elements; replaces the contact law
    SX_BOND_SMOOTHJOINT = 8, ///< bonded smooth joint (sx_joint_add): a contact across a joint plane, until it breaks
} sx_bond_kind;

/// Bond installation, like PFC's: every ball-ball pair closer than `gap`
/// (of the given materials; with gap 0, touching to 1e-9 of the radii's
/// sum) gets a bond. A parameter left NaN (sx_bond_default_def) takes the
/// mean of the two materials' bond micro-parameters; a value given, 0
/// included, is taken (elements and sectors: 0 is the materials').
typedef struct sx_bond_def {
    sx_bond_kind kind;
    double gap;                 ///< m, install where d - RA - RB < gap (>= 0)
    uint64_t seed;              ///< seed of the per-bond strength draws
    int material_a, material_b; ///< restrict to pairs of these materials (-1: any)
    /* contact bond */
    double normal_strength, normal_strength_sd; ///< N, tensile force to break (mean, std)
    double shear_strength, shear_strength_sd;   ///< N, shear force to break (mean, std)
    /* parallel bond */
    double radius_multiplier;   ///< lambda-bar (4-53), > 0
    double modulus;             ///< Pa, Ec-bar: kn-bar = Ec-bar / (RA + RB) (4-51)
    double stiffness_ratio;     ///< kn-bar / ks-bar (4-52)
    double tensile_strength, tensile_strength_sd; ///< Pa, sigma-bar_c (mean, std)
    double cohesion, cohesion_sd;                 ///< Pa, tau-bar_c (mean, std)
    /* flat joint: the parallel bond's radius_multiplier, modulus, stiffness_ratio,
     * tensile_strength and cohesion (drawn per element) and these */
    double friction_angle;      ///< degrees, phi-bar of a bonded element's shear strength c - sigma tan(phi)
    double friction;            ///< mu of an unbonded or broken element
    double elements;            ///< 2D: elements along the face; 3D: rings (0: 4 in 2D, 2 in 3D)
    double sectors;             ///< 3D: sectors of each ring (0: 4)
    double unbonded_fraction;   ///< probability that an element starts unbonded, in [0, 1]
    double initial_gap;         ///< m, >= 0: the gap of the elements that start unbonded
    bool gapped;                ///< a pair installed apart (surface gap > 0) gets a gapped face: every element
                                ///< unbonded, its gap the pair's (Potyondy 2012's gapped grains)
} sx_bond_def;

/// Every micro-parameter NaN (not given: the mean of the pair's materials'
/// values; a value given, 0 included, is taken), kind parallel, gap 0,
/// seed 1, any materials.
SX_API sx_bond_def sx_bond_default_def(void);
/// Installs bonds; writes the number installed to *count (may be NULL).
/// Refused for Hertz pairs (the seed: Hertz is not to be used with bonds).
SX_API sx_status sx_bond_install(sx_model *m, const sx_bond_def *def, int64_t *count);
/// Number of intact bonds (a pair with both kinds counts once).
SX_API int64_t sx_bond_count(const sx_model *m);

/// The bonded-particle micro-parameters of a material (4.4), used by
/// sx_bond_install where its def leaves a value NaN.
typedef struct sx_bpm_def {
    double radius_multiplier, modulus, stiffness_ratio;
    double tensile_strength, tensile_strength_sd, cohesion, cohesion_sd;
    double normal_strength, normal_strength_sd, shear_strength, shear_strength_sd;
    /* flat joint (see sx_bond_def) */
    double friction_angle, friction, elements, sectors, unbonded_fraction, initial_gap;
} sx_bpm_def;
SX_API sx_status sx_material_set_bpm(sx_model *m, int material, const sx_bpm_def *def);
/// The bond kinds of the registry (src/core/laws/bonds.h): their count, and
/// kind k's name (m:bond's `kind`; its bit into *kind if not NULL), NULL out of range.
SX_API int sx_bond_kind_count(void);
SX_API const char *sx_bond_kind_name(int k, sx_bond_kind *kind);
/// The kinds' micro-parameters, each once (a material's `bond` keys, the
/// files' bond_* columns, m:bond's keys): their count, key i's name (its
/// unit into *unit if not NULL), and its field in an sx_bpm_def and in an
/// sx_bond_def (NULL out of range).
SX_API int sx_bond_key_count(void);
SX_API const char *sx_bond_key(int i, const char **unit);
SX_API double *sx_bond_key_material(sx_bpm_def *d, int i);
SX_API double *sx_bond_key_call(sx_bond_def *d, int i);
SX_API sx_status sx_material_get_bpm(const sx_model *m, int material, sx_bpm_def *out);

typedef enum sx_crack_mode { SX_CRACK_TENSION = 1, SX_CRACK_SHEAR = 2 } sx_crack_mode;

/// A broken bond.
typedef struct sx_crack {
    double time;          ///< s
    int64_t step;
    double pos[3];        ///< m, contact point (4-4)
    sx_crack_mode mode;
    sx_bond_kind kind;    ///< which bond broke
    int64_t a, b;         ///< ball ids
    double fn;            ///< N, normal force at failure (compression positive)
    double fs;            ///< N, shear force magnitude at failure
    double mn;            ///< N m, twisting moment magnitude at failure (parallel bond, 3D)
    double ms;            ///< N m, bending moment magnitude at failure (parallel bond)
    int element;          ///< the flat joint's element that broke (-1: not a flat joint)
} sx_crack;

SX_API int64_t sx_crack_count(const sx_model *m);
/// A model a lazy cycle left scattered (sx_model_scattered), where each
/// rank holds the cracks of its own balls since the last exchange: the
/// ranks' cracks made one log in the serial order on every rank, as a
/// gather makes it (sx_crack_count and sx_crack_get then read the whole
/// log), without the rest of the state. A collective call; SX_OK at once
/// when not scattered; SX_ELOCKED while m is stepping; SX_EINVAL when the
/// ranks could not exchange.
SX_API sx_status sx_model_share_cracks(sx_model *m);
/// The intact bonds, the tension cracks and the shear cracks, into
/// counts[0..2]. Of a decomposed model left scattered
/// (sx_model_scattered), where the crack log and the intact count are each
/// rank's part, a collective call: each rank counts the rows it holds
/// current and the ranks add them. False: out of memory, or the ranks
/// could not exchange.
SX_API bool sx_model_bond_counts(const sx_model *m, int64_t counts[3]);

/// State of a flat-joint element.
typedef enum sx_fj_state {
    SX_FJ_UNBONDED = 0,   ///< installed unbonded: compression and friction only
    SX_FJ_BONDED = 1,
    SX_FJ_TENSION = 2,    ///< broken in tension, now unbonded
    SX_FJ_SHEAR = 3,      ///< broken in shear, now unbonded
} sx_fj_state;

/// A flat-joint element as the last force evaluation left it, in the
/// joint's a -> b orientation (a, b as installed: sx_flatjoint_get).
typedef struct sx_fj_element {
    sx_fj_state state;
    double area;          ///< m^2 (2D: m, unit thickness)
    double centroid[3];   ///< m, its centroid (world)
    double gap;           ///< m, at its centroid (< 0: closed)
    double fn;            ///< N, normal force (compression positive)
    double fs;            ///< N, shear force magnitude
    double tensile_strength, cohesion; ///< Pa, as drawn
} sx_fj_element;

/// The flat joint between balls a and b: its element count (0 when there
/// is none) and, when out is given, element e.
SX_API int sx_flatjoint_get(const sx_model *m, int64_t a, int64_t b, int e, sx_fj_element *out);
/// Makes element e of the flat joint between a and b unbonded (a slit, as
/// PFC's `flatjoint unbond element e`): it keeps its gap and shear force
/// and from now on carries compression and friction only; no crack.
SX_API sx_status sx_flatjoint_unbond(sx_model *m, int64_t a, int64_t b, int e);
SX_API sx_status sx_crack_get(const sx_model *m, int64_t i, sx_crack *out);

/* --------------------------------------------------------- smooth joints */

/// A smooth joint (Mas Ivars et al. 2011; src/core/laws/smoothjoint.h): a
/// plane through the model, or a disk of it (3D; a segment in 2D) about
/// its point, as the fractures of a discrete fracture network are. A
/// contact or bond between two balls whose centre line crosses it takes
/// the smooth-joint law: its normal is the plane's, its shear lies in the
/// plane.
typedef struct sx_joint_def {
    double point[3];          ///< m, a point of the plane
    double normal[3];         ///< its normal (any length > 0; 2D: z ignored)
    double kn, ks;            ///< Pa/m, normal and shear stiffness per unit area (> 0)
    double friction;          ///< mu >= 0
    double dilation;          ///< degrees, psi in [0, 90)
    double tension;           ///< Pa, bond's tensile strength (0 with cohesion 0: unbonded)
    double cohesion;          ///< Pa, bond's shear strength at zero normal stress
    double friction_angle;    ///< degrees, the bond's phi_b in [0, 90): c + sigma_n tan(phi_b)
    double radius_multiplier; ///< lambda > 0: the interface radius is lambda min(RA, RB)
    double radius;            ///< m, the joint's extent about point (a disk; 2D a segment); 0: the whole plane
} sx_joint_def;

/// Plane through the origin with normal +y, kn = ks = 0 (to be given), friction 0.5, no
/// dilation, unbonded, lambda 1, the whole plane (radius 0).
SX_API sx_joint_def sx_joint_default_def(void);
/// Adds a joint (number sx_joint_count - 1 afterwards) and installs it on the
/// pairs it crosses (their centre line crosses the plane, within radius of
/// point when radius > 0): each bond between balls on opposite sides is removed,
/// and a bonded joint takes its place, stress free (*bonds counts them);
/// each other overlapping pair takes the joint's law as an unbonded contact
/// (*contacts counts these). Later contacts across the plane take it as
/// they form (the first joint crossed, in joint order). Bonds installed
/// after a joint are not cut by it.
SX_API sx_status sx_joint_add(sx_model *m, const sx_joint_def *def, int64_t *bonds, int64_t *contacts);
SX_API int64_t sx_joint_count(const sx_model *m);
/// Joint k (0-based) as given (its normal made unit).
SX_API sx_status sx_joint_get(const sx_model *m, int64_t k, sx_joint_def *out);

/* ------------------------------------------------------- periodic space */

/// Periodic space (PFC's periodic space, YADE's periodic cell): a ball that
/// leaves the cell on a periodic axis comes back at the opposite face, and
/// balls near a face touch the images of the balls near the opposite one.
/// The cell is lo + H f with f in [0, 1) on each periodic axis; H is upper
/// triangular: the cell vectors are len[0] e_x, (tilt_xy, len[1]) and, in 3D,
/// (tilt_xz, tilt_yz, len[2]), so a tilted cell is a general parallelepiped
/// (simple shear). A tilt couples two periodic axes only.
typedef struct sx_periodic_def {
    bool axis[3];    ///< the periodic axes (any subset; 2D uses [0..1])
    double lo[3];    ///< m, the cell's corner on the periodic axes
    double len[3];   ///< m, its edge along each periodic axis
    double tilt[3];  ///< m, H's entries xy, xz, yz (0: an orthogonal box)
} sx_periodic_def;

/// Makes the model's space periodic (no axis set: not periodic). Balls
/// outside the cell are brought in at the next build. The cell must be
/// thicker than twice the contact reach (4 radii + 2 skins) across each
/// periodic axis; a thinner one is refused at the build, with the size.
SX_API sx_status sx_model_set_periodic(sx_model *m, const sx_periodic_def *def);
/// The cell as it is now (it deforms under sx_cell_set_control); false and
/// a zeroed def when the space is not periodic.
SX_API bool sx_model_periodic(const sx_model *m, sx_periodic_def *out);

/// Components of the cell's deformation and stress: the normal ones along
/// x, y, z and the shear ones xy, xz, yz (2D: xx, yy, xy).
typedef enum sx_cell_component {
    SX_CELL_XX, SX_CELL_YY, SX_CELL_ZZ, SX_CELL_XY, SX_CELL_XZ, SX_CELL_YZ, SX_CELL_COMPONENTS
} sx_cell_component;

typedef enum sx_cell_mode {
    SX_CELL_FIXED,   ///< the component does not change
    SX_CELL_RATE,    ///< a strain rate: d len_i/dt = rate len_i; shear ij: d tilt_ij/dt = rate len_j
    SX_CELL_STRESS,  ///< a servo on the cell's average stress (PFC's periodic servo)
} sx_cell_mode;

/// How the cell deforms, component by component. A servo'd component moves
/// at rate = alpha (sigma - target) / (K dt) each step, K = (1/V) sum over
/// the contacts of kn l_i^2 (shear: ks l_j^2), the stress the cell gains
/// per unit strain, so that one step removes about a fraction alpha of the
/// error. Compression positive: a normal stress above target makes the
/// cell grow.
typedef struct sx_cell_control {
    sx_cell_mode mode[SX_CELL_COMPONENTS];
    double rate[SX_CELL_COMPONENTS];   ///< 1/s (SX_CELL_RATE)
    double target[SX_CELL_COMPONENTS]; ///< Pa (2D: N/m), compression positive (SX_CELL_STRESS)
    double alpha;                      ///< servo gain fraction, 0 < alpha <= 1 (default 0.5)
    double max_rate;                   ///< 1/s, bound on a servo's strain rate (> 0, default 1)
} sx_cell_control;

SX_API sx_cell_control sx_cell_default_control(void); ///< every component fixed, alpha 0.5, max_rate 1
/// Drives the periodic cell (every axis of the model must be periodic).
/// Images move with the cell: their velocity is the owner's plus the rate
/// of the cell vectors that carry them.
SX_API sx_status sx_cell_set_control(sx_model *m, const sx_cell_control *c);
SX_API sx_status sx_cell_control_get(const sx_model *m, sx_cell_control *c);
/// The cell's average stress from the last step's contacts (Love-Weber
/// over every ball-ball contact, bonds included, branch vectors through the
/// boundary), Pa (2D: N/m), compression positive, and the cell's volume
/// (m^3; 2D: m^2). SX_EINVAL when the space is not periodic on every axis.
/// Of a decomposed model left scattered (sx_model_scattered), a collective
/// call: the ranks' own contacts' terms chained in the serial order.
SX_API sx_status sx_cell_stress(const sx_model *m, double stress[3][3], double *volume);

/* ---------------------------------------------------------- measurement */

typedef enum sx_region_shape { SX_SHAPE_SPHERE, SX_SHAPE_BOX } sx_region_shape;

/// A measurement region (PFC's measurement sphere/circle, or a box).
typedef struct sx_region {
    sx_region_shape shape;
    double centre[3], radius;  ///< sphere (2D: circle)
    double lo[3], hi[3];       ///< box (2D: rectangle)
} sx_region;

typedef struct sx_measurement {
    double stress[3][3];   ///< Pa (2D: N/m), compression positive: -(1/V) sum over balls in the
                           ///< region of their contacts' F (x_c - x); 2D fills [0..1][0..1]
    double volume;         ///< m^3 (2D: m^2) of the region
    double solid;          ///< m^3 (2D: m^2) of the balls inside: each ball's part in the region
    double porosity;       ///< 1 - solid / volume
    double coordination;   ///< ball-ball contacts per ball inside
    double fabric[3][3];   ///< (1/Nc) sum n n over ball-ball contacts of balls inside
    int64_t balls, contacts;
} sx_measurement;

/// Measures inside a region from the last step's contacts.
SX_API sx_status sx_measure(sx_model *m, const sx_region *region, sx_measurement *out);

/* ------------------------------------------------------------- energies */

typedef struct sx_energy {
    double kinetic;        ///< J, translational + rotational
    double gravitational;  ///< J, -sum m g.x (zero at the origin)
    double strain;         ///< J, stored in contact springs
    double bond_strain;    ///< J, stored in parallel bonds
    /* accumulated since tracking was switched on (zero when off) */
    double slip;           ///< J, dissipated by Coulomb slip (and shear springs released when contacts open)
    double local_damping;  ///< J, dissipated by local damping
    double viscous;        ///< J, dissipated by contact dashpots
    double boundary_work;  ///< J, work done on the balls by moving walls and applied loads
    double bond_released;  ///< J, strain energy released by bonds when they broke
} sx_energy;

/// Energies of the current state (computed on demand, O(N + contacts)) and
/// the accumulated terms; every term NaN when the model cannot be prepared
/// (sx_model_error says why: a skin refused, materials that cannot meet,
/// ranks that could not exchange). On a model a lazy cycle left
/// scattered, a collective call (the ranks' sums chained: the serial bits).
SX_API sx_energy sx_model_energy(sx_model *m);
/// Switches tracking of the accumulated terms on (reset to zero) or off.
SX_API void sx_model_track_energy(sx_model *m, bool on);

/* --------------------------------------------------------------- clumps */

/* A clump is a rigid body made of balls ("pebbles", possibly overlapping)
 * that moves as one: its translation by central differences like a ball
 * (4-46, 4-48), its rotation by Euler's equations (4-42) in its principal
 * frame. Its pebbles stay balls for contacts, walls, bonds (between pebbles
 * of different clumps), contact models and queries; pebbles of one clump
 * never touch each other. A pebble's position, velocity and spin follow
 * its clump and cannot be set; it cannot be removed alone. A pebble
 * reports its clump's mass (sx_ball_get SX_BALL_MASS) and smallest
 * principal moment (SX_BALL_INERTIA).
 *
 * A clump is an instance of a template: pebble centres and radii in the
 * template's own frame, placed with a position (of the centroid), an
 * orientation and a scale. Templates are never removed, like materials. */

typedef struct sx_clump_template_def {
    const double *pos;    ///< m, pebble centres in the template frame, dim numbers per pebble
    const double *radius; ///< m, pebble radii (> 0)
    int64_t count;        ///< number of pebbles (>= 1)
    int64_t lines;        ///< lines per axis integrating overlapping pebbles (0: default,
                          ///< 512 in 3D, 65536 in 2D; at least 16); unused without overlaps
} sx_clump_template_def;

/// Mass properties of a template, per unit density at scale 1: mass = density
/// scale^dim volume, inertia = density scale^(dim + 2) inertia.
typedef struct sx_clump_props {
    int64_t count;        ///< pebbles
    bool overlapping;     ///< some pebbles overlap (the union was integrated numerically)
    double volume;        ///< m^3 (2D: m^2 of a unit-thickness slice) of the union of the pebbles
    double centroid[3];   ///< m, in the template frame
    double inertia[3][3]; ///< m^5, about the centroid, template frame (2D: [2][2] = Izz, m^4)
    double principal[3];  ///< principal moments, ascending (2D: [0] = Izz)
    double axes[3][3];    ///< principal axes as the columns of a rotation, in the template frame (2D: identity)
    double error;         ///< estimated relative error of volume, centroid and inertia (0: exact, no overlaps)
} sx_clump_props;

/// Adds a template (names are unique); writes its index (>= 0) to *out if not NULL.
SX_API sx_status sx_clump_template_add(sx_model *m, const char *name, const sx_clump_template_def *def, int *out);
/// Index of the named template, or -1.
SX_API int sx_clump_template_find(const sx_model *m, const char *name);
SX_API int sx_clump_template_count(const sx_model *m);
SX_API const char *sx_clump_template_name(const sx_model *m, int t);
SX_API sx_status sx_clump_template_props(const sx_model *m, int t, sx_clump_props *out);
/// Pebble k of template t: centre (template frame, m) and radius (m).
SX_API sx_status sx_clump_template_pebble(const sx_model *m, int t, int64_t k, double pos[3], double *radius);

typedef struct sx_clump_def {
    int template_index;     ///< a template of the model
    double pos[3];          ///< m, where the centroid goes
    double orientation[4];  ///< unit quaternion (w, x, y, z) turning the template frame into space
                            ///< (normalised on input); 2D: a rotation about z (x = y = 0)
    double scale;           ///< > 0: template lengths are multiplied by it
    double vel[3];          ///< m/s, of the centroid
    double spin[3];         ///< rad/s (2D: spin[0], about z)
    int material;           ///< material of every pebble; its density gives the clump's mass
} sx_clump_def;

/// Template 0, at the origin, identity orientation, scale 1, at rest, material 0.
SX_API sx_clump_def sx_clump_default_def(void);
/// Adds a clump and its pebbles; its stable id (>= 1, its own numbering) is written to *id.
SX_API sx_status sx_clump_add(sx_model *m, const sx_clump_def *def, int64_t *id);
/// Removes a clump and its pebbles (and their contacts and bonds).
SX_API sx_status sx_clump_remove(sx_model *m, int64_t id);
SX_API int64_t sx_clump_count(const sx_model *m);
SX_API int64_t sx_clump_id_at(const sx_model *m, int64_t i);
SX_API bool sx_clump_exists(const sx_model *m, int64_t id);
/// The clump a ball belongs to, 0 for a free ball (or no such ball).
SX_API int64_t sx_ball_clump(const sx_model *m, int64_t ball_id);

typedef enum sx_clump_vec {
    SX_CLUMP_POS,      ///< m, centroid (settable: moves the clump)
    SX_CLUMP_VEL,      ///< m/s (settable)
    SX_CLUMP_SPIN,     ///< rad/s, in space (settable; 2D: [0])
    SX_CLUMP_FORCE,    ///< N: the pebbles' contact and applied forces of the last step
    SX_CLUMP_MOMENT,   ///< N m: their moment about the centroid
    SX_CLUMP_ANGULAR_MOMENTUM, ///< kg m^2/s about the centroid, in space (2D: [0])
} sx_clump_vec;

SX_API sx_status sx_clump_get_vec(const sx_model *m, int64_t id, sx_clump_vec which, double out[3]);
SX_API sx_status sx_clump_set_vec(sx_model *m, int64_t id, sx_clump_vec which, const double v[3]);
/// The orientation as a unit quaternion (w, x, y, z) from the template frame to space.
SX_API sx_status sx_clump_orientation(const sx_model *m, int64_t id, double q[4]);
/// Turns the clump about its centroid (its spin in space is kept).
SX_API sx_status sx_clump_set_orientation(sx_model *m, int64_t id, const double q[4]);

typedef enum sx_clump_scalar {
    SX_CLUMP_MASS,    ///< kg
    SX_CLUMP_VOLUME,  ///< m^3 (2D: m^2)
    SX_CLUMP_SCALE,   ///< of its template
    SX_CLUMP_DAMPING, ///< local damping alpha (settable)
} sx_clump_scalar;

SX_API sx_status sx_clump_get(const sx_model *m, int64_t id, sx_clump_scalar which, double *out);
SX_API sx_status sx_clump_set(sx_model *m, int64_t id, sx_clump_scalar which, double value);
/// Principal moments (kg m^2, ascending; 2D: [0] = Izz) and the inertia tensor
/// about the centroid in space axes (2D: [2][2]); either may be NULL.
SX_API sx_status sx_clump_inertia(const sx_model *m, int64_t id, double principal[3], double tensor[3][3]);
SX_API sx_status sx_clump_template_of(const sx_model *m, int64_t id, int *t);
/// Writes up to cap pebble ids (in template order) and their number to *count.
SX_API sx_status sx_clump_pebbles(const sx_model *m, int64_t id, int64_t *ids, int64_t cap, int64_t *count);
/// Material of the clump (its pebbles may have others of the same density).
SX_API sx_status sx_clump_material(const sx_model *m, int64_t id, int *material);
/// Gives the clump and every pebble the material; mass and inertia follow its density.
SX_API sx_status sx_clump_set_material(sx_model *m, int64_t id, int material);
/// Fixities of the body (SX_FIX_*, space axes). In 3D the spin is fixed as a
/// whole (SX_FIX_SPIN or none): a spin imposed on some axes only would need a
/// constraint torque Euler's equations do not give.
SX_API sx_status sx_clump_fixity(const sx_model *m, int64_t id, unsigned *mask);
SX_API sx_status sx_clump_set_fixity(sx_model *m, int64_t id, unsigned mask);
