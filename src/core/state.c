/* Sizing and checking the complete state of a model for the I/O layer
 * (see state.h). Allocation goes through the model's tracked allocator
 * with the same capacity rules as the stores' own growth, so a restored
 * model grows, frees and reports its bytes like any other. */
#include "state.h"

#include "clumps.h"
#include "laws/bond.h"
#include "joints.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* An array of n elements of `size` bytes, zeroed; false when out of memory. */
static bool alloc_array(sx_model *m, void **p, int64_t n, size_t size)
{
    *p = NULL;
    if (n <= 0) return true;
    *p = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)n, size);
    return *p != NULL;
}

static bool empty(const sx_model *m)
{
    return m->balls.cap == 0 && m->balls.index_cap == 0 && m->bb.cap == 0 && m->bw.cap == 0 && m->bonds.cap == 0 &&
           m->cracks.cap == 0 && m->cap_wall == 0 && m->cap_mat == 0 && m->step == 0;
}

sx_status sx__state_alloc(sx_model *m, const sx_state_sizes *s)
{
    if (!empty(m)) return sx__fail(m, SX_EINVAL, "state: the model to restore into must be new and empty");
    if (s->balls < 0 || s->next_ball_id < 1 || s->balls > s->next_ball_id - 1 || s->next_ball_id >= INT32_MAX ||
        s->bb < 0 || s->bb > INT32_MAX || s->bw < 0 || s->bw > INT32_MAX || s->bonds < 0 ||
        s->bonds > INT32_MAX - 1 || s->joints < 0 || s->joints > INT32_MAX || s->fj_elements < 0 || s->fj_elements > INT32_MAX - 1 || s->cracks < 0 || s->walls < 0 || s->walls > INT32_MAX || s->materials < 0 ||
        s->materials > UINT16_MAX || s->cmodels < 0 || s->cmodels > 4096)
        return sx__fail(m, SX_EINVAL,
                        "state: sizes out of range (%lld balls, next id %lld, %lld + %lld pairs, %lld bonds, "
                        "%lld walls, %d materials)",
                        (long long)s->balls, (long long)s->next_ball_id, (long long)s->bb, (long long)s->bw,
                        (long long)s->bonds, (long long)s->walls, s->materials);
    const int d = m->dim, r = m->rdim;

    /* balls: the store's own reserve, then the cold arrays at its capacity */
    sx_balls *b = &m->balls;
    /* applied loads live at the balls' capacity: a store that had them keeps one */
    if ((s->balls > 0 || s->applied) && sx__balls_reserve(m, s->balls > 0 ? s->balls : 1)) goto nomem;
    /* the damping and group arrays for the file to fill (sx__state_finish frees them when uniform) */
    if (b->cap > 0 && (sx__balls_expand_damping(m) || sx__balls_expand_groups(m))) goto nomem;
    if (s->applied) {
        if (!alloc_array(m, (void **)&b->fapp, b->cap * d, sizeof(double)) ||
            !alloc_array(m, (void **)&b->tapp, b->cap * r, sizeof(double)))
            goto nomem;
    }
    if (s->unwrap && b->cap > 0 && sx__balls_expand_unwrap(m)) goto nomem;
    if (!alloc_array(m, (void **)&b->index_of, s->next_ball_id, sizeof(int32_t))) goto nomem;
    b->index_cap = s->next_ball_id;
    b->n = s->balls;
    b->next_id = s->next_ball_id;

    /* pairs: a store that carried bond slots gets them back, even when empty */
    if (sx__pairs_reserve(m, &m->bb, s->bb_bonds && s->bb == 0 ? 1 : s->bb)) goto nomem;
    if (s->bb_bonds && sx__bonds_reserve_pairs(m)) goto nomem;
    if (sx__pairs_reserve(m, &m->bw, s->bw_facets && s->bw == 0 ? 1 : s->bw)) goto nomem;
    if (s->bw_facets && sx__pairs_expand_facets(m)) goto nomem;
    if (s->rolling && sx__pairs_expand(m, offsetof(sx_pairs, mr), r)) goto nomem;
    if (s->total_shear && sx__pairs_expand(m, offsetof(sx_pairs, us), d)) goto nomem;
    if (s->joints > 0 && sx__joints_reserve_pairs(m)) goto nomem; /* their definitions: sx__joints_restore */
    m->bb.n = s->bb;
    m->bw.n = s->bw;

    /* bonds and cracks at exactly their sizes; the stores grow from there */
    sx_bonds *k = &m->bonds;
    const int64_t nb = s->bonds;
    sx_bond_field bf[SX_BOND_FIELDS_MAX];
    const int nbf = sx__bond_fields(m, k, bf);
    for (int j = 0; j < nbf; j++)
        if (!alloc_array(m, bf[j].data, nb * bf[j].per, sx__field_size(bf[j].type))) goto nomem;
    k->n = k->cap = nb;
    sx_fjels *e = &m->fjel;
    const int64_t ne = s->fj_elements;
    if (!alloc_array(m, (void **)&e->state, ne, 1) || !alloc_array(m, (void **)&e->sigma_c, ne, sizeof(double)) ||
        !alloc_array(m, (void **)&e->coh, ne, sizeof(double)) || !alloc_array(m, (void **)&e->gap0, ne, sizeof(double)) ||
        !alloc_array(m, (void **)&e->fs, ne * (d - 1), sizeof(double)) ||
        !alloc_array(m, (void **)&e->fn, ne, sizeof(double)))
        goto nomem;
    e->n = e->cap = ne;
    if (!alloc_array(m, (void **)&m->cracks.ev, s->cracks, sizeof(sx_crack))) goto nomem;
    m->cracks.n = m->cracks.cap = s->cracks;

    if (!alloc_array(m, (void **)&m->walls, s->walls, sizeof(sx_wall))) goto nomem;
    m->nwall = m->cap_wall = s->walls;
    if (!alloc_array(m, (void **)&m->mats, s->materials, sizeof(sx_material))) goto nomem;
    m->nmat = m->cap_mat = s->materials;
    if (!alloc_array(m, (void **)&m->cmodel, s->cmodels, sizeof(sx_cmodel_row))) goto nomem;
    m->ncmodel = m->cap_cmodel = s->cmodels;
    if ((s->bb_cmodel && !sx__cmodel_store(m, &m->bb)) || (s->bw_cmodel && !sx__cmodel_store(m, &m->bw))) goto nomem;
    return SX_OK;
nomem:
    return sx__fail(m, SX_ENOMEM, "state: out of memory for %lld balls, %lld pairs, %lld bonds", (long long)s->balls,
                    (long long)(s->bb + s->bw), (long long)s->bonds);
}

