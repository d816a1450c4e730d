/* SPDX-License-Identifier: Apache-2.0 */
/* test_tool_roles: who drives a tool and where it goes (server/session/tool_roles.h,
 * the contract above idl ToolRole): command classification per station, the
 * authority mix, an absent side, buttons and orientation of the dominant
 * side, validation of ASSIGN_TOOL / GUIDE, versions, the writer-station
 * cache, the scene `station:` key and the SessionControl answers. */
#include <string.h>

#include "check.h"
#include "scene.h"
#include "scene_expect.h"
#include "session/session_control.h"
#include "session/tool_roles.h"
#include "session/writer_stations.h"

#define MS 1000000ull

static scene_t scene; /* two probes, tool 1 owned by "alice" from the scene */
static verr_t err;

static void load_scene(void) {
  static const char yaml[] = "scene: roles\n"
                             "organs:\n"
                             "  - {name: kidney, mesh: k.obj}\n"
                             "tools:\n"
                             "  - {name: p0, stiffness: 300}\n"
                             "  - {name: p1, stiffness: 150, station: alice}\n";
  CHECK(scene_loads(&scene, &err, yaml, "/base"));
}

static tool_cmd_t command(double x, double y, double z, uint32_t buttons, float max_force, uint64_t seq) {
  tool_cmd_t c;
  memset(&c, 0, sizeof c);
  c.position[0] = (float)x;
  c.position[1] = (float)y;
  c.position[2] = (float)z;
  c.orientation[0] = 1;
  c.buttons = buttons;
  c.max_force = max_force;
  c.seq = seq;
  c.echo = seq * 1000;
  return c;
}

static viscera_SessionControl control(viscera_ControlKind kind, int32_t tool, const char *station, double a, double k) {
  viscera_SessionControl c;
  memset(&c, 0, sizeof c);
  c.source_id = 1;
  c.seq = 1;
  c.kind = kind;
  c.tool_id = tool;
  c.organ_id = -1;
  c.values[0] = a;
  c.values[1] = k;
  snprintf(c.text, sizeof c.text, "%s", station);
  return c;
}

static int apply(tool_roles_t *r, viscera_ControlKind kind, int32_t tool, const char *station, double a, double k,
                 char *text, size_t n) {
  viscera_SessionControl c = control(kind, tool, station, a, k);
  int rc = tool_roles_apply(r, &c, text, n);
  if (rc) fprintf(stderr, "  (refused: %s)\n", text);
  return rc;
}

static void test_init_and_classify(void) {
  tool_roles_t r;
  tool_roles_init(&r, &scene);
  CHECK(r.ntools == 2);
  CHECK(r.changed == 3); /* both published at start */
  CHECK(!strcmp(r.tool[0].owner, "") && !strcmp(r.tool[1].owner, "alice"));
  CHECK(r.tool[0].version == 1 && r.tool[1].version == 1);
  /* Tool 0: anyone drives it (as before roles existed). */
  CHECK(tool_roles_classify(&r, 0, "") == TOOL_SIDE_OWNER);
  CHECK(tool_roles_classify(&r, 0, "bob") == TOOL_SIDE_OWNER);
  /* Tool 1: only alice. */
  CHECK(tool_roles_classify(&r, 1, "alice") == TOOL_SIDE_OWNER);
  CHECK(tool_roles_classify(&r, 1, "bob") == TOOL_SIDE_REJECTED);
  CHECK(tool_roles_classify(&r, 1, "") == TOOL_SIDE_REJECTED);
  CHECK(tool_roles_classify(&r, 1, "Alice") == TOOL_SIDE_REJECTED); /* names are exact */
  viscera_ToolRole m;
  tool_roles_fill(&r, 1, 42, &m);
  CHECK(m.tool_id == 1 && m.sim_time_ns == 42 && m.version == 1 && !strcmp(m.owner, "alice") && !m.guide[0]);
  CHECK(m.authority == 0 && m.coupling_stiffness == 0);
}

