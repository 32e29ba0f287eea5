/* Private declarations shared by the files of m:generate: generate.c (the
 * arguments, the bodies added, their relaxation, the binding), sizes.c
 * (the RNG, the sizes and their distributions) and placement.c (where the
 * bodies go).
 *
 * Every working array is a Lua userdata on the stack: an error anywhere
 * frees them. */
#pragma once

#include "bindings.h"

enum { MAX_GENERATE = 10000000 };

/// The state of the xoshiro256** generator (sizes.c).
typedef struct rng {
    uint64_t s[4];
} rng;

enum { M_RANDOM, M_DISTRIBUTE, M_EXPAND, M_LATTICE };
enum { P_SQUARE, P_HEX, P_CUBIC, P_FCC };
enum { D_UNIFORM, D_NORMAL, D_LOGNORMAL, D_PSD };
enum { MAX_PSD = 100 };

/// The arguments of one m:generate call, as read and checked (generate.c).
typedef struct gen {
    int dim, method, packing, dist, material;
    int tpl;        /* clump template, -1 for balls */
    double unit;    /* volume of a body of size 1 over a ball's of radius 1 (1 for balls) */
    int32_t group;
    int64_t count, tries;
    bool has_count, has_porosity;
    double porosity, rmin, rmax, mean, std;
    double log_mean, log_std; /* lognormal: of ln r */
    int psd_points;
    double psd_r[MAX_PSD];    /* the grading curve's radii, increasing */
    double psd_count[MAX_PSD]; /* the fraction of the balls' count up to each (by count, not volume) */
    sx_lua_region region;
    uint64_t seed;
    bool relax;
    int64_t relax_steps, calm;
    double relax_ratio;
} gen;

static inline double ball_volume(int dim, double r) { return dim == 3 ? 4.0 / 3.0 * SX_LUA_PI * r * r * r : SX_LUA_PI * r * r; }

/* The volume of a generated body of size r: a ball of radius r, or a clump at scale r. */
static inline double body_volume(const gen *g, double r) { return g->unit * ball_volume(g->dim, r); }

/* ----------------------------------------------------------- sizes.c */

/// Seeds r through splitmix64: the same seed, the same draws on every run.
void sx_lua_rng_seed(rng *r, uint64_t seed);
/// A draw uniform in [0, 1).
double sx_lua_rng_uniform(rng *r);
/// Reads the sizes of the argument table at 2 into g: `radius` (balls) or
/// `scale` (clumps, g->tpl >= 0) with `distribution`, `mean` and `std`, or
/// a grading curve `psd`; warns of sizes outside the usual range.
void sx_lua_read_sizes(lua_State *L, gen *g);
/// Draws the radii: g->count of them, or as many as the porosity takes
/// (setting g->count); scaled to the porosity when both are given (g->rmin
/// and g->rmax scaled too). Pushes their storage.
double *sx_lua_draw_radii(lua_State *L, gen *g, rng *r);

/* ------------------------------------------------------- placement.c */

/// Methods random and expand: places n balls of radii rad (sorted, largest
/// first) without overlaps among them and with the model's balls; writes
/// the centres to x (3 per ball). Pushes the grid's storage.
void sx_lua_place_random(lua_State *L, sx_lua_run *run, const sx_model *m, const gen *g, rng *r, const double *rad,
                         int64_t n, double *x);
/// Method distribute: centres at random with overlaps, pushed apart until
/// none exceeds a hundredth of the smaller radius; an error when they stay
/// above 0.9 of it, or when a ball lies over one of the model's beyond
/// `limit` (seixo.model{overlap_limit}). Writes the centres to x.
void sx_lua_place_distributed(lua_State *L, sx_lua_run *run, const gen *g, rng *r, const double *rad, int64_t n,
                              double *x, double limit);
/// Method lattice: the sites of g->packing in the region (the first
/// g->count, an error if fewer fit) into a pushed array of centres (3 per
/// site); their number in *count.
double *sx_lua_lattice_sites(lua_State *L, const gen *g, int64_t *count);
/// Clumps: places n clumps of template g->tpl at scales s (sorted, largest
/// first), each at a random centroid and orientation where all its pebbles
/// lie in the region without overlapping one another's or the model's
/// balls; writes centroids to x (3 per clump) and orientations to q (4 per
/// clump). Pushes the grid's storage.
void sx_lua_place_clumps(lua_State *L, const sx_model *m, const gen *g, rng *r, const double *s, int64_t n, double *x,
                         double *q);
