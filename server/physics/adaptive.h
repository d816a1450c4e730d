/* SPDX-License-Identifier: Apache-2.0 */
/* adaptive: adaptive area-based refinement and simplification of a surface
 * Kelvin-Voigt mass-spring model (docs/methods.md B ch. 5).
 *
 * Physics (docs/methods.md B §5.2.1): every edge is a spring with a dashpot in
 * parallel (eq. 5.3, Kelvin-Voigt); every vertex has a damped home spring to
 * its rest position (§5.2.4, shape preservation of a hollow surface model);
 * M a + C v + K u = F_ext (eq. 5.5) integrated by semi-implicit Euler,
 * v += h F / m then x += h v (eq. 5.8-5.9: the position update uses the new
 * velocity). Own small force code: nothing of mass_spring.c is used.
 *
 * Refinement (docs/methods.md B §5.2.2.3): when the contact force exceeds
 * refine_force (§5.3), the one-ring faces of the touched node whose area
 * exceeds refine_area are split 1-to-4 (red: edge midpoints), each child
 * again while its area exceeds refine_area, up to refine_levels levels.
 * Neighbouring faces are fixed up without T-junctions (red-green): a 2:1
 * balance is enforced (a leaf whose neighbour is two levels finer along an
 * edge is itself split), and leaves with split edges are closed by green
 * templates (one split edge: bisection; two: a corner plus the quad cut
 * along its shorter diagonal; three: the red pattern). New vertices lie on
 * the coarse faces (midpoints), so the refined surface is the coarse surface.
 *
 * Simplification (§5.2.2.4): when no contact has been seen for release_time,
 * the coarse mesh, masses, springs and time step are restored; the coarse
 * vertices keep their state, the new vertices are dropped.
 *
 * Parameter identification (§5.2.3), per rule (see adaptive.c for the why):
 *   mass   ADAPT_MASS_AREA (default): each refined coarse face hands the mass
 *            its three vertices held over it to its new triangles by area,
 *            so total mass is conserved exactly and stays local (the
 *            conservation of eq. 5.10-5.11, the level blending of eq.
 *            5.12-5.14 falls out of the area shares);
 *          ADAPT_MASS_UNIFORM: eq. 5.10-5.11 literally (every node M / N').
 *   springs ADAPT_K_MEMBRANE (default): new springs keep k_s and k_d (a
 *            triangle lattice's membrane stiffness does not depend on the
 *            edge length);
 *          ADAPT_K_THESIS: eq. 5.15-5.17 with SLoD = 4:
 *            k = 2^l k_s mean(m_refined) / mean(m_coarse), k_d scaled alike.
 *   home   ADAPT_HOME_MASS (default): home springs and dampers scale with the
 *            node mass (k_h m / m_coarse: the same acceleration, the principle
 *            of eq. 5.15), so the home stiffness per area - what a probe of
 *            given size presses against - is unchanged: a probe's felt
 *            stiffness stays within 3 % (test_adaptive);
 *          ADAPT_HOME_MATCH: then those on the touched node's one-ring faces
 *            are scaled so their sum is the coarse one-ring's (the force to
 *            push exactly the one-ring in is kept; a probe feels ~20 %
 *            stiffer). Kept for comparison.
 *   time step: eq. 5.18, h = h_coarse / 2^l for the deepest level l, raised
 *            further if a Gershgorin bound of the refined nodes needs it;
 *            only the refined region takes the small step (multi-rate: the
 *            coarse nodes keep h_coarse), so a refined step costs the coarse
 *            step plus the region's sub-cycles.
 *
 * Capacity for the deepest refinement anywhere on the mesh is allocated at
 * create; stepping, refining and simplifying allocate nothing. Not
 * thread-safe: one physics thread owns it. */
#ifndef VISCERA_ADAPTIVE_H
#define VISCERA_ADAPTIVE_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "physics/coupling.h"
#include "physics/model.h"
#include "physics/model_guard.h"
#include "verr.h"

#define ADAPT_MAX_LEVELS 5
#define ADAPT_NONE UINT32_MAX

typedef enum adapt_mass_rule { ADAPT_MASS_AREA, ADAPT_MASS_UNIFORM } adapt_mass_rule_t;
typedef enum adapt_k_rule { ADAPT_K_MEMBRANE, ADAPT_K_THESIS } adapt_k_rule_t;
typedef enum adapt_home_rule { ADAPT_HOME_MASS, ADAPT_HOME_MATCH } adapt_home_rule_t;

