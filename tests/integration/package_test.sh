#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The Debian package (issue 18): `cpack -G DEB` in the build tree makes the
# .deb; its Depends were computed (dpkg-shlibdeps: Cyclone DDS, assimp, yaml,
# sqlite3 ... appear without being listed anywhere by hand); it holds every
# binary of this build, their man pages and bash completions, the assets
# under usr/share/viscera, the Cyclone configurations, the units (ExecStart
# in /usr/bin, --checkpoint into the state directory), the sysusers.d file
# and the licence. Then it is unpacked into a scratch root (dpkg -x) and a
# short session runs from there, from another directory, with
# CYCLONEDDS_URI and VISCERA_DATA_DIR unset: the server finds the installed
# scene by name, the scripted trainee the installed trajectory, both the
# installed loopback configuration, and the trainee presses the kidney.
# Exit 77 when dpkg-deb or cpack is missing.
# usage: package_test.sh BUILD SRC OUT
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/prelude.sh"
unset CYCLONEDDS_URI VISCERA_DATA_DIR
for t in dpkg-deb dpkg-shlibdeps file cpack; do
  command -v $t > /dev/null || { echo "SKIP: $t not installed"; exit 77; }
done
(cd "$BUILD" && nice cpack -G DEB -B "$OUT/pkg") > "$OUT/cpack.log" 2>&1 || fail "cpack failed: $(tail -5 "$OUT/cpack.log")"
DEB=$(ls "$OUT"/pkg/viscera_*.deb)
dpkg-deb -I "$DEB" > "$OUT/info.txt"
dpkg-deb -c "$DEB" | awk '{ print $6 }' | sed 's|^\./||' > "$OUT/contents.txt"
deps=$(sed -n 's/^ Depends: //p' "$OUT/info.txt")
echo "Depends: $deps"
for lib in libddsc libassimp libyaml libsqlite3 libpng libc6; do
  grep -q "$lib" <<< "$deps" || fail "Depends lacks $lib (shlibdeps not run?)"
done
bins=$(cd "$BUILD" && find . -name 'viscera-*' -type f -perm -u+x ! -path '*/CMakeFiles/*' -printf '%f\n' | sort -u)
[ "$(wc -l <<< "$bins")" -ge 10 ] || fail "too few binaries in the build: $bins"
for b in $bins; do
  grep -qx "usr/bin/$b" "$OUT/contents.txt" || fail "the package lacks usr/bin/$b"
  grep -q "^usr/share/man/man1/$b.1" "$OUT/contents.txt" || fail "the package lacks the man page of $b"
  grep -qx "usr/share/bash-completion/completions/$b" "$OUT/contents.txt" || fail "the package lacks the completion of $b"
done
for f in usr/share/viscera/assets/scenes/default.yaml usr/share/viscera/assets/meshes/kidney.obj \
  usr/share/viscera/assets/trajectories/palpate_kidney.traj usr/share/viscera/deploy/cyclonedds-loopback.xml \
  usr/share/viscera/deploy/cyclonedds-lan.xml usr/lib/systemd/system/viscera-server@.service \
  usr/lib/systemd/system/viscera-recorder@.service usr/lib/systemd/system/viscera-seats@.service \
  usr/lib/sysusers.d/viscera.conf usr/share/doc/viscera/copyright; do
  grep -qx "$f" "$OUT/contents.txt" || fail "the package lacks $f"
done
echo "package: $(wc -l < "$OUT/contents.txt") entries, $(wc -l <<< "$bins") binaries, $(du -k "$DEB" | cut -f1) kB"

R="$OUT/root"
dpkg -x "$DEB" "$R"
grep -q "^ExecStart=/usr/bin/viscera-server .*--checkpoint /var/lib/viscera/%i.ckpt" \
  "$R/usr/lib/systemd/system/viscera-server@.service" || fail "the installed server unit does not run /usr/bin/viscera-server --checkpoint"
grep -q "^u viscera " "$R/usr/lib/sysusers.d/viscera.conf" || fail "sysusers.d file declares no viscera user"
grep -q "Apache License" "$R/usr/share/doc/viscera/copyright" || fail "no licence text"
grep -q "^\.TH VISCERA-SERVER" <(zcat -f "$R"/usr/share/man/man1/viscera-server.1*) || fail "the man page is not a man page"
"$R/usr/bin/viscera-server" --version | grep -q "^viscera-server " || fail "the installed server has no --version"

mkdir -p "$OUT/elsewhere"
cd "$OUT/elsewhere"
"$R/usr/bin/viscera-server" --scene default.yaml --partition pkg/seat01 --duration 9 > "$OUT/server.log" 2>&1 &
SRV=$!; PIDS+=("$SRV")
"$R/usr/bin/viscera-recorder" --partition pkg/seat01 --out "$OUT/session.db" --duration 8 --quiet \
  > "$OUT/recorder.log" 2>&1 & REC=$!; PIDS+=("$REC")
"$R/usr/bin/viscera-haptic" --partition pkg/seat01 --trajectory palpate_kidney.traj --quiet > "$OUT/haptic.log" 2>&1 ||
  fail "the installed haptic client failed"
wait $SRV || fail "the installed server failed"
wait $REC || fail "the installed recorder failed"
PIDS=()
grep -q "scene default.yaml found as $R/usr/bin/../share/viscera/assets/scenes/default.yaml" "$OUT/server.log" ||
  fail "the installed server did not take the installed scene"
peak=$(sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p' "$OUT/haptic.log" | head -1)
echo "installed session: trainee peak force ${peak:-none} N"
awk -v p="${peak:-0}" 'BEGIN { exit !(p > 0.5) }' || fail "the trainee did not press the kidney (peak ${peak:-none} N)"
n=$("$R/usr/bin/viscera-recinfo" "$OUT/session.db" | tail -1)
echo "recording: $n"
echo PASS
