/* SPDX-License-Identifier: Apache-2.0 */
/* scene: YAML scene file -> scene_t.
 *
 * Two passes. libyaml's event parser first builds a small tree of scalars,
 * lists and mappings that remembers where each node starts; the schema check
 * then walks that tree, so every message can name the line and the field path
 * even though the error is found after parsing. The tree is freed before
 * returning: the result is plain data. */
#include "scene.h"
#include "scene_limits.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <yaml.h>

#include "station.h"

/* A scene is a few kilobytes; the caps keep a hostile or mistaken file (a
 * mesh passed by accident, a YAML bomb) from costing more than a few MB. */
#define SCENE_MAX_BYTES (1u << 20)
#define SCENE_MAX_DEPTH 16 /* the schema needs 4 */
#define SCENE_MAX_NODES 20000
#define SCENE_MAX_KEYS 24 /* most keys any one mapping of the schema has */
#define SHOW_LEN 48       /* longest excerpt of user text quoted in a message */
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

/* The accepted names for each choice field, the first being the default.
 * Adding a model, integrator or tool kind means adding it here only. */
static const char *const scene_models[] = {"mass_spring_surface", "mass_spring_tet",     "molecular", "pbd", "xpbd",
                                           "vertex_based",        "adaptive_mass_spring"};
static const char *const scene_integrators[] = {"symplectic_euler", "explicit_euler", "verlet", "rk4",
                                                "implicit_euler",   "implicit_pcg"};
static const char *const scene_tool_kinds[] = {"probe", "grasper", "scalpel", "extractor", "syringe"};
static const char *const scene_object_kinds[] = {"stone"};
static const char *const scene_task_kinds[] = {"stone_removal", "palpate_target", "grasp_pull"};
static const char *const scene_task_starts[] = {"first_command", "instructor"};

/* ---- the tree ---------------------------------------------------------- */

enum node_kind { N_SCALAR, N_SEQ, N_MAP };

typedef struct node {
  enum node_kind kind;
  int line, col;      /* 1-based, where the node starts */
  int plain;          /* scalar: plain style and untagged, so it may be a number or null */
  char *text;         /* scalar: NUL-terminated copy */
  size_t len;         /* scalar: length in bytes (YAML escapes can put NUL bytes inside) */
  struct node **kids; /* list: items; mapping: key, value, key, value, ... */
  size_t nkids, cap;
} node_t;

static void node_free(node_t *n) {
  if (!n) return;
  for (size_t i = 0; i < n->nkids; i++) node_free(n->kids[i]);
  free(n->kids);
  free(n->text);
  free(n);
}

typedef struct ctx {
  const char *name; /* file name for messages */
  verr_t *err;
} ctx_t;

typedef struct builder {
  node_t *root;
  node_t *stack[SCENE_MAX_DEPTH]; /* open lists and mappings, innermost last */
  int depth;
  size_t nnodes;
  int ndocs;
} builder_t;

static int add_node(const ctx_t *c, builder_t *b, enum node_kind kind, const yaml_event_t *ev) {
  int line = (int)ev->start_mark.line + 1, col = (int)ev->start_mark.column + 1;
  if (++b->nnodes > SCENE_MAX_NODES)
    return verr_set(c->err, "%s:%d:%d: too many YAML nodes (max %d)", c->name, line, col, SCENE_MAX_NODES);
  if (kind != N_SCALAR && b->depth >= SCENE_MAX_DEPTH)
    return verr_set(c->err, "%s:%d:%d: nesting deeper than %d levels", c->name, line, col, SCENE_MAX_DEPTH);
  node_t *n = calloc(1, sizeof *n);
  if (!n) return verr_set(c->err, "%s: out of memory", c->name);
  n->kind = kind;
  n->line = line;
  n->col = col;
  if (kind == N_SCALAR) {
    n->len = ev->data.scalar.length;
    n->text = malloc(n->len + 1);
    if (!n->text) {
      free(n);
      return verr_set(c->err, "%s: out of memory", c->name);
    }
    memcpy(n->text, ev->data.scalar.value, n->len);
    n->text[n->len] = '\0';
    /* A quoted or tagged scalar is a string by the author's choice: it is
     * never read as a number or as null. */
    n->plain = ev->data.scalar.style == YAML_PLAIN_SCALAR_STYLE && ev->data.scalar.tag == NULL;
  }
  if (b->depth == 0) {
    b->root = n; /* one document, so one root: a second DOCUMENT_START is refused */
  } else {
    node_t *parent = b->stack[b->depth - 1];
    if (parent->nkids == parent->cap) {
      size_t cap = parent->cap ? 2 * parent->cap : 8;
      node_t **kids = realloc(parent->kids, cap * sizeof *kids);
      if (!kids) {
        node_free(n);
        return verr_set(c->err, "%s: out of memory", c->name);
      }
      parent->kids = kids;
      parent->cap = cap;
    }
    parent->kids[parent->nkids++] = n;
  }
  if (kind != N_SCALAR) b->stack[b->depth++] = n;
  return 0;
}

static int syntax_err(const ctx_t *c, const yaml_parser_t *p, const char *text, size_t len) {
  if (p->error == YAML_MEMORY_ERROR) return verr_set(c->err, "%s: out of memory while parsing", c->name);
  const char *problem = p->problem ? p->problem : "unknown error";
  size_t line, col;
  if (p->error == YAML_READER_ERROR) {
    /* Reader errors (bad UTF-8, control characters) carry a byte offset, not
     * a mark: count the lines up to it ourselves. */
    size_t off = p->problem_offset < len ? p->problem_offset : len, bol = 0;
    line = 1;
    for (size_t i = 0; i < off; i++)
      if (text[i] == '\n') {
        line++;
        bol = i + 1;
      }
    col = off - bol + 1;
    if (p->problem_value >= 0)
      return verr_set(c->err, "%s:%zu:%zu: YAML syntax error: %s (byte 0x%02X)", c->name, line, col, problem,
                      (unsigned)p->problem_value);
    return verr_set(c->err, "%s:%zu:%zu: YAML syntax error: %s", c->name, line, col, problem);
  }
  line = p->problem_mark.line + 1;
  col = p->problem_mark.column + 1;
  if (p->context)
    return verr_set(c->err, "%s:%zu:%zu: YAML syntax error: %s (%s at line %zu)", c->name, line, col, problem,
                    p->context, (size_t)p->context_mark.line + 1);
  return verr_set(c->err, "%s:%zu:%zu: YAML syntax error: %s", c->name, line, col, problem);
}

/* Parses one YAML document into a tree; *root is NULL for a stream with no
 * document at all (empty or comments only). */
static int parse_tree(const ctx_t *c, const char *text, size_t len, node_t **root) {
  yaml_parser_t p;
  *root = NULL;
  if (!yaml_parser_initialize(&p)) return verr_set(c->err, "%s: out of memory", c->name);
  yaml_parser_set_input_string(&p, (const unsigned char *)text, len);
  builder_t b;
  memset(&b, 0, sizeof b);
  int rc = 0, done = 0;
  while (!done && rc == 0) {
    yaml_event_t ev;
    if (!yaml_parser_parse(&p, &ev)) {
      rc = syntax_err(c, &p, text, len);
      break;
    }
    int line = (int)ev.start_mark.line + 1, col = (int)ev.start_mark.column + 1;
    switch (ev.type) {
    case YAML_STREAM_END_EVENT:
      done = 1;
      break;
    case YAML_DOCUMENT_START_EVENT:
      /* Silently using the first of several documents would hide the rest. */
      if (++b.ndocs > 1)
        rc = verr_set(c->err, "%s:%d: only one YAML document is allowed in a scene file", c->name, line);
      break;
    case YAML_ALIAS_EVENT:
      /* Aliases would make the tree a graph and open the door to
       * exponential expansion; a scene is small enough to write out. */
      rc = verr_set(c->err, "%s:%d:%d: YAML alias '*%.*s' is not supported: write the value out", c->name, line, col,
                    SHOW_LEN, (const char *)ev.data.alias.anchor);
      break;
    case YAML_SCALAR_EVENT:
      rc = add_node(c, &b, N_SCALAR, &ev);
      break;
    case YAML_SEQUENCE_START_EVENT:
      rc = add_node(c, &b, N_SEQ, &ev);
      break;
    case YAML_MAPPING_START_EVENT:
      rc = add_node(c, &b, N_MAP, &ev);
      break;
    case YAML_SEQUENCE_END_EVENT:
    case YAML_MAPPING_END_EVENT:
      b.depth--;
      break;
    default:
      break;
    }
    yaml_event_delete(&ev);
  }
  yaml_parser_delete(&p);
  if (rc) {
    node_free(b.root);
    return -1;
  }
  *root = b.root;
  return 0;
}

