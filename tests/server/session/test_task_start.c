/* SPDX-License-Identifier: Apache-2.0 */
/* test_task_start: tasks started by the instructor (issue 7 "starts tasks")
 * on the real runtime (kidney mesh, mass-spring model), no networking:
 * - scene `start:` read (default first_command), anything else refused
 *   with the line and field;
 * - a `start: instructor` task stays idle while its tool moves and touches
 *   the target (no clock, no completion) while a first_command task of the
 *   same tool starts and completes;
 * - START_TASK by name starts it (session_control + tasks_start, as the
 *   server does) and it completes; by index restarts a completed task:
 *   the earlier run is replaced (clock from the restart, completion
 *   cleared), ToolMetrics count the task once with the new run's time;
 * - unknown names, indices out of range or not whole are refused, nothing
 *   changes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_runtime.h"
#include "runtime/scene_runtime.h"
#include "scene_expect.h"
#include "session/session_control.h"
#include "session/tool_metrics.h"

static runtime_t rt; /* large */
static scene_t sc;
static verr_t e;

#define KIDNEY "scene: t\norgans:\n  - {name: kidney, mesh: ../meshes/kidney.obj, material: {mass: 0.15}}\n"
/* Two palpate_target tasks of one probe on the top of the kidney. */
#define TASKS(start_b)                                                                                                 \
  KIDNEY "tools:\n  - {name: p, radius: 0.003, stiffness: 400}\n"                                                      \
         "tasks:\n  - {name: a, kind: palpate_target, tool: p, target: [0, 0, 0.035], target_radius: 0.006}\n"         \
         "  - {name: b, kind: palpate_target, tool: p, target: [0, 0, 0.035], target_radius: 0.006" start_b "}\n"

static int load(const char *yaml) { return test_runtime_load(&rt, &sc, yaml, &e); }

static int count_events(iev_kind_t kind, int task) {
  int n = 0;
  for (size_t i = 0; i < rt.events.n; i++) n += rt.events.ev[i].kind == kind && rt.events.ev[i].task == task;
  return n;
}

/* Steps n times with the probe moving linearly from a to b; counts the
 * task events of every step and empties the queue, as the server does. */
static int started[2], completed[2];
static void drive(const double a[3], const double b[3], int n) {
  for (int i = 1; i <= n; i++) {
    double p[3];
    for (int k = 0; k < 3; k++) p[k] = a[k] + (b[k] - a[k]) * i / n;
    runtime_set_tool(&rt, 0, p, 4);
    runtime_step(&rt);
    for (int t = 0; t < 2; t++) {
      started[t] += count_events(IEV_TASK_STARTED, t);
      completed[t] += count_events(IEV_TASK_COMPLETED, t);
    }
    rt.events.n = 0;
  }
}

static void test_scene_key(void) {
  static scene_t s;
  CHECK(scene_loads(&s, &e, TASKS(""), "/base"));
  CHECK(s.ntasks == 2 && !s.tasks[0].start_instructor && !s.tasks[1].start_instructor);
  CHECK(scene_loads(&s, &e, TASKS(", start: instructor"), "/base"));
  CHECK(!s.tasks[0].start_instructor && s.tasks[1].start_instructor);
  CHECK(scene_loads(&s, &e, TASKS(", start: first_command"), "/base"));
  CHECK(!s.tasks[1].start_instructor);
  CHECK(scene_fails_with(&s, &e, TASKS(", start: later"), "t.yaml:8: field 'tasks[1].start'",
                         "must be one of: first_command, instructor (got 'later')"));
  CHECK(scene_fails_with(&s, &e, TASKS(", start: [instructor]"), "t.yaml:8: field 'tasks[1].start'", "must be one of"));
}

static viscera_SessionControl start_cmd(uint64_t seq, const char *name, double index) {
  viscera_SessionControl c;
  memset(&c, 0, sizeof c);
  c.source_id = 4;
  c.seq = seq;
  c.kind = viscera_CONTROL_START_TASK;
  c.tool_id = -1;
  c.organ_id = -1;
  c.values[0] = index;
  snprintf(c.text, sizeof c.text, "%s", name);
  return c;
}

/* What the server does with a START_TASK (server.c start_task). */
static int apply(session_control_t *ctl, const viscera_SessionControl *c, char *text, size_t n) {
  session_tool_t tools[1];
  double maxf[1] = {4};
  int r = session_control_apply(ctl, c, tools, 1, maxf, &rt.scene, text, n);
  if (r == SESSION_CONTROL_START_TASK) tasks_start(&rt.tasks[ctl->start_task], rt.sim_time);
  return r;
}

static void metrics(uint32_t *total, uint32_t *done, double *op) {
  thr_tracker_t thr;
  thr_init(&thr, 0, 0, 0);
  tool_tally_t tl;
  memset(&tl, 0, sizeof tl);
  viscera_ToolMetrics m;
  tool_metrics_fill(&m, &rt, 0, &thr, &tl, 0);
  *total = m.tasks_total;
  *done = m.tasks_completed;
  *op = m.operation_time;
}

