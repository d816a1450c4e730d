# SPDX-License-Identifier: Apache-2.0
# shellcheck shell=bash
# prelude.sh: what every network test script starts with, sourced right after
# `set -euo pipefail` (arguments BUILD SRC OUT as ctest passes them):
#   BUILD, SRC, OUT   build tree, source tree, the test's output directory (emptied)
#   PIDS              processes to kill -9 when the script exits
#   fail MSG          prints MSG and the tail of every OUT/*.log, exits 1
#   net_press         one scripted palpation session through the link
#   server_stall_us, client_stall_us   a process's longest step / tick from its log
#   the sites.sh functions; exits 77 (skip) where sites cannot be made.
# At exit: PIDS killed, then the sites (namespaces, veths, emulator) removed.
BUILD="$1"; SRC="$2"; OUT="$3"
PIDS=()
# shellcheck source=sites.sh
source "$SRC/tests/network/sites.sh"
export LINK_EMU="$BUILD/tests/network/link_emu"
sites_require || exit $?
net_cleanup() {
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  sites_down quiet
}
fail() {
  echo "FAIL: $*" >&2
  for f in "$OUT"/*.log; do
    [ -e "$f" ] || continue
    echo "--- $f"; tail -"${FAIL_TAIL:-6}" "$f"
  done >&2
  exit 1
}
rm -rf "$OUT"; mkdir -p "$OUT"
# net_sites PFX: the two sites, removed at exit whatever happens.
net_sites() {
  sites_up "$1" "$OUT" || fail "could not make the sites"
  trap net_cleanup EXIT
}
# net_press NAME SECONDS SEED TRAJ [EMULATOR-OPTIONS...]: one palpation
# session through the link: the emulator started (--duration SECONDS --seed
# SEED and the options), the server in site a (assets/scenes/default.yaml,
# partition $SEAT, and the options in the array NET_SERVER_ARGS when the
# caller set it), the scripted trainee in site b along TRAJ at its default
# 1 kHz (killed after SECONDS), then the server stopped with SIGINT and the
# link stopped. Leaves OUT/NAME-server.out/.log, NAME-haptic.out/.log (its
# SUMMARY line), NAME-force.csv and NAME-link.txt; fail()s on any error.
net_press() {
  local name="$1" secs="$2" seed="$3" traj="$4" srv
  shift 4
  link_start --duration "$secs" --seed "$seed" "$@" || fail "$name: emulator did not start"
  run_in_site a "$BUILD/server/viscera-server" --scene "$SRC/assets/scenes/default.yaml" --partition "$SEAT" \
    ${NET_SERVER_ARGS[@]+"${NET_SERVER_ARGS[@]}"} > "$OUT/$name-server.out" 2> "$OUT/$name-server.log" &
  srv=$!; PIDS+=("$srv")
  run_in_site b timeout "$secs" "$BUILD/client/haptic/viscera-haptic" --trajectory "$traj" --partition "$SEAT" \
    --wait-server 15 --force-csv "$OUT/$name-force.csv" > "$OUT/$name-haptic.out" 2> "$OUT/$name-haptic.log" \
    || fail "$name: haptic client failed"
  kill -INT "$srv"; wait "$srv" || fail "$name: server exited with an error"
  link_stop > "$OUT/$name-link.txt"
}
# server_stall_us LOG: the server's longest step (us) from its log: a step
# longer than the feedback lease (150 ms) is a real stall (a loaded machine),
# and a "server lost" then is not false; nor when the client's own loop
# stalled 100 ms.
server_stall_us() { sed -n 's/^server: .* step time median .* max \([0-9.]*\) us.*/\1/p' "$1" | tail -1; }
# client_stall_us LOG: the haptic client's longest tick period (us): a loop
# starved for 100 ms or more means its DDS threads may have been too, past
# the lease.
client_stall_us() { sed -n 's/^haptic: .* period median .* max \([0-9.]*\) us.*/\1/p' "$1" | tail -1; }
# A key=value field from a SUMMARY-style line of FILE: field FILE KEY.
field() { sed -n "s/.*[ :]$2=\([-0-9.e+]*\).*/\1/p" "$1" | tail -1; }
# smooth_press FILE: the kidney palpation as a hand makes it (haptic client
# --trajectory): 3.5 cm above the top, pressed 8 mm in 1.5 s, held 1 s, let go;
# smoothstep between the points (velocity continuous), sampled every 10 ms.
# The press is slow enough that over a link of up to 100 ms one way the first
# contact sample reaches the client while the hand still presses: a hand that
# has stopped before it arrives has put no energy into the wall, and the
# client's passivity controller (client/haptic/passivity.h, observer <= 0 at
# every tick) may then not push it back out (palpate_kidney.traj's press ends
# 0.18 s after the surface).
smooth_press() {
  awk 'BEGIN { n = split("0.0 0.070 0.5 0.070 2.0 0.027 3.0 0.027 4.0 0.070 5.0 0.070", v, " ")
    for (i = 1; i + 2 < n; i += 2) { t0 = v[i]; z0 = v[i + 1]; t1 = v[i + 2]; z1 = v[i + 3]
      for (t = t0; t < t1 - 1e-9; t += 0.01) { s = (t - t0) / (t1 - t0); w = s * s * (3 - 2 * s)
        printf "%.3f 0.012 0.004 %.6f\n", t, z0 + w * (z1 - z0) } }
    printf "%.3f 0.012 0.004 %.6f\n", v[n - 1], v[n] }' > "$1"
}