bool sx__state_finite(const double *v, int64_t n)
{
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

bool sx__state_length_finite(const double *v, int64_t n)
{
    double len2 = 0;
    for (int64_t i = 0; i < n; i++) len2 += v[i] * v[i];
    return isfinite(len2);
}

static sx_status check_scalars(sx_model *m)
{
    const char *why = NULL;
    if (!sx__state_finite(m->gravity, 3)) why = "gravity is not finite";
    else if (!(m->dt_user >= 0) || !isfinite(m->dt_user)) why = "the user timestep is not >= 0";
    else if (!(m->dt >= 0) || !isfinite(m->dt) || !(m->dt_prev >= 0) || !isfinite(m->dt_prev))
        why = "the timestep is not >= 0";
    else if (!(m->dt_safety > 0 && m->dt_safety <= 1)) why = "the timestep safety factor is not in (0, 1]";
    else if (!(m->skin >= 0) || !isfinite(m->skin) || !(m->skin_user >= 0) || !isfinite(m->skin_user))
        why = "the skin is not >= 0";
    else if (!isfinite(m->time)) why = "the time is not finite";
    else if (m->step < 0 || m->builds < 0) why = "the step or build count is negative";
    else if (m->dim == 2 && m->gravity[2] != 0) why = "a 2D model has a z gravity component";
    else if (m->threads < 1 || m->threads > 1024) why = "the thread count is not in 1..1024";
    if (why) return sx__fail(m, SX_EINVAL, "state: %s", why);
    return SX_OK;
}

static sx_status check_materials(sx_model *m)
{
    for (int i = 0; i < m->nmat; i++) {
        sx_material *t = &m->mats[i];
        if (!memchr(t->name, 0, sizeof t->name) || !t->name[0])
            return sx__fail(m, SX_EINVAL, "state: material %d has no valid name", i);
        for (int j = 0; j < i; j++)
            if (strcmp(m->mats[j].name, t->name) == 0)
                return sx__fail(m, SX_EINVAL, "state: material '%s' appears twice", t->name);
        /* the rules of sx_material_set: a NaN stiffness would be blamed on the timestep at the first cycle */
        char why[256];
        if (sx__material_invalid(&t->def, why, sizeof why))
            return sx__fail(m, SX_EINVAL, "state: material '%s': %s", t->name, why);
        const double *bpm = (const double *)&t->bpm;
        for (size_t k = 0; k < sizeof t->bpm / sizeof(double); k++)
            if (!(bpm[k] >= 0) || !isfinite(bpm[k]))
                return sx__fail(m, SX_EINVAL, "state: material '%s' has a bond parameter that is negative or not "
                                              "finite (%g)", t->name, bpm[k]);
        if (sx__bond_params_invalid(&t->bpm, false, why, sizeof why)) /* the ranges of sx_material_set_bpm */
            return sx__fail(m, SX_EINVAL, "state: material '%s': bond %s", t->name, why);
        sx__material_derive(t);
    }
    return SX_OK;
}

/* The contact-model rows by the rules of sx_cmodel_add, and each contact's
 * row in range. */
static sx_status check_cmodels(sx_model *m)
{
    for (int r = 0; r < m->ncmodel; r++) {
        sx_cmodel_row *t = &m->cmodel[r];
        const sx_cmodel_def *d = &t->def;
        char why[256];
        if (!memchr(t->mat.name, 0, sizeof t->mat.name) || !t->mat.name[0])
            return sx__fail(m, SX_EINVAL, "state: contact-model row %d has no valid name", r + 1);
        t->def.law = t->mat.def; /* a file stores the row's law as a material */
        if (sx__cmodel_invalid(m, d, why, sizeof why))
            return sx__fail(m, SX_EINVAL, "state: contact-model row '%s': %s", t->mat.name, why);
        sx__cmodel_derive(t);
    }
    const sx_pairs *ps[2] = {&m->bb, &m->bw};
    for (int k = 0; k < 2; k++)
        for (int64_t c = 0; ps[k]->cmodel && c < ps[k]->n; c++)
            if (ps[k]->cmodel[c] < 0 || ps[k]->cmodel[c] > m->ncmodel)
                return sx__fail(m, SX_EINVAL, "state: %s pair %lld has contact-model row %d, there are %d",
                                k ? "ball-wall" : "ball-ball", (long long)c, (int)ps[k]->cmodel[c], m->ncmodel);
    for (int k = 0; k < 2; k++)
        if (sx__cmodel_any(m, k) && !ps[k]->cmodel)
            return sx__fail(m, SX_EINVAL, "state: a contact-model row matches %s contacts but their pairs carry no row",
                            k ? "ball-wall" : "ball-ball");
    return SX_OK;
}

sx_status sx__state_map_id(sx_model *m, const char *kind, int32_t *index_of, int64_t next_id, int64_t i, int64_t id)
{
    if (id < 1 || id >= next_id)
        return sx__fail(m, SX_EINVAL, "state: %s %lld has id %lld outside 1..%lld", kind, (long long)i, (long long)id,
                        (long long)(next_id - 1));
    if (index_of[id] >= 0) return sx__fail(m, SX_EINVAL, "state: %s id %lld appears twice", kind, (long long)id);
    index_of[id] = (int32_t)i;
    return SX_OK;
}

static sx_status check_balls(sx_model *m)
{
    sx_balls *b = &m->balls;
    const int d = m->dim, r = m->rdim;
    const unsigned valid = d == 3 ? (SX_FIX_VEL | SX_FIX_SPIN) : (SX_FIX_VX | SX_FIX_VY | SX_FIX_WX);
    for (int64_t id = 0; id < b->index_cap; id++) b->index_of[id] = -1;
    for (int64_t i = 0; i < b->n; i++) {
        const int64_t id = b->id[i];
        const sx_status st = sx__state_map_id(m, "ball", b->index_of, b->next_id, i, id);
        if (st) return st;
        if (b->mat[i] >= m->nmat)
            return sx__fail(m, SX_EINVAL, "state: ball %lld has material %d, there are %d", (long long)id,
                            (int)b->mat[i], m->nmat);
        if (b->fix[i] & ~valid) return sx__fail(m, SX_EINVAL, "state: ball %lld has invalid fixity bits", (long long)id);
        const double alpha = sx__ball_damping(m, i);
        /* (a denormal 1/m is an infinite mass: the reciprocals must be finite too) */
        if (!(b->rad[i] > 0) || !isfinite(b->rad[i]) || !(b->inv_mass[i] > 0) || !isfinite(b->inv_mass[i]) ||
            !isfinite(1 / b->inv_mass[i]) || !(b->inv_inertia[i] > 0) || !isfinite(b->inv_inertia[i]) ||
            !isfinite(1 / b->inv_inertia[i]) || !(alpha >= 0 && alpha < 1))
            return sx__fail(m, SX_EINVAL, "state: ball %lld has a radius, mass, inertia or damping out of range",
                            (long long)id);
        /* (a spin of 1e300, finite, turns a bond's moment into inf - inf at the next step) */
        if (!sx__state_length_finite(b->x + i * d, d) || !sx__state_length_finite(b->x_build + i * d, d) ||
            !sx__state_length_finite(b->v + i * d, d) || !sx__state_length_finite(b->w + i * r, r))
            return sx__fail(m, SX_EINVAL, "state: ball %lld has a position, velocity or spin that is not finite or "
                                          "too large (its square overflows)",
                            (long long)id);
        if (!sx__state_length_finite(b->f + i * d, d) || !sx__state_length_finite(b->t + i * r, r) ||
            (b->fapp && (!sx__state_length_finite(b->fapp + i * d, d) || !sx__state_length_finite(b->tapp + i * r, r))))
            return sx__fail(m, SX_EINVAL, "state: ball %lld has a force, moment or applied load that is not finite or "
                                          "too large (its square overflows)",
                            (long long)id);
    }
    return SX_OK;
}

/* A restored mesh: its numbers in range, then what follows from them. */
static sx_status check_mesh(sx_model *m, sx_wall *w)
{
    sx_mesh *s = w->mesh;
    const double *q = s->q, qq = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    bool vertices = true;
    for (int64_t v = 0; v < s->nv; v++) vertices = vertices && sx__state_length_finite(s->body + 3 * v, 3);
    if (!vertices || !sx__state_length_finite(w->def.spin, 3) || !sx__state_finite(q, 4) || !(fabs(qq - 1) < 1e-9))
        return sx__fail(m, SX_EINVAL, "state: mesh wall %lld has a non-finite vertex or spin, or an orientation that "
                                      "is not a unit quaternion", (long long)w->id);
    for (int64_t t = 0; t < 3 * s->nt; t++)
        if (s->tri[t] < 0 || s->tri[t] >= s->nv)
            return sx__fail(m, SX_EINVAL, "state: mesh wall %lld: triangle %lld names vertex %d of %lld", (long long)w->id,
                            (long long)(t / 3), s->tri[t], (long long)s->nv);
    if (!sx__mesh_weld_restored(m, s) || !sx__mesh_derive(m, s)) return sx__fail(m, SX_ENOMEM, "state: out of memory");
    sx__mesh_pose(w);
    return SX_OK;
}

static sx_status check_walls(sx_model *m)
{
    sx_status st;
    for (int64_t i = 0; i < m->nwall; i++) {
        const sx_wall *w = &m->walls[i];
        const sx_wall_kind k = w->def.kind;
        const bool ok = m->dim == 3 ? ((k == SX_WALL_PLANE || k == SX_WALL_RECT || k == SX_WALL_CYLINDER) && !w->mesh) ||
                                          (k == SX_WALL_MESH && w->mesh)
                                    : (k == SX_WALL_LINE || k == SX_WALL_SEGMENT);
        if (!ok) return sx__fail(m, SX_EINVAL, "state: wall %lld has kind %d, not a %dD wall", (long long)w->id, (int)k, m->dim);
        if (w->id < 1 || w->id > m->next_wall_id)
            return sx__fail(m, SX_EINVAL, "state: wall id %lld is outside 1..%lld", (long long)w->id,
                            (long long)m->next_wall_id);
        for (int64_t j = 0; j < i; j++)
            if (m->walls[j].id == w->id) return sx__fail(m, SX_EINVAL, "state: wall id %lld appears twice", (long long)w->id);
        const double *vectors[] = {w->def.point, w->def.normal, w->def.vel, w->def.edge1, w->def.edge2, w->force,
                                   w->moment};
        bool finite = true;
        for (size_t k = 0; k < sizeof vectors / sizeof *vectors; k++)
            finite = finite && sx__state_length_finite(vectors[k], 3);
        if (!finite)
            return sx__fail(m, SX_EINVAL, "state: wall %lld has a point, normal, edge, velocity, force or moment that "
                                          "is not finite or too large (its square overflows)", (long long)w->id);
        /* a unit normal (walls are stored normalised) */
        const double *nv = w->def.normal;
        if (!(fabs(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2] - 1) < 1e-6))
            return sx__fail(m, SX_EINVAL, "state: wall %lld has a normal of length other than 1", (long long)w->id);
        if (!(w->def.kn > 0) || !isfinite(w->def.kn) || !(w->def.ks >= 0) || !isfinite(w->def.ks) ||
            !(w->def.friction >= 0) || !isfinite(w->def.friction) || !(w->moved >= 0) || !isfinite(w->moved))
            return sx__fail(m, SX_EINVAL, "state: wall %lld has a stiffness, friction or move out of range",
                            (long long)w->id);
        if (w->def.material < SX_WALL_RIGID || w->def.material >= m->nmat)
            return sx__fail(m, SX_EINVAL, "state: wall %lld names material %d of %d", (long long)w->id, w->def.material,
                            m->nmat);
        if ((k == SX_WALL_RECT && !(w->len_u > 0 && w->len_v > 0)) || (k == SX_WALL_SEGMENT && !(w->seg_len > 0)))
            return sx__fail(m, SX_EINVAL, "state: wall %lld has a zero extent", (long long)w->id);
        if (k == SX_WALL_CYLINDER &&
            (!(w->def.radius > 0) || !isfinite(w->def.radius) || !(w->def.height >= 0) || !isfinite(w->def.height)))
            return sx__fail(m, SX_EINVAL, "state: cylinder %lld has a radius <= 0 or a height < 0", (long long)w->id);
        if (!isfinite(w->def.radial_vel) || !isfinite(w->load) || !isfinite(w->kn_sum) || w->contacts < 0)
            return sx__fail(m, SX_EINVAL, "state: wall %lld has a non-finite radial velocity or load, or a negative "
                                          "contact count", (long long)w->id);
        /* the servo divides by its area and is bounded by max_speed (sx_wall_set_servo's rules) */
        const sx_servo_def *s = &w->servo;
        if (w->servo_on && (!isfinite(s->target) || !(s->area > 0) || !isfinite(s->area) ||
                            !(s->alpha > 0 && s->alpha <= 1) || !(s->max_speed > 0) || !isfinite(s->max_speed)))
            return sx__fail(m, SX_EINVAL, "state: wall %lld has servo settings out of range", (long long)w->id);
        if (w->mesh && (st = check_mesh(m, &m->walls[i]))) return st;
    }
    return SX_OK;
}

