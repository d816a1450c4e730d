#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Guiding hand (issue 7), real processes on loopback: a server on the default
# probe scene; a trainee client (--station alice) held still at A and an
# instructor client (--station bob) held still at B, 2 cm apart in free
# space above the kidney; both write their per-tick forces. The instructor
# then runs viscera-control:
#   guide 0 bob 0.5 200: each feels 0.5 * 200 * |B - A| = 2 N towards the other;
#   takeover 0 bob:      the trainee feels 200 * |B - A| = 4 N towards B, the
#                        instructor ~0 (the tool is his, nothing touched);
#   (still taken over)   the instructor's client is restarted with a path that
#                        presses into the kidney: he feels the tissue push up,
#                        the trainee the pull towards his hand, clamped to the
#                        6 N device limit (roles belong to stations, so the new
#                        process is the guide at once);
#   release 0:           both ~0 in free space;
#   takeover again, then kill -9 the server: the coupling ends 250 ms after
#                        the last feedback and both forces stay zero.
# No wall-clock timing (issue 15.6): every step waits (60 s at most, a hang
# stop only) for the clients' log lines saying a command took effect and then
# for 400 of each client's own ticks (rows of its force CSV) in the expected
# coupling state before the next command. A phase is a range of a client's
# own rows, from its log line (same clock as its CSV) to 100 rows before the
# rows on disk when the next command was given (stdio buffering keeps that at
# or before the ticks done by then), and only its ticks in the phase's
# coupling state (from the log's "guide:" lines), 100 ticks past each change
# (the force ramps), are judged, on medians over >= 200 ticks: a loaded
# machine where a peer stalls for 100 ms (the coupling drops, as designed)
# makes the test wait longer instead of failing it. The press is cut by the
# instructor's own position and by the trainee's rows pulled down towards it.
# usage: guide_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
FAIL_TAIL=12
PART=test/guide
# A trainee, B instructor (above the kidney's top, z 0.0346 at x 0.012).
AX=0.032; BX=0.012; Y=0.004; Z=0.070; PRESS_Z=0.029
printf '0 %s %s %s\n' $AX $Y $Z > "$OUT/alice.traj"
printf '0 %s %s %s\n' $BX $Y $Z > "$OUT/bob1.traj"
# The restarted instructor holds B 3 s (time to see the trainee again: only
# his ticks after that are judged), presses 4-6 mm into the kidney for 4 s and
# comes back up to B.
printf '0 %s %s %s\n3.0 %s %s %s\n3.5 %s %s %s\n7.5 %s %s %s\n8.0 %s %s %s\n' \
  $BX $Y $Z $BX $Y $Z $BX $Y $PRESS_Z $BX $Y $PRESS_Z $BX $Y $Z > "$OUT/bob2.traj"
CTL=("$BUILD/client/control/viscera-control" --partition $PART --wait 30)
# Every process is stopped by the script; --duration only bounds a run gone wrong.
HAP=("$BUILD/client/haptic/viscera-haptic" --partition $PART --max-force 6 --duration 600 --wait-server 60)
"$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition $PART --duration 600 \
  > "$OUT/server.out" 2> "$OUT/server.log" & SRV=$!; PIDS+=($SRV)
haptic() { # haptic WHO STATION: starts a client on OUT/WHO.traj, its pid in HPID
  "${HAP[@]}" --trajectory "$OUT/$1.traj" --station "$2" --force-csv "$OUT/$1.csv" \
    > "$OUT/$1.out" 2> "$OUT/$1.log" & HPID=$!; PIDS+=($HPID)
}
haptic alice alice; ALICE=$HPID
haptic bob1 bob; BOB=$HPID

# wait_for COMMAND...: polls until COMMAND succeeds; 1 after 600 polls (a hang stop).
wait_for() { for _ in $(seq 600); do "$@" && return 0; sleep 0.1; done; return 1; }
rows() { if [ -f "$1" ]; then wc -l < "$1"; else echo 0; fi; }
has_rows() { [ "$(rows "$1")" -ge "$2" ]; }
# Loop time of WHO's first log line matching PAT after loop time T0.
t_from() { awk -v t0="$2" -v p="$3" 'index($0, p) && match($0, /t=[0-9.]+ s/) {
  t = substr($0, RSTART + 2, RLENGTH - 4); if (t + 0 > t0 + 0) { print t; exit } }' "$OUT/$1.log"; }
