/* SPDX-License-Identifier: Apache-2.0 */
/* scene: the scene file, parsed and validated before anything starts.
 *
 * Format: YAML (comments allowed), SI units. See assets/scenes/default.yaml
 * and the README for every field. scene_load() reads the whole file, checks
 * every field (type, range, known names, unknown keys refused) and fails on
 * the first problem with "FILE:LINE: field 'organs[0].material.stiffness':
 * must be >= 0 (got -3)". Relative mesh paths are resolved against the scene
 * file's directory. Nothing is allocated: the result is plain data. */
#ifndef VISCERA_SCENE_H
#define VISCERA_SCENE_H

#include <stddef.h>

#include "verr.h"

#define SCENE_MAX_ORGANS 16
#define SCENE_MAX_TOOLS 8
#define SCENE_MAX_OBJECTS 8
#define SCENE_MAX_TASKS 16
#define SCENE_NAME_LEN 64
#define SCENE_PATH_LEN 1024

typedef struct scene_material {
  double mass;           /* kg, total organ mass, spread over vertices (default 0.1) */
  double stiffness;      /* N/m, edge spring stiffness (default 30) */
  double damping;        /* N s/m, Kelvin-Voigt edge damping (default 0.02) */
  double home_stiffness; /* N/m, spring from each vertex to its rest position (default 30) */
  double home_damping;   /* N s/m, damping relative to the ground (default 0.005) */
  /* molecular (docs/methods.md A eq. 6-11); the scene is refused unless
   * bond_k * angle_k > 2 * stretch_bend_k^2. */
  double bond_k;         /* N/m, bond stretch k_r [30] */
  double angle_k;        /* J (N m), bond angle k_theta, cosine form [1e-3] */
  double stretch_bend_k; /* N, stretch-bend coupling k_sb [0] */
  /* PBD / XPBD (docs/methods.md C §4): stiffness in 0..1 for PBD, compliance
   * (m/N for distance, 1/(N m^2)... per constraint) for XPBD. */
  double distance_stiffness;  /* PBD [1] */
  double volume_stiffness;    /* PBD [1] */
  double distance_compliance; /* XPBD [1e-4] */
  double volume_compliance;   /* XPBD [1e-6] */
  /* vertex_based (docs/methods.md B ch. 4): slopes of the slope-intercept rule for
   * the touched node and its first and second rings, m1 > m2 > m3 > 0. */
  double slope_m1, slope_m2, slope_m3; /* [1, 0.6, 0.3] */
  /* adaptive_mass_spring (docs/methods.md B ch. 5): one-ring faces larger than
   * refine_area are subdivided, up to refine_levels levels. */
  double refine_area; /* m^2 [2e-5] */
  int refine_levels;  /* [2] */
} scene_material_t;

/* Default CG iteration cap of the integrator implicit_pcg (one step per ms). */
#define SCENE_PCG_ITERATIONS 10
/* Default constraint iterations per sub-step of the model xpbd (pbd: 10). Six
 * keep the S8-style probe force error within 2 % of XPBD at 10 iterations and
 * 1/4 ms x 4 on every shipped organ, at 0.6 of the sweep cost (docs/numerics.md
 * §9.1). */
#define SCENE_XPBD_ITERATIONS 6

/* Regional sleeping's defaults (ms_regions.h, docs/numerics.md §11):
 * 10 uN per sleeping node (a hundred of them by the probe hold at most 1 mN,
 * 0.1 % of a 1 N press) and 10 um/s. */
#define SCENE_REGION_FORCE 1e-5
#define SCENE_REGION_SPEED 1e-5

/* Model-specific settings (key `solver:` and extra `material:` keys in the
 * scene file). Each model reads only its own fields; defaults in brackets. */
typedef struct scene_solver {
  int substeps;          /* sub-steps per scene step; 0 = automatic from the stability bound [0] */
  int iterations;        /* PBD/XPBD constraint iterations per sub-step [10; xpbd SCENE_XPBD_ITERATIONS] */
  double cg_tolerance;   /* implicit Euler: relative CG residual [1e-3] */
  int cg_max_iterations; /* implicit Euler [200]; implicit_pcg [SCENE_PCG_ITERATIONS] */
  double tet_size;       /* m, target tetrahedron edge when a volume mesh is built [0: auto] */
  /* mass_spring_surface under symplectic Euler: regional sleeping
   * (server/physics/ms_regions.h). region_force: N, a sleeping node's net
   * force that wakes it, 0 = off [SCENE_REGION_FORCE]; region_speed: m/s, an
   * awake node slower than this may sleep [SCENE_REGION_SPEED]. */
  double region_force;
  double region_speed;
} scene_solver_t;