static void test_mix(void) {
  tool_roles_t r;
  char text[200];
  tool_roles_init(&r, &scene);
  CHECK(apply(&r, viscera_CONTROL_ASSIGN_TOOL, 0, "alice", 0, 0, text, sizeof text) == 0);
  CHECK(strstr(text, "assigned to station 'alice'") != NULL);
  CHECK(r.tool[0].version == 2);
  CHECK(tool_roles_classify(&r, 0, "bob") == TOOL_SIDE_REJECTED);
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "bob", 0.25, 0, text, sizeof text) == 0);
  CHECK(r.tool[0].version == 3);
  CHECK_NEAR(r.tool[0].coupling, 200, 0); /* default */
  CHECK(tool_roles_classify(&r, 0, "bob") == TOOL_SIDE_GUIDE);
  CHECK(tool_roles_classify(&r, 0, "alice") == TOOL_SIDE_OWNER);
  CHECK(tool_roles_classify(&r, 0, "carol") == TOOL_SIDE_REJECTED);

  uint64_t t0 = 1000 * MS;
  tool_effective_t e;
  CHECK(tool_roles_effective(&r, 0, t0, &e) == 0); /* nobody sent anything yet */
  tool_cmd_t ca = command(0.0, 0.0, 0.04, 0, 4.0f, 7), cb = command(0.02, 0.0, 0.06, 1, 3.0f, 9);
  cb.orientation[0] = 0;
  cb.orientation[1] = 1; /* the guide holds its shaft another way */
  tool_roles_note(&r, 0, TOOL_SIDE_OWNER, "alice", 11, &ca, t0);
  tool_roles_note(&r, 0, TOOL_SIDE_GUIDE, "bob", 22, &cb, t0 + 1 * MS);
  CHECK(tool_roles_advance(&r) == 1u); /* the step puts them into effect (command_playout.h) */
  CHECK(tool_roles_effective(&r, 0, t0 + 2 * MS, &e) == 1);
  CHECK(e.owner_present && e.guide_present);
  CHECK_NEAR(e.cmd.pos[0], 0.25 * 0.02, 1e-7);
  CHECK_NEAR(e.cmd.pos[2], 0.75 * 0.04 + 0.25 * 0.06, 1e-7);
  CHECK(e.cmd.buttons == 0);                   /* authority < 0.5: the owner's */
  CHECK_NEAR(e.cmd.q[0], 1, 0);                /* and the owner's orientation */
  CHECK_NEAR(e.cmd.max_force, 3.0, 0);         /* the weaker device */
  CHECK(e.cmd.seq == 7 && e.cmd.echo == 7000); /* the owner's echo */

  /* Authority 0.5: halfway; the guide's buttons and orientation. */
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "bob", 0.5, 100, text, sizeof text) == 0);
  CHECK(r.tool[0].side[TOOL_SIDE_OWNER].has && r.tool[0].side[TOOL_SIDE_GUIDE].has); /* same stations: kept */
  CHECK(tool_roles_effective(&r, 0, t0 + 2 * MS, &e) == 1);
  CHECK_NEAR(e.cmd.pos[0], 0.01, 1e-7);
  CHECK_NEAR(e.cmd.pos[2], 0.05, 1e-7);
  CHECK(e.cmd.buttons == 1);
  CHECK_NEAR(e.cmd.q[1], 1, 0);
  CHECK(e.cmd.seq == 7);

  /* Take-over: the guide's pose. */
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "bob", 1, 0, text, sizeof text) == 0);
  CHECK(strstr(text, "taken over by station 'bob'") != NULL);
  CHECK(tool_roles_effective(&r, 0, t0 + 2 * MS, &e) == 1);
  CHECK_NEAR(e.cmd.pos[0], 0.02, 1e-7);
  CHECK_NEAR(e.cmd.pos[2], 0.06, 1e-7);

  /* Authority 0: the owner's pose although the guide is there. */
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "bob", 0, 0, text, sizeof text) == 0);
  CHECK(tool_roles_effective(&r, 0, t0 + 2 * MS, &e) == 1);
  CHECK_NEAR(e.cmd.pos[0], 0.0, 1e-7);
  CHECK(e.guide_present);
}

