/* SPDX-License-Identifier: Apache-2.0 */
// bullet_soft: the Bullet side of bench_bullet (see bullet_soft.h).
#include "bullet_soft.h"

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <new>
#include <vector>

struct bullet_soft {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  btSoftBody *body = nullptr;
};

extern "C" bullet_soft_t *bullet_soft_create(const double *pos, size_t nv, const uint32_t *tris, size_t nt, double mass,
                                             const double gravity[3], int iterations, double damping) {
  bullet_soft_t *b = new (std::nothrow) bullet_soft_t;
  if (!b) return nullptr;
  const btVector3 g{static_cast<btScalar>(gravity[0]), static_cast<btScalar>(gravity[1]),
                    static_cast<btScalar>(gravity[2])};
  b->world.setGravity(g);
  btSoftBodyWorldInfo &wi = b->world.getWorldInfo();
  wi.m_gravity = g;
  wi.m_sparsesdf.Initialize();
  std::vector<btScalar> v(3 * nv);
  for (size_t i = 0; i < 3 * nv; i++) v[i] = btScalar(pos[i]);
  std::vector<int> t(3 * nt);
  for (size_t i = 0; i < 3 * nt; i++) t[i] = int(tris[i]);
  b->body = btSoftBodyHelpers::CreateFromTriMesh(wi, v.data(), t.data(), int(nt), false);
  if (!b->body) {
    delete b;
    return nullptr;
  }
  btSoftBody *sb = b->body;
  sb->m_materials[0]->m_kLST = 0.5;
  sb->m_cfg.piterations = iterations;
  sb->m_cfg.kDP = btScalar(damping);
  sb->m_cfg.kMT = 0.2; // pose matching holds the organ's shape
  sb->setTotalMass(btScalar(mass), false);
  sb->setPose(false, true);
  b->world.addSoftBody(sb);
  return b;
}

extern "C" void bullet_soft_pin(bullet_soft_t *b, uint32_t i, const double p[3]) {
  btSoftBody::Node &n = b->body->m_nodes[int(i)];
  n.m_x = btVector3(btScalar(p[0]), btScalar(p[1]), btScalar(p[2]));
  n.m_q = n.m_x;
  n.m_v = btVector3(0, 0, 0);
  b->body->setMass(int(i), 0);
}

extern "C" void bullet_soft_step(bullet_soft_t *b, double dt) { b->world.stepSimulation(btScalar(dt), 0); }

extern "C" double bullet_soft_max_speed(const bullet_soft_t *b) {
  double best = 0;
  for (int i = 0; i < b->body->m_nodes.size(); i++) best = std::fmax(best, double(b->body->m_nodes[i].m_v.length()));
  return best;
}

extern "C" void bullet_soft_node(const bullet_soft_t *b, uint32_t i, double p[3]) {
  const btVector3 &x = b->body->m_nodes[int(i)].m_x;
  p[0] = x.x();
  p[1] = x.y();
  p[2] = x.z();
}

extern "C" void bullet_soft_destroy(bullet_soft_t *b) {
  if (!b) return;
  if (b->body) {
    b->world.removeSoftBody(b->body);
    delete b->body;
  }
  delete b;
}

extern "C" int bullet_soft_scalar_bytes(void) { return int(sizeof(btScalar)); }