typedef struct scene_organ {
  char name[SCENE_NAME_LEN];
  char mesh[SCENE_PATH_LEN]; /* resolved path of the surface; "" when only `volume` is given */
  /* Key `volume:`, optional, only for the tetrahedral models (mass_spring_tet,
   * pbd, xpbd): a tetrahedral mesh made offline (gmsh .msh, VTK .vtk, TetGen
   * .node/.ele; common/volume_mesh.h) used instead of the automatic fill.
   * The surface is then `mesh` embedded in it, or its boundary when `mesh`
   * is not given. Resolved path, "" when not given. */
  char volume[SCENE_PATH_LEN];
  /* One of: mass_spring_surface, mass_spring_tet, molecular, pbd, xpbd,
   * vertex_based, adaptive_mass_spring. */
  char model[32];
  /* Force-based models: explicit_euler, symplectic_euler, verlet, rk4, implicit_euler. */
  char integrator[32];
  scene_solver_t solver;
  double position[3]; /* m, translation applied after scale (default 0) */
  double scale;       /* applied to the mesh coordinates (default 1) */
  float color[3];     /* RGB 0..1 (default 0.8 0.35 0.3) */
  scene_material_t material;
  int fixed_below_set;        /* 1 if fixed_below was given */
  double fixed_below;         /* m, vertices with z below this are fixed */
  int line;                   /* line of the organ entry, for later messages */
  int mesh_line, volume_line; /* lines of its `mesh:` and `volume:` keys (0: not given), for the files' problems */
} scene_organ_t;

/* Tool kinds and what each can do (key `kind:`):
 *   probe      palpation: touches and pushes through the god-object proxy.
 *   grasper    touches like a probe; closing the jaws (ToolCommand.buttons
 *              bit 0) within grasp_radius of the surface grabs a small
 *              patch of tissue and holds it to the tip until they open.
 *   scalpel    touches like a probe; with the button (bit 0) pressed its
 *              blade, blade_length along the tool axis from the tip, cuts
 *              pbd, xpbd and mass_spring_surface organs
 *              (server/runtime/step_cut.h).
 *   extractor  laparoscopic stone extractor: enters through an assumed port,
 *              so it does not collide with organs; closing the jaws within
 *              grasp_radius of a stone's surface grabs the stone and carries it.
 *   syringe    touches like a probe; injection is not simulated yet.
 * grasp_radius is accepted (and required to be meaningful) only for
 * grasper and extractor; jaw_opening only for grasper; blade_length only
 * for scalpel. */
typedef struct scene_tool {
  char name[SCENE_NAME_LEN];
  char kind[32];    /* probe | grasper | scalpel | extractor | syringe (default probe) */
  double radius;    /* m, tip radius (default 0.002) */
  double length;    /* m, shaft length for drawing (default 0.1) */
  double stiffness; /* N/m, proxy virtual spring (default 300) */
  double max_force; /* N, clamp (default 4) */
  /* Palpation force thresholds (docs/methods.md B ch. 6), N on the contact force
   * magnitude; 0 = not set (no events for it). Key `thresholds:`, each
   * optional: st (sound threshold: the audio/visual cue to ease off),
   * mpf (maximum palpation force: the target not to go beyond), sft
   * (stopping force threshold: the hard upper bound). Refused unless
   * 0 < st < mpf <= sft <= max_force for those given. */
  double sft, st, mpf;
  /* Coulomb friction coefficient mu of the tip on tissue, >= 0 and <= 2
   * (default 0: frictionless proxy). */
  double friction;
  /* grasper, extractor: m, how far from the tip the jaws reach when they
   * close (default 2 x radius). 0 for the other kinds. */
  double grasp_radius;
  /* grasper: m, jaw opening when open, for drawing (default 4 x radius). */
  double jaw_opening;
  /* scalpel: m, cutting edge from the tip along the tool axis (default
   * 0.02). 0 for the other kinds. */
  double blade_length;
  /* The station that drives the tool from the start (key `station:`, see
   * idl ToolRole and vdds.h: 1..31 of [A-Za-z0-9_.-]); "" = any station.
   * The instructor reassigns it at run time (CONTROL_ASSIGN_TOOL). */
  char station[32];
  int line;
} scene_tool_t;

