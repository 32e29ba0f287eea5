/* The contact-model table (PFC's contact model assignment table; issue 12
 * item 7): rows giving the ball-ball contacts of a pair of groups, of a
 * pair of materials, or any other, and the ball-wall contacts of a wall
 * with a ball group, a ball material or any ball, their own law and
 * parameters. A contact
 * takes its row when it is created and keeps it (sx_pairs.cmodel, a field
 * of the pair schema: restarts, the hash and snapshots carry it); a model
 * without rows has no such field and runs as it did before the table. */
#include "laws/law.h"

#include <stdio.h>
#include <string.h>

enum { CMODEL_MAX = 4096 }; /* rows, at most: a table is a handful of lines */

/* Does row r match balls of groups ga, gb and materials ma, mb? */
static bool matches(const sx_cmodel_def *r, int32_t ga, int32_t gb, int32_t ma, int32_t mb)
{
    if (r->match == SX_CMODEL_GROUPS) return (r->a == ga && r->b == gb) || (r->a == gb && r->b == ga);
    if (r->match == SX_CMODEL_MATERIALS) return (r->a == ma && r->b == mb) || (r->a == mb && r->b == ma);
    return r->match == SX_CMODEL_DEFAULT;
}

static bool is_wall_row(const sx_cmodel_def *r) { return r->match >= SX_CMODEL_WALL_GROUP && r->match <= SX_CMODEL_WALL; }

int32_t sx__cmodel_pick(const sx_model *m, int64_t i, int64_t j)
{
    const sx_balls *B = &m->balls;
    const int32_t ga = B->group ? B->group[i] : 0, gb = B->group ? B->group[j] : 0;
    const int32_t ma = B->mat[i], mb = B->mat[j];
    /* the most specific kind first, the newest row of a kind first */
    static const sx_cmodel_match order[] = {SX_CMODEL_GROUPS, SX_CMODEL_MATERIALS, SX_CMODEL_DEFAULT};
    for (int k = 0; k < 3; k++)
        for (int r = m->ncmodel - 1; r >= 0; r--) {
            const sx_cmodel_def *d = &m->cmodel[r].def;
            if (d->match == order[k] && matches(d, ga, gb, ma, mb)) return r + 1;
        }
    return 0;
}

int32_t sx__cmodel_pick_wall(const sx_model *m, int64_t i, int64_t w)
{
    const int32_t g = m->balls.group ? m->balls.group[i] : 0, mat = m->balls.mat[i];
    const int64_t id = m->walls[w].id;
    /* as for two balls: a ball group's row, a ball material's, any ball's; the newest first */
    static const sx_cmodel_match order[] = {SX_CMODEL_WALL_GROUP, SX_CMODEL_WALL_MATERIAL, SX_CMODEL_WALL};
    for (int k = 0; k < 3; k++)
        for (int r = m->ncmodel - 1; r >= 0; r--) {
            const sx_cmodel_def *d = &m->cmodel[r].def;
            if (d->match == order[k] && d->b == id &&
                (order[k] == SX_CMODEL_WALL || d->a == (order[k] == SX_CMODEL_WALL_GROUP ? g : mat)))
                return r + 1;
        }
    return 0;
}

const char *sx__cmodel_invalid(const sx_model *m, const sx_cmodel_def *d, char *why, size_t len)
{
    if (d->match == SX_CMODEL_GROUPS && (d->a < 0 || d->b < 0))
        return snprintf(why, len, "a group number must be >= 0 (got %d and %d)", (int)d->a, (int)d->b), why;
    if (d->match == SX_CMODEL_MATERIALS && (d->a < 0 || d->a >= m->nmat || d->b < 0 || d->b >= m->nmat))
        return snprintf(why, len, "no material with index %d or %d (there are %d)", (int)d->a, (int)d->b, m->nmat), why;
    if (d->match == SX_CMODEL_WALL_GROUP && d->a < 0)
        return snprintf(why, len, "a group number must be >= 0 (got %d)", (int)d->a), why;
    if (d->match == SX_CMODEL_WALL_MATERIAL && (d->a < 0 || d->a >= m->nmat))
        return snprintf(why, len, "no material with index %d (there are %d)", (int)d->a, m->nmat), why;
    if (d->match == SX_CMODEL_WALL && d->a != 0)
        return snprintf(why, len, "a row of any ball with a wall takes no ball match (got %d)", (int)d->a), why;
    if (is_wall_row(d) && d->b <= 0) return snprintf(why, len, "no wall with id %d", (int)d->b), why;
    if (is_wall_row(d) && d->law.modulus > 0)
        return snprintf(why, len, "a wall takes no BPM modulus law (the modulus is for two balls' radii)"), why;
    if (d->match < SX_CMODEL_DEFAULT || d->match > SX_CMODEL_WALL)
        return snprintf(why, len, "the match must be default, groups, materials or one of a wall's"), why;
    return sx__material_invalid(&d->law, why, len);
}

