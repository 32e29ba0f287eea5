/* Scene builders shared by tests, examples and benchmarks. */
#pragma once

#include "seixo.h"

struct Suite; /* Check's */

/// Runs every test of the Check suite s; the program's exit status
/// (EXIT_FAILURE when a test failed).
int scene_run_suite(struct Suite *s);

/// A model with one material "m" (linear, kn = ks = k, friction mu, density rho) and
/// the given gravity (m/s^2, may be NULL); aborts the test on failure.
sx_model *scene_model(int dim, const double *gravity, double dt, double k, double mu, double rho);
/// Index of the scene's single material.
int scene_material(sx_model *m);
/// Adds a ball and returns its id (aborts the test on failure).
int64_t scene_ball(sx_model *m, const double *pos, const double *vel, double radius);

/* ---- random assemblies (deterministic, seeded) ---- */

/// splitmix64: the next 64-bit value of the generator whose state is *s.
uint64_t scene_rng_u64(uint64_t *s);
/// A uniform double in [lo, hi) from the generator *s.
double scene_rng_uniform(uint64_t *s, double lo, double hi);
/// Walls enclosing the axis-aligned box [lo, hi] (2D: four lines, 3D: six
/// planes), normals pointing inwards, stiffness k (kn = ks) and friction mu.
void scene_box_walls(sx_model *m, const double *lo, const double *hi, double k, double mu);
/// Adds n balls with radii uniform in [rmin, rmax], centres uniform in the box
/// [lo + r, hi - r] and velocity components uniform in [-vmax, vmax]. A
/// candidate that would overlap an earlier ball by more than max_overlap times
/// the smaller radius is drawn again (O(n^2), for test-sized scenes). Writes
/// the ids to ids if not NULL; aborts the test if the box is too crowded.
void scene_random_balls(sx_model *m, int64_t n, const double *lo, const double *hi, double rmin, double rmax,
                        double vmax, double max_overlap, uint64_t seed, int64_t *ids);

/// Adds (or redefines) a named material from a full definition and returns its index.
int scene_material_def(sx_model *m, const char *name, const sx_material_def *def);
/// Adds a ball of the given material with a velocity and spin (either may be NULL) and returns its id.
int64_t scene_ball_full(sx_model *m, const double *pos, const double *vel, const double *spin, double radius,
                        int material);
/// Adds a one-sided infinite wall (3D plane, 2D line) through point with the given normal
/// (towards the balls) and stiffnesses/friction; returns its id.
int64_t scene_halfspace(sx_model *m, const double *point, const double *normal, double kn, double ks, double mu);

/// Adds a ball of the given material (index) and returns its id (aborts the test on failure).
int64_t scene_ball_of(sx_model *m, int material, const double *pos, const double *vel, double radius);
/// Imposes a velocity and a spin on a ball and fixes all its components (vel/spin may be NULL: zero).
void scene_impose(sx_model *m, int64_t id, const double *vel, const double *spin);
