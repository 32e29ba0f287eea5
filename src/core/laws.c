/* The contact-law registry (laws/registry.h) behind the public API: a law
 * by number or name, its parameters, and the check of a material's
 * parameters against its law's table. */
#include "laws/registry.h"

#include <stdio.h>
#include <string.h>

_Static_assert((int)SX_LAW_ID(linear) == (int)SX_MODEL_LINEAR && (int)SX_LAW_ID(hertz) == (int)SX_MODEL_HERTZ,
               "the public model numbers are the registry's");

#define SX_LAW_GET_(name) sx_law_##name,
static const sx_law *(*const registry[SX_LAW_COUNT])(void) = {SX_LAWS(SX_LAW_GET_)};
#undef SX_LAW_GET_

const sx_law *sx__law(int id) { return id >= 0 && id < SX_LAW_COUNT ? registry[id]() : NULL; }

int sx_law_count(void) { return SX_LAW_COUNT; }

const char *sx_law_name(int law)
{
    const sx_law *l = sx__law(law);
    return l ? l->name : NULL;
}

const char *sx_law_summary(int law)
{
    const sx_law *l = sx__law(law);
    return l ? l->summary : NULL;
}

int sx_law_find(const char *name)
{
    for (int i = 0; name && i < SX_LAW_COUNT; i++)
        if (strcmp(registry[i]()->name, name) == 0) return i;
    return -1;
}

int sx_law_param_count(int law)
{
    const sx_law *l = sx__law(law);
    return l ? l->nparams : 0;
}

const char *sx_law_param_name(int law, int k, const char **unit)
{
    const sx_law *l = sx__law(law);
    if (!l || k < 0 || k >= l->nparams) return NULL;
    if (unit) *unit = l->params[k].unit;
    return l->params[k].name;
}

double *sx_law_param_value(sx_material_def *d, int law, int k)
{
    const sx_law *l = sx__law(law);
    return l && k >= 0 && k < l->nparams ? sx__law_value(d, &l->params[k]) : NULL;
}

const char *sx__law_check(const sx_material_def *d, char *why, size_t len)
{
    const sx_law *l = sx__law((int)d->model);
    if (!l) {
        int n = snprintf(why, len, "model must be one of");
        for (int i = 0; i < SX_LAW_COUNT && n >= 0 && (size_t)n < len; i++)
            n += snprintf(why + n, len - (size_t)n, "%s %s", i ? "," : "", registry[i]()->name);
        return why;
    }
    for (int k = 0; k < l->nparams; k++) {
        const sx_law_param *p = &l->params[k];
        const double x = *sx__law_value((sx_material_def *)d, p);
        if (!isfinite(x) || !(p->lo_closed ? x >= p->lo : x > p->lo) || !(x < p->hi)) {
            snprintf(why, len, "%s (got %g)", p->what, x);
            return why;
        }
    }
    return NULL;
}