typedef struct adaptive_params {
  double mass;           /* kg, total (coarse nodes equal: mass / n) */
  double stiffness;      /* N/m, edge springs of the coarse mesh */
  double damping;        /* N s/m, edge dashpots of the coarse mesh */
  double home_stiffness; /* N/m per coarse vertex */
  double home_damping;   /* N s/m per coarse vertex */
  double gravity[3];
  double refine_area;    /* m^2, faces larger than this are split */
  int refine_levels;     /* 0..ADAPT_MAX_LEVELS */
  double refine_force;   /* N, contact force that triggers refinement (docs/methods.md B §5.3) */
  double release_time;   /* s without contact before simplification */
  double tool_stiffness; /* N/m, in the stability bound (0 when tool springs are coupled implicitly: cpl) */
  adapt_mass_rule_t mass_rule;
  adapt_k_rule_t k_rule;
  adapt_home_rule_t home_rule;
} adaptive_params_t;

/* Defaults for the fields the scene does not carry. */
#define ADAPT_DEFAULT_REFINE_FORCE 0.01
#define ADAPT_DEFAULT_RELEASE_TIME 0.05

typedef struct ad_spring {
  uint32_t i, j;
  double rest, k, c;
} ad_spring_t;

/* A triangle of the refinement tree inside one coarse (root) face. */
typedef struct ad_node {
  uint32_t v[3];
  int8_t cedge[3]; /* the root face's edge (0..2) this edge lies on, -1 inside the face */
  uint8_t level;
  uint32_t root;  /* root index */
  uint32_t child; /* first of 4 consecutive children, ADAPT_NONE for a leaf */
} ad_node_t;

typedef struct ad_hash {
  size_t cap;    /* power of two */
  uint64_t *key; /* UINT64_MAX = empty */
  uint32_t *val;
  uint32_t *used; /* slots filled since the last clear */
  size_t nused;
} ad_hash_t;

typedef struct adaptive {
  adaptive_params_t p;
  /* Coarse mesh: never changes. */
  size_t n0, t0, s0;
  uint32_t *tris0;           /* 3 t0 */
  uint32_t *fadj0;           /* 3 t0: face across edge k (v[k], v[k+1]), ADAPT_NONE on an open boundary */
  uint32_t *fspr0;           /* 3 t0: spring of edge k */
  double *area0;             /* t0, rest area */
  double *varea0;            /* n0, sum of incident face areas */
  uint32_t *vf_off, *vf_idx; /* vertex -> incident faces */
  double m0;                 /* coarse node mass */
  /* Capacities (allocated once). */
  size_t cap_v, cap_t, cap_s, cap_nodes, cap_roots;
  /* Current mesh and state. */
  size_t n, nt, ns;
  double *x, *v, *x_rest; /* 3 cap_v */
  double *f, *f_ext;
  model_guard_t guard; /* 3 cap_v: the state before the step, for rollback (physics/model_guard.h); scratch at create */
  double *mass, *inv_mass, *kh, *ch;
  uint8_t *fixed;
  uint8_t *vlevel;      /* 0 coarse, else the level that created the vertex */
  uint32_t *anchor;     /* coarse vertex a new vertex belongs to (index - n0) */
  uint32_t *tris;       /* 3 cap_t; coarse face f stays in slot f (its first piece) */
  uint32_t *tri_face;   /* cap_t: coarse face of each triangle */
  ad_spring_t *springs; /* cap_s: coarse springs first, then new ones */
  uint8_t *spring_off;  /* coarse springs replaced by their halves */
  /* Refinement state. */
  int refined;      /* a refinement around `centre` is in place */
  int topo_changed; /* it changed the mesh */
  uint32_t centre;
  int max_level;
  size_t nroots, nnodes;
  uint32_t *root_face, *root_node, *root_first, *root_count;
  uint32_t *face_root; /* t0, ADAPT_NONE unless rooted */
  ad_node_t *nodes;
  ad_hash_t mid, edge;
  uint32_t *disabled;
  size_t ndisabled;
  uint32_t *modv; /* coarse vertices whose mass was changed */
  size_t nmodv;
  uint8_t *vflag;      /* n0 scratch: bit 0 in modv, bit 1 in the star of the centre */
  uint32_t *stamp;     /* cap_s scratch */
  uint8_t *vmark;      /* cap_v scratch, all zero between uses */
  double home_match;   /* scale applied to the one-ring's home springs (1 if none) */
  double *ksum, *csum; /* cap_v scratch: spring stiffness and damping summed per node */
  int failed;          /* capacity exhausted during the current refinement */
  /* Stepping. */
  int substeps0;     /* coarse sub-steps per scene step */
  int substeps;      /* sub-steps of the finest nodes per scene step: substeps0 * fine_ratio */
  double dt;         /* s, the scene step the sub-steps divide */
  double stable_dt0; /* s, coarse bound (power iteration, includes the tool) */
  /* Multi-rate stepping while refined (eq. 5.18: the refined level has its
   * own time step): the fine nodes (vertices of refined faces, new ones
   * included) sub-cycle fine_ratio times per coarse sub-step. */
  uint8_t *fine; /* cap_v flags */
  uint32_t *fine_nodes, *fine_springs;
  size_t nfine, nfine_springs;
  int fine_ratio;  /* 1 when not refined */
  double *ffine;   /* 3 cap_v, forces on the fine nodes */
  double *im_fine; /* cap_v: inv_mass on the fine nodes, 0 elsewhere (the coarse ones are held in a sub-cycle) */
  /* Tool springs of the current (fine) sub-step taken implicitly
   * (physics/coupling.h), filled by pre(); NULL or empty: all explicit.
   * Owned by the caller (model_adaptive.c). */
  const coupling_set_t *cpl;
  uint32_t *forced; /* nodes with an external force this sub-step */
  size_t nforced;
  uint8_t *is_forced;
  uint32_t step_touched;
  double step_touched_mag;
  double release_timer;
  uint32_t topology_version; /* +1 on every change of the triangles */
  /* Statistics. */
  double last_refine_us, last_simplify_us;
  size_t refinements, simplifications, capacity_failures;
} adaptive_t;