static void test_absent_side(void) {
  tool_roles_t r;
  char text[200];
  tool_roles_init(&r, &scene);
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 1, "bob", 0.5, 0, text, sizeof text) == 0);
  CHECK_NEAR(r.tool[1].coupling, 150, 0); /* default capped by the tool's stiffness */
  uint64_t t0 = 5000 * MS;
  tool_cmd_t ca = command(0.0, 0.0, 0.04, 0, 4.0f, 1), cb = command(0.02, 0.0, 0.04, 1, 4.0f, 2);
  tool_roles_note(&r, 1, TOOL_SIDE_OWNER, "alice", 11, &ca, t0);
  tool_roles_note(&r, 1, TOOL_SIDE_GUIDE, "bob", 22, &cb, t0 + 60 * MS);
  CHECK(tool_roles_advance(&r) == 2u);
  tool_effective_t e;
  /* At +100 ms both are there (the owner exactly at its limit). */
  CHECK(tool_roles_effective(&r, 1, t0 + 100 * MS, &e) == 1);
  CHECK_NEAR(e.cmd.pos[0], 0.01, 1e-7);
  /* At +101 ms the owner has been silent for more than 100 ms: the guide alone,
   * with the guide's echo (the owner's is stale). */
  CHECK(tool_roles_effective(&r, 1, t0 + 101 * MS, &e) == 1);
  CHECK(!e.owner_present && e.guide_present);
  CHECK_NEAR(e.cmd.pos[0], 0.02, 1e-7);
  CHECK(e.cmd.buttons == 1 && e.cmd.seq == 2);
  /* Both silent: nothing to apply. */
  CHECK(tool_roles_effective(&r, 1, t0 + 161 * MS, &e) == 0);
  /* The guide's writer lost: the owner alone at once. */
  tool_roles_note(&r, 1, TOOL_SIDE_OWNER, "alice", 11, &ca, t0 + 200 * MS);
  tool_roles_note(&r, 1, TOOL_SIDE_GUIDE, "bob", 22, &cb, t0 + 200 * MS);
  CHECK(tool_roles_advance(&r) == 2u);
  CHECK(tool_roles_side_of_writer(&r, 1, 22) == TOOL_SIDE_GUIDE);
  CHECK(tool_roles_side_of_writer(&r, 1, 11) == TOOL_SIDE_OWNER);
  CHECK(tool_roles_side_of_writer(&r, 1, 33) == -1);
  tool_roles_forget(&r, 1, TOOL_SIDE_GUIDE);
  CHECK(tool_roles_effective(&r, 1, t0 + 201 * MS, &e) == 1);
  CHECK_NEAR(e.cmd.pos[0], 0.0, 1e-7);
  CHECK(tool_roles_side_of_writer(&r, 1, 22) == -1);
  /* A reset forgets every command and republishes every role. */
  r.changed = 0;
  tool_roles_forget_all(&r);
  CHECK(r.changed == 3);
  CHECK(tool_roles_effective(&r, 1, t0 + 202 * MS, &e) == 0);
  CHECK(!strcmp(r.tool[1].guide, "bob")); /* roles survive a reset */
}

static void test_role_changes_drop_stale_sides(void) {
  tool_roles_t r;
  char text[200];
  tool_roles_init(&r, &scene);
  uint64_t t0 = 100 * MS;
  tool_cmd_t cb = command(0.02, 0.0, 0.04, 0, 4.0f, 2);
  /* Tool 0 is anyone's: bob's command is an owner-side one... */
  tool_roles_note(&r, 0, TOOL_SIDE_OWNER, "bob", 22, &cb, t0);
  CHECK(tool_roles_advance(&r) == 1u && r.tool[0].side[TOOL_SIDE_OWNER].has);
  /* ...until bob becomes the guide: then it must not keep counting as the owner. */
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "bob", 0.5, 0, text, sizeof text) == 0);
  CHECK(!r.tool[0].side[TOOL_SIDE_OWNER].has);
  tool_effective_t e;
  CHECK(tool_roles_effective(&r, 0, t0, &e) == 0);
  /* Guide bob's command; then the tool is assigned to alice: guiding ends and
   * bob's pose goes. */
  tool_roles_note(&r, 0, TOOL_SIDE_GUIDE, "bob", 22, &cb, t0);
  CHECK(tool_roles_advance(&r) == 1u && r.tool[0].side[TOOL_SIDE_GUIDE].has);
  uint32_t v = r.tool[0].version;
  CHECK(apply(&r, viscera_CONTROL_ASSIGN_TOOL, 0, "alice", 0, 0, text, sizeof text) == 0);
  CHECK(strstr(text, "guiding by station 'bob' ended") != NULL);
  CHECK(r.tool[0].version == v + 1 && !r.tool[0].guide[0] && !r.tool[0].side[TOOL_SIDE_GUIDE].has);
  /* The same assignment again changes nothing: no new version, nothing to publish. */
  r.changed = 0;
  CHECK(apply(&r, viscera_CONTROL_ASSIGN_TOOL, 0, "alice", 0, 0, text, sizeof text) == 0);
  CHECK(r.tool[0].version == v + 1 && r.changed == 0 && strstr(text, "unchanged"));
  /* "*" and "" give the tool back to any station. */
  CHECK(apply(&r, viscera_CONTROL_ASSIGN_TOOL, 0, "*", 0, 0, text, sizeof text) == 0);
  CHECK(!r.tool[0].owner[0] && r.changed == 1 && strstr(text, "any station"));
  CHECK(tool_roles_classify(&r, 0, "carol") == TOOL_SIDE_OWNER);
  /* Guide "" ends guiding. */
  CHECK(apply(&r, viscera_CONTROL_ASSIGN_TOOL, 0, "alice", 0, 0, text, sizeof text) == 0);
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "bob", 0.7, 120, text, sizeof text) == 0);
  viscera_ToolRole m;
  tool_roles_fill(&r, 0, 0, &m);
  CHECK(!strcmp(m.guide, "bob") && m.authority > 0.69f && m.authority < 0.71f && m.coupling_stiffness == 120.0f);
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "", 0, 0, text, sizeof text) == 0);
  CHECK(strstr(text, "ended, back with station 'alice'") != NULL);
  tool_roles_fill(&r, 0, 0, &m);
  CHECK(!m.guide[0] && m.authority == 0 && m.coupling_stiffness == 0 && !strcmp(m.owner, "alice"));
}

