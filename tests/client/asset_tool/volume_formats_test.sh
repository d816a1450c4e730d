#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-asset tet --out writes the spleen's fill in every volume format,
# `volume` reads each back with the same counts, the server takes each as an
# organ's `volume:` (--check), and a damaged file is refused with exit 1
# naming its line. Args: viscera-asset viscera-server assets-dir out-dir.
set -u
ASSET=$1 SERVER=$2 ASSETS=$3 OUT=$4
mkdir -p "$OUT"
fail() { echo "FAIL: $*"; exit 1; }
for f in msh2:msh msh4:msh vtk:vtk tetgen:node; do
  fmt=${f%%:*} ext=${f##*:}
  file="$OUT/spleen_$fmt.$ext"
  "$ASSET" tet "$ASSETS/meshes/spleen.obj" --size 0.006 --out "$file" --format "$fmt" >"$OUT/tet_$fmt.txt" ||
    fail "tet --out $fmt"
  want=$(awk '/^  tetrahedra/ { print $2 }' "$OUT/tet_$fmt.txt")
  "$ASSET" volume "$file" >"$OUT/volume_$fmt.txt" || fail "volume $file"
  got=$(awk '/^  tetrahedra/ { print $2 }' "$OUT/volume_$fmt.txt")
  [ -n "$want" ] && [ "$want" = "$got" ] || fail "$fmt: wrote $want tetrahedra, read $got"
  grep -q "repaired  *0 tetrahedra" "$OUT/volume_$fmt.txt" || fail "$fmt: the writer's own file needed repairs"
  cat >"$OUT/scene_$fmt.yaml" <<YAML
scene: vol-$fmt
physics: {dt: 0.001}
organs:
  - {name: spleen, mesh: $ASSETS/meshes/spleen.obj, volume: $file, model: xpbd}
tools:
  - {name: probe}
YAML
  "$SERVER" --scene "$OUT/scene_$fmt.yaml" --check >"$OUT/check_$fmt.txt" 2>&1 || fail "--check with $fmt: $(cat "$OUT/check_$fmt.txt")"
  grep -q "$got tets" "$OUT/check_$fmt.txt" || fail "$fmt: the server did not simulate the file's $got tetrahedra"
  echo "$fmt: $got tetrahedra written, read and simulated"
done
# A corner naming a node that does not exist, on line 8 of a hand-made file.
printf '$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n' \
  >"$OUT/bad.msh"
"$ASSET" volume "$OUT/bad.msh" 2>"$OUT/bad.err"
rc=$?
[ $rc -eq 1 ] || fail "a damaged file: exit $rc, want 1"
grep -q "bad.msh:10: .*node 2" "$OUT/bad.err" || fail "the refusal does not name line 10: $(cat "$OUT/bad.err")"
echo "damaged file refused: $(cat "$OUT/bad.err")"
