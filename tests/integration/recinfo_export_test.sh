#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-recinfo --export csv / jsonl (issue 16 item 4): a stone_removal
# session (probe and extractor, two tasks) is recorded and one topic at a
# time exported, decoded with the recorded types; the contents are checked
# against what the server printed:
#  - ContactFeedback CSV: one row per recorded sample (recinfo's count), the
#    decoded columns named from the IDL (force[0..2], in_contact, ...); the
#    probe's peak |force| and its time in contact (each row counting the
#    simulated time since the previous one, as the report does)
#    equal its PALPATION line (peak within 0.02 N, contact within 0.05 s or
#    3 %: ContactFeedback is best-effort);
#  - SceneInfo JSONL: the probe's ST/MPF/SFT equal the PALPATION levels;
#  - SessionEvent JSONL: one line per sample; every TASK_COMPLETED names its
#    task (task_id, task_name) with the server's TASK operation time;
#  - a truncated copy exports what is readable, exit status 1;
#  - errors: no --topic, an unknown topic or format is a usage error (2).
# usage: recinfo_export_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
RECINFO="$BUILD/client/recorder/viscera-recinfo"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/*.log "$OUT"/*.err; do [ -f "$f" ] && { echo "--- $f"; tail -5 "$f"; }; done >&2; exit 1; }
rm -rf "$OUT"; mkdir -p "$OUT"
. "$(dirname "$0")/tools_session.sh"
tools_session "$BUILD" "$OUT" "$SRC/assets/scenes/stone_removal.yaml" \
  "0:$SRC/assets/trajectories/palpate_kidney.traj" "1:$SRC/assets/trajectories/stone_removal_extractor.traj" \
  || fail "session did not run"
REC="$OUT/session.db"
count() { "$RECINFO" "$REC" --topic "$1" | awk -v t="$1" '$1 == t { print $3 }'; }
srv() { grep '^PALPATION tool=probe ' "$OUT/server.out" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
near() { # NAME GOT WANT ABS REL
  awk -v g="$2" -v w="$3" -v a="$4" -v r="$5" 'BEGIN { d = g - w; if (d < 0) d = -d; t = r * (w < 0 ? -w : w);
    if (t < a) t = a; exit !(g != "" && d <= t) }' || fail "$1: export $2, server $3 (tolerance max($4, $5 rel))"
  echo "ok: $1 export $2 server $3"
}

"$RECINFO" "$REC" --export csv --topic viscera_ContactFeedback "$OUT/fb.csv" 2> "$OUT/csv.err" \
  || { cat "$OUT/csv.err"; fail "csv export failed"; }
head -1 "$OUT/fb.csv"
head -1 "$OUT/fb.csv" | grep -q '^source_time_ns,partition,tool_id,cmd_seq,.*,in_contact,.*,force\[0\],force\[1\],force\[2\],seq$' \
  || fail "unexpected CSV header"
[ "$(tail -n +2 "$OUT/fb.csv" | wc -l)" = "$(count viscera_ContactFeedback)" ] || fail "CSV rows differ from recinfo's count"
read -r peak contact < <(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  $c["tool_id"] == 0 { f = sqrt($c["force[0]"]^2 + $c["force[1]"]^2 + $c["force[2]"]^2); if (f > p) p = f;
    t = $c["sim_time_ns"] * 1e-9; dt = (seen && t == last) ? 0 : (seen && t > last && t - last <= 0.5) ? t - last : 0.001
    if ($c["in_contact"] == "true") n += dt; last = t; seen = 1 } END { printf "%.4f %.3f\n", p, n }' "$OUT/fb.csv")
near "probe peak force (N)" "$peak" "$(srv peak_force)" 0.02 0
near "probe contact time (s)" "$contact" "$(srv contact_time)" 0.05 0.03

"$RECINFO" "$REC" -q --export jsonl --topic viscera_SceneInfo "$OUT/scene.jsonl" || fail "SceneInfo jsonl export failed"
probe=$(grep -o '{"tool_id":0,"name":"probe"[^}]*}' "$OUT/scene.jsonl") || fail "no probe ToolInfo in $(cat "$OUT/scene.jsonl")"
for k in st mpf sft; do
  v=$(echo "$probe" | sed -n "s/.*\"$k\":\([^,}]*\).*/\1/p")
  near "probe $k (N)" "$v" "$(srv "${k^^}")" 0.0005 0
done

"$RECINFO" "$REC" -q --export jsonl --topic viscera_SessionEvent "$OUT/events.jsonl" || fail "SessionEvent jsonl export failed"
[ "$(wc -l < "$OUT/events.jsonl")" = "$(count viscera_SessionEvent)" ] || fail "JSONL lines differ from recinfo's count"
got=$(grep '"kind":"EVENT_TASK_COMPLETED"' "$OUT/events.jsonl" |
  sed -n 's/.*"value":\([^,]*\),.*"task_id":\([0-9]*\),"task_name":"\([^"]*\)".*/\3 \1/p' |
  awk '{ printf "%s=%.3f\n", $1, $2 }' | sort)
want=$(sed -n 's/^TASK task=\([^ ]*\) .*state=completed operation_time=\([0-9.]*\)$/\1=\2/p' "$OUT/server.out" | sort)
echo "tasks: $(echo $got)"
[ -n "$want" ] && [ "$got" = "$want" ] || fail "TASK_COMPLETED events '$got' differ from the TASK lines '$want'"

# A truncated copy: what is readable is exported, the exit status says damaged.
cp "$REC" "$OUT/trunc.db"; truncate -s $(( $(stat -c %s "$REC") * 6 / 10 )) "$OUT/trunc.db"
st=0; "$RECINFO" "$OUT/trunc.db" --export csv --topic viscera_ContactFeedback "$OUT/trunc.csv" 2> "$OUT/trunc.err" || st=$?
[ $st = 1 ] && grep -q "damaged" "$OUT/trunc.err" && [ "$(wc -l < "$OUT/trunc.csv")" -gt 100 ] \
  || fail "a truncated recording: exit $st, $(wc -l < "$OUT/trunc.csv") rows (want 1, a warning and the readable rows)"
st=0; "$RECINFO" "$REC" --export csv "$OUT/x.csv" 2> "$OUT/e1.err" || st=$?
[ $st = 2 ] && grep -q -- '--topic' "$OUT/e1.err" || fail "csv without --topic should be a usage error"
st=0; "$RECINFO" "$REC" --export csv --topic nope "$OUT/x.csv" 2> "$OUT/e2.err" || st=$?
[ $st = 2 ] && grep -q "no topic 'nope'" "$OUT/e2.err" || fail "an unknown topic should be a usage error"
st=0; "$RECINFO" "$REC" --export xls "$OUT/x.csv" 2> "$OUT/e3.err" || st=$?
[ $st = 2 ] || fail "an unknown format should be a usage error"
echo "PASS"
