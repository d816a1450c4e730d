#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every example scene in assets/scenes runs (SOFA-style smoke test): the server
# loads it, a scripted probe palpates the kidney, contact force rises above
# 0.1 N, and no step is rolled back; an adaptive_mass_spring scene must also
# have refined under the probe (the server logs the topology change).
# usage: scenes_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
DOMAIN="${VISCERA_DOMAIN:-16}"
mkdir -p "$OUT"
failures=0
for scene in "$SRC"/assets/scenes/*.yaml; do
  name=$(basename "$scene" .yaml)
  "$BUILD/server/viscera-server" --scene "$scene" --domain "$DOMAIN" --partition "test/$name" \
    >"$OUT/$name.server.out" 2>"$OUT/$name.server.log" & S=$!
  "$BUILD/client/haptic/viscera-haptic" --trajectory "$SRC/assets/trajectories/palpate_kidney.traj" \
    --domain "$DOMAIN" --partition "test/$name" --quiet >"$OUT/$name.haptic.out" 2>"$OUT/$name.haptic.log"
  hrc=$?
  kill -INT $S; wait $S; src=$?
  peak=$(grep -o 'peak_force=[^ ]*' "$OUT/$name.server.out" | cut -d= -f2)
  rolled=$(grep -o 'rollbacks=[^ ]*' "$OUT/$name.server.out" | cut -d= -f2)
  # A model that changes topology must have refined under the probe and streamed it.
  retopo=ok
  if grep -q 'adaptive_mass_spring' "$scene" && ! grep -q 'topology 1:' "$OUT/$name.server.log"; then retopo=missing; fi
  if [ $hrc -eq 0 ] && [ $src -eq 0 ] && [ "${rolled:-1}" = 0 ] && [ $retopo = ok ] &&
    awk -v p="${peak:-0}" 'BEGIN { exit !(p > 0.1) }'; then
    echo "ok   $name: peak force ${peak} N, no rollbacks"
  else
    echo "FAIL $name: haptic rc $hrc, server rc $src, peak ${peak:-?} N, rollbacks ${rolled:-?}, topology change $retopo"; tail -3 "$OUT/$name.server.log"
    failures=$((failures + 1))
  fi
done
[ $failures -eq 0 ] && echo PASS || { echo "$failures scene(s) failed"; exit 1; }
