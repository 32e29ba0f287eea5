#include "alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

void *sx_alloc_resize(sx_alloc *a, void *p, size_t old_n, size_t new_n, size_t size)
{
    if (new_n == 0) {
        sx_alloc_free(a, p, old_n, size);
        return NULL;
    }
    if (new_n > SIZE_MAX / size) return NULL;
    void *q = realloc(p, new_n * size);
    if (!q) return NULL;
    if (new_n > old_n) memset((char *)q + old_n * size, 0, (new_n - old_n) * size);
    a->bytes = a->bytes - old_n * size + new_n * size;
    if (a->bytes > a->peak) a->peak = a->bytes;
    return q;
}

void sx_alloc_free(sx_alloc *a, void *p, size_t n, size_t size)
{
    if (!p) return;
    free(p);
    a->bytes -= n * size;
}

bool sx_alloc_reserve_index(sx_alloc *a, int32_t **map, int64_t *cap, int64_t need)
{
    if (need <= *cap) return true;
    const int64_t n = *cap * 2 > need ? *cap * 2 : need + 64;
    if (n > INT32_MAX) return false;
    int32_t *q = sx_alloc_resize(a, *map, (size_t)*cap, (size_t)n, sizeof *q);
    if (!q) return false;
    *map = q;
    *cap = n;
    return true;
}
