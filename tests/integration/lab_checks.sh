# SPDX-License-Identifier: Apache-2.0
# shellcheck shell=bash
# Checks shared by the lab launcher tests (lab_launcher_test.sh,
# lab_launcher_secure_test.sh), sourced, not run. Each check fails the test
# through fail() (defined by the sourcing script) naming what is missing.
#
# launch_lab VAR OUTFILE ARGS...: starts deploy/lab.sh in its own session
# (setsid), with SIGINT at its default disposition: a background job of a
# script ignores SIGINT and bash cannot trap a signal ignored on entry, which
# would hide the very Ctrl-C path under test. The session id (= the pid)
# goes into VAR: every process lab.sh starts stays in that session, so
# `ps -s SID` lists whatever it left behind.

launch_lab() {
  local var="$1" log="$2"
  shift 2
  env --default-signal=INT setsid bash "$SRC/deploy/lab.sh" --build "$BUILD" "$@" > "$log" 2>&1 &
  printf -v "$var" '%s' "$!"
}

# left_in_session SID: the processes still in that session (none expected).
left_in_session() { ps -o pid=,args= -s "$1" 2>/dev/null || true; }

# expect_nothing_left SID WHAT: fails when lab.sh left a process running.
expect_nothing_left() {
  local left
  left="$(left_in_session "$1")"
  [ -z "$left" ] || fail "$2 left processes running: $left"
}

# recorded_by_partition DB: "partition topic samples" per line, data samples only.
recorded_by_partition() {
  sqlite3 -separator ' ' "$1" "SELECT w.partitions, t.name, count(*) FROM samples s JOIN writers w ON s.writer_id = w.id
    JOIN topics t ON t.id = s.topic_id WHERE s.kind = 0 GROUP BY 1, 2 ORDER BY 1, 2"
}

# expect_lab_recorded DB FIRST LAST DRIVEN...: the lab's recording (PREFIX
# lab) is closed, holds seats FIRST..LAST each from its own server
# (expect_seats_recorded) and ToolCommands in each DRIVEN seat (two digits);
# "partition topic samples" lines go to OUT/by_partition.txt (and stdout).
expect_lab_recorded() {
  local db="$1" first="$2" last="$3" s
  shift 3
  recorded_by_partition "$db" | tee "$OUT/by_partition.txt"
  expect_closed "$db"
  expect_seats_recorded "$db" lab "$first" "$last"
  for s in "$@"; do
    grep -q "^lab/seat$s viscera_ToolCommand [1-9]" "$OUT/by_partition.txt" || fail "no ToolCommand recorded in lab/seat$s"
  done
}

# expect_seats_recorded DB PREFIX FIRST LAST: every seat's server published
# in its own partition: MeshDelta samples from PREFIX/seatNN for each seat,
# written by one participant per seat (GUID prefix, the first 24 hex digits)
# that is different for every seat, and no writer in more than one partition.
expect_seats_recorded() {
  local db="$1" prefix="$2" first="$3" last="$4" i s n servers multi
  for i in $(seq "$first" "$last"); do
    s=$(printf '%s/seat%02d' "$prefix" "$i")
    n=$(sqlite3 "$db" "SELECT count(*) FROM samples s JOIN writers w ON s.writer_id = w.id JOIN topics t ON t.id = s.topic_id
      WHERE t.name = 'viscera_MeshDelta' AND w.partitions = '$s' AND s.kind = 0")
    # At least one: a seat without a trainee publishes few deltas once its
    # organ has settled (9 in a starved sanitizer run), so a larger bound
    # would judge the machine's speed, not the partitioning.
    [ "${n:-0}" -ge 1 ] || fail "the lab recording has no MeshDelta sample from $s"
  done
  servers=$(sqlite3 "$db" "SELECT count(DISTINCT w.partitions), count(DISTINCT substr(w.guid, 1, 24)) FROM writers w
    JOIN topics t ON t.id = w.topic_id WHERE t.name = 'viscera_MeshState'")
  [ "$servers" = "$((last - first + 1))|$((last - first + 1))" ] \
    || fail "MeshState writers: partitions|participants = $servers, expected one server per seat"
  multi=$(sqlite3 "$db" "SELECT count(*) FROM writers WHERE partitions LIKE '%,%'")
  [ "$multi" = 0 ] || fail "$multi writers publish in more than one partition"
}

# expect_trainee_force LOG: the scripted trainee felt the organ.
expect_trainee_force() {
  local peak
  peak=$(sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p' "$1")
  echo "  $(basename "$1"): peak force ${peak:-none} N"
  awk -v f="${peak:-0}" 'BEGIN { exit !(f > 0.3) }' || fail "no contact force in $1"
}

# expect_frames DIR: the viewer wrote at least two PNG frames that exist.
expect_frames() {
  local csv="$1/frames.csv" n f
  [ -f "$csv" ] || fail "no $csv"
  n=$(grep -c '\.png' "$csv" || true)
  [ "$n" -ge 2 ] || fail "$csv lists $n frames"
  f=$(awk -F, 'NR == 2 { print $2 }' "$csv")
  [ -s "$1/$f" ] || fail "$1/$f listed but missing"
}

# expect_logs DIR NAME...: one non-empty log per process.
expect_logs() {
  local dir="$1" n
  shift
  for n in "$@"; do [ -s "$dir/$n.log" ] || fail "no log $dir/$n.log"; done
}

# expect_closed DB: the recorder stopped cleanly (end time written).
expect_closed() {
  local end
  end=$(sqlite3 "$1" "SELECT end_wall_ns IS NOT NULL FROM session")
  [ "$end" = 1 ] || fail "$1 has no end time: the recorder did not stop cleanly"
}

# expect_recorded_pids_gone DB: every viscera process the recording saw (its
# USER_DATA names the pid) has exited, a second check next to the session's.
expect_recorded_pids_gone() {
  local p cmd
  for p in $(sqlite3 "$1" "SELECT user_data FROM participants" | sed -n 's/.* pid=\([0-9]*\).*/\1/p'); do
    cmd=$({ tr '\0' ' ' < "/proc/$p/cmdline"; } 2>/dev/null || true)
    # pid_max may be small: a reused pid runs something else.
    case "$cmd" in "$BUILD"/*) fail "pid $p ($cmd) from the recording still runs" ;; esac
  done
}

# wait_trainees LAB_PID NAME LOG...: every trainee log has its SUMMARY line
# (their palpation takes about 5 s after the lab's 2 s start delay; 60 s at
# most); fails if the lab ends first.
wait_trainees() {
  local lab="$1" name="$2" t n=0
  shift 2
  for ((t = 0; t < 600; t++)); do
    n=$(cat "$@" 2>/dev/null | grep -c '^SUMMARY' || true)
    [ "$n" = $# ] && return 0
    kill -0 "$lab" 2>/dev/null || fail "$name ended on its own"
    sleep 0.1
  done
  fail "the trainees did not finish within 60 s ($n of $# did)"
}