/* The history of pair c of store p is finite (a NaN shear force or
 * relative position would spread through the step unseen). The relative
 * position (or normal) is checked by its squared length, which is finite
 * only if every component is and none is so large (1e300) that the
 * contact's overlap would come out infinite. */
static bool pair_finite(const sx_model *m, const sx_pairs *p, int64_t c)
{
    const int d = m->dim;
    return sx__state_finite(p->fs + c * d, d) && sx__state_length_finite(p->geo + c * d, d) && isfinite(p->fn[c]) &&
           (!p->un || isfinite(p->un[c])) &&
           (!p->jun || (isfinite(p->jun[c]) && sx__state_finite(p->jnormal + c * d, d)));
}

static sx_status check_pairs(sx_model *m)
{
    const int64_t n = m->balls.n, ends = n + (m->cell ? m->cell->n : 0); /* b may be a ghost */
    const sx_pairs *p = &m->bb;
    for (int64_t c = 0; c < p->n; c++) {
        if (!pair_finite(m, p, c))
            return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld has a non-finite history", (long long)c);
        if (p->a[c] < 0 || p->a[c] >= n || p->a[c] >= p->b[c] || p->b[c] >= ends)
            return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld refers to balls %d, %d of %lld", (long long)c,
                            p->a[c], p->b[c], (long long)n);
        if (p->touching[c] > 1) return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld has a bad touching flag", (long long)c);
        if (p->joint && (p->joint[c] < 0 || p->joint[c] > m->njoint))
            return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld names joint %d of %lld", (long long)c, p->joint[c],
                            (long long)m->njoint);
        const int32_t slot = p->bond ? p->bond[c] - 1 : -1;
        if (slot >= 0 && slot < m->bonds.n && (m->bonds.kind[slot] & SX_BOND_SMOOTHJOINT) &&
            !(p->joint && p->joint[c] && p->touching[c]))
            return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld has a smooth-joint bond but no joint", (long long)c);
        if (p->bond) {
            const int32_t s = p->bond[c];
            if (s < 0 || s > m->bonds.n)
                return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld refers to bond %d of %lld", (long long)c, s,
                                (long long)m->bonds.n);
            if (s > 0) {
                const int32_t ia = m->balls.id[p->a[c]], ib = m->balls.id[p->b[c]];
                const int32_t ba = m->bonds.ida[s - 1], bb = m->bonds.idb[s - 1];
                if (!((ia == ba && ib == bb) || (ia == bb && ib == ba)))
                    return sx__fail(m, SX_EINVAL, "state: bond %d joins balls %d, %d but its pair joins %d, %d", s - 1,
                                    ba, bb, ia, ib);
            }
        }
    }
    p = &m->bw;
    for (int64_t c = 0; c < p->n; c++) {
        if (p->a[c] < 0 || p->a[c] >= n || p->b[c] < 0 || p->b[c] >= m->nwall)
            return sx__fail(m, SX_EINVAL, "state: ball-wall pair %lld refers to ball %d of %lld, wall %d of %lld",
                            (long long)c, p->a[c], (long long)n, p->b[c], (long long)m->nwall);
        if (p->touching[c] > 1) return sx__fail(m, SX_EINVAL, "state: ball-wall pair %lld has a bad touching flag", (long long)c);
        if (!pair_finite(m, p, c))
            return sx__fail(m, SX_EINVAL, "state: ball-wall pair %lld has a non-finite history", (long long)c);
        const sx_mesh *mesh = m->walls[p->b[c]].mesh;
        const int32_t facet = p->facet ? p->facet[c] : 0;
        if (facet < 0 || (mesh ? facet >= mesh->nt : facet != 0))
            return sx__fail(m, SX_EINVAL, "state: ball-wall pair %lld names facet %d of wall %lld, which has none such",
                            (long long)c, facet, (long long)m->walls[p->b[c]].id);
    }
    return SX_OK;
}