/* A rigid object inside an organ (key `objects:`). Only kind "stone" (a
 * rigid sphere, docs/methods.md A kidney-stone removal) so far. The scene file does
 * not open meshes, so "inside the organ" is checked by the runtime. */
typedef struct scene_object {
  char name[SCENE_NAME_LEN];
  char kind[16];      /* "stone" */
  double radius;      /* m, > 0 and <= 0.05 (required) */
  double position[3]; /* m, centre in the scene frame (required) */
  int organ;          /* index of the organ it sits in (key `organ:` names it, required) */
  float color[3];     /* default [0.85, 0.8, 0.55] */
  int line;
} scene_object_t;

/* A task the trainee performs (key `tasks:`). Its operation time runs from
 * the first command of its tool to the completion criterion:
 *   stone_removal   tool: an extractor; object: a stone; completes when the
 *                   stone's centre is outside its organ's rest surface by
 *                   more than the stone's radius.
 *   palpate_target  tool: any kind that touches (not an extractor); target,
 *                   target_radius; completes at the first contact within
 *                   target_radius of target (its time is the exploration
 *                   time to the target, docs/methods.md B ch. 6).
 *   grasp_pull      tool: a grasper; distance; completes when the tool,
 *                   holding tissue, is `distance` from where it grasped.
 * start: first_command (default: the clock starts at the tool's first
 * command) or instructor (nothing runs until a SessionControl
 * CONTROL_START_TASK names the task; the tool moving does not start it). */
typedef struct scene_task {
  char name[SCENE_NAME_LEN];
  char kind[32];
  int tool;             /* tool index */
  int object;           /* object index, -1 if none */
  double target[3];     /* m (palpate_target) */
  double target_radius; /* m (palpate_target, default 0.005) */
  double distance;      /* m (grasp_pull, default 0.01) */
  int start_instructor; /* 1: `start: instructor`, 0: `start: first_command` */
  int line;
} scene_task_t;

typedef struct scene {
  char path[SCENE_PATH_LEN];
  char name[SCENE_NAME_LEN]; /* required */
  char description[256];
  double dt;         /* s, physics step (default 0.001) */
  double publish_hz; /* MeshDelta rate (default 30) */
  double quant_step; /* m, MeshDelta quantization (default 1e-5) */
  double gravity[3]; /* m/s^2 (default 0 0 0: organs rest on home springs) */
  /* Organ sleeping (server/runtime/organ_sleep.h): an organ whose surface moved
   * slower than sleep_speed for sleep_after s, with no tool near, is not
   * stepped until a tool comes near. */
  double sleep_speed; /* m/s; 0 (the default) = organs never sleep */
  double sleep_after; /* s (default 0.1), >= 2 dt */
  /* s of wall time: a MeshDelta equal to the last one written is skipped
   * unless this long passed (server/session/mesh_publisher.h); 0 (the default)
   * writes every frame. */
  double publish_keepalive;
  /* physics.integrator: the integrator of every organ that names none
   * ("" when not given: organs default to symplectic_euler). */
  char integrator[32];
  size_t norgans; /* >= 1 */
  scene_organ_t organs[SCENE_MAX_ORGANS];
  size_t ntools;
  scene_tool_t tools[SCENE_MAX_TOOLS];
  size_t nobjects;
  scene_object_t objects[SCENE_MAX_OBJECTS];
  size_t ntasks;
  scene_task_t tasks[SCENE_MAX_TASKS];
} scene_t;

/* Fills *out with defaults, then the file's values. 0 on success; -1 with a
 * message naming file, line and field on any problem (missing or unreadable
 * file, YAML syntax error, unknown key, wrong type, out-of-range value,
 * missing required field, too many organs/tools/objects/tasks, duplicate
 * names, a capability key the tool kind does not have, a task whose tool
 * kind or object does not fit it). Does not
 * open the mesh files: the server imports them and reports their problems. */
int scene_load(const char *path, scene_t *out, verr_t *err);

/* Same, from a string; `name` stands in for the file name in messages and
 * relative mesh paths are resolved against `base_dir` (may be NULL: cwd). */
int scene_load_string(const char *text, const char *name, const char *base_dir, scene_t *out, verr_t *err);

#endif