sx_status sx_cmodel_add(sx_model *m, const char *name, const sx_cmodel_def *def, int *row)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "contact_model: the model is stepping");
    if (!name || !*name || strlen(name) >= sizeof m->cmodel[0].mat.name)
        return sx__fail(m, SX_EINVAL, "contact_model: the name must have 1 to %zu characters",
                        sizeof m->cmodel[0].mat.name - 1);
    char why[256];
    if (sx__cmodel_invalid(m, def, why, sizeof why)) return sx__fail(m, SX_EINVAL, "contact_model '%s': %s", name, why);
    if (m->ncmodel >= CMODEL_MAX) return sx__fail(m, SX_EINVAL, "contact_model: more than %d rows", CMODEL_MAX);
    /* the store of the row's pairs carries each contact's row from its first row on */
    if (!sx__cmodel_store(m, is_wall_row(def) ? &m->bw : &m->bb))
        return sx__fail(m, SX_ENOMEM, "contact_model: out of memory");
    if (m->ncmodel == m->cap_cmodel) {
        const int cap = m->cap_cmodel ? 2 * m->cap_cmodel : 4;
        sx_cmodel_row *q = sx_alloc_resize(&m->alloc, m->cmodel, (size_t)m->cap_cmodel, (size_t)cap, sizeof *q);
        if (!q) return sx__fail(m, SX_ENOMEM, "contact_model: out of memory");
        m->cmodel = q;
        m->cap_cmodel = cap;
    }
    sx_cmodel_row *r = &m->cmodel[m->ncmodel];
    memset(r, 0, sizeof *r);
    r->def = *def;
    snprintf(r->mat.name, sizeof r->mat.name, "%s", name);
    r->mat.def = def->law;
    sx__cmodel_derive(r);
    m->ncmodel++;
    m->dt_stale = true;
    m->guard_dirty = true; /* the contacts' laws may change: a new baseline */
    if (row) *row = m->ncmodel;
    return SX_OK;
}

bool sx__cmodel_store(sx_model *m, sx_pairs *p)
{
    if (sx__pairs_reserve(m, p, 1)) return false; /* a store with room, so the array exists */
    if (!p->cmodel) p->cmodel = sx_alloc_resize(&m->alloc, NULL, 0, (size_t)p->cap, sizeof *p->cmodel);
    return p->cmodel != NULL;
}

bool sx__cmodel_any(const sx_model *m, bool walls)
{
    for (int r = 0; r < m->ncmodel; r++)
        if (is_wall_row(&m->cmodel[r].def) == walls) return true;
    return false;
}

void sx__cmodel_derive(sx_cmodel_row *r)
{
    sx__material_derive(&r->mat);
    r->law = sx__pair_law_of(&r->mat, &r->mat); /* two balls of the row's material (4-22/4-23) */
    sx_wall_def w = {0};
    w.material = 0; /* a wall of the row's material (walls.c), not rigid */
    r->wlaw = sx__wall_law_of(&r->mat, &r->mat, &w);
}

int sx_cmodel_count(const sx_model *m) { return m->ncmodel; }

sx_status sx_cmodel_get(const sx_model *m, int row, sx_cmodel_def *def, const char **name)
{
    if (row < 1 || row > m->ncmodel)
        return sx__fail((sx_model *)m, SX_ENOTFOUND, "contact_model: no row %d (there are %d)", row, m->ncmodel);
    if (def) *def = m->cmodel[row - 1].def;
    if (name) *name = m->cmodel[row - 1].mat.name;
    return SX_OK;
}

sx_status sx__cmodel_prepare(sx_model *m)
{
    for (int r = 0; r < m->ncmodel; r++) { /* a row's law's history joins the pair stores, as a material's */
        const sx_material_def *d = &m->cmodel[r].mat.def;
        if ((d->rolling_friction > 0 && sx__pairs_expand(m, offsetof(sx_pairs, mr), m->rdim)) ||
            (d->total_shear == 1 && sx__pairs_expand(m, offsetof(sx_pairs, us), m->dim)))
            return sx__fail(m, SX_ENOMEM, "cycle: out of memory");
    }
    const sx_pairs *p = &m->bb;
    for (int64_t c = 0; p->bond && p->cmodel && c < p->n; c++) { /* seed 4.3.3: a bonded contact's law must take bonds */
        const int32_t r = p->touching[c] ? p->cmodel[c] : sx__cmodel_pick(m, p->a[c], p->b[c]);
        if (!p->bond[c] || !r || sx__law(m->cmodel[r - 1].law.law)->bonds) continue;
        return sx__fail(m, SX_EINVAL,
                        "contact model: balls %lld and %lld are bonded but their contact-model row '%s' uses the %s "
                        "model, which is not to be combined with bonds (seed 4.3.3)",
                        (long long)m->balls.id[p->a[c]], (long long)m->balls.id[p->b[c]], m->cmodel[r - 1].mat.name,
                        sx_law_name(m->cmodel[r - 1].law.law));
    }
    return SX_OK;
}
