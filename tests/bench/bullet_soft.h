/* SPDX-License-Identifier: Apache-2.0 */
/* bullet_soft: a Bullet btSoftBody built from a triangle surface, behind a
 * C interface so bench_bullet.c (C11) can drive it. The peer of the
 * surface mass-spring benchmark (docs/numerics.md §8): Debian's
 * libbullet-dev, its default soft-body solver, links from the triangle
 * edges, pose matching for the shape (Bullet's stand-in for home springs),
 * `iterations` position iterations and damping coefficient `damping`.
 * Built only when libbullet-dev is installed (tests/bench/bullet.cmake). */
#ifndef VISCERA_BENCH_BULLET_SOFT_H
#define VISCERA_BENCH_BULLET_SOFT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bullet_soft bullet_soft_t;

/* pos: 3 nv (m), tris: 3 nt; mass kg total; NULL on failure. */
bullet_soft_t *bullet_soft_create(const double *pos, size_t nv, const uint32_t *tris, size_t nt, double mass,
                                  const double gravity[3], int iterations, double damping);
/* Node i held at p (infinite mass): how the probe's dent is imposed. */
void bullet_soft_pin(bullet_soft_t *b, uint32_t i, const double p[3]);
/* One world step of dt seconds (no internal sub-stepping). */
void bullet_soft_step(bullet_soft_t *b, double dt);
/* Largest node speed, m/s. */
double bullet_soft_max_speed(const bullet_soft_t *b);
/* Node i's position into p. */
void bullet_soft_node(const bullet_soft_t *b, uint32_t i, double p[3]);
void bullet_soft_destroy(bullet_soft_t *b);
/* Size of btScalar in bytes (4: the float build Debian's bullet.pc links). */
int bullet_soft_scalar_bytes(void);

#ifdef __cplusplus
}
#endif

#endif
