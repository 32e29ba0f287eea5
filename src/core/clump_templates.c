/* Clump templates: a clump's shape, its pebbles in its own frame, defined
 * once by name and never removed (their store is in clumps.h, their mass
 * properties are computed by clump_mass.c). The API checks what a user
 * gives and reads back what a template holds. */
#include "clump_math.h"
#include "clumps_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

sx_status sx_clump_template_add(sx_model *m, const char *name, const sx_clump_template_def *def, int *out)
{
    if (m->locked) return sx__fail(m, SX_ELOCKED, "clump_template: the model is stepping");
    if (!name || !*name || strlen(name) >= sizeof m->clumps->tpl[0].name)
        return sx__fail(m, SX_EINVAL, "clump_template: the name must have 1 to %zu characters",
                        sizeof m->clumps->tpl[0].name - 1);
    if (sx_clump_template_find(m, name) >= 0)
        return sx__fail(m, SX_EINVAL, "clump_template: a template named '%s' exists (templates cannot be redefined)",
                        name);
    if (def->count < 1 || def->count > 1000000 || !def->pos || !def->radius)
        return sx__fail(m, SX_EINVAL, "clump_template '%s': 1 to 1000000 pebbles expected (got %lld)", name,
                        (long long)def->count);
    /* 3D integrates over lines x lines lines: 2^20 of them per axis would
     * take days, and nothing (not even a Ctrl-C) could stop it */
    const int64_t max_lines = m->dim == 3 ? LINES_MAX_3D : LINES_MAX_2D;
    if (def->lines != 0 && (def->lines < LINES_MIN || def->lines > max_lines))
        return sx__fail(m, SX_EINVAL, "clump_template '%s': lines must be 0 (default) or in %d..%lld (got %lld)", name,
                        LINES_MIN, (long long)max_lines, (long long)def->lines);
    const int d = m->dim;
    for (int64_t i = 0; i < def->count; i++) {
        bool ok = def->radius[i] > 0 && isfinite(def->radius[i]);
        for (int k = 0; k < d; k++) ok &= isfinite(def->pos[i * d + k]) && fabs(def->pos[i * d + k]) < 1e100;
        if (!ok || def->radius[i] > 1e100)
            return sx__fail(m, SX_EINVAL, "clump_template '%s': pebble %lld needs a finite centre and radius > 0", name,
                            (long long)i + 1);
    }
    if (sx__clump_template_reserve(m, def->count))
        return sx__fail(m, SX_ENOMEM, "clump_template '%s': out of memory", name);
    sx_clumps *C = m->clumps;
    sx_clump_tpl *t = &C->tpl[C->ntpl];
    memset(t, 0, sizeof *t);
    snprintf(t->name, sizeof t->name, "%s", name);
    t->first = C->tp_n;
    t->n = def->count;
    memcpy(C->tp_pos + t->first * d, def->pos, (size_t)(def->count * d) * sizeof(double));
    memcpy(C->tp_rad + t->first, def->radius, (size_t)def->count * sizeof(double));
    const sx_status st = sx__clump_mass_props(m, t, def->lines);
    if (st == SX_ENOMEM) return sx__fail(m, SX_ENOMEM, "clump_template '%s': out of memory", name);
    if (st == SX_EINTERRUPT) return sx__fail(m, st, "clump_template '%s': interrupted (no template added)", name);
    if (st) return sx__fail(m, SX_EINVAL, "clump_template '%s': its mass properties are degenerate", name);
    C->tp_n += def->count;
    if (out) *out = C->ntpl;
    C->ntpl++;
    return SX_OK;
}

int sx_clump_template_find(const sx_model *m, const char *name)
{
    if (!m->clumps || !name) return -1;
    for (int i = 0; i < m->clumps->ntpl; i++)
        if (strcmp(m->clumps->tpl[i].name, name) == 0) return i;
    return -1;
}

int sx_clump_template_count(const sx_model *m) { return m->clumps ? m->clumps->ntpl : 0; }

const char *sx_clump_template_name(const sx_model *m, int t)
{
    return t >= 0 && t < sx_clump_template_count(m) ? m->clumps->tpl[t].name : NULL;
}

const sx_clump_tpl *sx__clump_template_at(const sx_model *m, int t, const char *fn)
{
    if (t < 0 || t >= sx_clump_template_count(m)) {
        sx__fail((sx_model *)m, SX_ENOTFOUND, "%s: no clump template with index %d", fn, t);
        return NULL;
    }
    return &m->clumps->tpl[t];
}

sx_status sx_clump_template_props(const sx_model *m, int ti, sx_clump_props *out)
{
    const sx_clump_tpl *t = sx__clump_template_at(m, ti, "clump_template_props");
    if (!t) return SX_ENOTFOUND;
    memset(out, 0, sizeof *out);
    out->count = t->n;
    out->overlapping = t->lines > 0;
    out->volume = t->volume;
    out->error = t->error;
    for (int k = 0; k < 3; k++) {
        out->centroid[k] = t->centroid[k];
        out->principal[k] = t->principal[k];
    }
    if (m->dim == 3) {
        double R[9];
        qmatrix(t->frame, R);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                out->inertia[a][b] = t->inertia[3 * a + b];
                out->axes[a][b] = R[3 * a + b];
            }
    } else {
        out->inertia[2][2] = t->inertia[0];
        for (int k = 0; k < 3; k++) out->axes[k][k] = 1;
    }
    return SX_OK;
}

sx_status sx_clump_template_pebble(const sx_model *m, int ti, int64_t k, double pos[3], double *radius)
{
    const sx_clump_tpl *t = sx__clump_template_at(m, ti, "clump_template_pebble");
    if (!t) return SX_ENOTFOUND;
    if (k < 0 || k >= t->n)
        return sx__fail((sx_model *)m, SX_ENOTFOUND, "clump_template_pebble: template '%s' has %lld pebbles, not %lld",
                        t->name, (long long)t->n, (long long)k + 1);
    const int d = m->dim;
    pos[0] = pos[1] = pos[2] = 0;
    for (int j = 0; j < d; j++) pos[j] = m->clumps->tp_pos[(t->first + k) * d + j];
    *radius = m->clumps->tp_rad[t->first + k];
    return SX_OK;
}
