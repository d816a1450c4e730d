/* SPDX-License-Identifier: Apache-2.0 */
/* avx_rows: the 4x4 transpose the AVX2 spring loops share (ms_linear.c,
 * mass_spring.c).
 * Four rows r[q] = (x, y, z, -) of four springs, loaded as masked 4-wide
 * rows, become one vector per component: c0 = (r0.x .. r3.x), c1, c2.
 * Defines VISCERA_HAVE_AVX_ROWS where the compiler can build AVX2 code
 * (GCC or Clang on x86); whether the processor runs it is checked at run
 * time by the caller. Header-only. */
#ifndef VISCERA_AVX_ROWS_H
#define VISCERA_AVX_ROWS_H

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define VISCERA_HAVE_AVX_ROWS 1
#include <immintrin.h>

__attribute__((target("avx2"))) static inline void avx_rows_transpose3(const __m256d r[4], __m256d *c0, __m256d *c1,
                                                                       __m256d *c2) {
  const __m256d t0 = _mm256_unpacklo_pd(r[0], r[1]), t1 = _mm256_unpackhi_pd(r[0], r[1]);
  const __m256d t2 = _mm256_unpacklo_pd(r[2], r[3]), t3 = _mm256_unpackhi_pd(r[2], r[3]);
  *c0 = _mm256_permute2f128_pd(t0, t2, 0x20);
  *c1 = _mm256_permute2f128_pd(t1, t3, 0x20);
  *c2 = _mm256_permute2f128_pd(t0, t2, 0x31);
}
#endif

#endif
