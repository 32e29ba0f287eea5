/* Ball store: a structure of arrays indexed densely, with stable ids mapped
 * to dense indices. Removal fills the holes with the last balls and patches
 * the candidate pairs in one pass over the pair store, however many balls
 * go, so contact history survives deletions and removing k balls costs
 * O(N + pairs), not O(k x pairs). */
#include "model_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Grows s->field from s->cap to cap elements of `per` components. */
#define RESIZE(s, field, per)                                                              \
    do {                                                                                   \
        void *q = sx_alloc_resize(&m->alloc, (s)->field, (size_t)((s)->cap * (per)),       \
                                  (size_t)(cap * (per)), sizeof *(s)->field);              \
        if (!q) return SX_ENOMEM;                                                          \
        (s)->field = q;                                                                    \
    } while (0)

static sx_status balls_resize(sx_model *m, int64_t cap);
static sx_status grow_index(sx_model *m, int64_t need);

sx_status sx__balls_reserve(sx_model *m, int64_t cap)
{
    sx_balls *b = &m->balls;
    if (cap <= b->cap) return SX_OK;
    if (cap < 2 * b->cap) cap = 2 * b->cap;
    if (cap < 64) cap = 64;
    return balls_resize(m, cap);
}

sx_status sx_ball_reserve(sx_model *m, int64_t count)
{
    if (count < 0 || count > INT32_MAX / 4)
        return sx__fail(m, SX_EINVAL, "ball_reserve: count must be in 0..%d (got %lld)", INT32_MAX / 4,
                        (long long)count);
    const int64_t need = m->balls.n + count;
    if ((need > m->balls.cap && balls_resize(m, need)) || grow_index(m, m->balls.next_id + count + 1))
        return sx__fail(m, SX_ENOMEM, "ball_reserve: out of memory for %lld balls", (long long)need);
    return SX_OK;
}

int sx__ball_fields(const sx_model *m, sx_balls *b, sx_ball_field *f)
{
    const int d = m->dim, r = m->rdim;
    int n = 0;
    f[n++] = (sx_ball_field){(void **)&b->x, d, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->v, d, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->w, r, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->f, d, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->t, r, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->x_build, d, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->rad, 1, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->inv_mass, 1, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->inv_inertia, 1, SX_FIELD_F64, true};
    f[n++] = (sx_ball_field){(void **)&b->id, 1, SX_FIELD_I32, true};
    f[n++] = (sx_ball_field){(void **)&b->mat, 1, SX_FIELD_U16, true};
    f[n++] = (sx_ball_field){(void **)&b->fix, 1, SX_FIELD_U8, true};
    if (b->alpha) f[n++] = (sx_ball_field){(void **)&b->alpha, 1, SX_FIELD_F64, true};
    if (b->group) f[n++] = (sx_ball_field){(void **)&b->group, 1, SX_FIELD_I32, true};
    if (b->clump) f[n++] = (sx_ball_field){(void **)&b->clump, 1, SX_FIELD_I32, true};
    if (b->fapp) {
        f[n++] = (sx_ball_field){(void **)&b->fapp, d, SX_FIELD_F64, false};
        f[n++] = (sx_ball_field){(void **)&b->tapp, r, SX_FIELD_F64, false};
    }
    if (b->unwrap) f[n++] = (sx_ball_field){(void **)&b->unwrap, d, SX_FIELD_F64, false};
    return n;
}

/* Resizes every per-ball array to exactly cap balls. */
static sx_status balls_resize(sx_model *m, int64_t cap)
{
    sx_balls *b = &m->balls;
    if (cap > INT32_MAX / 4) return SX_ENOMEM;
    sx_ball_field f[SX_BALL_FIELDS_MAX];
    const int nf = sx__ball_fields(m, b, f);
    for (int k = 0; k < nf; k++)
        if (!sx__field_resize(&m->alloc, f[k].data, f[k].per, f[k].type, b->cap, cap)) return SX_ENOMEM;
    b->cap = cap;
    return SX_OK;
}

static void free_field(sx_model *m, void *p, int64_t n, size_t size)
{
    sx_alloc_free(&m->alloc, p, (size_t)n, size);
}

void sx__balls_free(sx_model *m)
{
    sx_balls *b = &m->balls;
    sx_ball_field f[SX_BALL_FIELDS_MAX];
    const int nf = sx__ball_fields(m, b, f);
    for (int k = 0; k < nf; k++) free_field(m, *f[k].data, b->cap * f[k].per, sx__field_size(f[k].type));
    free_field(m, b->index_of, b->index_cap, sizeof(int32_t));
    memset(b, 0, sizeof *b);
}

/* 4-43 and its 2D analogue: sphere I = 2/5 m R^2, disk of unit thickness I = 1/2 m R^2. */
/* A radius the ball's mass and inertia can follow: both positive and
 * finite (1e300 m would make them infinite, 1e-200 m zero). */
