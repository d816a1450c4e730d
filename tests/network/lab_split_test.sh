#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A lab split over two sites (issue 14) as deploy/README.md describes for
# several machines: deploy/lab.sh --seats 2 (with the lab recorder) in site a,
# deploy/lab.sh --first 3 --seats 2 --no-record in site b, both with
# deploy/cyclonedds-lan.xml (multicast discovery: the SPDP multicast crosses
# the emulated link like every frame) and a scripted trainee per seat; one
# dashboard in site b. At two link settings: 5 ms, 1 % loss, run --insecure
# (the plain LAN file: lab.sh warns); 30 +- 5 ms without reordering, 3 % loss,
# run --secure with one PKI for both sites (copies, as on two machines; the
# dashboard with the observer identity):
#   - the one recorder (site a) holds MeshDelta from all four seats and the
#     trainees' ToolCommands of all four, those of seats 3-4 from across the link;
#   - the dashboard (site b) showed a scene in all four seats, seats 1-2 from
#     across the link;
#   - every lab.sh exits 0.
# And secure by default: lab.sh on the LAN configuration without --secure or
# --insecure refuses to start (exit 2, naming both); --insecure warns.
# usage: lab_split_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
command -v sqlite3 >/dev/null || { echo "SKIP: sqlite3 missing (deploy/install_deps.sh installs it)"; exit 77; }
net_sites lk5
export CYCLONEDDS_URI="file://$SRC/deploy/cyclonedds-lan.xml" VISCERA_LAB_STOP_GRACE=3
LAB=(bash "$SRC/deploy/lab.sh" --build "$BUILD" --trainees --viewers 0)
LAN="$CYCLONEDDS_URI"
bash "$SRC/deploy/pki.sh" "$OUT/pki-a" --seats 4 > "$OUT/pki.txt" 2>&1 || fail "pki.sh failed"
cp -a "$OUT/pki-a" "$OUT/pki-b"

# Secure by default.
if run_in_site a bash "$SRC/deploy/lab.sh" --build "$BUILD" --seats 1 --duration 1 --out "$OUT/refused" \
  > "$OUT/refused.txt" 2>&1; then
  fail "lab.sh ran on the LAN configuration without --secure or --insecure"
fi
grep -q "is not the loopback configuration: run with --secure.*--insecure" "$OUT/refused.txt" \
  || fail "lab.sh did not say why it refused: $(cat "$OUT/refused.txt")"

split() { # split NAME insecure|secure EMULATOR-OPTIONS...
  local n="$1" mode="$2" la lb dash q seat sa=(--insecure) sb=(--insecure) dash_uri="$LAN" dash_opt=(--insecure)
  shift 2
  if [ "$mode" = secure ]; then
    sa=(--secure --pki "$OUT/pki-a") sb=(--secure --pki "$OUT/pki-b")
    dash_uri="$LAN,file://$OUT/pki-b/identities/observer/security.xml" dash_opt=()
  fi
  link_start --duration 60 --seed 19 "$@" || fail "$n: emulator did not start"
  run_in_site a "${LAB[@]}" "${sa[@]}" --seats 2 --duration 13 --out "$OUT/$n-a" > "$OUT/$n-lab-a.txt" 2>&1 &
  la=$!; PIDS+=("$la")
  run_in_site b "${LAB[@]}" "${sb[@]}" --first 3 --seats 2 --no-record --duration 12 --out "$OUT/$n-b" > "$OUT/$n-lab-b.txt" 2>&1 &
  lb=$!; PIDS+=("$lb")
  CYCLONEDDS_URI="$dash_uri" run_in_site b "$BUILD/client/dashboard/viscera-dashboard" "${dash_opt[@]}" --prefix lab --seats 4 --out "$OUT/$n-dash" \
    --interval-ms 500 --duration 11 > "$OUT/$n-dashboard.log" 2>&1 &
  dash=$!; PIDS+=("$dash")
  wait "$dash" || fail "$n: dashboard failed"
  wait "$la" || fail "$n: lab.sh in site a failed: $(tail -5 "$OUT/$n-lab-a.txt")"
  wait "$lb" || fail "$n: lab.sh in site b failed: $(tail -5 "$OUT/$n-lab-b.txt")"
  PIDS=()
  link_stop > "$OUT/$n-link.txt"
  if [ "$mode" = insecure ]; then
    grep -q "WARNING: insecure: DDS Security is off" "$OUT/$n-lab-a.txt" || fail "$n: lab.sh --insecure did not warn"
  else
    grep -q "WARNING" "$OUT/$n-lab-a.txt" && fail "$n: lab.sh --secure warned"
  fi
  q() { sqlite3 "$OUT/$n-a/lab.db" "SELECT count(*) FROM samples s JOIN writers w ON s.writer_id = w.id
    JOIN topics t ON t.id = s.topic_id WHERE t.name = '$1' AND w.partitions = '$2' AND s.kind = 0"; }
  for seat in lab/seat01 lab/seat02 lab/seat03 lab/seat04; do
    [ "$(q viscera_MeshDelta $seat)" -ge 1 ] || fail "$n: the recording has no MeshDelta of $seat"
    [ "$(q viscera_ToolCommand $seat)" -ge 100 ] || fail "$n: the recording has $(q viscera_ToolCommand $seat) ToolCommands of $seat"
  done
  awk -F, 'NR > 1 && $4 == 1 { scene[$3] = 1 }
    END { n = scene["lab/seat01"] + scene["lab/seat02"] + scene["lab/seat03"] + scene["lab/seat04"]
          printf "dashboard: %d of 4 seats with a scene\n", n; exit n != 4 }' "$OUT/$n-dash/dashboard.csv" \
    || fail "$n: the dashboard did not see all four seats"
  echo "$n: recorded per seat (MeshDelta/ToolCommand): $(for s in 1 2 3 4; do
    printf '%s/%s ' "$(q viscera_MeshDelta lab/seat0$s)" "$(q viscera_ToolCommand lab/seat0$s)"; done)"
  grep '^link ' "$OUT/$n-link.txt"
}

split near insecure --delay 5 --loss 1
split far secure --delay 30 --jitter 5 --no-reorder --loss 3
echo PASS