/* Builds the coarse model and allocates capacity for refine_levels around
 * any vertex. `dt` is the scene step the sub-steps are chosen for and
 * `substeps` > 0 forces the coarse sub-step count. Returns 0, or -1 with err
 * (bad parameters, non-manifold edge, OOM, more than 256 sub-steps). */
int adaptive_create(adaptive_t *ad, const mesh_t *surface, const adaptive_params_t *p, double dt, int substeps,
                    verr_t *err);
void adaptive_destroy(adaptive_t *ad);

/* Fixes every coarse vertex whose rest z is below z. Returns how many. */
size_t adaptive_fix_below(adaptive_t *ad, double z);

/* Force (N) on vertex i for the current sub-step; the vertex with the
 * largest single force of a step is the touched node. */
void adaptive_add_force(adaptive_t *ad, uint32_t i, const double f[3]);

typedef void (*adaptive_pre_fn)(void *ctx);

/* One scene step of h: substeps0 coarse sub-steps, each sub-cycling the
 * refined region fine_ratio times with its coarse neighbours held; pre(ctx)
 * runs before every fine sub-step (ad->substeps calls per step), and forces
 * it puts on coarse nodes are averaged over their sub-step. Tool springs
 * pre() declares in ad->cpl are integrated implicitly between kick and
 * drift (coupling.h; in a sub-cycle over the fine nodes, the held coarse
 * ones masked; in the coarse step after it over the coarse nodes, the fine
 * ones masked), so their stiffness is in no bound: with tool_stiffness 0
 * the coarse sub-steps and the fine ratio follow the tissue alone.
 * Afterwards refines around the touched node, re-centres, or simplifies
 * after release_time without contact. Returns 0, or -1 when the state
 * became non-finite: it is then restored and the topology is left alone. */
int adaptive_step(adaptive_t *ad, double h, adaptive_pre_fn pre, void *ctx);

/* Direct control (the step calls these). refine: simplifies first if
 * needed; 0 on success, -1 if the capacity would be exceeded (the coarse
 * mesh is then kept). */
int adaptive_refine(adaptive_t *ad, uint32_t centre);
void adaptive_simplify(adaptive_t *ad);

/* Forces at state (x, v), including f_ext, into f (3 n). */
void adaptive_forces(const adaptive_t *ad, const double *x, const double *v, double *f);
double adaptive_energy(const adaptive_t *ad);
double adaptive_max_strain(const adaptive_t *ad);
double adaptive_total_mass(const adaptive_t *ad);

/* For re-attaching a contact after a topology change: the coarse face a
 * current triangle belongs to, and the current triangle of a coarse face
 * nearest to point p (closest point, barycentrics in bary). */
static inline uint32_t adaptive_tri_face(const adaptive_t *ad, uint32_t tri) {
  return tri < ad->nt ? ad->tri_face[tri] : ADAPT_NONE;
}
uint32_t adaptive_locate(const adaptive_t *ad, uint32_t face, const double p[3], double bary[3]);

/* The scene model "adaptive_mass_spring" (model_adaptive.c). */
typedef struct adaptive_model {
  model_t base; /* base.topology_version follows ad.topology_version (model.h) */
  adaptive_t ad;
  coupling_set_t cpl; /* the sub-step's tool springs (ad.cpl points here) */
} adaptive_model_t;

model_t *model_adaptive_create(const model_params_t *p, verr_t *err);
/* m as an adaptive model, or NULL if it is another model. */
adaptive_model_t *model_adaptive_of(model_t *m);

#endif
