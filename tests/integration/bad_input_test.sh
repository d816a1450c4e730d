#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Bad scene and mesh files: a message naming the file and what is wrong, and
# a non-zero exit. usage: bad_input_test.sh BUILD SRC OUT
set -uo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
SERVER="$BUILD/server/viscera-server"
rm -rf "$OUT"; mkdir -p "$OUT"
failures=0
expect_fail() { # name, expected substring, args...
  local name="$1" needle="$2"; shift 2
  local msg rc
  msg=$("$SERVER" "$@" 2>&1 >/dev/null); rc=$?
  if [ $rc -ne 0 ] && grep -qF -- "$needle" <<<"$msg"; then
    echo "ok   $name: $msg"
  else
    echo "FAIL $name (rc=$rc, wanted '$needle'): $msg"; failures=$((failures + 1))
  fi
}
scene() { # file, mesh path
  cat > "$1" <<YAML
scene: bad-input
organs:
  - name: organ
    mesh: $2
tools:
  - name: probe
YAML
}
expect_fail "missing scene" "$OUT/nope.yaml" --scene "$OUT/nope.yaml" --check
printf 'scene: x\norgans: [\n' > "$OUT/syntax.yaml"
expect_fail "malformed scene" "syntax.yaml:" --scene "$OUT/syntax.yaml" --check
printf 'scene: x\norgans:\n  - name: a\n    mesh: a.obj\n    material:\n      stiffness: -3\n' > "$OUT/range.yaml"
expect_fail "out-of-range field" "range.yaml:6: field 'organs[0].material.stiffness'" --scene "$OUT/range.yaml" --check
scene "$OUT/missing_mesh.yaml" "$OUT/missing.obj"
# A mesh's own problems point at the scene's `mesh:` line (line 4), not the organ's.
expect_fail "missing mesh" "missing_mesh.yaml:4: field 'organs[0].mesh': organ 'organ'" --scene "$OUT/missing_mesh.yaml" --check
expect_fail "missing mesh" "missing.obj" --scene "$OUT/missing_mesh.yaml" --check
: > "$OUT/empty.obj"; scene "$OUT/empty_mesh.yaml" "$OUT/empty.obj"
expect_fail "empty mesh" "empty.obj" --scene "$OUT/empty_mesh.yaml" --check
printf 'v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n' > "$OUT/nan.obj"; scene "$OUT/nan_mesh.yaml" "$OUT/nan.obj"
expect_fail "NaN mesh" "nan.obj" --scene "$OUT/nan_mesh.yaml" --check
expect_fail "NaN mesh" "nan_mesh.yaml:4: field 'organs[0].mesh'" --scene "$OUT/nan_mesh.yaml" --check
# A volume file's problem points at the `volume:` line (line 5) and names the file's own line.
printf '$MeshFormat\n9.9 0 8\n$EndMeshFormat\n' > "$OUT/bad.msh"
printf 'scene: bad-volume\norgans:\n  - name: organ\n    model: xpbd\n    volume: %s\n' "$OUT/bad.msh" > "$OUT/bad_volume.yaml"
expect_fail "bad volume" "bad_volume.yaml:5: field 'organs[0].volume': organ 'organ' (model xpbd): $OUT/bad.msh:2:" \
  --scene "$OUT/bad_volume.yaml" --check
head -c 4096 /dev/urandom > "$OUT/garbage.stl"; scene "$OUT/garbage_mesh.yaml" "$OUT/garbage.stl"
expect_fail "garbage mesh" "garbage.stl" --scene "$OUT/garbage_mesh.yaml" --check
printf 'v 0 0 0\n' > "$OUT/unreadable.obj"; chmod 000 "$OUT/unreadable.obj"
scene "$OUT/unreadable_mesh.yaml" "$OUT/unreadable.obj"
if [ "$(id -u)" -ne 0 ]; then expect_fail "unreadable mesh" "unreadable.obj" --scene "$OUT/unreadable_mesh.yaml" --check; fi
# And the good scene passes the same check.
if "$SERVER" --scene "$SRC/assets/scenes/default.yaml" --check; then echo "ok   default scene"; else
  echo "FAIL default scene"; failures=$((failures + 1)); fi
[ $failures -eq 0 ] && echo PASS || { echo "$failures failure(s)"; exit 1; }