static bool radius_ok(const sx_model *m, double r, int mat)
{
    if (!(r > 0) || !isfinite(r)) return false;
    const double rho = m->mats[mat].def.density;
    const double mass = sx__ball_volume(m->dim, r) * rho;
    const double inertia = mass * r * r;
    return mass > 0 && isfinite(mass) && inertia > 0 && isfinite(inertia) && isfinite(1 / inertia);
}

void sx__ball_update_mass(sx_model *m, int64_t i)
{
    sx_balls *b = &m->balls;
    if (b->clump && b->clump[i]) return; /* a pebble carries its clump's mass (clumps.c) */
    const double r = b->rad[i], rho = m->mats[b->mat[i]].def.density;
    const double mass = sx__ball_volume(m->dim, r) * rho;
    const double inertia = (m->dim == 3 ? 0.4 : 0.5) * mass * r * r; /* a solid sphere's, a disk's */
    b->inv_mass[i] = 1.0 / mass;
    b->inv_inertia[i] = 1.0 / inertia;
}

int64_t sx__ball_index(const sx_model *m, int64_t id)
{
    const sx_balls *b = &m->balls;
    if (id < 1 || id >= b->next_id) return -1;
    return b->index_of[id];
}

/* A pebble's motion, size and mass are its clump's (clumps.c): refused with a message. */
static bool pebble(sx_model *m, int64_t i, const char *fn, const char *what)
{
    if (!m->balls.clump || !m->balls.clump[i]) return false;
    sx__fail(m, SX_EINVAL, "%s: ball %lld is a pebble of clump %lld, which owns its %s", fn,
             (long long)m->balls.id[i], (long long)m->balls.clump[i], what);
    return true;
}

static sx_status grow_index(sx_model *m, int64_t need)
{
    sx_balls *b = &m->balls;
    return sx_alloc_reserve_index(&m->alloc, &b->index_of, &b->index_cap, need) ? SX_OK : SX_ENOMEM;
}

/* Finite and below 1e100 in magnitude: the step squares differences of
 * positions and velocities, which a finite 1e300 would overflow into a
 * NaN force (the fuzz harness found one). */
static bool finite_vec(const double *v, int n)
{
    for (int k = 0; k < n; k++)
        if (!(fabs(v[k]) < 1e100)) return false;
    return true;
}

sx_status sx_ball_add(sx_model *m, const sx_ball_def *def, int64_t *out_id)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    if (m->locked) return sx__fail(m, SX_ELOCKED, "ball_add: the model is stepping; add balls between cycles");
    if (!(def->radius > 0) || !isfinite(def->radius))
        return sx__fail(m, SX_EINVAL, "ball_add: radius must be a positive finite number (got %g)", def->radius);
    if (def->material < 0 || def->material >= m->nmat)
        return sx__fail(m, SX_ENOTFOUND, "ball_add: no material with index %d (define one with material first)",
                        def->material);
    if (!radius_ok(m, def->radius, def->material))
        return sx__fail(m, SX_EINVAL, "ball_add: a radius of %g m gives a mass or inertia of 0 or infinity", def->radius);
    const int d = m->dim, r = m->rdim;
    if (!finite_vec(def->pos, d) || !finite_vec(def->vel, d) || !finite_vec(def->spin, r))
        return sx__fail(m, SX_EINVAL, "ball_add: position, velocity and spin must be finite, below 1e100");
    sx_balls *b = &m->balls;
    if (b->next_id < 1) b->next_id = 1;
    if (b->next_id >= INT32_MAX) return sx__fail(m, SX_ENOMEM, "ball_add: ball ids exhausted");
    const int64_t ghosts = m->cell ? m->cell->n : 0; /* periodic space: the ghosts' slots follow the balls */
    if (sx__balls_reserve(m, b->n + 1 + ghosts) || grow_index(m, b->next_id + 1))
        return sx__fail(m, SX_ENOMEM, "ball_add: out of memory at %lld balls", (long long)b->n);
    if (m->cell) sx__cell_ghosts_move(m, b->n + 1, true);
    const int64_t i = b->n++;
    const int64_t id = b->next_id++;
    for (int k = 0; k < d; k++) {
        b->x[i * d + k] = def->pos[k];
        b->v[i * d + k] = def->vel[k];
        b->f[i * d + k] = 0;
        b->x_build[i * d + k] = def->pos[k];
    }
    /* 2D: the scalar spin is about z; accept it in spin[0] (documented) */
    for (int k = 0; k < r; k++) {
        b->w[i * r + k] = def->spin[k];
        b->t[i * r + k] = 0;
    }
    if (b->fapp) {
        for (int k = 0; k < d; k++) b->fapp[i * d + k] = 0;
        for (int k = 0; k < r; k++) b->tapp[i * r + k] = 0;
    }
    sx__ball_placed(m, i);
    b->rad[i] = def->radius;
    b->mat[i] = (uint16_t)def->material;
    if (b->alpha) b->alpha[i] = m->mats[def->material].def.damping;
    b->fix[i] = 0;
    if (b->group) b->group[i] = 0;
    if (b->clump) b->clump[i] = 0;
    b->id[i] = (int32_t)id;
    b->index_of[id] = (int32_t)i;
    sx__ball_update_mass(m, i);
    m->build_needed = true;
    m->dt_stale = true;
    if (out_id) *out_id = id;
    return SX_OK;
}