static sx_status check_cracks(sx_model *m)
{
    for (int64_t i = 0; i < m->cracks.n; i++) {
        const sx_crack *c = &m->cracks.ev[i];
        const double v[] = {c->time, c->pos[0], c->pos[1], c->pos[2], c->fn, c->fs, c->mn, c->ms};
        if (!sx__state_finite(v, (int64_t)(sizeof v / sizeof *v)))
            return sx__fail(m, SX_EINVAL, "state: crack %lld has a non-finite time, position, force or moment",
                            (long long)i);
    }
    return SX_OK;
}

static sx_status check_bonds(sx_model *m)
{
    sx_bonds *k = &m->bonds;
    k->intact = 0;
    for (int64_t s = 0; s < k->n; s++) {
        if (k->kind[s] & ~(unsigned)(SX_BOND_CONTACT | SX_BOND_PARALLEL | SX_BOND_FLATJOINT | SX_BOND_SMOOTHJOINT) ||
            ((k->kind[s] & SX_BOND_SMOOTHJOINT) && k->kind[s] != SX_BOND_SMOOTHJOINT))
            return sx__fail(m, SX_EINVAL, "state: bond %lld has an unknown kind %d", (long long)s, k->kind[s]);
        /* a broken flat joint keeps its elements, which the hash reads */
        const int64_t nel = m->fjel.n > 0 ? (int64_t)k->fj_nr[s] * k->fj_na[s] : 0;
        if (nel && (k->fj_first[s] < 0 || k->fj_first[s] + nel > m->fjel.n))
            return sx__fail(m, SX_EINVAL, "state: bond %lld's flat-joint elements (%d x %d from %d) lie outside the %lld elements",
                            (long long)s, k->fj_nr[s], k->fj_na[s], k->fj_first[s], (long long)m->fjel.n);
        if (!k->kind[s]) continue; /* broken: its balls may be gone */
        if (!m->bb.bond) return sx__fail(m, SX_EINVAL, "state: intact bonds but no bond slots in the pair store");
        if (sx__ball_index(m, k->ida[s]) < 0 || sx__ball_index(m, k->idb[s]) < 0 || k->ida[s] == k->idb[s])
            return sx__fail(m, SX_EINVAL, "state: intact bond %lld joins balls %d and %d, which do not exist",
                            (long long)s, k->ida[s], k->idb[s]);
        if ((k->kind[s] & (SX_BOND_PARALLEL | SX_BOND_FLATJOINT)) && !(k->rbar[s] > 0 && k->kn[s] > 0 && k->ks[s] > 0 &&
                                                 isfinite(k->rbar[s]) && isfinite(k->kn[s]) && isfinite(k->ks[s])))
            return sx__fail(m, SX_EINVAL, "state: bond %lld has a radius or stiffness <= 0 or not finite",
                            (long long)s);
        /* NaN or infinite strengths never break, zero or negative ones break at once (m:bond refuses both) */
        if ((k->kind[s] & SX_BOND_PARALLEL) &&
            !(k->sigma_c[s] > 0 && isfinite(k->sigma_c[s]) && k->tau_c[s] > 0 && isfinite(k->tau_c[s])))
            return sx__fail(m, SX_EINVAL, "state: parallel bond %lld has a strength <= 0 or not finite", (long long)s);
        if ((k->kind[s] & SX_BOND_CONTACT) && !(k->cb_n[s] > 0 && isfinite(k->cb_n[s]) && k->cb_s[s] > 0 &&
                                                isfinite(k->cb_s[s])))
            return sx__fail(m, SX_EINVAL, "state: contact bond %lld has a strength <= 0 or not finite", (long long)s);
        /* by their squared lengths: a finite 1e300 breaks the bond into a NaN crack */
        if (!sx__state_length_finite(k->fn + s, 1) || !sx__state_length_finite(k->fs + s * m->dim, m->dim) ||
            !sx__state_length_finite(k->mn + s, 1) || !sx__state_length_finite(k->ms + s * m->rdim, m->rdim))
            return sx__fail(m, SX_EINVAL, "state: bond %lld has a non-finite force or moment", (long long)s);
        if (k->kind[s] & SX_BOND_FLATJOINT) {
            if (k->kind[s] != SX_BOND_FLATJOINT || nel < 1 || (m->dim == 2 && k->fj_na[s] != 1))
                return sx__fail(m, SX_EINVAL, "state: flat joint %lld has bad elements (%d x %d from %d of %lld)",
                                (long long)s, k->fj_nr[s], k->fj_na[s], k->fj_first[s], (long long)m->fjel.n);
            if (!(k->fj_mu[s] >= 0) || !(k->fj_tanphi[s] >= 0) || !sx__state_length_finite(k->fj_mu + s, 1) ||
                !sx__state_length_finite(k->fj_tanphi + s, 1) || !sx__state_length_finite(k->fj_d0 + s, 1) ||
                !sx__state_length_finite(k->fj_rot + s * (m->dim - 1), m->dim - 1) ||
                (m->dim == 3 && !sx__state_length_finite(k->fj_axis + s * 3, 3)))
                return sx__fail(m, SX_EINVAL, "state: flat joint %lld has a friction, gap or rotation that is negative, "
                                              "not finite or too large",
                                (long long)s);
        }
        k->intact++;
    }
    const sx_fjels *E = &m->fjel;
    const int fsd = m->dim - 1;
    for (int64_t e = 0; e < E->n; e++) {
        if (E->state[e] > SX_FJ_SHEAR)
            return sx__fail(m, SX_EINVAL, "state: flat-joint element %lld has an unknown state %d", (long long)e,
                            E->state[e]);
        /* as a bond's: NaN or infinite strengths never break, zero or negative ones break at once */
        if (E->state[e] == SX_FJ_BONDED &&
            !(E->sigma_c[e] > 0 && isfinite(E->sigma_c[e]) && E->coh[e] > 0 && isfinite(E->coh[e])))
            return sx__fail(m, SX_EINVAL, "state: flat-joint element %lld is bonded with a strength <= 0 or not finite",
                            (long long)e);
        if (!sx__state_length_finite(E->gap0 + e, 1) || !sx__state_length_finite(E->fn + e, 1) ||
            !sx__state_length_finite(E->fs + e * fsd, fsd))
            return sx__fail(m, SX_EINVAL, "state: flat-joint element %lld has a gap or force that is not finite or "
                                          "too large (its square overflows)",
                            (long long)e);
    }
    return SX_OK;
}

