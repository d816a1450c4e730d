#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-server --check on the hostile scenes of issue 15 item 3: values
# out of their physical range and mesh defects are refused with exit 1 and a
# message naming file, line, key (or the mesh and its defect); an inside-out
# or inconsistently wound mesh is repaired and said. Before the fix every
# one of these passed --check (and dt 1e-300 then died of SIGFPE).
# Usage: check_hostile_test.sh SERVER_BINARY SOURCE_DIR
set -u
SERVER="$1"
SRC="$2"
DIR="$(mktemp -d /tmp/hardinput_check.XXXXXX)"
trap 'rm -rf "$DIR"' EXIT
fail=0
KIDNEY="$SRC/assets/meshes/kidney.obj"

scene() { # scene NAME MESH EXTRA_ORGAN_LINES PHYSICS_LINE
  printf 'scene: hostile\n%sorgans:\n  - name: organ\n    mesh: %s\n%s' "$4" "$2" "$3" >"$DIR/$1.yaml"
}
# refused NAME EXPECTED...: exit 1 and each expected text in the output
refused() {
  local name="$1"
  shift
  "$SERVER" --check --scene "$DIR/$name.yaml" >"$DIR/$name.out" 2>&1
  local rc=$?
  if [ "$rc" != 1 ]; then
    echo "FAIL $name: exit $rc, want 1"; cat "$DIR/$name.out"; fail=1; return
  fi
  for want in "$@"; do
    if ! grep -qF -- "$want" "$DIR/$name.out"; then
      echo "FAIL $name: '$want' not in:"; cat "$DIR/$name.out"; fail=1; return
    fi
  done
  echo "ok   $name: $(tail -n 1 "$DIR/$name.out")"
}
repaired() {
  local name="$1" want="$2"
  "$SERVER" --check --scene "$DIR/$name.yaml" >"$DIR/$name.out" 2>&1
  local rc=$?
  if [ "$rc" != 0 ] || ! grep -qF -- "$want" "$DIR/$name.out"; then
    echo "FAIL $name: exit $rc, want 0 and '$want':"; cat "$DIR/$name.out"; fail=1; return
  fi
  echo "ok   $name: $(grep -F "mesh repaired" "$DIR/$name.out")"
}
# An OBJ of the 8-vertex cube scaled by $1, triangles from stdin lines "a b c".
cube() {
  awk -v s="$1" 'BEGIN { split("0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1", v, " ");
    for (i = 0; i < 8; i++) printf "v %.17g %.17g %.17g\n", v[3*i+1]*s, v[3*i+2]*s, v[3*i+3]*s }
    { print "f", $1, $2, $3 }'
}
OUT='1 3 2
1 4 3
5 6 7
5 7 8
1 2 6
1 6 5
2 3 7
2 7 6
3 4 8
3 8 7
4 1 5
4 5 8'

scene dt "$KIDNEY" "" $'physics:\n  dt: 1e-300\n'
refused dt "dt.yaml:3: field 'physics.dt'" "(got 1e-300)" ">= 1e-05 and <= 0.05 s"
scene mass "$KIDNEY" $'    material: {mass: 1e-300}\n' ""
refused mass "mass.yaml:5: field 'organs[0].material.mass'" "(got 1e-300)" ">= 0.001 and <= 20 kg"
scene stiff "$KIDNEY" $'    material: {stiffness: 1e300}\n' ""
refused stiff "field 'organs[0].material.stiffness'" "(got 1e300)"

echo "$OUT" | cube 1e30 >"$DIR/huge.obj"
scene huge "$DIR/huge.obj" "" ""
refused huge "huge.obj: the mesh is 1.73205e+30 m across" "outside 0.0001 .. 10 m"
echo "$OUT" | cube 1e-30 >"$DIR/tiny.obj"
scene tiny "$DIR/tiny.obj" "" ""
refused tiny "tiny.obj: the mesh is 1.73205e-30 m across"
echo "$OUT" | awk '{ print $1, $3, $2 }' | cube 0.05 >"$DIR/inside_out.obj"
scene inside_out "$DIR/inside_out.obj" "" ""
repaired inside_out "mesh repaired: inside out"
echo "$OUT" | awk 'NR % 4 == 0 { print $1, $3, $2; next } { print }' | cube 0.05 >"$DIR/wound.obj"
scene wound "$DIR/wound.obj" "" ""
repaired wound "mesh repaired: 3 of 12 triangles re-wound"
echo "$OUT" | head -n 10 | cube 0.05 >"$DIR/open.obj"
scene open "$DIR/open.obj" $'    model: xpbd\n' ""
refused open "open.obj: open surface (4 boundary edge(s))" "model xpbd"
{ echo "$OUT" | cube 0.05; echo "$OUT" | awk '{ print $1 + 8, $2 + 8, $3 + 8 }' |
  cube 0.05 | grep '^f'; echo "$OUT" | cube 0.05 | grep '^v' | awk '{ print "v", $2 + 0.2, $3, $4 }'; } |
  awk '/^v/ { v[nv++] = $0; next } { f[nf++] = $0 } END { for (i = 0; i < nv; i++) print v[i]; for (i = 0; i < nf; i++) print f[i] }' \
  >"$DIR/two.obj"
scene two "$DIR/two.obj" "" ""
refused two "two.obj: the mesh is in 2 separate parts"
{ echo "$OUT" | cube 0.05; echo "v 0.025 -0.05 -0.05"; echo "f 1 2 9"; } >"$DIR/nonmanifold.obj"
scene nonmanifold "$DIR/nonmanifold.obj" "" ""
refused nonmanifold "nonmanifold.obj: non-manifold: 1 edge(s)"
exit $fail