/* Moves ball `from` into slot `to` (all per-ball fields). */
static void move_ball(sx_model *m, int64_t to, int64_t from)
{
    sx_balls *b = &m->balls;
    sx_ball_field f[SX_BALL_FIELDS_MAX];
    const int nf = sx__ball_fields(m, b, f);
    for (int k = 0; k < nf; k++) {
        const size_t row = sx__ball_row(&f[k]);
        memcpy((char *)*f[k].data + (size_t)to * row, (char *)*f[k].data + (size_t)from * row, row);
    }
    b->index_of[b->id[to]] = (int32_t)to;
}

/* Drops the pairs that have a removed ball (remap < 0; their bonds break)
 * and renames the ends of the rest to the balls' new indices. Ball-ball
 * pairs keep a < b by swapping the ends (and flipping the history's sign,
 * which is expressed relative to a -> b). */
static void patch_pairs_after_remove(sx_model *m, const int32_t *remap)
{
    sx_pairs *p = &m->bb;
    int64_t k = 0;
    for (int64_t c = 0; c < p->n; c++) {
        const int32_t a = remap[p->a[c]], bb = remap[p->b[c]];
        if (a < 0 || bb < 0) {
            if (p->bond && p->bond[c])
                sx__bond_break(m, p->bond[c] - 1, SX_BOND_CONTACT | SX_BOND_PARALLEL | SX_BOND_FLATJOINT | SX_BOND_SMOOTHJOINT);
            continue;
        }
        sx__pair_move(m, p, k, c);
        p->a[k] = a;
        p->b[k] = bb;
        if (a > bb) sx__pair_flip(m, p, k);
        k++;
    }
    p->n = k;
    p = &m->bw;
    k = 0;
    for (int64_t c = 0; c < p->n; c++) {
        const int32_t a = remap[p->a[c]];
        if (a < 0) continue;
        sx__pair_move(m, p, k, c);
        p->a[k] = a;
        k++;
    }
    p->n = k;
}

sx_status sx_ball_remove_many(sx_model *m, const int64_t *ids, int64_t n)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    if (m->locked) return sx__fail(m, SX_ELOCKED, "ball_remove: the model is stepping");
    if (n < 0) return sx__fail(m, SX_EINVAL, "ball_remove: the number of ids must be >= 0 (got %lld)", (long long)n);
    sx_balls *b = &m->balls;
    const int64_t nb = b->n;
    for (int64_t j = 0; j < n; j++) {
        const int64_t i = sx__ball_index(m, ids[j]);
        if (i < 0) return sx__fail(m, SX_ENOTFOUND, "ball_remove: no ball with id %lld", (long long)ids[j]);
        if (pebble(m, i, "ball_remove", "pebbles (remove the clump)")) return SX_EINVAL;
    }
    if (n == 0) return SX_OK;
    /* remap: old dense index -> new one, -1 for a removed ball */
    /* periodic space: the ghosts' slots (past the balls) are renamed too */
    const int64_t nr = nb + (m->cell ? m->cell->n : 0);
    int32_t *remap = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)nr, sizeof *remap);
    if (!remap) return sx__fail(m, SX_ENOMEM, "ball_remove: out of memory for %lld balls", (long long)nb);
    for (int64_t i = 0; i < nb; i++) remap[i] = (int32_t)i;
    int64_t gone = 0;
    for (int64_t j = 0; j < n; j++) {
        const int64_t i = sx__ball_index(m, ids[j]);
        if (remap[i] < 0) continue; /* listed twice */
        remap[i] = -1;
        gone++;
    }
    /* the holes below the new count take the survivors above it, both in
     * index order; so one removal moves the last ball into its hole */
    const int64_t keep = nb - gone;
    int64_t from = keep;
    for (int64_t i = 0; i < keep; i++) {
        if (remap[i] >= 0) continue;
        while (remap[from] < 0) from++;
        remap[from++] = (int32_t)i;
    }
    if (m->cell) sx__cell_ghosts_remap(m, remap, keep);
    patch_pairs_after_remove(m, remap);
    for (int64_t i = 0; i < nb; i++)
        if (remap[i] < 0) b->index_of[b->id[i]] = -1;
    for (int64_t i = keep; i < nb; i++)
        if (remap[i] >= 0) move_ball(m, remap[i], i);
    b->n = keep;
    if (m->cell) sx__cell_ghosts_move(m, keep, false);
    sx_alloc_free(&m->alloc, remap, (size_t)nr, sizeof *remap);
    m->build_needed = true;
    m->dt_stale = true;
    return SX_OK;
}

