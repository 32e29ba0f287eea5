/* The contact-law registry (laws/registry.h) behind the public API: a law
 * by number or name, its parameters, and the check of a material's
 * parameters against its law's table. */
#include "laws/registry.h"

#include <stdio.h>
#include <string.h>

_Static_assert((int)SX_LAW_ID(linear) == (int)SX_MODEL_LINEAR && (int)SX_LAW_ID(hertz) == (int)SX_MODEL_HERTZ,
               "the public model numbers are the registry's");

#define SX_LAW_GET_(name) sx_law_##name,
static const sx_law *(*const registry[SX_LAW_COUNT])(void) = {SX_LAWS(SX_LAW_GET_) SX_PARTS(SX_LAW_GET_)};
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

bool sx_law_is_model(int law) { return law >= 0 && law < SX_MODEL_COUNT; }

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

/* Unit u's parameters of d in range, and its rule for them. */
static const char *check_unit(const sx_law *u, const sx_material_def *d, char *why, size_t len)
{
    for (int k = 0; k < u->nparams; k++) {
        const sx_law_param *p = &u->params[k];
        const double x = *sx__law_value((sx_material_def *)d, p);
        if (!isfinite(x) || !(p->lo_closed ? x >= p->lo : x > p->lo) || !(p->hi_closed ? x <= p->hi : x < p->hi)) {
            snprintf(why, len, "%s (got %g)", p->what, x);
            return why;
        }
    }
    const char *rule = u->check ? u->check(d) : NULL;
    if (rule) snprintf(why, len, "%s", rule);
    return rule ? why : NULL;
}

const char *sx__law_check(const sx_material_def *d, char *why, size_t len)
{
    if (!sx_law_is_model((int)d->model)) {
        int n = snprintf(why, len, "model must be one of");
        for (int i = 0; i < SX_MODEL_COUNT && n >= 0 && (size_t)n < len; i++)
            n += snprintf(why + n, len - (size_t)n, "%s %s", i ? "," : "", registry[i]()->name);
        return why;
    }
    if (check_unit(sx__law((int)d->model), d, why, len)) return why;
    for (int i = SX_MODEL_COUNT; i < SX_LAW_COUNT; i++)
        if (check_unit(registry[i](), d, why, len)) return why;
    return NULL;
}

void sx__material_derive(sx_material *t)
{
    for (int i = 0; i < SX_LAW_COUNT; i++) {
        const sx_law *u = registry[i]();
        t->derived[i] = u->derive ? u->derive(&t->def) : 0;
    }
}

void sx__law_parts_mix(sx_pair_law *l, const sx_material *a, const sx_material *b)
{
    for (int i = SX_MODEL_COUNT; i < SX_LAW_COUNT; i++) registry[i]()->mix(l, a, b, i);
}