static void test_validation(void) {
  tool_roles_t r;
  char text[200];
  tool_roles_init(&r, &scene);
  uint32_t v0 = r.tool[0].version;
  struct {
    viscera_ControlKind kind;
    int32_t tool;
    const char *station;
    double a, k;
    const char *why;
  } bad[] = {
      {viscera_CONTROL_ASSIGN_TOOL, 2, "alice", 0, 0, "tool id out of range"},
      {viscera_CONTROL_ASSIGN_TOOL, -1, "alice", 0, 0, "tool id out of range"},
      {viscera_CONTROL_ASSIGN_TOOL, 0, "al ice", 0, 0, "is not 1..31 characters"},
      {viscera_CONTROL_ASSIGN_TOOL, 0, "a/b", 0, 0, "is not 1..31 characters"},
      {viscera_CONTROL_ASSIGN_TOOL, 0, "abcdefghijklmnopqrstuvwxyz0123456", 0, 0, "is not 1..31 characters"},
      {viscera_CONTROL_GUIDE, 0, "*", 0.5, 0, "one named station"},
      {viscera_CONTROL_GUIDE, 0, "bob;rm", 0.5, 0, "is not 1..31 characters"},
      {viscera_CONTROL_GUIDE, 0, "bob", -0.1, 0, "authority"},
      {viscera_CONTROL_GUIDE, 0, "bob", 1.5, 0, "authority"},
      {viscera_CONTROL_GUIDE, 0, "bob", NAN, 0, "authority"},
      {viscera_CONTROL_GUIDE, 0, "bob", 0.5, INFINITY, "not finite"},
      {viscera_CONTROL_GUIDE, 0, "bob", 0.5, NAN, "not finite"},
      {viscera_CONTROL_GUIDE, 0, "bob", 0.5, 301, "above the tool's stiffness 300"},
      {viscera_CONTROL_GUIDE, 1, "alice", 0.5, 0, "owns the tool"},
      {viscera_CONTROL_PAUSE, 0, "", 0, 0, "not a tool role command"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    viscera_SessionControl c = control(bad[i].kind, bad[i].tool, bad[i].station, bad[i].a, bad[i].k);
    text[0] = 0;
    int rc = tool_roles_apply(&r, &c, text, sizeof text);
    CHECK(rc == -1);
    if (!strstr(text, bad[i].why)) {
      fprintf(stderr, "  case %zu: got '%s', want '%s'\n", i, text, bad[i].why);
      CHECK(0);
    }
  }
  CHECK(r.tool[0].version == v0 && !r.tool[0].guide[0] && !r.tool[0].owner[0]);
  /* Exactly the bounds are fine: 31 characters, authority 0 and 1, k = the tool's stiffness. */
  CHECK(apply(&r, viscera_CONTROL_ASSIGN_TOOL, 0, "abcdefghijklmnopqrstuvwxyz01234", 0, 0, text, sizeof text) == 0);
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "b.o-b_1", 1, 300, text, sizeof text) == 0);
  CHECK(apply(&r, viscera_CONTROL_GUIDE, 0, "b.o-b_1", 0, 300, text, sizeof text) == 0);
}