sx_status sx_ball_remove(sx_model *m, int64_t id) { return sx_ball_remove_many(m, &id, 1); }

/* to[i] = from[order[i]], rows of `row` bytes: a build permutes every
 * field, so the usual sizes get a copy of constant size (one move; a
 * memcpy call per element would cost more than the copy). */
static void gather_rows(void *to, const void *from, const int32_t *order, int64_t n, size_t row)
{
    char *t = to;
    const char *s = from;
#define ROWS(size)                                                                                         \
    for (int64_t i = 0; i < n; i++) memcpy(t + (size_t)i * (size), s + (size_t)order[i] * (size), (size)); \
    break;
    switch (row) {
    case 1: ROWS(1)
    case 2: ROWS(2)
    case 4: ROWS(4)
    case 8: ROWS(8)
    case 16: ROWS(16)
    case 24: ROWS(24)
    default: ROWS(row)
    }
#undef ROWS
}

void sx__balls_permute(sx_model *m, const int32_t *order, double *scratch)
{
    sx_balls *b = &m->balls;
    const int64_t n = b->n;
    sx_ball_field f[SX_BALL_FIELDS_MAX];
    const int nf = sx__ball_fields(m, b, f);
    /* scratch holds n rows of the widest field (dim doubles) */
    for (int k = 0; k < nf; k++) {
        const size_t row = sx__ball_row(&f[k]);
        gather_rows(scratch, *f[k].data, order, n, row);
        memcpy(*f[k].data, scratch, (size_t)n * row);
    }
    for (int64_t i = 0; i < n; i++) b->index_of[b->id[i]] = (int32_t)i;
}

int sx__pair_fields(const sx_model *m, sx_pairs *p, sx_pair_field *f)
{
    const int d = m->dim;
    const bool walls = p == &m->bw;
    int n = 0;
    f[n++] = (sx_pair_field){(void **)&p->a, 1, SX_FIELD_I32, false, true, "a", NULL};
    f[n++] = (sx_pair_field){(void **)&p->b, 1, SX_FIELD_I32, false, true, "b", NULL};
    f[n++] = (sx_pair_field){(void **)&p->fs, d, SX_FIELD_F64, true, false, "shear_force", "N"};
    /* the last evaluation's geometry: a ball-wall pair's normal, a ball-ball pair's relative position */
    f[n++] = walls ? (sx_pair_field){(void **)&p->geo, d, SX_FIELD_F64, true, false, "normal", "1"}
                   : (sx_pair_field){(void **)&p->geo, d, SX_FIELD_F64, true, false, "relative_position", "m"};
    if (walls) f[n++] = (sx_pair_field){(void **)&p->un, 1, SX_FIELD_F64, false, false, "overlap", "m"};
    f[n++] = (sx_pair_field){(void **)&p->touching, 1, SX_FIELD_U8, false, false, "touching", NULL};
    f[n++] = (sx_pair_field){(void **)&p->fn, 1, SX_FIELD_F64, false, false, "normal_force", "N"};
    if (p->bond) f[n++] = (sx_pair_field){(void **)&p->bond, 1, SX_FIELD_I32, false, false, "bond", NULL};
    if (p->mr) f[n++] = (sx_pair_field){(void **)&p->mr, m->rdim, SX_FIELD_F64, true, false, "rolling_moment", "N m"};
    if (p->us)
        f[n++] = (sx_pair_field){(void **)&p->us, d, SX_FIELD_F64, true, false, "shear_displacement", "m"};
    if (p->cmodel) f[n++] = (sx_pair_field){(void **)&p->cmodel, 1, SX_FIELD_I32, false, false, "contact_model", NULL};
    if (!walls && p->joint) { /* smooth joints (laws/smoothjoint.h) */
        f[n++] = (sx_pair_field){(void **)&p->joint, 1, SX_FIELD_I32, false, false, "joint", NULL};
        f[n++] = (sx_pair_field){(void **)&p->jnormal, d, SX_FIELD_F64, true, false, "joint_normal", "1"};
        f[n++] = (sx_pair_field){(void **)&p->jun, 1, SX_FIELD_F64, false, false, "joint_overlap", "m"};
    }
    /* a mesh's facet is a third end of a ball-wall pair: listed by the broad phase */
    if (walls && m->mesh_pairs) f[n++] = (sx_pair_field){(void **)&p->facet, 1, SX_FIELD_I32, false, true, "facet", NULL};
    return n;
}

sx_status sx__pairs_expand(sx_model *m, size_t field, int per)
{
    sx_pairs *ps[2] = {&m->bb, &m->bw};
    for (int s = 0; s < 2; s++) {
        double **data = (double **)((char *)ps[s] + field);
        if (*data) continue;
        if (sx__pairs_reserve(m, ps[s], 1)) return SX_ENOMEM; /* a store with room, so the array exists */
        *data = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(ps[s]->cap * per), sizeof **data);
        if (!*data) return SX_ENOMEM;
    }
    return SX_OK;
}