# Loop time of WHO's first "server silent" line after its last coupling (a
# feedback gap of 250 ms on a loaded machine may have ended the coupling for
# a moment before the server was killed).
t_lost() { awk 'match($0, /t=[0-9.]+ s/) { t = substr($0, RSTART + 2, RLENGTH - 4) }
                index($0, "guide: coupled as") { lost = "" }
                index($0, "not coupled (server silent") && lost == "" { lost = t }
                END { print lost }' "$OUT/$1.log"; }
# CSV line number (header = 1) of the first tick at or after loop time T.
row_of() { awk -F, -v t="$2" 'NR > 1 && $1 + 0 >= t + 0 { print NR; exit }' "$1"; }
# ann WHO: WHO's force CSV with two columns added from its log (same clock):
# $11 the coupling state of the tick (owner0.50, guide1.00, ... or none) and
# $12 the ticks since that state began (the force ramps in after a change).
ann() {
  awk -F, 'FNR == NR { if (match($0, /t=[0-9.]+ s guide: /)) {
             n++; T[n] = substr($0, RSTART + 2) + 0; S[n] = "none"
             if (match($0, /coupled as (owner|guide) .*own share [0-9.]+/)) {
               S[n] = (index($0, "as owner") ? "owner" : "guide") substr($0, RSTART + RLENGTH - 4, 4) } }
           next }
           FNR == 1 { print $0 ",state,since"; next }
           { while (k < n && $1 + 0 >= T[k + 1]) { k++; since = 0 }
             print $0 "," (k ? S[k] : "none") "," since; since++ }' "$OUT/$1.log" "$OUT/$1.csv" > "$OUT/$1.ann"
}
# settled WHO T0 PAT STATE N: WHO logged PAT after loop time T0 and has, from
# that line on, N ticks in STATE past its ramp (100 ticks); the line's loop time in EV.
RAMP=100
settled() {
  local t r; t=$(t_from "$1" "$2" "$3"); [ -n "$t" ] || return 1
  r=$(row_of "$OUT/$1.csv" "$t"); [ -n "$r" ] || return 1
  ann "$1"
  awk -F, -v r="$r" -v s="$4" -v n="$5" -v ramp=$RAMP 'NR >= r && $11 == s && $12 >= ramp { c++ } END { exit !(c >= n) }' \
    "$OUT/$1.ann" && EV=$t
}
lost_settled() { local t r; t=$(t_lost "$1"); [ -n "$t" ] || return 1
  r=$(row_of "$OUT/$1.csv" "$t"); [ -n "$r" ] && has_rows "$OUT/$1.csv" $((r + 500)); }
OWN=(coupled as owner "(trainee),"); GDE=(coupled as guide "(instructor),")
A50="${OWN[*]} own share 0.50"; B50="${GDE[*]} own share 0.50"
A00="${OWN[*]} own share 0.00"; B100="${GDE[*]} own share 1.00"
REL="guide ''"
TICKS=400 # ticks each phase lasts at least on each client (in its state, past the ramp) before the next command

