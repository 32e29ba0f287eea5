/* The bond-law registry (laws/bonds.h) behind the public API: the kinds by
 * number and name, and the union of their micro-parameters (each key once,
 * in registry order) with their fields in sx_bpm_def and sx_bond_def, for
 * Lua, the files and the checks of sx_material_set_bpm and sx_bond_install. */
#include "laws/bonds.h"

#include <stdio.h>
#include <string.h>

#define SX_BOND_GET_(name) sx_bond_##name,
static const sx_bond_law *(*const registry[])(void) = {SX_BONDS(SX_BOND_GET_)};
#undef SX_BOND_GET_
enum { NKINDS = sizeof registry / sizeof *registry, MAX_KEYS = 64 };

static const sx_bond_law *bond_law(int k) { return k >= 0 && k < NKINDS ? registry[k]() : NULL; }

int sx_bond_kind_count(void) { return NKINDS; }

const char *sx_bond_kind_name(int k, sx_bond_kind *kind)
{
    const sx_bond_law *l = bond_law(k);
    if (l && kind) *kind = l->kind;
    return l ? l->name : NULL;
}

/* The union of the kinds' parameters, each once, made on first use (the
 * registry is constant, so every call makes the same list). */
static int keys(const sx_bond_param **out)
{
    int n = 0;
    for (int k = 0; k < NKINDS; k++) {
        const sx_bond_law *l = registry[k]();
        for (int j = 0; j < l->nparams; j++) {
            bool seen = false;
            for (int q = 0; q < n && !seen; q++) seen = strcmp(out[q]->name, l->params[j].name) == 0;
            if (!seen && n < MAX_KEYS) out[n++] = &l->params[j];
        }
    }
    return n;
}

int sx_bond_key_count(void)
{
    const sx_bond_param *p[MAX_KEYS];
    return keys(p);
}

static const sx_bond_param *key(int i)
{
    const sx_bond_param *p[MAX_KEYS];
    return i >= 0 && i < keys(p) ? p[i] : NULL;
}

const char *sx_bond_key(int i, const char **unit)
{
    const sx_bond_param *p = key(i);
    if (p && unit) *unit = p->unit;
    return p ? p->name : NULL;
}

double *sx_bond_key_material(sx_bpm_def *d, int i)
{
    const sx_bond_param *p = key(i);
    return p ? (double *)((char *)d + p->material) : NULL;
}

double *sx_bond_key_call(sx_bond_def *d, int i)
{
    const sx_bond_param *p = key(i);
    return p ? (double *)((char *)d + p->call) : NULL;
}

const char *sx__bond_params_invalid(const void *d, bool call, char *why, size_t len)
{
    const sx_bond_param *p[MAX_KEYS];
    const int n = keys(p);
    for (int i = 0; i < n; i++) { /* every one >= 0 first, then the upper bounds; a call's NaN: not given */
        const double x = *(const double *)((const char *)d + (call ? p[i]->call : p[i]->material));
        if (call && isnan(x)) continue;
        if (!(x >= p[i]->lo) || !isfinite(x))
            return snprintf(why, len, "%s must be >= %g (got %g)", p[i]->name, p[i]->lo, x), why;
    }
    for (int i = 0; i < n; i++) {
        const double x = *(const double *)((const char *)d + (call ? p[i]->call : p[i]->material));
        if (call && isnan(x)) continue;
        if (p[i]->hi_closed ? !(x <= p[i]->hi) : !(x < p[i]->hi))
        {
            const char *unit = strcmp(p[i]->unit, "1") ? p[i]->unit : "";
            return snprintf(why, len, "%s must be in [%g, %g%s%s%s (got %g)", p[i]->name, p[i]->lo, p[i]->hi,
                            p[i]->hi_closed ? "]" : ")", *unit ? " " : "", unit, x),
                   why;
        }
        if (p[i]->whole && x != floor(x))
            return snprintf(why, len, "%s must be a whole number (got %g)", p[i]->name, x), why;
    }
    return NULL;
}