/* Resizes every array of the pair store to exactly cap pairs. */
static sx_status pairs_resize(sx_model *m, sx_pairs *p, int64_t cap)
{
    if (cap > INT32_MAX) return SX_ENOMEM;
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    for (int k = 0; k < nf; k++)
        if (!sx__field_resize(&m->alloc, f[k].data, f[k].per, f[k].type, p->cap, cap)) return SX_ENOMEM;
    p->cap = cap;
    return SX_OK;
}

sx_status sx__pairs_reserve(sx_model *m, sx_pairs *p, int64_t cap)
{
    if (cap <= p->cap) return SX_OK;
    if (cap < p->cap + p->cap / 2) cap = p->cap + p->cap / 2;
    if (cap < 256) cap = 256;
    return pairs_resize(m, p, cap);
}

void sx__pair_move(sx_model *m, sx_pairs *p, int64_t to, int64_t from)
{
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    for (int k = 0; k < nf; k++) {
        const size_t row = (size_t)f[k].per * sx__pair_size(&f[k]);
        char *data = *f[k].data;
        memmove(data + (size_t)to * row, data + (size_t)from * row, row);
    }
}

void sx__pair_flip(sx_model *m, sx_pairs *p, int64_t k)
{
    const int32_t a = p->a[k];
    p->a[k] = p->b[k];
    p->b[k] = a;
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    for (int q = 0; q < nf; q++) /* the shear force, the relative position and the normal alike */
        for (int j = 0; f[q].sign && j < f[q].per; j++) ((double *)*f[q].data)[k * f[q].per + j] *= -1;
    if (p->bond && p->bond[k]) sx__bond_flip(m, p->bond[k] - 1);
}

bool sx__pairs_sort(sx_model *m, sx_pairs *p)
{
    int64_t c = 1;
    while (c < p->n && p->a[c - 1] <= p->a[c]) c++;
    if (c >= p->n) return true;
    const int64_t n = p->n, nb = m->balls.n;
    /* counting sort: pos[c] is the new place of pair c */
    int32_t *pos = malloc((size_t)n * sizeof *pos);
    int64_t *count = calloc((size_t)nb + 1, sizeof *count);
    void *tmp = malloc((size_t)(n * m->dim) * sizeof(double)); /* the widest field */
    if (!pos || !count || !tmp) {
        free(pos);
        free(count);
        free(tmp);
        return false;
    }
    for (c = 0; c < n; c++) count[p->a[c] + 1]++;
    for (int64_t i = 0; i < nb; i++) count[i + 1] += count[i];
    for (c = 0; c < n; c++) pos[c] = (int32_t)count[p->a[c]]++;
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    for (int k = 0; k < nf; k++) {
        const size_t row = (size_t)f[k].per * sx__pair_size(&f[k]);
        char *data = *f[k].data, *q = tmp;
        for (int64_t e = 0; e < n; e++) memcpy(q + (size_t)pos[e] * row, data + (size_t)e * row, row);
        memcpy(data, q, (size_t)n * row);
    }
    const bool ok = sx__dd_sources_sort(m, p == &m->bw, pos, n);
    free(pos);
    free(count);
    free(tmp);
    return ok;
}

void sx__pairs_free(sx_model *m, sx_pairs *p)
{
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, p, f);
    for (int k = 0; k < nf; k++)
        free_field(m, *f[k].data, *f[k].data ? p->cap * f[k].per : 0, sx__pair_size(&f[k]));
    memset(p, 0, sizeof *p);
}

size_t sx__balls_bytes(const sx_model *m)
{
    const sx_balls *b = &m->balls;
    sx_ball_field f[SX_BALL_FIELDS_MAX];
    const int nf = sx__ball_fields(m, (sx_balls *)b, f);
    size_t per = 0;
    for (int k = 0; k < nf; k++) per += sx__ball_row(&f[k]);
    return (size_t)b->cap * per + (size_t)b->index_cap * sizeof(int32_t);
}

size_t sx__pairs_bytes(const sx_model *m, const sx_pairs *p)
{
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, (sx_pairs *)p, f);
    size_t per = 0;
    for (int k = 0; k < nf; k++) per += (size_t)f[k].per * sx__pair_size(&f[k]);
    return (size_t)p->cap * per;
}

/* ------------------------------------------------------------ accessors */

int64_t sx_ball_count(const sx_model *m) { return m->balls.n; }

int64_t sx_ball_id_at(const sx_model *m, int64_t i)
{
    return i >= 0 && i < m->balls.n ? m->balls.id[i] : -1;
}

bool sx_ball_exists(const sx_model *m, int64_t id) { return sx__ball_index(m, id) >= 0; }

/* A ball's row is cheaper to fetch alone than every ball's motion for a
 * few balls; a script that reads more (a loop over the balls) is served
 * by one exchange of every ball's motion, which then holds until the next
 * cycle. */