wait_for has_rows "$OUT/alice.csv" $((TICKS + 300)) || fail "the trainee's client did not start driving"
wait_for has_rows "$OUT/bob1.csv" $((TICKS + 300)) || fail "the instructor's client did not start driving"
ra_g=$(rows "$OUT/alice.csv"); rb_g=$(rows "$OUT/bob1.csv")
"${CTL[@]}" guide 0 bob 0.5 200 > "$OUT/ctl.log" 2>&1 || fail "guide not applied"
wait_for settled alice -1 "$A50" owner0.50 $TICKS || fail "the trainee's client did not couple at 0.5"; ta_g=$EV
wait_for settled bob1 -1 "$B50" guide0.50 $TICKS || fail "the instructor's client did not couple at 0.5"; tb_g=$EV
ra_t=$(rows "$OUT/alice.csv"); rb_t=$(rows "$OUT/bob1.csv")
"${CTL[@]}" takeover 0 bob >> "$OUT/ctl.log" 2>&1 || fail "takeover not applied"
wait_for settled alice "$ta_g" "$A00" owner0.00 $TICKS || fail "the trainee's client did not couple as taken over"; ta_t=$EV
wait_for settled bob1 "$tb_g" "$B100" guide1.00 $TICKS || fail "the instructor's client did not couple as taking over"; tb_t=$EV
# The instructor's client is replaced by one that presses (still taken over).
ra_p=$(rows "$OUT/alice.csv"); rb_end=$(rows "$OUT/bob1.csv")
kill -INT $BOB; wait $BOB || fail "the first instructor client failed"
haptic bob2 bob; BOB=$HPID
# pressed_and_back: bob2 went below 0.031 and has 500 ticks back up at B.
pressed_and_back() { awk -F, -v z="$Z" 'NR > 1 && $4 < 0.031 { p = 1; n = 0 } p && $4 >= z - 1e-6 { n++ }
                                         END { exit !(p && n >= 500) }' "$OUT/bob2.csv"; }
wait_for settled bob2 -1 "$B100" guide1.00 1 || fail "the restarted instructor's client did not couple as taking over"; tb_p=$EV
wait_for pressed_and_back || fail "the instructor's press did not end"
ra_rel=$(rows "$OUT/alice.csv"); rb_rel=$(rows "$OUT/bob2.csv")
"${CTL[@]}" release 0 >> "$OUT/ctl.log" 2>&1 || fail "release not applied"
wait_for settled alice "$ta_t" "$REL" none $TICKS || fail "the trainee's client was not released"; ta_r=$EV
wait_for settled bob2 "$tb_p" "$REL" none $TICKS || fail "the instructor's client was not released"; tb_r=$EV
ra_tk2=$(rows "$OUT/alice.csv"); rb_tk2=$(rows "$OUT/bob2.csv")
# Taken over again, then the server dies: the coupling must end with it.
"${CTL[@]}" takeover 0 bob >> "$OUT/ctl.log" 2>&1 || fail "second takeover not applied"
wait_for settled alice "$ta_r" "$A00" owner0.00 $TICKS || fail "the trainee's client did not couple again"; ta_t2=$EV
wait_for settled bob2 "$tb_r" "$B100" guide1.00 $TICKS || fail "the instructor's client did not couple again"
ra_k=$(rows "$OUT/alice.csv")
{ kill -9 $SRV && wait $SRV; } 2>/dev/null || true
for who in alice bob2; do
  wait_for lost_settled $who || fail "$who stayed coupled to a dead server"
done
kill -INT $ALICE $BOB
cat "$OUT/ctl.log"
wait $ALICE || fail "trainee client failed"
wait $BOB || fail "instructor client failed"
PIDS=()
grep -h 'guide:\|GUIDE\|latency\|another station' "$OUT/alice.log" "$OUT/bob1.log" "$OUT/bob2.log"

# start WHO T: CSV line of WHO's first tick at its loop time T.
start() { row_of "$OUT/$1.csv" "$2"; }
for who in alice bob1 bob2; do ann $who; done
# median ANN R0 R1 EXPR [FILTER]: median of an awk expression over lines
# R0..R1 (and FILTER) of an annotated CSV, only the ticks in state ST past the
# ramp (ann above); prints "median count".
median() {
  awk -F, -v r0="$2" -v r1="$3" -v st="$ST" -v ramp=$RAMP \
    "NR > 1 && NR >= r0 && NR <= r1 && \$11 == st && \$12 >= ramp ${5:+&& ($5)} { print $4 }" "$1" | sort -g |
    awk '{ a[NR] = $1 } END { if (NR == 0) print "nan 0"; else print a[int((NR + 1) / 2)], NR }'
}
mag='sqrt($5*$5 + $6*$6 + $7*$7)'
# expect WHAT WHO R0 R1 EXPR LO HI [FILTER]: the median over WHO's CSV lines
# R0..R1 in state ST lies in [LO, HI], over at least 200 ticks.
expect() {
  local r; r=$(median "$OUT/$2.ann" "$3" "$4" "$5" "${8:-}")
  local m=${r% *} n=${r#* }
  printf '  %-44s median %9.4f over %5d ticks (want %s..%s)\n' "$1" "$m" "$n" "$6" "$7"
  awk -v m="$m" -v n="$n" -v lo="$6" -v hi="$7" 'BEGIN { exit !(n >= 200 && m >= lo && m <= hi) }' \
    || fail "$1: median $m over $n ticks, want $6..$7 over >= 200 ticks"
}
# Before guiding: free space, no force.
ST=none
expect "alice before guiding |F|" alice 300 $((ra_g - 100)) "$mag" 0 0.05
expect "bob before guiding |F|" bob1 300 $((rb_g - 100)) "$mag" 0 0.05
# Authority 0.5: 2 N along x, towards each other (B is at smaller x).
a=$(start alice "$ta_g"); b=$(start bob1 "$tb_g")
ST=owner0.50
expect "alice guided 0.5: Fx" alice "$a" $((ra_t - 100)) '$5' -2.2 -1.8
expect "alice guided 0.5: |F|" alice "$a" $((ra_t - 100)) "$mag" 1.8 2.2
ST=guide0.50
expect "bob guiding 0.5: Fx" bob1 "$b" $((rb_t - 100)) '$5' 1.8 2.2
expect "bob guiding 0.5: |F|" bob1 "$b" $((rb_t - 100)) "$mag" 1.8 2.2
# Take-over, the instructor still at B: trainee pulled with the whole spring, instructor free.
a=$(start alice "$ta_t"); b=$(start bob1 "$tb_t")
ST=owner0.00
expect "alice taken over: Fx" alice "$a" $((ra_p - 100)) '$5' -4.4 -3.6
expect "alice taken over: |F|" alice "$a" $((ra_p - 100)) "$mag" 3.6 4.4
ST=guide1.00
expect "bob taking over: |F|" bob1 "$b" $((rb_end - 100)) "$mag" 0 0.05
# The press, still taken over (the instructor's ticks below z 0.031): he feels
# the tissue push up (no coupling on his side); the trainee is pulled towards
# his hand, down and to -x, clamped to 6 N (her ticks pulled down by > 2 N:
# only his hand below hers does that).
pz='$4 < 0.031'
b=$(row_of "$OUT/bob2.csv" "$tb_p")
expect "bob pressing: Fz (tissue)" bob2 "$b" "$rb_rel" '$7' 0.3 6 "$pz"
expect "bob pressing: |Fx| (tissue only, no spring)" bob2 "$b" "$rb_rel" 'sqrt($5*$5)' 0 0.3 "$pz"
expect "bob pressing: in contact" bob2 "$b" "$rb_rel" '$8' 1 1 "$pz"
down='$7 < -2'
ST=owner0.00
expect "alice during the press: |F| (clamped)" alice "$ra_p" "$ra_rel" "$mag" 5.9 6.01 "$down"
# Direction towards the instructor's commanded position (BX - AX, 0, PRESS_Z -
# AX's z) normalised: (-0.44, 0, -0.90).
expect "alice during the press: Fx/|F|" alice "$ra_p" "$ra_rel" "\$5 / $mag" -0.5 -0.38 "$down"
expect "alice during the press: Fz/|F|" alice "$ra_p" "$ra_rel" "\$7 / $mag" -0.93 -0.86 "$down"
# Released: both free, nothing felt (until the second take-over).
a=$(start alice "$ta_r"); b=$(start bob2 "$tb_r")
ST=none
expect "alice released |F|" alice "$a" $((ra_tk2 - 100)) "$mag" 0 0.05
expect "bob released |F|" bob2 "$b" $((rb_tk2 - 100)) "$mag" 0 0.05
# Server killed during the second take-over: the trainee is pulled until the
# server has been silent for 250 ms, then both render nothing to the end.
a=$(start alice "$ta_t2")
ST=owner0.00
expect "alice taken over again: Fx" alice "$a" $((ra_k - 100)) '$5' -4.4 -3.6
for who in alice bob2; do
  tl=$(t_lost $who); [ -n "$tl" ] || fail "$who: the coupling did not end when the server was killed"
  r=$(awk -F, -v t0="$tl" "NR > 1 && \$1 > t0 + 0 { n++; f = $mag; if (f > m) m = f } END { print n + 0, m + 0 }" "$OUT/$who.csv")
  echo "  $who after the server was lost: ${r% *} ticks, largest |F| ${r#* } N"
  awk -v n="${r% *}" -v m="${r#* }" 'BEGIN { exit !(n >= 300 && m == 0) }' || fail "$who: force after the server was lost: $r"
done
# Summaries: coupled time on the right side; latency only from own echoes.
grep -q 'GUIDE coupled .* s as owner (trainee), 0.0 s as guide (instructor); last: as owner (trainee), authority 1.00, k 200 N/m, peer bob' "$OUT/alice.log" \
  || fail "trainee summary"
for b in bob1 bob2; do
  grep -q 'GUIDE coupled 0.0 s as owner (trainee), .* s as guide (instructor); last: as guide (instructor), authority 1.00, k 200 N/m, peer alice' "$OUT/$b.log" \
    || fail "instructor summary ($b)"
done
grep -q "answered another station's commands" "$OUT/bob1.log" || fail "the instructor counted the trainee's echoes as his"
echo PASS