static void test_session_control_answers(void) {
  tool_roles_t r;
  tool_roles_init(&r, &scene);
  session_control_t sc;
  memset(&sc, 0, sizeof sc);
  session_tool_t tools[2];
  double maxf[2] = {4, 4};
  char text[300];
  viscera_SessionControl c = control(viscera_CONTROL_ASSIGN_TOOL, 0, "alice", 0, 0);
  /* Without the server's table: refused, not crashed. */
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == -1);
  sc.roles = &r;
  c.seq = 2;
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == 0);
  CHECK(strstr(text, "assigned to station 'alice'") && strstr(text, "[station 1 seq 2]"));
  c = control(viscera_CONTROL_GUIDE, 0, "bob", 2, 0);
  c.seq = 3;
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == -1);
  CHECK(strstr(text, "SessionControl refused: authority 2") && strstr(text, "[station 1 seq 3]"));
  CHECK(sc.applied == 1 && sc.refused == 2);
}

static void test_writer_stations(void) {
  static writer_stations_t ws;
  writer_stations_init(&ws);
  CHECK(writer_stations_find(&ws, 5) == NULL);
  CHECK(!strcmp(writer_stations_put(&ws, 5, "alice"), "alice"));
  CHECK(!strcmp(writer_stations_find(&ws, 5), "alice"));
  /* Full: the oldest goes first, the rest stay. */
  for (uint64_t h = 100; h < 100 + WRITER_STATIONS_CAP - 1; h++) writer_stations_put(&ws, h, "");
  CHECK(ws.n == WRITER_STATIONS_CAP && ws.evictions == 0);
  writer_stations_put(&ws, 7, "bob");
  CHECK(ws.evictions == 1);
  CHECK(writer_stations_find(&ws, 5) == NULL);
  CHECK(!strcmp(writer_stations_find(&ws, 7), "bob"));
  CHECK(writer_stations_find(&ws, 100) != NULL);
  writer_stations_put(&ws, 8, "carol");
  CHECK(writer_stations_find(&ws, 100) == NULL && !strcmp(writer_stations_find(&ws, 8), "carol"));
}

static void test_scene_station_key(void) {
  static scene_t s;
  static const char head[] = "scene: t\n"
                             "organs:\n"
                             "  - {name: kidney, mesh: k.obj}\n"
                             "tools:\n";
  char yaml[400];
  snprintf(yaml, sizeof yaml, "%s  - {name: p}\n", head);
  CHECK(scene_loads(&s, &err, yaml, "/base") && s.tools[0].station[0] == 0);
  snprintf(yaml, sizeof yaml, "%s  - {name: p, station: seat03.left-hand_2}\n", head);
  CHECK(scene_loads(&s, &err, yaml, "/base") && !strcmp(s.tools[0].station, "seat03.left-hand_2"));
  snprintf(yaml, sizeof yaml, "%s  - name: p\n    station: \"bad name\"\n", head);
  CHECK(scene_fails_with(&s, &err, yaml, "t.yaml:6: field 'tools[0].station'", "must be 1..31 characters"));
  snprintf(yaml, sizeof yaml, "%s  - {name: p, station: \"*\"}\n", head);
  CHECK(scene_fails_with(&s, &err, yaml, "t.yaml:5: field 'tools[0].station'", "got '*'"));
  snprintf(yaml, sizeof yaml, "%s  - {name: p, station: abcdefghijklmnopqrstuvwxyz0123456}\n", head);
  CHECK(scene_fails_with(&s, &err, yaml, "field 'tools[0].station'", "too long"));
  snprintf(yaml, sizeof yaml, "%s  - {name: p, station: [a]}\n", head);
  CHECK(scene_fails_with(&s, &err, yaml, "field 'tools[0].station'", "must be a string"));
}

int main(void) {
  load_scene();
  test_init_and_classify();
  test_mix();
  test_absent_side();
  test_role_changes_drop_stale_sides();
  test_validation();
  test_session_control_answers();
  test_writer_stations();
  test_scene_station_key();
  return check_report("test_tool_roles");
}