enum { FETCH_MAX = 16 };

bool sx_model_motion_current(const sx_model *m) { return !sx_model_scattered(m) || m->dd->motion_whole; }

sx_status sx_ball_fetch(sx_model *m, int64_t id)
{
    if (sx_model_motion_current(m)) return SX_OK;
    sx_dd *d = m->dd;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "ball %lld: the model is stepping", (long long)id);
    /* ranks reading the same field of different balls at once (a loop
     * over pairs() of a table, whose order each process draws) are served
     * by a gather, as they were before any fetch: the same on every rank */
    if (!d->x.agree(d->x.ud, (uint64_t)id)) return sx_model_gather(m);
    if (!sx_ball_exists(m, id)) return SX_OK;
    if (++d->fetched > FETCH_MAX) return sx_model_share_motion(m);
    if (!sx__dd_fetch_ball(m, sx__ball_index(m, id)))
        return sx__fail(m, SX_EINVAL, "ball %lld: the ranks could not exchange its state", (long long)id);
    return SX_OK;
}

sx_status sx_model_share_motion(sx_model *m)
{
    if (sx_model_motion_current(m)) return SX_OK;
    if (m->locked) return sx__fail(m, SX_ELOCKED, "the balls' motion: the model is stepping");
    if (!sx__dd_fetch_ball(m, -1)) return sx__fail(m, SX_EINVAL, "the ranks could not exchange the balls' motion");
    m->dd->motion_whole = true;
    return SX_OK;
}

/* Resolves an id or fails with a message naming the caller. */
static int64_t lookup(const sx_model *m, int64_t id, const char *fn)
{
    const int64_t i = sx__ball_index(m, id);
    if (i < 0) sx__fail((sx_model *)m, SX_ENOTFOUND, "%s: no ball with id %lld", fn, (long long)id);
    return i;
}


static sx_status ensure_applied(sx_model *m)
{
    sx_balls *b = &m->balls;
    if (b->fapp) return SX_OK;
    const int64_t c = b->cap;
    b->fapp = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(c * m->dim), sizeof(double));
    b->tapp = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(c * m->rdim), sizeof(double));
    if (!b->fapp || !b->tapp) return SX_ENOMEM;
    return SX_OK;
}

sx_status sx__balls_expand_damping(sx_model *m)
{
    sx_balls *b = &m->balls;
    if (b->alpha) return SX_OK;
    if (!(b->alpha = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)b->cap, sizeof *b->alpha))) return SX_ENOMEM;
    for (int64_t i = 0; i < b->n; i++) b->alpha[i] = m->mats[b->mat[i]].def.damping;
    return SX_OK;
}

sx_status sx__balls_expand_unwrap(sx_model *m)
{
    sx_balls *b = &m->balls;
    if (!b->unwrap && !(b->unwrap = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)(b->cap * m->dim), sizeof *b->unwrap)))
        return SX_ENOMEM;
    return SX_OK;
}

void sx__ball_placed(sx_model *m, int64_t i)
{
    if (m->balls.unwrap) memset(m->balls.unwrap + i * m->dim, 0, (size_t)m->dim * sizeof *m->balls.unwrap);
}

void sx__ball_wraps(const sx_model *m, int64_t i, double *s)
{
    const int d = m->dim;
    for (int q = 0; q < d; q++) s[q] = m->balls.unwrap ? m->balls.unwrap[i * d + q] : 0;
}

void sx__ball_unwrapped(const sx_model *m, int64_t i, double *x)
{
    double s[3];
    sx__ball_wraps(m, i, s);
    for (int q = 0; q < m->dim; q++) x[q] = m->balls.x[i * m->dim + q] + s[q];
}

sx_status sx__balls_expand_groups(sx_model *m)
{
    sx_balls *b = &m->balls;
    if (!b->group && !(b->group = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)b->cap, sizeof *b->group)))
        return SX_ENOMEM;
    return SX_OK;
}

void sx__balls_compact(sx_model *m)
{
    sx_balls *b = &m->balls;
    bool own_damping = false, grouped = false;
    for (int64_t i = 0; i < b->n && b->alpha && !own_damping; i++)
        own_damping = b->alpha[i] != m->mats[b->mat[i]].def.damping;
    for (int64_t i = 0; i < b->n && b->group && !grouped; i++) grouped = b->group[i] != 0;
    if (!own_damping) {
        free_field(m, b->alpha, b->alpha ? b->cap : 0, sizeof(double));
        b->alpha = NULL;
    }
    if (!grouped) {
        free_field(m, b->group, b->group ? b->cap : 0, sizeof(int32_t));
        b->group = NULL;
    }
}