sx_status sx__state_finish(sx_model *m)
{
    sx_status st;
    if ((st = check_scalars(m)) || (st = check_materials(m)) || (st = check_cmodels(m)) || (st = check_balls(m)) || (st = check_walls(m)) ||
        (m->cell && (st = sx__cell_finish(m))) || (st = check_pairs(m)) || (st = check_bonds(m)) || (st = check_cracks(m)) ||
        (st = sx__clumps_finish(m)))
        return st;
    sx__balls_compact(m);
    /* the ball-ball pass's chunks follow from the pair store alone: planned
     * again they are those the last build made */
    const sx_kernels *k = sx__kernels(m);
    m->nchunk = 0;
    if (m->balls.n > 0 && !k->plan(m)) return sx__fail(m, SX_ENOMEM, "state: out of memory");
    return SX_OK;
}

/* ---------------------------------------------------------------- hash
 *
 * The state hash covers what a restart restores (see state.h), in a
 * canonical form, so that equal hashes mean states that continue
 * bit-identically, and states that differ only in representation hash
 * alike:
 *  - balls, contact histories, bond slots, cracks and clumps as per-row
 *    digests summed (order-free, each digest mixed before the sum so that
 *    no cancellation is cheap: sx_hash_bag), not in dense order (a
 *    broad-phase build re-sorts balls and pairs), so that the ranks of a
 *    scattered model sum their own rows' and add the sums;
 *  - each pair oriented from its smaller ball id (a re-sort can flip a
 *    pair, which negates its vectors, sx__pair_flip);
 *  - -0 hashed as +0;
 *  - what the next cycle derives before its first step hashed as derived:
 *    with a broad-phase build pending, the build positions are the
 *    positions, the walls have not moved, and the automatic timestep is
 *    stale; an automatic timestep is hashed only while it is up to date,
 *    the automatic skin (a fifth of the mean radius at the last build) not. A query that prepares the model (m:timestep(), m:energy(),
 *    m:contacts()) therefore leaves the hash as it was.
 * Left out: the thread count (results do not depend on it), the number of
 * builds (a statistic), caches rebuilt by every cycle (laws, grid,
 * chunks), the profile. */

/* FNV-1a over bytes, and over doubles with -0 hashed as +0 (the hash and
 * the ranks' digests). */
uint64_t sx__fnv(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) h = (h ^ p[i]) * 0x100000001b3ULL;
    return h;
}

uint64_t sx__fnv_doubles(uint64_t h, const double *v, int64_t n, double sign)
{
    for (int64_t i = 0; i < n; i++) {
        const double x = v ? sign * v[i] : 0;
        const double c = x == 0 ? 0.0 : x; /* -0 as +0: the states continue alike */
        h = sx__fnv(h, &c, sizeof c);
    }
    return h;
}

typedef struct hasher {
    uint64_t h;
} hasher;

static void put(hasher *s, const void *data, size_t n) { s->h = sx__fnv(s->h, data, n); }

static void put_doubles(hasher *s, const double *v, int64_t n, double sign) { s->h = sx__fnv_doubles(s->h, v, n, sign); }

static void put_double(hasher *s, double v) { put_doubles(s, &v, 1, 1); }

static void put_int(hasher *s, int64_t v) { put(s, &v, sizeof v); }