static void test_instructor_start(void) {
  CHECK(load(TASKS(", start: instructor")));
  double above[3] = {0, 0, 0.06}, press[3] = {0, 0, 0.032};
  drive(above, press, 300);
  drive(press, press, 200);
  /* Task a started at the first command and completed at the touch; b did
   * not start although its tool moved and touched its target. */
  CHECK(rt.tasks[0].started && rt.tasks[0].completed && started[0] == 1 && completed[0] == 1);
  CHECK(!rt.tasks[1].started && !rt.tasks[1].completed && started[1] == 0 && completed[1] == 0);
  CHECK(rt.tools[0].fb_contact);
  uint32_t total, done;
  double op;
  metrics(&total, &done, &op);
  CHECK(total == 2 && done == 1);
  double op_a = rt.tasks[0].t_end - rt.tasks[0].t_start;
  CHECK_NEAR(op, op_a, 1e-12);

  /* The instructor starts b by name while the probe rests on the target:
   * it completes on the next step, its clock from the start. */
  session_control_t ctl;
  memset(&ctl, 0, sizeof ctl);
  char text[300];
  viscera_SessionControl c = start_cmd(1, "b", 0);
  double t_cmd = rt.sim_time;
  CHECK(apply(&ctl, &c, text, sizeof text) == SESSION_CONTROL_START_TASK && ctl.start_task == 1);
  CHECK(strstr(text, "task 'b' started by the instructor (tool 'p')") && strstr(text, "[station 4 seq 1]"));
  CHECK(rt.tasks[1].started && rt.tasks[1].t_start == t_cmd);
  drive(press, press, 2);
  CHECK(rt.tasks[1].completed && completed[1] == 1);
  CHECK(rt.tasks[1].t_end - rt.tasks[1].t_start <= 2 * sc.dt + 1e-12);
  metrics(&total, &done, &op);
  CHECK(total == 2 && done == 2);

  /* Restart of the completed task a by index, the probe lifted off: the
   * earlier run is replaced: not completed, counted once, operation time
   * only b's until a completes again. */
  drive(press, above, 300);
  c = start_cmd(2, "", 0);
  double t_restart = rt.sim_time;
  CHECK(apply(&ctl, &c, text, sizeof text) == SESSION_CONTROL_START_TASK && ctl.start_task == 0);
  CHECK(strstr(text, "task 'a' started by the instructor") != NULL);
  CHECK(rt.tasks[0].started && !rt.tasks[0].completed && rt.tasks[0].t_start == t_restart);
  drive(above, above, 50);
  CHECK(!rt.tasks[0].completed);
  metrics(&total, &done, &op);
  CHECK(total == 2 && done == 1);
  CHECK_NEAR(op, rt.tasks[1].t_end - rt.tasks[1].t_start, 1e-12);
  drive(above, press, 300);
  CHECK(rt.tasks[0].completed && completed[0] == 2);
  /* The new run's time: from the restart, longer than the 50 + steps of the way down. */
  CHECK(rt.tasks[0].t_start == t_restart && rt.tasks[0].t_end - t_restart > 0.05);
  metrics(&total, &done, &op);
  CHECK(total == 2 && done == 2);
  CHECK_NEAR(op, (rt.tasks[0].t_end - rt.tasks[0].t_start) + (rt.tasks[1].t_end - rt.tasks[1].t_start), 1e-12);
  printf("task start: a %.3f s first run, %.3f s after the restart; b %.3f s after the instructor's start\n", op_a,
         rt.tasks[0].t_end - rt.tasks[0].t_start, rt.tasks[1].t_end - rt.tasks[1].t_start);

  /* Refused: nothing starts, start_task untouched. */
  const viscera_SessionControl bad[] = {start_cmd(3, "zzz", 0), start_cmd(4, "", 2),   start_cmd(5, "", -1),
                                        start_cmd(6, "", NAN),  start_cmd(7, "", 0.5), start_cmd(8, "", INFINITY)};
  const char *why[] = {"no task of that name",    "task index out of range", "task index out of range",
                       "task index out of range", "task index out of range", "task index out of range"};
  ctl.start_task = 77;
  double t0 = rt.tasks[0].t_start;
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    CHECK(apply(&ctl, &bad[i], text, sizeof text) == -1);
    CHECK(strstr(text, "SessionControl refused") && strstr(text, why[i]));
  }
  CHECK(ctl.start_task == 77 && ctl.refused == 6 && ctl.applied == 2);
  CHECK(rt.tasks[0].completed && rt.tasks[0].t_start == t0);
  runtime_destroy(&rt);
}

int main(void) {
  test_scene_key();
  test_instructor_start();
  return check_report("test_task_start");
}