/* Where a vector field lives and how many components it has. */
static double *vec_field(const sx_model *m, sx_ball_vec which, int *n)
{
    const sx_balls *b = &m->balls;
    *n = m->dim;
    switch (which) {
    case SX_BALL_POS: return b->x;
    case SX_BALL_VEL: return b->v;
    case SX_BALL_FORCE: return b->f;
    case SX_BALL_APPLIED_FORCE: return b->fapp;
    default: break;
    }
    *n = m->rdim;
    switch (which) {
    case SX_BALL_SPIN: return b->w;
    case SX_BALL_MOMENT: return b->t;
    case SX_BALL_APPLIED_MOMENT: return b->tapp;
    default: return NULL;
    }
}

sx_status sx_ball_get_vec(const sx_model *m, int64_t id, sx_ball_vec which, double out[3])
{
    const int64_t i = lookup(m, id, "ball_get_vec");
    if (i < 0) return SX_ENOTFOUND;
    if (which < SX_BALL_POS || which > SX_BALL_APPLIED_MOMENT)
        return sx__fail((sx_model *)m, SX_EINVAL, "ball_get_vec: unknown field %d", (int)which);
    int n;
    const double *src = vec_field(m, which, &n);
    out[0] = out[1] = out[2] = 0;
    if (src)
        for (int k = 0; k < n; k++) out[k] = src[i * n + k];
    return SX_OK;
}

sx_status sx_ball_get_unwrapped(const sx_model *m, int64_t id, double out[3])
{
    const int64_t i = lookup(m, id, "ball_get_unwrapped");
    if (i < 0) return SX_ENOTFOUND;
    out[0] = out[1] = out[2] = 0;
    sx__ball_unwrapped(m, i, out);
    return SX_OK;
}

sx_status sx_ball_set_vec(sx_model *m, int64_t id, sx_ball_vec which, const double val[3])
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    const int64_t i = lookup(m, id, "ball_set_vec");
    if (i < 0) return SX_ENOTFOUND;
    if (which == SX_BALL_FORCE || which == SX_BALL_MOMENT)
        return sx__fail(m, SX_EINVAL, "ball_set_vec: force and moment are results of the step; set the applied force instead");
    if (which < SX_BALL_POS || which > SX_BALL_APPLIED_MOMENT)
        return sx__fail(m, SX_EINVAL, "ball_set_vec: unknown field %d", (int)which);
    if ((which == SX_BALL_POS || which == SX_BALL_VEL || which == SX_BALL_SPIN) &&
        pebble(m, i, "ball_set_vec", "position, velocity and spin (set the clump's)"))
        return SX_EINVAL;
    if ((which == SX_BALL_APPLIED_FORCE || which == SX_BALL_APPLIED_MOMENT) && ensure_applied(m))
        return sx__fail(m, SX_ENOMEM, "ball_set_vec: out of memory");
    int n;
    double *dst = vec_field(m, which, &n);
    if (!finite_vec(val, n)) return sx__fail(m, SX_EINVAL, "ball_set_vec: components must be finite, below 1e100");
    for (int k = 0; k < n; k++) dst[i * n + k] = val[k];
    if (which == SX_BALL_POS) {
        m->build_needed = true; /* a jump may skip the skin test */
        sx__ball_placed(m, i);
    }
    if (which == SX_BALL_VEL && sx__speed_rated(m)) m->dt_stale = true;
    return SX_OK;
}

sx_status sx_ball_get(const sx_model *m, int64_t id, sx_ball_scalar which, double *out)
{
    const int64_t i = lookup(m, id, "ball_get");
    if (i < 0) return SX_ENOTFOUND;
    const sx_balls *b = &m->balls;
    switch (which) {
    case SX_BALL_RADIUS: *out = b->rad[i]; return SX_OK;
    case SX_BALL_MASS: *out = 1.0 / b->inv_mass[i]; return SX_OK;
    case SX_BALL_INERTIA: *out = 1.0 / b->inv_inertia[i]; return SX_OK;
    case SX_BALL_DAMPING: *out = sx__ball_damping(m, i); return SX_OK;
    }
    return sx__fail((sx_model *)m, SX_EINVAL, "ball_get: unknown field %d", (int)which);
}

sx_status sx_ball_set(sx_model *m, int64_t id, sx_ball_scalar which, double value)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    const int64_t i = lookup(m, id, "ball_set");
    if (i < 0) return SX_ENOTFOUND;
    sx_balls *b = &m->balls;
    if ((which == SX_BALL_RADIUS || which == SX_BALL_DAMPING) &&
        pebble(m, i, "ball_set", "size and damping (set the clump's damping)"))
        return SX_EINVAL;
    switch (which) {
    case SX_BALL_RADIUS:
        if (!(value > 0) || !isfinite(value))
            return sx__fail(m, SX_EINVAL, "ball_set: radius must be a positive finite number (got %g)", value);
        if (!radius_ok(m, value, b->mat[i]))
            return sx__fail(m, SX_EINVAL, "ball_set: a radius of %g m gives a mass or inertia of 0 or infinity", value);
        b->rad[i] = value;
        sx__ball_update_mass(m, i);
        m->build_needed = true;
        m->dt_stale = true;
        return SX_OK;
    case SX_BALL_DAMPING:
        if (!(value >= 0 && value < 1))
            return sx__fail(m, SX_EINVAL, "ball_set: local damping must be in [0, 1) (got %g)", value);
        if (!b->alpha && value == sx__ball_damping(m, i)) return SX_OK; /* it follows its material already */
        if (sx__balls_expand_damping(m)) return sx__fail(m, SX_ENOMEM, "ball_set: out of memory");
        b->alpha[i] = value;
        return SX_OK;
    case SX_BALL_MASS:
    case SX_BALL_INERTIA:
        return sx__fail(m, SX_EINVAL, "ball_set: mass and inertia follow from radius and density");
    }
    return sx__fail(m, SX_EINVAL, "ball_set: unknown field %d", (int)which);
}

