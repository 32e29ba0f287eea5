/* The vector-lane helpers of the batched passes (pair contacts, wall
 * contacts, the law of motion): four pairs, wall contacts or balls at a
 * time in GCC vector extensions; each lane does the scalar pass's
 * arithmetic in its order, so both give the same bits. Part of the
 * per-dimension unit kernels.c. */
#pragma once

enum { LANES = 4 };

/* Four doubles and four lane masks (-1 or 0), GCC's vector extensions:
 * an AVX register in the avx2 clone below, two SSE2 halves in the
 * baseline one; each operation is the IEEE operation of each lane. */
typedef double vd __attribute__((vector_size(LANES * sizeof(double))));
typedef int64_t vm __attribute__((vector_size(LANES * sizeof(int64_t))));
typedef uint8_t v4u8 __attribute__((vector_size(LANES))); /* four pairs' touching flags */

/* (macros, not functions: a vector argument would change the baseline ABI) */
#define VSEL(msk, a, b) ((vd)(((vm)(a) & (msk)) | ((vm)(b) & ~(msk))))
#define VSQRT(a)                                                        \
    __extension__({                                                     \
        const vd a_ = (a);                                              \
        vd r_;                                                          \
        for (int q_ = 0; q_ < LANES; q_++) r_[q_] = sqrt(a_[q_]);       \
        r_;                                                             \
    })
#define VANY(msk) (((msk)[0] | (msk)[1] | (msk)[2] | (msk)[3]) != 0)
#define VZERO ((vd){0, 0, 0, 0})

/* component k of each lane's element idx[q] of an array of `per` components */
#define LANES_OF(arr, idx, per, k)                                                                          \
    ((vd){(arr)[(idx)[0] * (per) + (k)], (arr)[(idx)[1] * (per) + (k)], (arr)[(idx)[2] * (per) + (k)],   \
          (arr)[(idx)[3] * (per) + (k)]})

/* Four consecutive pairs' D-vectors (a pair's components adjacent in
 * memory) to and from one vector per component, by shuffles. */
static inline void load_lanes(const double *p, vd *out)
{
#if D == 3
    vd m0, m1, m2;
    memcpy(&m0, p, sizeof m0), memcpy(&m1, p + 4, sizeof m1), memcpy(&m2, p + 8, sizeof m2);
    out[0] = __builtin_shuffle(__builtin_shuffle(m0, m1, (vm){0, 3, 6, 0}), m2, (vm){0, 1, 2, 5});
    out[1] = __builtin_shuffle(__builtin_shuffle(m0, m1, (vm){1, 4, 7, 0}), m2, (vm){0, 1, 2, 6});
    out[2] = __builtin_shuffle(__builtin_shuffle(m0, m1, (vm){2, 5, 0, 0}), m2, (vm){0, 1, 4, 7});
#else
    vd m0, m1;
    memcpy(&m0, p, sizeof m0), memcpy(&m1, p + 4, sizeof m1);
    out[0] = __builtin_shuffle(m0, m1, (vm){0, 2, 4, 6});
    out[1] = __builtin_shuffle(m0, m1, (vm){1, 3, 5, 7});
#endif
}

static inline void store_lanes(double *p, const vd *in)
{
#if D == 3
    const vd o0 = __builtin_shuffle(__builtin_shuffle(in[0], in[1], (vm){0, 4, 1, 0}), in[2], (vm){0, 1, 4, 2});
    const vd o1 = __builtin_shuffle(__builtin_shuffle(in[1], in[2], (vm){1, 5, 2, 0}), in[0], (vm){0, 1, 6, 2});
    const vd o2 = __builtin_shuffle(__builtin_shuffle(in[0], in[1], (vm){3, 7, 0, 0}), in[2], (vm){6, 0, 1, 7});
    memcpy(p, &o0, sizeof o0), memcpy(p + 4, &o1, sizeof o1), memcpy(p + 8, &o2, sizeof o2);
#else
    const vd o0 = __builtin_shuffle(in[0], in[1], (vm){0, 4, 1, 5}), o1 = __builtin_shuffle(in[0], in[1], (vm){2, 6, 3, 7});
    memcpy(p, &o0, sizeof o0), memcpy(p + 4, &o1, sizeof o1);
#endif
}

/* The shear force g of four lanes, as the scalar passes make it: the
 * stored one where the pair had a contact (had) and none otherwise,
 * rotated (4-14, as carry_make and carry_apply) from the previous normal
 * (prev; n for a new contact) into n, then in 3D (4-15) about n by half
 * the bodies' summed spin about it (spin_sum; a wall does not spin, so
 * there its ball's spin alone); the increment of the shear velocity vs
 * (4-18 ... 4-20); the Coulomb limit fmax (4-30/4-31). (Arrays and masks
 * by pointer: a vector argument would change the baseline ABI.) */
static inline __attribute__((always_inline)) void shear_lanes(vd *g, const vd *fs_old, const vd *prev, const vm *had,
                                                              const vd *n, const vd *spin_sum, const vd *vs,
                                                              const vd *ks, const vd *fmax, double dt)
{
    vd no[D];
    for (int k = 0; k < D; k++) {
        g[k] = VSEL(*had, fs_old[k], VZERO);
        no[k] = VSEL(*had, prev[k], n[k]);
    }
#if D == 3
    const vd c0v = no[1] * n[2] - no[2] * n[1], c1v = no[2] * n[0] - no[0] * n[2], c2v = no[0] * n[1] - no[1] * n[0];
    vd t0 = c1v * g[2] - c2v * g[1], t1 = c2v * g[0] - c0v * g[2], t2 = c0v * g[1] - c1v * g[0];
    g[0] += t0, g[1] += t1, g[2] += t2;
    const vd wbar = 0.5 * (((VZERO + spin_sum[0] * n[0]) + spin_sum[1] * n[1]) + spin_sum[2] * n[2]);
    const vd r0 = wbar * n[0] * dt, r1 = wbar * n[1] * dt, r2 = wbar * n[2] * dt;
    t0 = r1 * g[2] - r2 * g[1], t1 = r2 * g[0] - r0 * g[2], t2 = r0 * g[1] - r1 * g[0];
    g[0] += t0, g[1] += t1, g[2] += t2;
#else
    (void)spin_sum;
    const vd cz = no[0] * n[1] - no[1] * n[0], g0 = g[0];
    g[0] -= cz * g[1];
    g[1] += cz * g0;
#endif
    const vd ksdt = *ks * dt;
    for (int k = 0; k < D; k++) g[k] -= ksdt * vs[k];
    vd f2 = VZERO;
    for (int k = 0; k < D; k++) f2 += g[k] * g[k];
    const vm slips = f2 > *fmax * *fmax;
    if (VANY(slips)) {
        const vd sc = VSEL(slips, *fmax / VSQRT(f2), VZERO + 1.0);
        for (int k = 0; k < D; k++) g[k] *= sc;
    }
}

/* The batched pass is compiled three times where the compiler can pick at
 * run time (GCC's function multi-versioning on x86-64 GNU/Linux): for
 * x86-64-v4 (AVX-512: the same four lanes, in twice as many registers, so
 * fewer spills), with AVX2, four lanes per instruction, and for the
 * baseline ISA. None fuses (-ffp-contract=off) and all round every
 * operation alike, so they give the same bits. AddressSanitizer builds keep
 * the baseline alone (an ifunc resolver runs before the sanitizer is set
 * up). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && !defined(__SANITIZE_ADDRESS__)
#define SX_VECTOR_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define SX_VECTOR_CLONES
#endif
