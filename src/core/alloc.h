/* A tracked allocator: the model owns all its memory and counts it, so it
 * can report its bytes per ball and per contact. Callers pass the sizes
 * they know (array capacities), so no header is hidden in each block. */
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct sx_alloc {
    size_t bytes;  /* currently allocated */
    size_t peak;   /* high-water mark */
} sx_alloc;

/* Resizes p from old_n to new_n elements of `size` bytes; new elements are
 * zeroed. Returns NULL (p untouched) on failure or overflow. */
void *sx_alloc_resize(sx_alloc *a, void *p, size_t old_n, size_t new_n, size_t size);
void sx_alloc_free(sx_alloc *a, void *p, size_t n, size_t size);
/* An id -> dense index map (*map, *cap entries) grown to hold `need`
 * entries: to twice its size, or to need + 64 when that is not enough;
 * new entries zeroed. False (the map untouched) when out of memory or past
 * INT32_MAX entries. The balls' and the clumps' maps grow alike. */
bool sx_alloc_reserve_index(sx_alloc *a, int32_t **map, int64_t *cap, int64_t need);