sx_status sx_ball_material(const sx_model *m, int64_t id, int *material)
{
    const int64_t i = lookup(m, id, "ball_material");
    if (i < 0) return SX_ENOTFOUND;
    *material = m->balls.mat[i];
    return SX_OK;
}

sx_status sx_ball_set_material(sx_model *m, int64_t id, int material)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    const int64_t i = lookup(m, id, "ball_set_material");
    if (i < 0) return SX_ENOTFOUND;
    if (material < 0 || material >= m->nmat)
        return sx__fail(m, SX_ENOTFOUND, "ball_set_material: no material with index %d", material);
    /* a pebble may take another material of its clump's density (its friction, stiffness), not another mass */
    if (m->balls.clump && m->balls.clump[i]) {
        int cm;
        sx_clump_material(m, m->balls.clump[i], &cm);
        if (m->mats[cm].def.density != m->mats[material].def.density &&
            pebble(m, i, "ball_set_material", "mass: a pebble's material needs the clump's density"))
            return SX_EINVAL;
    }
    m->balls.mat[i] = (uint16_t)material;
    if (m->balls.alpha) m->balls.alpha[i] = m->mats[material].def.damping;
    sx__ball_update_mass(m, i);
    m->dt_stale = true;
    return SX_OK;
}

/* The store keeps the 2D scalar spin's fixity in the first rotational bit. */
static unsigned to_store_mask(const sx_model *m, unsigned mask)
{
    if (m->dim == 3) return mask & (SX_FIX_VEL | SX_FIX_SPIN);
    return (mask & (SX_FIX_VX | SX_FIX_VY)) | ((mask & SX_FIX_WZ) ? SX_FIX_WX : 0);
}

static unsigned from_store_mask(const sx_model *m, unsigned mask)
{
    if (m->dim == 3) return mask;
    return (mask & (SX_FIX_VX | SX_FIX_VY)) | ((mask & SX_FIX_WX) ? SX_FIX_WZ : 0);
}

sx_status sx_ball_fixity(const sx_model *m, int64_t id, unsigned *mask)
{
    const int64_t i = lookup(m, id, "ball_fixity");
    if (i < 0) return SX_ENOTFOUND;
    *mask = from_store_mask(m, m->balls.fix[i]);
    return SX_OK;
}

sx_status sx_ball_set_fixity(sx_model *m, int64_t id, unsigned mask)
{
    m->guard_dirty = true; /* new energy baseline for the stability guard */
    const int64_t i = lookup(m, id, "ball_set_fixity");
    if (i < 0) return SX_ENOTFOUND;
    if (pebble(m, i, "ball_set_fixity", "motion (fix the clump)")) return SX_EINVAL;
    const unsigned valid = m->dim == 3 ? (SX_FIX_VEL | SX_FIX_SPIN) : (SX_FIX_VX | SX_FIX_VY | SX_FIX_WZ);
    if (mask & ~valid)
        return sx__fail(m, SX_EINVAL, "ball_set_fixity: mask 0x%x has components a %dD ball does not have", mask,
                        m->dim);
    m->balls.fix[i] = (uint8_t)to_store_mask(m, mask);
    return SX_OK;
}

sx_ball_def sx_ball_default_def(void)
{
    sx_ball_def d;
    memset(&d, 0, sizeof d);
    d.radius = 1.0;
    return d;
}

sx_status sx_ball_group(const sx_model *m, int64_t id, int32_t *group)
{
    const int64_t i = lookup(m, id, "ball_group");
    if (i < 0) return SX_ENOTFOUND;
    *group = m->balls.group ? m->balls.group[i] : 0;
    return SX_OK;
}

sx_status sx_ball_set_group(sx_model *m, int64_t id, int32_t group)
{
    const int64_t i = lookup(m, id, "ball_set_group");
    if (i < 0) return SX_ENOTFOUND;
    if (!m->balls.group && group == 0) return SX_OK;
    if (sx__balls_expand_groups(m)) return sx__fail(m, SX_ENOMEM, "ball_set_group: out of memory");
    m->balls.group[i] = group;
    return SX_OK;
}