/* A 64-bit finaliser (splitmix64): digests are mixed before they are summed. */
static uint64_t mix(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* (model_internal.h) Each digest mixed before the sum, so that no
 * cancellation is cheap. */
void sx__hash_bag_add(sx_hash_bag *b, uint64_t h)
{
    b->sum[0] += mix(h);
    b->sum[1] += mix(h ^ 0x9e3779b97f4a7c15ULL);
    b->n++;
}

static void put_bag(hasher *s, const sx_hash_bag *b)
{
    put_int(s, (int64_t)b->n);
    put(s, b->sum, sizeof b->sum);
}

static void hash_scalars(hasher *s, const sx_model *m)
{
    put_int(s, m->dim);
    put_doubles(s, m->gravity, 3, 1);
    put_double(s, m->dt_user);
    put_double(s, m->dt_safety);
    /* an automatic timestep is derived again before the next step when stale */
    const bool dt_fresh = m->dt_user == 0 && !m->dt_stale && !m->build_needed;
    put_int(s, dt_fresh);
    if (dt_fresh) put_double(s, m->dt);
    put_double(s, m->dt_prev);
    /* the skin in use is the user's or follows from the radii at each build */
    put_double(s, m->skin_user);
    put_double(s, m->time);
    put_int(s, m->step);
    put_int(s, m->guard_on);
    put_int(s, m->guard_dirty);
    put_double(s, m->guard_e0);
    put_double(s, m->guard_scale);
    put_int(s, m->track_energy);
    put_doubles(s, (const double *)&m->acc, sizeof m->acc / sizeof(double), 1);
    put_int(s, m->balls.next_id);
    put_int(s, m->next_wall_id);
}

/* Every registry parameter of a material (the models' and the parts'),
 * each by its unit's and its own name, so that a law added to the registry
 * shifts no other's. */
static void hash_law_params(hasher *s, const sx_material_def *d)
{
    for (int u = 0; u < sx_law_count(); u++) {
        const char *unit = sx_law_name(u);
        for (int k = 0; k < sx_law_param_count(u); k++) {
            const char *name = sx_law_param_name(u, k, NULL);
            put(s, unit, strlen(unit) + 1);
            put(s, name, strlen(name) + 1);
            put_double(s, *sx_law_param_value((sx_material_def *)d, u, k));
        }
    }
}

static void hash_material(hasher *s, const sx_material *t)
{
    put(s, t->name, strnlen(t->name, sizeof t->name));
    put_int(s, t->def.model);
    /* the fixed parameters; the models' own (Hertz's shear_modulus and
     * poisson) come from the registry with the parts' */
    const double def[] = {t->def.density, t->def.kn,       t->def.ks,       t->def.modulus,       t->def.stiffness_ratio,
                          t->def.friction, t->def.damping, t->def.viscous_normal, t->def.viscous_shear};
    put_doubles(s, def, sizeof def / sizeof *def, 1);
    put_doubles(s, (const double *)&t->bpm, sizeof t->bpm / sizeof(double), 1);
    hash_law_params(s, &t->def);
}

static void hash_materials(hasher *s, const sx_model *m)
{
    put_int(s, m->nmat);
    for (int i = 0; i < m->nmat; i++) hash_material(s, &m->mats[i]);
    if (!m->ncmodel) return; /* a model without the table hashes as before it existed */
    put_int(s, m->ncmodel);
    for (int r = 0; r < m->ncmodel; r++) { /* each row: its match and its law */
        const sx_cmodel_row *t = &m->cmodel[r];
        put_int(s, t->def.match);
        put_int(s, t->def.a);
        put_int(s, t->def.b);
        hash_material(s, &t->mat);
    }
}

/* Each ball's digest: its id and state. */
static void bag_balls(sx_hash_bag *out, const sx_model *m, const sx_rows_held *part)
{
    const sx_balls *b = &m->balls;
    const int d = m->dim, r = m->rdim;
    const int64_t lo = part->all ? 0 : part->balls.lo, hi = part->all ? b->n : part->balls.hi;
    for (int64_t i = lo; i < hi; i++) {
        hasher s1 = {SX_FNV_BASIS}, *s = &s1;
        put_int(s, b->id[i]);
        put_doubles(s, b->x + i * d, d, 1);
        put_doubles(s, (m->build_needed ? b->x : b->x_build) + i * d, d, 1);
        put_doubles(s, b->v + i * d, d, 1);
        put_doubles(s, b->w + i * r, r, 1);
        put_doubles(s, b->f + i * d, d, 1);
        put_doubles(s, b->t + i * r, r, 1);
        put_doubles(s, b->fapp ? b->fapp + i * d : NULL, d, 1);
        put_doubles(s, b->tapp ? b->tapp + i * r : NULL, r, 1);
        const double scalars[] = {b->rad[i], b->inv_mass[i], b->inv_inertia[i], sx__ball_damping(m, i)};
        put_doubles(s, scalars, 4, 1);
        put_int(s, b->mat[i]);
        put_int(s, b->fix[i]);
        put_int(s, b->group ? b->group[i] : 0);
        const double *uw = b->unwrap ? b->unwrap + i * d : NULL; /* none: as zeros */
        bool wrapped = false;
        for (int k = 0; uw && k < d; k++) wrapped |= uw[k] != 0;
        if (wrapped) put_doubles(s, uw, d, 1);
        sx__hash_bag_add(out, s1.h);
    }
}

/* The order-free sum of the digests of the pairs with a live history:
 * every field of the store's schema (sx__pair_fields: a law's history
 * fields join it there), its vectors from the pair's smaller id. */
static void bag_pairs(sx_hash_bag *out, const sx_model *m, const sx_pairs *p, bool walls, const sx_rows_held *part)
{
    const int d = m->dim, r = m->rdim;
    const sx_bonds *k = &m->bonds;
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, (sx_pairs *)p, f);
    const sx_span rows = part->all ? (sx_span){0, p->n} : walls ? part->bw : part->bb;
    for (int64_t c = rows.lo; c < rows.hi; c++) {
        if (!p->touching[c]) continue;
        int64_t ia = m->balls.id[p->a[c]], ib = walls ? m->walls[p->b[c]].id : m->balls.id[p->b[c]];
        /* a ball-ball pair from its smaller id: the vectors of b -> a are the negated ones */
        const double sign = !walls && ia > ib ? -1 : 1;
        if (sign < 0) {
            const int64_t t = ia;
            ia = ib;
            ib = t;
        }
        hasher one = {SX_FNV_BASIS};
        put_int(&one, ia);
        put_int(&one, ib);
        if (!walls && m->cell && p->b[c] >= m->cell->base) { /* b is a ghost: the image it is seen through */
            const int8_t *image = m->cell->image + (p->b[c] - m->cell->base) * 3;
            for (int k = 0; k < 3; k++) put_int(&one, (int64_t)(sign * image[k]));
        }
        for (int j = 0; j < nf; j++) {
            /* the ends are the ids above (a mesh's facet is hashed here); the bond slot below, present or not */
            if (f[j].data == (void **)&p->a || f[j].data == (void **)&p->b || f[j].data == (void **)&p->bond) continue;
            const int64_t at = c * f[j].per;
            if (f[j].type == SX_FIELD_F64)
                put_doubles(&one, (const double *)*f[j].data + at, f[j].per, f[j].sign ? sign : 1);
            else
                for (int e = 0; e < f[j].per; e++)
                    put_int(&one, f[j].type == SX_FIELD_I32 ? ((const int32_t *)*f[j].data)[at + e]
                                                           : ((const uint8_t *)*f[j].data)[at + e]);
        }
        const int32_t slot = p->bond ? p->bond[c] - 1 : -1;
        put_int(&one, slot);
        if (slot >= 0) { /* the bond's vectors follow the pair's orientation (sx__bond_flip) */
            put_doubles(&one, k->fs + (int64_t)slot * d, d, sign);
            put_doubles(&one, k->ms + (int64_t)slot * r, r, sign);
        }
        sx__hash_bag_add(out, one.h);
    }
}

