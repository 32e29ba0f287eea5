/* Scenes and helpers shared by the I/O tests: models that exercise every
 * piece of state a restart must carry (walls of every kind, moving walls,
 * friction, dashpots, bonds that break, applied loads, fixities, groups,
 * removed balls, energy tracking). */
#pragma once

#include "scenes.h"
#include "seixo_io.h"

#include <check.h>
#include <hdf5.h>
#include <stdint.h>

#define io_cycle(m, n) \
    ck_assert_msg(sx_model_cycle((m), (n)) == SX_OK, "cycle failed: %s", sx_model_error(m))

/// Balls settling under gravity in a box whose lid moves down, with two
/// materials, a finite wall (3D rect / 2D segment) as an obstacle, an
/// applied force, fixities, groups, a removed ball and energy tracking.
sx_model *io_scene_granular(int dim, int nballs);
/// A bonded lattice (parallel and contact bonds) pulled apart by its top
/// layer while a wall presses on its side: bonds break, cracks are logged.
sx_model *io_scene_bonded(int dim);
/// The same lattice joined by flat joints (a fifth of their elements slit and gapped).
sx_model *io_scene_flatjoint(int dim);
/// Hertz-Mindlin balls dropped on a floor with a fixed user timestep.
sx_model *io_scene_hertz(int dim);
/// A specimen squeezed by servo-controlled walls: 3D, a cylinder of finite
/// height whose radius is servo-controlled, a fixed bottom platen and a
/// servo-controlled top one; 2D, four lines of which two are servo-controlled.
/// The walls start touching the balls, so the servos act from the first step.
sx_model *io_scene_servo(int dim);

/// A fresh temporary folder (removed with io_rmdir); the path is static storage.
const char *io_tmpdir(void);
/// path = dir + "/" + name into out.
const char *io_path(char *out, size_t len, const char *name);
/// Removes the folder made by io_tmpdir and everything in it.
void io_rmdir(void);

/// Saves m to path (asserts success).
void io_save(const sx_model *m, const char *path);
/// Loads path (asserts success).
sx_model *io_load(const char *path, int dim);
/// Removes dataset d's seixo checksum, as one who edits a file on purpose
/// does (the loader would otherwise refuse the edit as damage), so that
/// only the loader's checks of the values can catch what a test writes.
void io_drop_checksum(hid_t d);
/// No HDF5 object (file, group, dataset, ...) is left open.
void io_assert_no_handles(void);
/// Energies equal to the bit.
void io_assert_same_energy(sx_model *a, sx_model *b);
/// Same crack log, bond and contact counts, walls' definitions, forces and
/// servo loads (bits).
void io_assert_same_extras(const sx_model *a, const sx_model *b);

/// Loads the committed sample dir/formatN.h5 of file format `version`
/// (asserts success) and checks what its provenance says: that version,
/// seixo 0.1.0, written by tests/io/make_formatN.c; info is the caller's to free.
sx_model *io_load_sample(const char *dir, int version, sx_snapshot_info *info);
/// The first ball-ball contact of m in the core's order into *ci (asserts one exists).
void io_first_ball_contact(const sx_model *m, sx_contact_info *ci);
/// main() of a program of one Check test named name: 0 when it passes.
int io_run_test(const char *name, const TTest *test);
/// main() of a program of a suite: runs it with a fresh temporary folder
/// (io_tmpdir, removed at the end); 0 when every test passes.
int io_run_suite(Suite *s);
/// main() of a sample writer (`prog out.h5`, run once to make a committed
/// file of an old format): *out_path = argv[1], then the writer test runs
/// in this process; 2 on a bad command line, 1 when the writer fails.
int io_run_writer(int argc, char **argv, const char *name, const TTest *writer, const char **out_path);
