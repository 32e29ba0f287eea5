/* Sizing and checking the complete state of a model for the I/O layer
 * (see state.h). Allocation goes through the model's tracked allocator
 * with the same capacity rules as the stores' own growth, so a restored
 * model grows, frees and reports its bytes like any other. */
#include "state.h"

#include "clumps.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

void sx__state_sizes(const sx_model *m, sx_state_sizes *out)
{
    memset(out, 0, sizeof *out);
    out->balls = m->balls.n;
    out->next_ball_id = m->balls.next_id < 1 ? 1 : m->balls.next_id;
    out->applied = m->balls.fapp != NULL;
    out->bb = m->bb.n;
    out->bw = m->bw.n;
    out->bw_facets = m->mesh_pairs;
    out->bb_bonds = m->bb.bond != NULL;
    out->rolling = m->bb.mr != NULL;
    out->total_shear = m->bb.us != NULL;
    out->bonds = m->bonds.n;
    out->cracks = m->cracks.n;
    out->walls = m->nwall;
    out->materials = m->nmat;
}

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
        s->bonds > INT32_MAX - 1 || s->cracks < 0 || s->walls < 0 || s->walls > INT32_MAX || s->materials < 0 ||
        s->materials > UINT16_MAX)
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
    m->bb.n = s->bb;
    m->bw.n = s->bw;

    /* bonds and cracks at exactly their sizes; the stores grow from there */
    sx_bonds *k = &m->bonds;
    const int64_t nb = s->bonds;
    if (!alloc_array(m, (void **)&k->kind, nb, 1) || !alloc_array(m, (void **)&k->ida, nb, sizeof(int32_t)) ||
        !alloc_array(m, (void **)&k->idb, nb, sizeof(int32_t)) || !alloc_array(m, (void **)&k->cb_n, nb, sizeof(double)) ||
        !alloc_array(m, (void **)&k->cb_s, nb, sizeof(double)) || !alloc_array(m, (void **)&k->rbar, nb, sizeof(double)) ||
        !alloc_array(m, (void **)&k->kn, nb, sizeof(double)) || !alloc_array(m, (void **)&k->ks, nb, sizeof(double)) ||
        !alloc_array(m, (void **)&k->sigma_c, nb, sizeof(double)) ||
        !alloc_array(m, (void **)&k->tau_c, nb, sizeof(double)) || !alloc_array(m, (void **)&k->fn, nb, sizeof(double)) ||
        !alloc_array(m, (void **)&k->fs, nb * d, sizeof(double)) || !alloc_array(m, (void **)&k->mn, nb, sizeof(double)) ||
        !alloc_array(m, (void **)&k->ms, nb * r, sizeof(double)))
        goto nomem;
    k->n = k->cap = nb;
    if (!alloc_array(m, (void **)&m->cracks.ev, s->cracks, sizeof(sx_crack))) goto nomem;
    m->cracks.n = m->cracks.cap = s->cracks;

    if (!alloc_array(m, (void **)&m->walls, s->walls, sizeof(sx_wall))) goto nomem;
    m->nwall = m->cap_wall = s->walls;
    if (!alloc_array(m, (void **)&m->mats, s->materials, sizeof(sx_material))) goto nomem;
    m->nmat = m->cap_mat = s->materials;
    return SX_OK;
nomem:
    return sx__fail(m, SX_ENOMEM, "state: out of memory for %lld balls, %lld pairs, %lld bonds", (long long)s->balls,
                    (long long)(s->bb + s->bw), (long long)s->bonds);
}

static bool finite_all(const double *v, int64_t n)
{
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

static sx_status check_scalars(sx_model *m)
{
    const char *why = NULL;
    if (!finite_all(m->gravity, 3)) why = "gravity is not finite";
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
        char why[256];
        if (sx__law_check(&t->def, why, sizeof why))
            return sx__fail(m, SX_EINVAL, "state: material '%s' (contact model %d): %s", t->name, (int)t->def.model,
                            why);
        sx__material_derive(t);
        if (!(t->def.density > 0) || !isfinite(t->def.density) || !(t->def.stiffness_ratio > 0))
            return sx__fail(m, SX_EINVAL, "state: material '%s' has a density or stiffness ratio <= 0", t->name);
    }
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
        if (id < 1 || id >= b->next_id)
            return sx__fail(m, SX_EINVAL, "state: ball %lld has id %lld outside 1..%lld", (long long)i, (long long)id,
                            (long long)(b->next_id - 1));
        if (b->index_of[id] >= 0) return sx__fail(m, SX_EINVAL, "state: ball id %lld appears twice", (long long)id);
        b->index_of[id] = (int32_t)i;
        if (b->mat[i] >= m->nmat)
            return sx__fail(m, SX_EINVAL, "state: ball %lld has material %d, there are %d", (long long)id,
                            (int)b->mat[i], m->nmat);
        if (b->fix[i] & ~valid) return sx__fail(m, SX_EINVAL, "state: ball %lld has invalid fixity bits", (long long)id);
        const double alpha = sx__ball_damping(m, i);
        if (!(b->rad[i] > 0) || !isfinite(b->rad[i]) || !(b->inv_mass[i] > 0) || !isfinite(b->inv_mass[i]) ||
            !(b->inv_inertia[i] > 0) || !isfinite(b->inv_inertia[i]) || !(alpha >= 0 && alpha < 1))
            return sx__fail(m, SX_EINVAL, "state: ball %lld has a radius, mass, inertia or damping out of range",
                            (long long)id);
        if (!finite_all(b->x + i * d, d) || !finite_all(b->x_build + i * d, d) || !finite_all(b->v + i * d, d) ||
            !finite_all(b->w + i * r, r))
            return sx__fail(m, SX_EINVAL, "state: ball %lld has a non-finite position, velocity or spin",
                            (long long)id);
    }
    return SX_OK;
}