/* Each bond's digest: its slot (slots are never reused: canonical) and
 * state, with a flat joint's face and its elements. */
static void bag_bonds(sx_hash_bag *out, const sx_model *m, const sx_rows_held *part)
{
    const sx_bonds *k = &m->bonds;
    const sx_fjels *e = &m->fjel;
    const int t = m->dim - 1;
    for (int64_t i = 0; i < k->n; i++) {
        if (!part->all && !part->bond[i]) continue;
        hasher s1 = {SX_FNV_BASIS}, *s = &s1;
        put_int(s, i);
        put_int(s, k->kind[i]);
        put_int(s, k->ida[i]);
        put_int(s, k->idb[i]);
        const double v[] = {k->cb_n[i], k->cb_s[i], k->rbar[i], k->kn[i],
                            k->ks[i],   k->sigma_c[i], k->tau_c[i], k->fn[i], k->mn[i]};
        put_doubles(s, v, sizeof v / sizeof *v, 1);
        if (e->n > 0) { /* flat joints (laws/flatjoint.h): the face, then the elements */
            const int64_t nel = (int64_t)k->fj_nr[i] * k->fj_na[i];
            if (k->kind[i] & SX_BOND_FLATJOINT) {
                put_int(s, k->fj_first[i]);
                put_int(s, k->fj_nr[i]);
                put_int(s, k->fj_na[i]);
                const double f[] = {k->fj_mu[i], k->fj_tanphi[i], k->fj_d0[i]};
                put_doubles(s, f, 3, 1);
                put_doubles(s, k->fj_rot + i * t, t, 1);
                if (m->dim == 3) put_doubles(s, k->fj_axis + i * 3, 3, 1);
            }
            for (int64_t x = k->fj_first[i]; x < k->fj_first[i] + nel; x++) {
                put_int(s, e->state[x]);
                const double g[] = {e->sigma_c[x], e->coh[x], e->gap0[x], e->fn[x]};
                put_doubles(s, g, 4, 1);
                put_doubles(s, e->fs + x * t, t, 1);
            }
        }
        sx__hash_bag_add(out, s1.h);
    }
}

/* Of a scattered model, rank 0 holds the merged entries, and each rank
 * those of its own balls' bonds that it logged since (the other ranks
 * that stepped the bond logged it too). */
bool sx__holds_crack(const sx_model *m, const sx_rows_held *part, int64_t i)
{
    if (part->all) return true;
    if (i < part->crack0) return part->first;
    const int64_t a = sx__ball_index(m, m->cracks.ev[i].a);
    return a >= part->balls.lo && a < part->balls.hi;
}

static uint64_t crack_digest(const sx_crack *c)
{
    hasher s = {SX_FNV_BASIS};
    put_int(&s, c->step);
    put_int(&s, c->mode);
    put_int(&s, c->kind);
    put_int(&s, c->a);
    put_int(&s, c->b);
    const double v[] = {c->time, c->pos[0], c->pos[1], c->pos[2], c->fn, c->fs, c->mn, c->ms};
    put_doubles(&s, v, sizeof v / sizeof *v, 1);
    return s.h;
}

/* Each crack's digest (order-free: the ranks hold the log's newest
 * entries in parts until a gather merges them in the serial order). */
static void bag_cracks(sx_hash_bag *out, const sx_model *m, const sx_rows_held *part)
{
    for (int64_t i = 0; i < m->cracks.n; i++)
        if (sx__holds_crack(m, part, i)) sx__hash_bag_add(out, crack_digest(&m->cracks.ev[i]));
}

static void hash_walls(hasher *s, const sx_model *m)
{
    put_int(s, m->nwall);
    for (int64_t i = 0; i < m->nwall; i++) {
        const sx_wall *w = &m->walls[i];
        put_int(s, w->id);
        put_int(s, w->def.kind);
        put_doubles(s, w->def.point, 3, 1);
        put_doubles(s, w->def.normal, 3, 1);
        put_doubles(s, w->def.edge1, 3, 1);
        put_doubles(s, w->def.edge2, 3, 1);
        put_doubles(s, w->def.vel, 3, 1);
        const double def[] = {w->def.radius, w->def.height, w->def.radial_vel, w->def.kn, w->def.ks, w->def.friction};
        put_doubles(s, def, sizeof def / sizeof *def, 1);
        put_doubles(s, w->force, 3, 1);
        put_doubles(s, w->moment, 3, 1);
        const double last[] = {w->load, w->kn_sum, m->build_needed ? 0 : w->moved};
        put_doubles(s, last, 3, 1);
        put_int(s, w->contacts);
        if (w->def.material != SX_WALL_NO_MATERIAL) put_int(s, w->def.material); /* a plain wall hashes as before */
        if (w->mesh) { /* its turn and spin */
            put_doubles(s, w->mesh->q, sizeof w->mesh->q / sizeof(double), 1);
            put_doubles(s, w->def.spin, 3, 1);
        }
        put_int(s, w->servo_on);
        if (w->servo_on) put_doubles(s, (const double *)&w->servo, sizeof w->servo / sizeof(double), 1);
    }
}

/* The clumps, the periodic cell and the smooth joints, each hashed by its
 * module (the clumps' own digests summed in clumps). */
static bool has_clumps(const sx_model *m)
{
    /* an empty clump store (a template that was refused) is no clumps */
    return m->clumps && (m->clumps->ntpl > 0 || m->clumps->n > 0);
}

static void hash_stores(hasher *s, const sx_model *m, const sx_hash_bag *clumps)
{
    if (has_clumps(m)) {
        s->h = sx__clumps_hash(m, s->h);
        put_bag(s, clumps);
    }
    if (m->cell) s->h = sx__cell_hash(m, s->h);
    if (m->njoint) s->h = sx__joints_hash(m, s->h);
}

enum { BAG_BALLS, BAG_BB, BAG_BW, BAG_BONDS, BAG_CRACKS, BAG_CLUMPS, BAGS };

/* The rows go into order-free sums, so that a decomposed model left
 * scattered by a lazy cycle hashes without a gather: each rank sums the
 * digests of the rows it holds current (sx__dd_rows_held), and the sums
 * are added over the ranks (a collective call then). Every rank that
 * could not take part makes the hash 0 on every rank. */
