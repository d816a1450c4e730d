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
#define SCENE_NAME_LEN 64
#define SCENE_PATH_LEN 1024

typedef struct scene_material {
  double mass;           /* kg, total organ mass, spread over vertices (default 0.1) */
  double stiffness;      /* N/m, edge spring stiffness (default 30) */
  double damping;        /* N s/m, Kelvin-Voigt edge damping (default 0.02) */
  double home_stiffness; /* N/m, spring from each vertex to its rest position (default 30) */
  double home_damping;   /* N s/m, damping relative to the ground (default 0.005) */
  /* molecular (seed 000 eq. 6-11); the scene is refused unless
   * bond_k * angle_k > 2 * stretch_bend_k^2. */
  double bond_k;         /* N/m, bond stretch k_r [30] */
  double angle_k;        /* J (N m), bond angle k_theta, cosine form [1e-3] */
  double stretch_bend_k; /* N, stretch-bend coupling k_sb [0] */
  /* PBD / XPBD (seed 003 §4): stiffness in 0..1 for PBD, compliance
   * (m/N for distance, 1/(N m^2)... per constraint) for XPBD. */
  double distance_stiffness;   /* PBD [1] */
  double volume_stiffness;     /* PBD [1] */
  double distance_compliance;  /* XPBD [1e-4] */
  double volume_compliance;    /* XPBD [1e-6] */
  /* vertex_based (seed 002 ch. 4): slopes of the slope-intercept rule for
   * the touched node and its first and second rings, m1 > m2 > m3 > 0. */
  double slope_m1, slope_m2, slope_m3; /* [1, 0.6, 0.3] */
  /* adaptive_mass_spring (seed 002 ch. 5): one-ring faces larger than
   * refine_area are subdivided, up to refine_levels levels. */
  double refine_area;    /* m^2 [2e-5] */
  int refine_levels;     /* [2] */
} scene_material_t;

/* Model-specific settings (key `solver:` and extra `material:` keys in the
 * scene file). Each model reads only its own fields; defaults in brackets. */
typedef struct scene_solver {
  int substeps;          /* sub-steps per scene step; 0 = automatic from the stability bound [0] */
  int iterations;        /* PBD/XPBD constraint iterations per sub-step [10] */
  double cg_tolerance;   /* implicit Euler: relative CG residual [1e-3] */
  int cg_max_iterations; /* implicit Euler [200] */
  double tet_size;       /* m, target tetrahedron edge when a volume mesh is built [0: auto] */
} scene_solver_t;

typedef struct scene_organ {
  char name[SCENE_NAME_LEN];
  char mesh[SCENE_PATH_LEN]; /* resolved path */
  /* One of: mass_spring_surface, mass_spring_tet, molecular, pbd, xpbd,
   * vertex_based, adaptive_mass_spring. */
  char model[32];
  /* Force-based models: explicit_euler, symplectic_euler, verlet, rk4, implicit_euler. */
  char integrator[32];
  scene_solver_t solver;
  double position[3];        /* m, translation applied after scale (default 0) */
  double scale;              /* applied to the mesh coordinates (default 1) */
  float color[3];            /* RGB 0..1 (default 0.8 0.35 0.3) */
  scene_material_t material;
  int fixed_below_set;       /* 1 if fixed_below was given */
  double fixed_below;        /* m, vertices with z below this are fixed */
  int line;                  /* line of the organ entry, for later messages */
} scene_organ_t;

typedef struct scene_tool {
  char name[SCENE_NAME_LEN];
  char kind[32];    /* "probe" (v1); later "grasper", "scalpel", ... */
  double radius;    /* m, tip radius (default 0.002) */
  double length;    /* m, shaft length for drawing (default 0.1) */
  double stiffness; /* N/m, proxy virtual spring (default 300) */
  double max_force; /* N, clamp (default 4) */
  /* Palpation force thresholds (seed 002 ch. 6), N on the contact force
   * magnitude; 0 = not set (no events for it). Key `thresholds:`, each
   * optional: st (sound threshold: the audio/visual cue to ease off),
   * mpf (maximum palpation force: the target not to go beyond), sft
   * (stopping force threshold: the hard upper bound). Refused unless
   * 0 < st < mpf <= sft <= max_force for those given. */
  double sft, st, mpf;
  int line;
} scene_tool_t;

typedef struct scene {
  char path[SCENE_PATH_LEN];
  char name[SCENE_NAME_LEN];  /* required */
  char description[256];
  double dt;                  /* s, physics step (default 0.001) */
  double publish_hz;          /* MeshDelta rate (default 30) */
  double quant_step;          /* m, MeshDelta quantization (default 1e-5) */
  double gravity[3];          /* m/s^2 (default 0 0 0: organs rest on home springs) */
  size_t norgans;             /* >= 1 */
  scene_organ_t organs[SCENE_MAX_ORGANS];
  size_t ntools;
  scene_tool_t tools[SCENE_MAX_TOOLS];
} scene_t;

/* Fills *out with defaults, then the file's values. 0 on success; -1 with a
 * message naming file, line and field on any problem (missing or unreadable
 * file, YAML syntax error, unknown key, wrong type, out-of-range value,
 * missing required field, too many organs/tools, duplicate names). Does not
 * open the mesh files: the server imports them and reports their problems. */
int scene_load(const char *path, scene_t *out, verr_t *err);

/* Same, from a string; `name` stands in for the file name in messages and
 * relative mesh paths are resolved against `base_dir` (may be NULL: cwd). */
int scene_load_string(const char *text, const char *name, const char *base_dir, scene_t *out, verr_t *err);

#endif