/* A restored mesh: its numbers in range, then what follows from them. */
static sx_status check_mesh(sx_model *m, sx_wall *w)
{
    sx_mesh *s = w->mesh;
    const double *q = s->q, qq = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!finite_all(s->body, 3 * s->nv) || !finite_all(w->def.spin, 3) || !finite_all(q, 4) || !(fabs(qq - 1) < 1e-9))
        return sx__fail(m, SX_EINVAL, "state: mesh wall %lld has a non-finite vertex or spin, or an orientation that "
                                      "is not a unit quaternion", (long long)w->id);
    for (int64_t t = 0; t < 3 * s->nt; t++)
        if (s->tri[t] < 0 || s->tri[t] >= s->nv)
            return sx__fail(m, SX_EINVAL, "state: mesh wall %lld: triangle %lld names vertex %d of %lld", (long long)w->id,
                            (long long)(t / 3), s->tri[t], (long long)s->nv);
    if (!sx__mesh_derive(m, s)) return sx__fail(m, SX_ENOMEM, "state: out of memory");
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
        if (!finite_all(w->def.point, 3) || !finite_all(w->def.normal, 3) || !finite_all(w->def.vel, 3))
            return sx__fail(m, SX_EINVAL, "state: wall %lld has a non-finite point, normal or velocity", (long long)w->id);
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

static sx_status check_pairs(sx_model *m)
{
    const int64_t n = m->balls.n;
    const sx_pairs *p = &m->bb;
    for (int64_t c = 0; c < p->n; c++) {
        if (p->a[c] < 0 || p->a[c] >= p->b[c] || p->b[c] >= n)
            return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld refers to balls %d, %d of %lld", (long long)c,
                            p->a[c], p->b[c], (long long)n);
        if (p->touching[c] > 1) return sx__fail(m, SX_EINVAL, "state: ball-ball pair %lld has a bad touching flag", (long long)c);
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
        const sx_mesh *mesh = m->walls[p->b[c]].mesh;
        const int32_t facet = p->facet ? p->facet[c] : 0;
        if (facet < 0 || (mesh ? facet >= mesh->nt : facet != 0))
            return sx__fail(m, SX_EINVAL, "state: ball-wall pair %lld names facet %d of wall %lld, which has none such",
                            (long long)c, facet, (long long)m->walls[p->b[c]].id);
    }
    return SX_OK;
}

static sx_status check_bonds(sx_model *m)
{
    sx_bonds *k = &m->bonds;
    k->intact = 0;
    for (int64_t s = 0; s < k->n; s++) {
        if (k->kind[s] & ~(unsigned)(SX_BOND_CONTACT | SX_BOND_PARALLEL))
            return sx__fail(m, SX_EINVAL, "state: bond %lld has an unknown kind %d", (long long)s, k->kind[s]);
        if (!k->kind[s]) continue; /* broken: its balls may be gone */
        if (!m->bb.bond) return sx__fail(m, SX_EINVAL, "state: intact bonds but no bond slots in the pair store");
        if (sx__ball_index(m, k->ida[s]) < 0 || sx__ball_index(m, k->idb[s]) < 0 || k->ida[s] == k->idb[s])
            return sx__fail(m, SX_EINVAL, "state: intact bond %lld joins balls %d and %d, which do not exist",
                            (long long)s, k->ida[s], k->idb[s]);
        if ((k->kind[s] & SX_BOND_PARALLEL) && !(k->rbar[s] > 0 && k->kn[s] > 0 && k->ks[s] > 0))
            return sx__fail(m, SX_EINVAL, "state: parallel bond %lld has a radius or stiffness <= 0", (long long)s);
        k->intact++;
    }
    return SX_OK;
}

sx_status sx__state_finish(sx_model *m)
{
    sx_status st;
    if ((st = check_scalars(m)) || (st = check_materials(m)) || (st = check_balls(m)) || (st = check_walls(m)) ||
        (st = check_pairs(m)) || (st = check_bonds(m)) || (st = sx__clumps_finish(m)))
        return st;
    sx__balls_compact(m);
    /* the ball-ball pass's chunks follow from the pair store alone: planned
     * again they are those the last build made */
    const sx_kernels *k = m->dim == 2 ? &sx_kernels_2d : &sx_kernels_3d;
    m->nchunk = 0;
    if (m->balls.n > 0 && !k->plan(m)) return sx__fail(m, SX_ENOMEM, "state: out of memory");
    return SX_OK;
}