uint64_t sx_model_state_hash(const sx_model *m)
{
    sx_rows_held part = {.all = true};
    sx_hash_bag b[BAGS + 1] = {{0, {0, 0}}}; /* the last: a count of the ranks that failed */
    const bool scattered = sx_model_scattered(m);
    if (scattered && !sx__dd_rows_held(m, &part)) b[BAGS].n = 1;
    if (!b[BAGS].n) {
        bag_balls(&b[BAG_BALLS], m, &part);
        bag_pairs(&b[BAG_BB], m, &m->bb, false, &part);
        bag_pairs(&b[BAG_BW], m, &m->bw, true, &part);
        bag_bonds(&b[BAG_BONDS], m, &part);
        bag_cracks(&b[BAG_CRACKS], m, &part);
        if (has_clumps(m)) sx__clumps_bag(m, &part, &b[BAG_CLUMPS]);
    }
    free(part.bond);
    if (scattered && !sx__dd_sum(m, (uint64_t *)b, (int)(sizeof b / (sizeof(uint64_t))))) return 0;
    if (b[BAGS].n) return 0;
    hasher s = {SX_FNV_BASIS};
    hash_scalars(&s, m);
    hash_materials(&s, m);
    put_int(&s, m->balls.n);
    put_bag(&s, &b[BAG_BALLS]);
    hash_walls(&s, m);
    put_bag(&s, &b[BAG_BB]);
    put_bag(&s, &b[BAG_BW]);
    put_int(&s, m->bonds.n);
    put_int(&s, m->fjel.n);
    put_bag(&s, &b[BAG_BONDS]);
    put_bag(&s, &b[BAG_CRACKS]); /* its count is the log's (a scattered rank holds a part beyond crack0) */
    hash_stores(&s, m, &b[BAG_CLUMPS]);
    return s.h;
}

/* ---------------------------------------------------------------- digest */

/* What the ranks of a decomposed model compare when a cycle starts
 * (decompose.c): ranks that made the same calls hold the same bytes in
 * the same dense order, so the big stores (balls, pairs, bonds) go raw, a
 * word at a time in four independent lanes (xxHash's round), at about the
 * speed of memory; the byte-at-a-time canonical hash costs some five steps
 * of a 400,000-ball bed, at every cycle's start. The small parts and the
 * crack log go through the canonical hash's functions. Not a state hash:
 * it depends on the dense order and on the representation. */
typedef struct digest {
    uint64_t lane[4];
} digest;

static uint64_t digest_round(uint64_t acc, uint64_t w)
{
    acc += w * 0xc2b2ae3d27d4eb4fULL;
    acc = acc << 31 | acc >> 33;
    return acc * 0x9e3779b185ebca87ULL;
}

/* n entries of size bytes at data; a NULL array (an optional one not
 * allocated) differs from any allocated one. */
static void digest_array(digest *g, const void *data, int64_t n, size_t size)
{
    const size_t bytes = data ? (size_t)n * size : 0;
    const unsigned char *p = data;
    size_t i = 0;
    for (; i + 32 <= bytes; i += 32)
        for (int k = 0; k < 4; k++) {
            uint64_t w;
            memcpy(&w, p + i + 8 * k, sizeof w);
            g->lane[k] = digest_round(g->lane[k], w);
        }
    for (; i < bytes; i++) g->lane[i & 3] = digest_round(g->lane[i & 3], p[i]);
    g->lane[0] = digest_round(g->lane[0], data ? (uint64_t)bytes : UINT64_MAX);
}

static void digest_balls(digest *g, const sx_model *m)
{
    const sx_balls *b = &m->balls;
    const uint64_t counts[] = {(uint64_t)b->n, (uint64_t)b->next_id};
    digest_array(g, counts, 2, sizeof *counts);
    sx_ball_field f[SX_BALL_FIELDS_MAX];
    const int nf = sx__ball_fields(m, (sx_balls *)b, f);
    for (int k = 0; k < nf; k++) digest_array(g, *f[k].data, b->n * f[k].per, sx__field_size(f[k].type));
}

/* Every field of the store's schema (the ends too: the build's lists). */
static void digest_pairs(digest *g, const sx_model *m, const sx_pairs *p)
{
    sx_pair_field f[SX_PAIR_FIELDS_MAX];
    const int nf = sx__pair_fields(m, (sx_pairs *)p, f);
    digest_array(g, &p->n, 1, sizeof p->n);
    for (int k = 0; k < nf; k++) digest_array(g, *f[k].data, p->n * f[k].per, sx__pair_size(&f[k]));
}

static void digest_bonds(digest *g, const sx_model *m)
{
    const sx_bonds *k = &m->bonds;
    const sx_fjels *e = &m->fjel;
    const int64_t n = k->n, t = m->dim - 1;
    digest_array(g, &k->n, 1, sizeof k->n);
    sx_bond_field f[SX_BOND_FIELDS_MAX];
    const int nf = sx__bond_fields(m, (sx_bonds *)k, f);
    for (int j = 0; j < nf; j++) /* a flat joint's only once the model has elements */
        if (!f[j].joint || e->n) digest_array(g, *f[j].data, n * f[j].per, sx__field_size(f[j].type));
    digest_array(g, &e->n, 1, sizeof e->n);
    digest_array(g, e->state, e->n, sizeof *e->state);
    digest_array(g, e->sigma_c, e->n, sizeof *e->sigma_c);
    digest_array(g, e->coh, e->n, sizeof *e->coh);
    digest_array(g, e->gap0, e->n, sizeof *e->gap0);
    digest_array(g, e->fn, e->n, sizeof *e->fn);
    digest_array(g, e->fs, e->n * t, sizeof *e->fs);
}

/* What every rank holds whole, even while the balls are scattered. */
static void hash_replicated(hasher *s, const sx_model *m)
{
    hash_scalars(s, m);
    hash_materials(s, m);
    hash_walls(s, m);
}

uint64_t sx__replicated_digest(const sx_model *m)
{
    hasher s = {SX_FNV_BASIS};
    hash_replicated(&s, m);
    return mix(s.h);
}

uint64_t sx__state_digest(const sx_model *m)
{
    hasher s = {SX_FNV_BASIS};
    hash_replicated(&s, m);
    /* the crack log in its order (the ranks hold it whole and alike here) */
    put_int(&s, m->cracks.n);
    for (int64_t i = 0; i < m->cracks.n; i++) put_int(&s, (int64_t)crack_digest(&m->cracks.ev[i]));
    const sx_rows_held all = {.all = true};
    sx_hash_bag clumps = {0, {0, 0}};
    if (has_clumps(m)) sx__clumps_bag(m, &all, &clumps);
    hash_stores(&s, m, &clumps);
    digest g = {{s.h, SX_FNV_BASIS, ~SX_FNV_BASIS, s.h ^ 0x9e3779b97f4a7c15ULL}};
    digest_balls(&g, m);
    digest_pairs(&g, m, &m->bb);
    digest_pairs(&g, m, &m->bw);
    digest_bonds(&g, m);
    uint64_t h = 0;
    for (int k = 0; k < 4; k++) h = mix(h ^ g.lane[k]);
    return h;
}