/* ---- messages ---------------------------------------------------------- */

static int field_err(const ctx_t *c, const node_t *n, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int field_err(const ctx_t *c, const node_t *n, const char *path, const char *fmt, ...) {
  char what[VERR_MSG_LEN];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  return verr_set(c->err, "%s:%d: field '%s': %s", c->name, n->line, path, what);
}

static int is_null(const node_t *n) {
  if (n->kind != N_SCALAR || !n->plain) return 0;
  const char *t = n->text;
  return n->len == 0 || !strcmp(t, "~") || !strcmp(t, "null") || !strcmp(t, "Null") || !strcmp(t, "NULL");
}

static const char *kind_name(const node_t *n) {
  if (n->kind == N_SEQ) return "a list";
  if (n->kind == N_MAP) return "a mapping";
  return is_null(n) ? "null" : "a single value";
}

/* "%.*s%s" arguments quoting at most SHOW_LEN bytes of a scalar. */
#define SHOW(n) (int)((n)->len > SHOW_LEN ? SHOW_LEN : (n)->len), (n)->text, ((n)->len > SHOW_LEN ? "..." : "")

/* Field path "prefix.key". Schema paths are far shorter than the buffers;
 * should one ever be cut, the "..." shows it rather than hiding it. */
static void join(char *dst, size_t size, const char *prefix, const char *key) {
  int w = snprintf(dst, size, "%s%s%s", prefix, *prefix ? "." : "", key);
  if (w < 0 || (size_t)w >= size) memcpy(dst + size - 4, "...", 4);
}

static void list_names(char *dst, size_t size, const char *const *names, size_t n) {
  size_t k = 0;
  dst[0] = '\0';
  for (size_t i = 0; i < n && k < size; i++) {
    int w = snprintf(dst + k, size - k, "%s%s", i ? ", " : "", names[i]);
    if (w < 0) break;
    k += (size_t)w;
  }
}

/* ---- value readers ----------------------------------------------------- */

/* Every numeric key's range is a row of the one table (scene_limits.h);
 * `lk` names the row. */
static int get_number(const ctx_t *c, const node_t *n, const char *path, const char *lk, double *out) {
  if (n->kind != N_SCALAR || is_null(n)) return field_err(c, n, path, "must be a number (got %s)", kind_name(n));
  if (!n->plain) return field_err(c, n, path, "must be a number, not a quoted string (got \"%.*s%s\")", SHOW(n));
  /* YAML spells them .nan and .inf; strtod would also take nan and inf. */
  const char *t = n->text + (n->text[0] == '+' || n->text[0] == '-');
  if (*t == '.') t++;
  if (!strcasecmp(t, "nan") || !strcasecmp(t, "inf") || !strcasecmp(t, "infinity"))
    return field_err(c, n, path, "must be a finite number (got %.*s%s)", SHOW(n));
  /* Only decimal notation: strtod would also read hex floats, and YAML 1.1
   * forms such as 1_000 or 0o17 are not worth a surprise. */
  if (n->len == 0 || strspn(n->text, "0123456789+-.eE") != n->len)
    return field_err(c, n, path, "must be a number (got '%.*s%s')", SHOW(n));
  char *end;
  errno = 0;
  double v = strtod(n->text, &end);
  if (end != n->text + n->len) return field_err(c, n, path, "must be a number (got '%.*s%s')", SHOW(n));
  if (!isfinite(v)) return field_err(c, n, path, "must be a finite number (got %.*s%s)", SHOW(n));
  const scene_limit_t *l = scene_limit(lk);
  if (!l) return field_err(c, n, path, "no range known for '%s' (a bug in scene.c)", lk);
  if (!scene_limit_ok(l, v)) {
    char want[96];
    scene_limit_describe(l, want, sizeof want);
    return field_err(c, n, path, "%s (got %.*s%s): %s", want, SHOW(n), l->why);
  }
  *out = v;
  return 0;
}

/* Optional number field: n == NULL (absent) keeps the default in *out. */
static int opt_number(const ctx_t *c, const node_t *n, const char *prefix, const char *key, const char *lk,
                      double *out) {
  if (!n) return 0;
  char path[128];
  join(path, sizeof path, prefix, key);
  return get_number(c, n, path, lk, out);
}

/* A whole number in r (the range is checked first, so the message for 1e9
 * is the range, not the type). */
static int get_int(const ctx_t *c, const node_t *n, const char *path, const char *lk, int *out) {
  double v;
  if (get_number(c, n, path, lk, &v)) return -1;
  if (v != floor(v) || fabs(v) > 1e9) return field_err(c, n, path, "must be a whole number (got %.*s%s)", SHOW(n));
  *out = (int)v;
  return 0;
}

static int opt_int(const ctx_t *c, const node_t *n, const char *prefix, const char *key, const char *lk, int *out) {
  if (!n) return 0;
  char path[128];
  join(path, sizeof path, prefix, key);
  return get_int(c, n, path, lk, out);
}

static int get_vec3(const ctx_t *c, const node_t *n, const char *path, const char *lk, double out[3]) {
  if (n->kind != N_SEQ || n->nkids != 3) {
    if (n->kind == N_SEQ)
      return field_err(c, n, path, "must be a list of 3 numbers [x, y, z] (got %zu items)", n->nkids);
    return field_err(c, n, path, "must be a list of 3 numbers [x, y, z] (got %s)", kind_name(n));
  }
  double v[3];
  for (int i = 0; i < 3; i++) {
    char p[160];
    snprintf(p, sizeof p, "%s[%d]", path, i);
    if (get_number(c, n->kids[i], p, lk, &v[i])) return -1;
  }
  memcpy(out, v, sizeof v);
  return 0;
}

static int get_string(const ctx_t *c, const node_t *n, const char *path, char *dst, size_t size) {
  if (n->kind != N_SCALAR || is_null(n)) return field_err(c, n, path, "must be a string (got %s)", kind_name(n));
  if (memchr(n->text, '\0', n->len)) return field_err(c, n, path, "must not contain NUL bytes");
  if (n->len >= size) return field_err(c, n, path, "too long (%zu bytes, max %zu)", n->len, size - 1);
  memcpy(dst, n->text, n->len + 1);
  return 0;
}

/* Names end up in topic keys, file names and log lines: keep them plain. */
static int get_name(const ctx_t *c, const node_t *n, const char *path, char *dst, size_t size) {
  if (get_string(c, n, path, dst, size)) return -1;
  if (!dst[0]) return field_err(c, n, path, "must not be empty");
  size_t ok = strspn(dst, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-");
  if (dst[ok]) return field_err(c, n, path, "may contain only letters, digits, '_' and '-' (got '%.*s%s')", SHOW(n));
  return 0;
}

static int get_choice(const ctx_t *c, const node_t *n, const char *path, const char *const *names, size_t count,
                      char *dst, size_t size) {
  char buf[64];
  if (get_string(c, n, path, buf, sizeof buf) == 0)
    for (size_t i = 0; i < count; i++)
      if (!strcmp(buf, names[i])) {
        if (strlen(names[i]) >= size) return field_err(c, n, path, "'%s' does not fit the scene_t field", names[i]);
        strcpy(dst, names[i]);
        return 0;
      }
  /* Either not a string or not a known name: list what is accepted. */
  char allowed[256];
  list_names(allowed, sizeof allowed, names, count);
  if (n->kind != N_SCALAR || is_null(n))
    return field_err(c, n, path, "must be one of: %s (got %s)", allowed, kind_name(n));
  return field_err(c, n, path, "must be one of: %s (got '%.*s%s')", allowed, SHOW(n));
}

/* Checks that `n` is a mapping whose keys are all in `keys`, each at most
 * once, and sets vals[i] to the value given for keys[i] (NULL if absent). */
static int get_fields(const ctx_t *c, const node_t *n, const char *path, const char *const *keys, size_t nkeys,
                      const node_t **vals) {
  const node_t *seen[SCENE_MAX_KEYS] = {0};
  if (n->kind != N_MAP)
    return field_err(c, n, *path ? path : "(top level)", "must be a mapping of fields (got %s)", kind_name(n));
  for (size_t i = 0; i < nkeys; i++) vals[i] = NULL;
  for (size_t p = 0; p + 1 < n->nkids; p += 2) {
    const node_t *k = n->kids[p];
    char kpath[160];
    if (k->kind != N_SCALAR)
      return field_err(c, k, *path ? path : "(top level)", "keys must be plain names (got %s)", kind_name(k));
    snprintf(kpath, sizeof kpath, "%s%s%.*s%s", path, *path ? "." : "", SHOW(k));
    size_t i = 0;
    while (i < nkeys && !(strlen(keys[i]) == k->len && !memcmp(keys[i], k->text, k->len))) i++;
    if (i == nkeys) {
      char allowed[400];
      list_names(allowed, sizeof allowed, keys, nkeys);
      return field_err(c, k, kpath, "unknown key (allowed: %s)", allowed);
    }
    if (seen[i]) return field_err(c, k, kpath, "duplicate key (first given at line %d)", seen[i]->line);
    seen[i] = k;
    vals[i] = n->kids[p + 1];
  }
  return 0;
}

static int missing(const ctx_t *c, const node_t *owner, const char *prefix, const char *key) {
  char path[128];
  join(path, sizeof path, prefix, key);
  return field_err(c, owner, path, "required field missing");
}

/* ---- the schema -------------------------------------------------------- */

enum {
  P_DT,
  P_PUBLISH_HZ,
  P_QUANT_STEP,
  P_GRAVITY,
  P_SLEEP_SPEED,
  P_SLEEP_AFTER,
  P_PUBLISH_KEEPALIVE,
  P_INTEGRATOR,
  P_NKEYS
};
static const char *const physics_keys[P_NKEYS] = {[P_DT] = "dt",
                                                  [P_PUBLISH_HZ] = "publish_hz",
                                                  [P_QUANT_STEP] = "quant_step",
                                                  [P_GRAVITY] = "gravity",
                                                  [P_SLEEP_SPEED] = "sleep_speed",
                                                  [P_SLEEP_AFTER] = "sleep_after",
                                                  [P_PUBLISH_KEEPALIVE] = "publish_keepalive",
                                                  [P_INTEGRATOR] = "integrator"};

enum {
  M_MASS,
  M_STIFFNESS,
  M_DAMPING,
  M_HOME_STIFFNESS,
  M_HOME_DAMPING,
  M_BOND_K,
  M_ANGLE_K,
  M_STRETCH_BEND_K,
  M_DISTANCE_STIFFNESS,
  M_VOLUME_STIFFNESS,
  M_DISTANCE_COMPLIANCE,
  M_VOLUME_COMPLIANCE,
  M_SLOPE_M1,
  M_SLOPE_M2,
  M_SLOPE_M3,
  M_REFINE_AREA,
  M_REFINE_LEVELS,
  M_NKEYS
};
static const char *const material_keys[M_NKEYS] = {[M_MASS] = "mass",
                                                   [M_STIFFNESS] = "stiffness",
                                                   [M_DAMPING] = "damping",
                                                   [M_HOME_STIFFNESS] = "home_stiffness",
                                                   [M_HOME_DAMPING] = "home_damping",
                                                   [M_BOND_K] = "bond_k",
                                                   [M_ANGLE_K] = "angle_k",
                                                   [M_STRETCH_BEND_K] = "stretch_bend_k",
                                                   [M_DISTANCE_STIFFNESS] = "distance_stiffness",
                                                   [M_VOLUME_STIFFNESS] = "volume_stiffness",
                                                   [M_DISTANCE_COMPLIANCE] = "distance_compliance",
                                                   [M_VOLUME_COMPLIANCE] = "volume_compliance",
                                                   [M_SLOPE_M1] = "slope_m1",
                                                   [M_SLOPE_M2] = "slope_m2",
                                                   [M_SLOPE_M3] = "slope_m3",
                                                   [M_REFINE_AREA] = "refine_area",
                                                   [M_REFINE_LEVELS] = "refine_levels"};

enum {
  V_SUBSTEPS,
  V_ITERATIONS,
  V_CG_TOLERANCE,
  V_CG_MAX_ITERATIONS,
  V_TET_SIZE,
  V_REGION_FORCE,
  V_REGION_SPEED,
  V_NKEYS
};
static const char *const solver_keys[V_NKEYS] = {
    [V_SUBSTEPS] = "substeps",         [V_ITERATIONS] = "iterations",
    [V_CG_TOLERANCE] = "cg_tolerance", [V_CG_MAX_ITERATIONS] = "cg_max_iterations",
    [V_TET_SIZE] = "tet_size",         [V_REGION_FORCE] = "region_force",
    [V_REGION_SPEED] = "region_speed"};

enum {
  O_NAME,
  O_MESH,
  O_MODEL,
  O_INTEGRATOR,
  O_SOLVER,
  O_POSITION,
  O_SCALE,
  O_COLOR,
  O_FIXED_BELOW,
  O_MATERIAL,
  O_VOLUME,
  O_NKEYS
};
static const char *const organ_keys[O_NKEYS] = {[O_NAME] = "name",
                                                [O_MESH] = "mesh",
                                                [O_MODEL] = "model",
                                                [O_INTEGRATOR] = "integrator",
                                                [O_SOLVER] = "solver",
                                                [O_POSITION] = "position",
                                                [O_SCALE] = "scale",
                                                [O_COLOR] = "color",
                                                [O_FIXED_BELOW] = "fixed_below",
                                                [O_MATERIAL] = "material",
                                                [O_VOLUME] = "volume"};

enum {
  T_NAME,
  T_KIND,
  T_RADIUS,
  T_LENGTH,
  T_STIFFNESS,
  T_MAX_FORCE,
  T_THRESHOLDS,
  T_FRICTION,
  T_GRASP_RADIUS,
  T_JAW_OPENING,
  T_BLADE_LENGTH,
  T_STATION,
  T_NKEYS
};
static const char *const tool_keys[T_NKEYS] = {[T_NAME] = "name",
                                               [T_KIND] = "kind",
                                               [T_RADIUS] = "radius",
                                               [T_LENGTH] = "length",
                                               [T_STIFFNESS] = "stiffness",
                                               [T_MAX_FORCE] = "max_force",
                                               [T_THRESHOLDS] = "thresholds",
                                               [T_FRICTION] = "friction",
                                               [T_GRASP_RADIUS] = "grasp_radius",
                                               [T_JAW_OPENING] = "jaw_opening",
                                               [T_BLADE_LENGTH] = "blade_length",
                                               [T_STATION] = "station"};

enum { J_NAME, J_KIND, J_RADIUS, J_POSITION, J_ORGAN, J_COLOR, J_NKEYS };
static const char *const object_keys[J_NKEYS] = {[J_NAME] = "name",         [J_KIND] = "kind",   [J_RADIUS] = "radius",
                                                 [J_POSITION] = "position", [J_ORGAN] = "organ", [J_COLOR] = "color"};

enum { K_NAME, K_KIND, K_TOOL, K_OBJECT, K_TARGET, K_TARGET_RADIUS, K_DISTANCE, K_START, K_NKEYS };
static const char *const task_keys[K_NKEYS] = {
    [K_NAME] = "name",         [K_KIND] = "kind",     [K_TOOL] = "tool",
    [K_OBJECT] = "object",     [K_TARGET] = "target", [K_TARGET_RADIUS] = "target_radius",
    [K_DISTANCE] = "distance", [K_START] = "start"};

/* In the order they must rise: ST < MPF <= SFT (docs/methods.md B ch. 6). */
enum { H_ST, H_MPF, H_SFT, H_NKEYS };
static const char *const threshold_keys[H_NKEYS] = {[H_ST] = "st", [H_MPF] = "mpf", [H_SFT] = "sft"};

enum { S_SCENE, S_DESCRIPTION, S_PHYSICS, S_ORGANS, S_TOOLS, S_OBJECTS, S_TASKS, S_NKEYS };
static const char *const top_keys[S_NKEYS] = {
    [S_SCENE] = "scene", [S_DESCRIPTION] = "description", [S_PHYSICS] = "physics", [S_ORGANS] = "organs",
    [S_TOOLS] = "tools", [S_OBJECTS] = "objects",         [S_TASKS] = "tasks"};

/* get_fields() tracks the keys seen in a fixed array of SCENE_MAX_KEYS. */
_Static_assert(P_NKEYS <= SCENE_MAX_KEYS && M_NKEYS <= SCENE_MAX_KEYS && V_NKEYS <= SCENE_MAX_KEYS &&
                   O_NKEYS <= SCENE_MAX_KEYS && T_NKEYS <= SCENE_MAX_KEYS && H_NKEYS <= SCENE_MAX_KEYS &&
                   S_NKEYS <= SCENE_MAX_KEYS && J_NKEYS <= SCENE_MAX_KEYS && K_NKEYS <= SCENE_MAX_KEYS,
               "raise SCENE_MAX_KEYS");
_Static_assert(sizeof(((scene_tool_t *)0)->station) == STATION_NAME_MAX, "scene_tool_t.station: one station name");

static void organ_defaults(scene_organ_t *o) {
  memset(o, 0, sizeof *o);
  snprintf(o->model, sizeof o->model, "%s", scene_models[0]);
  snprintf(o->integrator, sizeof o->integrator, "%s", scene_integrators[0]);
  o->scale = 1;
  o->color[0] = 0.8f;
  o->color[1] = 0.35f;
  o->color[2] = 0.3f;
  o->material.mass = 0.1;
  o->material.stiffness = 30;
  o->material.damping = 0.02;
  o->material.home_stiffness = 30;
  o->material.home_damping = 0.005;
  o->material.bond_k = 30;
  o->material.angle_k = 1e-3;
  o->material.stretch_bend_k = 0;
  o->material.distance_stiffness = 1;
  o->material.volume_stiffness = 1;
  o->material.distance_compliance = 1e-4;
  o->material.volume_compliance = 1e-6;
  o->material.slope_m1 = 1;
  o->material.slope_m2 = 0.6;
  o->material.slope_m3 = 0.3;
  o->material.refine_area = 2e-5;
  o->material.refine_levels = 2;
  o->solver.substeps = 0;
  o->solver.iterations = 10;
  o->solver.cg_tolerance = 1e-3;
  o->solver.cg_max_iterations = 200;
  o->solver.tet_size = 0;
  o->solver.region_force = SCENE_REGION_FORCE;
  o->solver.region_speed = SCENE_REGION_SPEED;
}

static void tool_defaults(scene_tool_t *t) {
  memset(t, 0, sizeof *t);
  snprintf(t->kind, sizeof t->kind, "%s", scene_tool_kinds[0]);
  t->radius = 0.002;
  t->length = 0.1;
  t->stiffness = 300;
  t->max_force = 4;
}

static int parse_physics(const ctx_t *c, const node_t *n, scene_t *s) {
  const node_t *v[P_NKEYS];
  if (get_fields(c, n, "physics", physics_keys, P_NKEYS, v)) return -1;
  if (opt_number(c, v[P_DT], "physics", "dt", "physics.dt", &s->dt)) return -1;
  if (opt_number(c, v[P_PUBLISH_HZ], "physics", "publish_hz", "physics.publish_hz", &s->publish_hz)) return -1;
  if (opt_number(c, v[P_QUANT_STEP], "physics", "quant_step", "physics.quant_step", &s->quant_step)) return -1;
  if (v[P_GRAVITY] && get_vec3(c, v[P_GRAVITY], "physics.gravity", "physics.gravity", s->gravity)) return -1;
  if (opt_number(c, v[P_SLEEP_SPEED], "physics", "sleep_speed", "physics.sleep_speed", &s->sleep_speed)) return -1;
  if (opt_number(c, v[P_SLEEP_AFTER], "physics", "sleep_after", "physics.sleep_after", &s->sleep_after)) return -1;
  if (opt_number(c, v[P_PUBLISH_KEEPALIVE], "physics", "publish_keepalive", "physics.publish_keepalive",
                 &s->publish_keepalive))
    return -1;
  /* The integrator of every organ that names none (issue 17.3). */
  if (v[P_INTEGRATOR] && get_choice(c, v[P_INTEGRATOR], "physics.integrator", scene_integrators,
                                    COUNT(scene_integrators), s->integrator, sizeof s->integrator))
    return -1;
  /* Fewer than two steps of stillness is no evidence of rest. */
  if (v[P_SLEEP_AFTER] && s->sleep_after < 2 * s->dt)
    return field_err(c, v[P_SLEEP_AFTER], "physics.sleep_after", "must be at least two steps (2 dt)");
  return 0;
}

/* v[] receives the value nodes so the model-specific checks in parse_organ
 * can point at the line of the value they complain about. */
static int parse_material(const ctx_t *c, const node_t *n, const char *path, scene_material_t *m, const node_t **v) {
  if (get_fields(c, n, path, material_keys, M_NKEYS, v)) return -1;
  if (opt_number(c, v[M_MASS], path, "mass", "organs.material.mass", &m->mass)) return -1;
  if (opt_number(c, v[M_STIFFNESS], path, "stiffness", "organs.material.stiffness", &m->stiffness)) return -1;
  if (opt_number(c, v[M_DAMPING], path, "damping", "organs.material.damping", &m->damping)) return -1;
  if (opt_number(c, v[M_HOME_STIFFNESS], path, "home_stiffness", "organs.material.home_stiffness", &m->home_stiffness))
    return -1;
  if (opt_number(c, v[M_HOME_DAMPING], path, "home_damping", "organs.material.home_damping", &m->home_damping))
    return -1;
  if (opt_number(c, v[M_BOND_K], path, "bond_k", "organs.material.bond_k", &m->bond_k)) return -1;
  if (opt_number(c, v[M_ANGLE_K], path, "angle_k", "organs.material.angle_k", &m->angle_k)) return -1;
  /* The coupling may have either sign; only its square enters the
   * definiteness condition checked in parse_organ. */
  if (opt_number(c, v[M_STRETCH_BEND_K], path, "stretch_bend_k", "organs.material.stretch_bend_k", &m->stretch_bend_k))
    return -1;
  if (opt_number(c, v[M_DISTANCE_STIFFNESS], path, "distance_stiffness", "organs.material.distance_stiffness",
                 &m->distance_stiffness))
    return -1;
  if (opt_number(c, v[M_VOLUME_STIFFNESS], path, "volume_stiffness", "organs.material.volume_stiffness",
                 &m->volume_stiffness))
    return -1;
  if (opt_number(c, v[M_DISTANCE_COMPLIANCE], path, "distance_compliance", "organs.material.distance_compliance",
                 &m->distance_compliance))
    return -1;
  if (opt_number(c, v[M_VOLUME_COMPLIANCE], path, "volume_compliance", "organs.material.volume_compliance",
                 &m->volume_compliance))
    return -1;
  if (opt_number(c, v[M_SLOPE_M1], path, "slope_m1", "organs.material.slope_m1", &m->slope_m1)) return -1;
  if (opt_number(c, v[M_SLOPE_M2], path, "slope_m2", "organs.material.slope_m2", &m->slope_m2)) return -1;
  if (opt_number(c, v[M_SLOPE_M3], path, "slope_m3", "organs.material.slope_m3", &m->slope_m3)) return -1;
  if (opt_number(c, v[M_REFINE_AREA], path, "refine_area", "organs.material.refine_area", &m->refine_area)) return -1;
  if (opt_int(c, v[M_REFINE_LEVELS], path, "refine_levels", "organs.material.refine_levels", &m->refine_levels))
    return -1;
  return 0;
}

static int parse_solver(const ctx_t *c, const node_t *n, const char *path, scene_solver_t *sv) {
  const node_t *v[V_NKEYS];
  if (get_fields(c, n, path, solver_keys, V_NKEYS, v)) return -1;
  if (opt_int(c, v[V_SUBSTEPS], path, "substeps", "organs.solver.substeps", &sv->substeps)) return -1;
  if (opt_int(c, v[V_ITERATIONS], path, "iterations", "organs.solver.iterations", &sv->iterations)) return -1;
  if (opt_number(c, v[V_CG_TOLERANCE], path, "cg_tolerance", "organs.solver.cg_tolerance", &sv->cg_tolerance))
    return -1;
  if (opt_int(c, v[V_CG_MAX_ITERATIONS], path, "cg_max_iterations", "organs.solver.cg_max_iterations",
              &sv->cg_max_iterations))
    return -1;
  if (opt_number(c, v[V_TET_SIZE], path, "tet_size", "organs.solver.tet_size", &sv->tet_size)) return -1;
  if (opt_number(c, v[V_REGION_FORCE], path, "region_force", "organs.solver.region_force", &sv->region_force))
    return -1;
  if (opt_number(c, v[V_REGION_SPEED], path, "region_speed", "organs.solver.region_speed", &sv->region_speed))
    return -1;
  /* 0 asks for the automatic size; anything else below 0.1 mm would build
   * millions of tetrahedra for an organ. */
  if (sv->tet_size != 0 && sv->tet_size < 1e-4) {
    char fp[128];
    join(fp, sizeof fp, path, "tet_size");
    return field_err(c, v[V_TET_SIZE], fp, "must be 0 (automatic) or >= 0.0001 and <= 0.1 (got %.*s%s)",
                     SHOW(v[V_TET_SIZE]));
  }
  return 0;
}

/* Checks that need the model and the material together. `mv` holds the
 * material's value nodes (all NULL when no material was given); a complaint
 * points at the value to change, or at the model line for defaults. */
static int check_model_material(const ctx_t *c, const node_t *model_node, const node_t *organ_node,
                                const node_t *const *mv, const char *path, const scene_organ_t *o) {
  const scene_material_t *m = &o->material;
  char fp[128];
  if (!strcmp(o->model, "molecular")) {
    /* Seed 000 eq. 11: the stretch-bend energy is positive definite only if
     * k_r k_theta > 2 k_sb^2 (docs/numerics.md §6). */
    double lhs = m->bond_k * m->angle_k, rhs = 2 * m->stretch_bend_k * m->stretch_bend_k;
    if (!(lhs > rhs)) {
      int key = mv[M_STRETCH_BEND_K] ? M_STRETCH_BEND_K : mv[M_ANGLE_K] ? M_ANGLE_K : M_BOND_K;
      const node_t *at = mv[key] ? mv[key] : model_node ? model_node : organ_node;
      join(fp, sizeof fp, path, material_keys[key]);
      char sb[40]; /* a negative coupling in brackets, so its square reads right */
      snprintf(sb, sizeof sb, m->stretch_bend_k < 0 ? "(%g)" : "%g", m->stretch_bend_k);
      return field_err(c, at, fp,
                       "the molecular model needs bond_k * angle_k > 2 * stretch_bend_k^2 for a positive-definite "
                       "energy (got %g * %g = %g <= 2 * %s^2 = %g)",
                       m->bond_k, m->angle_k, lhs, sb, rhs);
    }
  }
  if (!strcmp(o->model, "vertex_based") && !(m->slope_m1 > m->slope_m2 && m->slope_m2 > m->slope_m3)) {
    /* The touched node moves most, its rings less: point at the first
     * slope out of order. */
    int key = !(m->slope_m1 > m->slope_m2) ? (mv[M_SLOPE_M2] ? M_SLOPE_M2 : M_SLOPE_M1)
                                           : (mv[M_SLOPE_M3] ? M_SLOPE_M3 : M_SLOPE_M2);
    const node_t *at = mv[key] ? mv[key] : model_node ? model_node : organ_node;
    join(fp, sizeof fp, path, material_keys[key]);
    return field_err(c, at, fp, "the vertex_based model needs slope_m1 > slope_m2 > slope_m3 (got %g, %g, %g)",
                     m->slope_m1, m->slope_m2, m->slope_m3);
  }
  return 0;
}

/* Relative paths are taken from the scene's directory so a scene can be
 * loaded from any working directory; no normalisation is needed to open it. */
static int resolve_mesh(const ctx_t *c, const node_t *n, const char *path, const char *base_dir, char *dst,
                        size_t size) {
  char rel[SCENE_PATH_LEN];
  if (get_string(c, n, path, rel, sizeof rel)) return -1;
  if (!rel[0]) return field_err(c, n, path, "must not be empty");
  if (rel[0] == '/' || !base_dir || !base_dir[0]) {
    memcpy(dst, rel, strlen(rel) + 1);
    return 0;
  }
  size_t bl = strlen(base_dir);
  const char *sep = base_dir[bl - 1] == '/' ? "" : "/";
  int w = snprintf(dst, size, "%s%s%s", base_dir, sep, rel);
  if (w < 0 || (size_t)w >= size)
    return field_err(c, n, path, "too long once joined to the directory '%s' (%d bytes, max %zu)", base_dir, w,
                     size - 1);
  return 0;
}

static int parse_organ(const ctx_t *c, const node_t *n, size_t idx, const char *base_dir, scene_t *s) {
  scene_organ_t *o = &s->organs[idx];
  const node_t *v[O_NKEYS];
  char path[64], fp[128];
  snprintf(path, sizeof path, "organs[%zu]", idx);
  organ_defaults(o);
  if (s->integrator[0]) snprintf(o->integrator, sizeof o->integrator, "%s", s->integrator);
  o->line = n->line;
  if (get_fields(c, n, path, organ_keys, O_NKEYS, v)) return -1;
  if (!v[O_NAME]) return missing(c, n, path, "name");
  if (!v[O_MESH] && !v[O_VOLUME]) return missing(c, n, path, "mesh");
  join(fp, sizeof fp, path, "name");
  if (get_name(c, v[O_NAME], fp, o->name, sizeof o->name)) return -1;
  for (size_t j = 0; j < idx; j++)
    if (!strcmp(s->organs[j].name, o->name))
      return field_err(c, v[O_NAME], fp, "duplicate organ name '%s' (first used by organs[%zu] at line %d)", o->name, j,
                       s->organs[j].line);
  join(fp, sizeof fp, path, "mesh");
  if (v[O_MESH] && resolve_mesh(c, v[O_MESH], fp, base_dir, o->mesh, sizeof o->mesh)) return -1;
  o->mesh_line = v[O_MESH] ? v[O_MESH]->line : 0;
  o->volume_line = v[O_VOLUME] ? v[O_VOLUME]->line : 0;
  join(fp, sizeof fp, path, "model");
  if (v[O_MODEL] && get_choice(c, v[O_MODEL], fp, scene_models, COUNT(scene_models), o->model, sizeof o->model))
    return -1;
  if (v[O_VOLUME]) {
    join(fp, sizeof fp, path, "volume");
    if (resolve_mesh(c, v[O_VOLUME], fp, base_dir, o->volume, sizeof o->volume)) return -1;
    /* Only these models simulate tetrahedra; the others would ignore it. */
    if (strcmp(o->model, "mass_spring_tet") && strcmp(o->model, "pbd") && strcmp(o->model, "xpbd"))
      return field_err(c, v[O_VOLUME], fp,
                       "a tetrahedral mesh is simulated only by the models mass_spring_tet, pbd and xpbd (this organ's "
                       "model is %s: set `model:`)",
                       o->model);
  }
  join(fp, sizeof fp, path, "integrator");
  if (v[O_INTEGRATOR] && get_choice(c, v[O_INTEGRATOR], fp, scene_integrators, COUNT(scene_integrators), o->integrator,
                                    sizeof o->integrator))
    return -1;
  /* implicit_pcg is built for a small fixed CG budget per step (integrator.h);
   * solver.cg_max_iterations, when given, overrides it. */
  if (!strcmp(o->integrator, "implicit_pcg")) o->solver.cg_max_iterations = SCENE_PCG_ITERATIONS;
  /* XPBD's default iteration count keeps every shipped organ real time at one
   * 1 ms sub-step (docs/numerics.md §9.1); solver.iterations, when given,
   * overrides it. PBD keeps 10: its stiffness depends on the count. */
  if (!strcmp(o->model, "xpbd")) o->solver.iterations = SCENE_XPBD_ITERATIONS;
  if (v[O_SOLVER]) {
    join(fp, sizeof fp, path, "solver");
    if (parse_solver(c, v[O_SOLVER], fp, &o->solver)) return -1;
  }
  join(fp, sizeof fp, path, "position");
  if (v[O_POSITION] && get_vec3(c, v[O_POSITION], fp, "organs.position", o->position)) return -1;
  if (opt_number(c, v[O_SCALE], path, "scale", "organs.scale", &o->scale)) return -1;
  if (v[O_COLOR]) {
    double rgb[3];
    join(fp, sizeof fp, path, "color");
    if (get_vec3(c, v[O_COLOR], fp, "organs.color", rgb)) return -1;
    for (int k = 0; k < 3; k++) o->color[k] = (float)rgb[k];
  }
  if (v[O_FIXED_BELOW]) {
    if (opt_number(c, v[O_FIXED_BELOW], path, "fixed_below", "organs.fixed_below", &o->fixed_below)) return -1;
    o->fixed_below_set = 1;
  }
  const node_t *mv[M_NKEYS] = {0};
  join(fp, sizeof fp, path, "material");
  if (v[O_MATERIAL] && parse_material(c, v[O_MATERIAL], fp, &o->material, mv)) return -1;
  return check_model_material(c, v[O_MODEL], n, mv, fp, o);
}

/* thresholds: {st: N, mpf: N, sft: N}, each optional, checked against each
 * other and against the tool's max_force (already parsed). */
static int parse_thresholds(const ctx_t *c, const node_t *n, const char *path, scene_tool_t *t) {
  const node_t *hv[H_NKEYS];
  double *dst[H_NKEYS] = {[H_ST] = &t->st, [H_MPF] = &t->mpf, [H_SFT] = &t->sft};
  char fp[160];
  if (get_fields(c, n, path, threshold_keys, H_NKEYS, hv)) return -1;
  for (int k = 0; k < H_NKEYS; k++) {
    if (!hv[k]) continue;
    if (opt_number(c, hv[k], path, threshold_keys[k], "tools.thresholds", dst[k])) return -1;
    join(fp, sizeof fp, path, threshold_keys[k]);
    if (*dst[k] > t->max_force)
      return field_err(c, hv[k], fp, "must be <= the tool's max_force %g N (got %g)", t->max_force, *dst[k]);
  }
  /* Each given threshold must lie above every lower one given. */
  for (int k = 1; k < H_NKEYS; k++) {
    if (!hv[k]) continue;
    for (int j = 0; j < k; j++) {
      if (!hv[j]) continue;
      int bad = (k == H_SFT && j == H_MPF) ? !(*dst[k] >= *dst[j]) : !(*dst[k] > *dst[j]);
      if (bad) {
        join(fp, sizeof fp, path, threshold_keys[k]);
        return field_err(c, hv[k], fp, "must be %s %s %g N: the order is st < mpf <= sft (got %g)",
                         k == H_SFT && j == H_MPF ? ">=" : ">", threshold_keys[j], *dst[j], *dst[k]);
      }
    }
  }
  return 0;
}

/* Friction for every kind; grasp_radius and jaw_opening only for the kinds
 * that have jaws: a key a kind cannot use is refused, not ignored, so a
 * scene never promises a capability the tool does not have. */
static int parse_capability(const ctx_t *c, const node_t *const *v, const char *path, scene_tool_t *t) {
  char fp[128];
  if (opt_number(c, v[T_FRICTION], path, "friction", "tools.friction", &t->friction)) return -1;
  int jaws = !strcmp(t->kind, "grasper") || !strcmp(t->kind, "extractor");
  if (v[T_GRASP_RADIUS] && !jaws) {
    join(fp, sizeof fp, path, "grasp_radius");
    return field_err(c, v[T_GRASP_RADIUS], fp, "only a grasper or an extractor grasps (this tool is a %s)", t->kind);
  }
  if (v[T_JAW_OPENING] && strcmp(t->kind, "grasper")) {
    join(fp, sizeof fp, path, "jaw_opening");
    return field_err(c, v[T_JAW_OPENING], fp, "only a grasper has jaws to open (this tool is a %s)", t->kind);
  }
  if (v[T_BLADE_LENGTH] && strcmp(t->kind, "scalpel")) {
    join(fp, sizeof fp, path, "blade_length");
    return field_err(c, v[T_BLADE_LENGTH], fp, "only a scalpel has a blade (this tool is a %s)", t->kind);
  }
  if (!strcmp(t->kind, "scalpel")) t->blade_length = 0.02;
  if (opt_number(c, v[T_BLADE_LENGTH], path, "blade_length", "tools.blade_length", &t->blade_length)) return -1;
  if (jaws) t->grasp_radius = 2 * t->radius;
  if (!strcmp(t->kind, "grasper")) t->jaw_opening = 4 * t->radius;
  if (opt_number(c, v[T_GRASP_RADIUS], path, "grasp_radius", "tools.grasp_radius", &t->grasp_radius)) return -1;
  if (opt_number(c, v[T_JAW_OPENING], path, "jaw_opening", "tools.jaw_opening", &t->jaw_opening)) return -1;
  return 0;
}

static int parse_tool(const ctx_t *c, const node_t *n, size_t idx, scene_t *s) {
  scene_tool_t *t = &s->tools[idx];
  const node_t *v[T_NKEYS];
  char path[64], fp[128];
  snprintf(path, sizeof path, "tools[%zu]", idx);
  tool_defaults(t);
  t->line = n->line;
  if (get_fields(c, n, path, tool_keys, T_NKEYS, v)) return -1;
  if (!v[T_NAME]) return missing(c, n, path, "name");
  join(fp, sizeof fp, path, "name");
  if (get_name(c, v[T_NAME], fp, t->name, sizeof t->name)) return -1;
  for (size_t j = 0; j < idx; j++)
    if (!strcmp(s->tools[j].name, t->name))
      return field_err(c, v[T_NAME], fp, "duplicate tool name '%s' (first used by tools[%zu] at line %d)", t->name, j,
                       s->tools[j].line);
  join(fp, sizeof fp, path, "kind");
  if (v[T_KIND] && get_choice(c, v[T_KIND], fp, scene_tool_kinds, COUNT(scene_tool_kinds), t->kind, sizeof t->kind))
    return -1;
  if (opt_number(c, v[T_RADIUS], path, "radius", "tools.radius", &t->radius)) return -1;
  if (opt_number(c, v[T_LENGTH], path, "length", "tools.length", &t->length)) return -1;
  if (opt_number(c, v[T_STIFFNESS], path, "stiffness", "tools.stiffness", &t->stiffness)) return -1;
  if (opt_number(c, v[T_MAX_FORCE], path, "max_force", "tools.max_force", &t->max_force)) return -1;
  if (v[T_THRESHOLDS]) {
    join(fp, sizeof fp, path, "thresholds");
    if (parse_thresholds(c, v[T_THRESHOLDS], fp, t)) return -1;
  }
  if (v[T_STATION]) { /* the initial owner (idl ToolRole); absent: any station */
    join(fp, sizeof fp, path, "station");
    if (get_string(c, v[T_STATION], fp, t->station, sizeof t->station)) return -1;
    if (!station_name_valid(t->station))
      return field_err(c, v[T_STATION], fp, "must be 1..%d characters of A-Z a-z 0-9 _ . - (got '%.*s%s')",
                       STATION_NAME_MAX - 1, SHOW(v[T_STATION]));
  }
  return parse_capability(c, v, path, t);
}

/* Looks `n` up among `count` names spaced `stride` bytes apart; -1 with a
 * message listing them when absent. */
static int find_name(const ctx_t *c, const node_t *n, const char *path, const char *what, const char *names,
                     size_t stride, size_t count, int *out) {
  char want[SCENE_NAME_LEN];
  if (get_string(c, n, path, want, sizeof want)) return -1;
  char known[400] = "";
  size_t k = 0;
  for (size_t i = 0; i < count; i++) {
    const char *nm = names + i * stride;
    if (!strcmp(nm, want)) {
      *out = (int)i;
      return 0;
    }
    if (k < sizeof known) {
      int w = snprintf(known + k, sizeof known - k, "%s%s", i ? ", " : "", nm);
      if (w > 0) k += (size_t)w;
    }
  }
  return field_err(c, n, path, "no %s named '%.*s%s' (known: %s)", what, SHOW(n), count ? known : "none");
}

static int parse_object(const ctx_t *c, const node_t *n, size_t idx, scene_t *s) {
  scene_object_t *o = &s->objects[idx];
  const node_t *v[J_NKEYS];
  char path[64], fp[128];
  snprintf(path, sizeof path, "objects[%zu]", idx);
  memset(o, 0, sizeof *o);
  snprintf(o->kind, sizeof o->kind, "%s", scene_object_kinds[0]);
  o->color[0] = 0.85f;
  o->color[1] = 0.8f;
  o->color[2] = 0.55f;
  o->line = n->line;
  if (get_fields(c, n, path, object_keys, J_NKEYS, v)) return -1;
  if (!v[J_NAME]) return missing(c, n, path, "name");
  if (!v[J_RADIUS]) return missing(c, n, path, "radius");
  if (!v[J_POSITION]) return missing(c, n, path, "position");
  if (!v[J_ORGAN]) return missing(c, n, path, "organ");
  join(fp, sizeof fp, path, "name");
  if (get_name(c, v[J_NAME], fp, o->name, sizeof o->name)) return -1;
  for (size_t j = 0; j < idx; j++)
    if (!strcmp(s->objects[j].name, o->name))
      return field_err(c, v[J_NAME], fp, "duplicate object name '%s' (first used by objects[%zu] at line %d)", o->name,
                       j, s->objects[j].line);
  join(fp, sizeof fp, path, "kind");
  if (v[J_KIND] && get_choice(c, v[J_KIND], fp, scene_object_kinds, COUNT(scene_object_kinds), o->kind, sizeof o->kind))
    return -1;
  if (opt_number(c, v[J_RADIUS], path, "radius", "objects.radius", &o->radius)) return -1;
  join(fp, sizeof fp, path, "position");
  if (get_vec3(c, v[J_POSITION], fp, "objects.position", o->position)) return -1;
  join(fp, sizeof fp, path, "organ");
  if (find_name(c, v[J_ORGAN], fp, "organ", s->organs[0].name, sizeof s->organs[0], s->norgans, &o->organ)) return -1;
  if (v[J_COLOR]) {
    double rgb[3];
    join(fp, sizeof fp, path, "color");
    if (get_vec3(c, v[J_COLOR], fp, "objects.color", rgb)) return -1;
    for (int k = 0; k < 3; k++) o->color[k] = (float)rgb[k];
  }
  return 0;
}

/* A key given to a task kind that does not read it is refused. */
static int task_key_unused(const ctx_t *c, const node_t *const *v, int key, const char *path, const char *kind) {
  if (!v[key]) return 0;
  char fp[128];
  join(fp, sizeof fp, path, task_keys[key]);
  return field_err(c, v[key], fp, "a %s task does not use this key", kind);
}

static int parse_task(const ctx_t *c, const node_t *n, size_t idx, scene_t *s) {
  scene_task_t *t = &s->tasks[idx];
  const node_t *v[K_NKEYS];
  char path[64], fp[128];
  snprintf(path, sizeof path, "tasks[%zu]", idx);
  memset(t, 0, sizeof *t);
  t->object = -1;
  t->target_radius = 0.005;
  t->distance = 0.01;
  t->line = n->line;
  if (get_fields(c, n, path, task_keys, K_NKEYS, v)) return -1;
  if (!v[K_NAME]) return missing(c, n, path, "name");
  if (!v[K_KIND]) return missing(c, n, path, "kind");
  if (!v[K_TOOL]) return missing(c, n, path, "tool");
  join(fp, sizeof fp, path, "name");
  if (get_name(c, v[K_NAME], fp, t->name, sizeof t->name)) return -1;
  for (size_t j = 0; j < idx; j++)
    if (!strcmp(s->tasks[j].name, t->name))
      return field_err(c, v[K_NAME], fp, "duplicate task name '%s' (first used by tasks[%zu] at line %d)", t->name, j,
                       s->tasks[j].line);
  join(fp, sizeof fp, path, "kind");
  if (get_choice(c, v[K_KIND], fp, scene_task_kinds, COUNT(scene_task_kinds), t->kind, sizeof t->kind)) return -1;
  if (v[K_START]) {
    char start[16];
    join(fp, sizeof fp, path, "start");
    if (get_choice(c, v[K_START], fp, scene_task_starts, COUNT(scene_task_starts), start, sizeof start)) return -1;
    t->start_instructor = !strcmp(start, "instructor");
  }
  join(fp, sizeof fp, path, "tool");
  if (find_name(c, v[K_TOOL], fp, "tool", s->tools[0].name, sizeof s->tools[0], s->ntools, &t->tool)) return -1;
  const char *tk = s->tools[t->tool].kind;
  if (!strcmp(t->kind, "stone_removal")) {
    if (strcmp(tk, "extractor"))
      return field_err(c, v[K_TOOL], fp, "a stone_removal task needs an extractor (tool '%s' is a %s)",
                       s->tools[t->tool].name, tk);
    if (!v[K_OBJECT]) return missing(c, n, path, "object");
    join(fp, sizeof fp, path, "object");
    if (find_name(c, v[K_OBJECT], fp, "object", s->objects[0].name, sizeof s->objects[0], s->nobjects, &t->object))
      return -1;
    if (task_key_unused(c, v, K_TARGET, path, t->kind) || task_key_unused(c, v, K_TARGET_RADIUS, path, t->kind) ||
        task_key_unused(c, v, K_DISTANCE, path, t->kind))
      return -1;
  } else if (!strcmp(t->kind, "palpate_target")) {
    if (!strcmp(tk, "extractor"))
      return field_err(c, v[K_TOOL], fp,
                       "a palpate_target task needs a tool that touches tissue (tool '%s' is an "
                       "extractor)",
                       s->tools[t->tool].name);
    if (!v[K_TARGET]) return missing(c, n, path, "target");
    join(fp, sizeof fp, path, "target");
    if (get_vec3(c, v[K_TARGET], fp, "tasks.target", t->target)) return -1;
    if (opt_number(c, v[K_TARGET_RADIUS], path, "target_radius", "tasks.target_radius", &t->target_radius)) return -1;
    if (task_key_unused(c, v, K_OBJECT, path, t->kind) || task_key_unused(c, v, K_DISTANCE, path, t->kind)) return -1;
  } else { /* grasp_pull */
    if (strcmp(tk, "grasper"))
      return field_err(c, v[K_TOOL], fp, "a grasp_pull task needs a grasper (tool '%s' is a %s)",
                       s->tools[t->tool].name, tk);
    if (opt_number(c, v[K_DISTANCE], path, "distance", "tasks.distance", &t->distance)) return -1;
    if (task_key_unused(c, v, K_OBJECT, path, t->kind) || task_key_unused(c, v, K_TARGET, path, t->kind) ||
        task_key_unused(c, v, K_TARGET_RADIUS, path, t->kind))
      return -1;
  }
  return 0;
}

/* Checks a list's length against [min, max]; an excess is reported at the
 * first entry past the limit, where the author has to cut. */
static int check_list(const ctx_t *c, const node_t *n, const char *path, const char *what, size_t min, size_t max) {
  if (n->kind != N_SEQ) return field_err(c, n, path, "must be a list of %ss (got %s)", what, kind_name(n));
  if (n->nkids < min) return field_err(c, n, path, "needs at least %zu %s (got %zu)", min, what, n->nkids);
  if (n->nkids > max) return field_err(c, n->kids[max], path, "too many %ss (%zu, max %zu)", what, n->nkids, max);
  return 0;
}

static int parse_scene(const ctx_t *c, const node_t *root, const char *base_dir, scene_t *s) {
  const node_t *v[S_NKEYS];
  if (get_fields(c, root, "", top_keys, S_NKEYS, v)) return -1;
  if (!v[S_SCENE]) return missing(c, root, "", "scene");
  if (!v[S_ORGANS]) return missing(c, root, "", "organs");
  if (get_name(c, v[S_SCENE], "scene", s->name, sizeof s->name)) return -1;
  if (v[S_DESCRIPTION] && get_string(c, v[S_DESCRIPTION], "description", s->description, sizeof s->description))
    return -1;
  if (v[S_PHYSICS] && parse_physics(c, v[S_PHYSICS], s)) return -1;
  if (check_list(c, v[S_ORGANS], "organs", "organ", 1, SCENE_MAX_ORGANS)) return -1;
  for (size_t i = 0; i < v[S_ORGANS]->nkids; i++) {
    if (parse_organ(c, v[S_ORGANS]->kids[i], i, base_dir, s)) return -1;
    s->norgans = i + 1;
  }
  if (v[S_TOOLS]) {
    if (check_list(c, v[S_TOOLS], "tools", "tool", 0, SCENE_MAX_TOOLS)) return -1;
    for (size_t i = 0; i < v[S_TOOLS]->nkids; i++) {
      if (parse_tool(c, v[S_TOOLS]->kids[i], i, s)) return -1;
      s->ntools = i + 1;
    }
  }
  /* Objects name organs and tasks name tools and objects: parsed after them. */
  if (v[S_OBJECTS]) {
    if (check_list(c, v[S_OBJECTS], "objects", "object", 0, SCENE_MAX_OBJECTS)) return -1;
    for (size_t i = 0; i < v[S_OBJECTS]->nkids; i++) {
      if (parse_object(c, v[S_OBJECTS]->kids[i], i, s)) return -1;
      s->nobjects = i + 1;
    }
  }
  if (v[S_TASKS]) {
    if (check_list(c, v[S_TASKS], "tasks", "task", 0, SCENE_MAX_TASKS)) return -1;
    for (size_t i = 0; i < v[S_TASKS]->nkids; i++) {
      if (parse_task(c, v[S_TASKS]->kids[i], i, s)) return -1;
      s->ntasks = i + 1;
    }
  }
  return 0;
}

/* ---- entry points ------------------------------------------------------ */

static int load_text(const char *text, size_t len, const char *name, const char *base_dir, scene_t *out, verr_t *err) {
  ctx_t c = {name, err};
  memset(out, 0, sizeof *out);
  out->dt = 0.001;
  out->publish_hz = 30;
  out->quant_step = 1e-5;
  out->sleep_speed = 0;
  out->sleep_after = 0.1;
  if (strlen(name) >= sizeof out->path)
    return verr_set(err, "%.*s...: scene path too long (max %zu bytes)", 64, name, sizeof out->path - 1);
  memcpy(out->path, name, strlen(name) + 1);
  node_t *root;
  if (parse_tree(&c, text, len, &root)) return -1;
  int rc;
  if (!root || (root->kind == N_SCALAR && root->plain && root->len == 0))
    rc = verr_set(err, "%s: empty scene file", name);
  else if (root->kind != N_MAP)
    rc = verr_set(err, "%s:%d: the top level must be a mapping of scene fields (got %s)", name, root->line,
                  kind_name(root));
  else
    rc = parse_scene(&c, root, base_dir, out);
  node_free(root);
  return rc;
}

int scene_load_string(const char *text, const char *name, const char *base_dir, scene_t *out, verr_t *err) {
  if (!name) name = "<string>";
  if (!text || !out) return verr_set(err, "%s: scene_load_string: NULL text or result", name);
  size_t len = strnlen(text, SCENE_MAX_BYTES + 1);
  if (len > SCENE_MAX_BYTES) return verr_set(err, "%s: scene text too large (max %u bytes)", name, SCENE_MAX_BYTES);
  return load_text(text, len, name, base_dir, out, err);
}

static void errno_text(int e, char *buf, size_t size) {
  /* strerror() may share a static buffer between threads. */
  if (strerror_r(e, buf, size) != 0) snprintf(buf, size, "error %d", e);
}

int scene_load(const char *path, scene_t *out, verr_t *err) {
  if (!path || !out) return verr_set(err, "scene_load: NULL path or result");
  if (strlen(path) >= SCENE_PATH_LEN)
    return verr_set(err, "%.64s...: scene path too long (max %d bytes)", path, SCENE_PATH_LEN - 1);
  char ebuf[128];
  FILE *f = fopen(path, "rb");
  if (!f) {
    errno_text(errno, ebuf, sizeof ebuf);
    return verr_set(err, "%s: cannot open: %s", path, ebuf);
  }
  /* Read one byte past the cap to tell "exactly at the cap" from "over". */
  char *buf = malloc(SCENE_MAX_BYTES + 2);
  if (!buf) {
    fclose(f);
    return verr_set(err, "%s: out of memory", path);
  }
  size_t n = fread(buf, 1, SCENE_MAX_BYTES + 1, f);
  int read_errno = ferror(f) ? errno : 0;
  fclose(f);
  if (read_errno) {
    free(buf);
    errno_text(read_errno, ebuf, sizeof ebuf);
    return verr_set(err, "%s: cannot read: %s", path, ebuf);
  }
  if (n > SCENE_MAX_BYTES) {
    free(buf);
    return verr_set(err, "%s: scene file too large (max %u bytes)", path, SCENE_MAX_BYTES);
  }
  buf[n] = '\0';
  /* The directory part of the path, "" for a bare file name (the cwd). */
  char dir[SCENE_PATH_LEN];
  const char *slash = strrchr(path, '/');
  size_t dl = slash ? (slash == path ? 1 : (size_t)(slash - path)) : 0;
  memcpy(dir, path, dl);
  dir[dl] = '\0';
  int rc = load_text(buf, n, path, dir, out, err);
  free(buf);
  return rc;
}
