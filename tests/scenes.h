/* Scene builders shared by tests, examples and benchmarks. */
#pragma once

#include "seixo.h"

/// A model with one material "m" (linear, kn = ks = k, friction mu, density rho) and
/// the given gravity (m/s^2, may be NULL); aborts the test on failure.
sx_model *scene_model(int dim, const double *gravity, double dt, double k, double mu, double rho);
/// Index of the scene's single material.
int scene_material(sx_model *m);
/// Adds a ball and returns its id (aborts the test on failure).
int64_t scene_ball(sx_model *m, const double *pos, const double *vel, double radius);

/// Adds a ball of the given material (index) and returns its id (aborts the test on failure).
int64_t scene_ball_of(sx_model *m, int material, const double *pos, const double *vel, double radius);
/// Imposes a velocity and a spin on a ball and fixes all its components (vel/spin may be NULL: zero).
void scene_impose(sx_model *m, int64_t id, const double *vel, const double *spin);
