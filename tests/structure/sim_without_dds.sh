#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# sim_without_dds.sh SOURCE_ROOT BUILD_DIR [cmake args...]: the simulation
# core builds and its unit tests pass without Cyclone DDS. Configures the tree
# with -DVISCERA_SIM_ONLY=ON (which never looks for CycloneDDS or the IDL),
# builds it, and checks that
#   - CMake did not find or use Cyclone DDS,
#   - no symbol of the core library refers to DDS (dds_*, ddsi_*, ddsrt_*),
#   - no built executable links libddsc,
#   - the core's unit tests run and pass (at least 20 of them).
set -uo pipefail
SRC="$1"
B="$2"
shift 2
fail() { echo "FAIL: $*"; exit 1; }

cmake -S "$SRC" -B "$B" -DVISCERA_SIM_ONLY=ON -DVISCERA_BUILD_BENCH=OFF "$@" > "$B.configure.log" 2>&1 ||
  { cat "$B.configure.log"; fail "configure with VISCERA_SIM_ONLY=ON failed"; }
cmake --build "$B" -j"$(nproc)" > "$B.build.log" 2>&1 || { tail -40 "$B.build.log"; fail "the core does not build without DDS"; }

if grep -E '^CycloneDDS_DIR:PATH=/' "$B/CMakeCache.txt"; then fail "CMake found Cyclone DDS in a VISCERA_SIM_ONLY build"; fi
core="$(find "$B" -name libviscera_sim.a | head -1)"
[ -n "$core" ] || fail "no libviscera_sim.a in $B"
dds_syms="$(nm -u "$core" | grep -E ' (dds|ddsi|ddsrt)_' | sort -u)"
[ -z "$dds_syms" ] || fail "the core refers to DDS symbols: $dds_syms"
n_exe=0
while IFS= read -r exe; do
  n_exe=$((n_exe + 1))
  if ldd "$exe" 2>/dev/null | grep -q 'libddsc'; then fail "$exe links libddsc"; fi
done < <(find "$B" -type f -perm -u+x -name 'test_*' -o -type f -perm -u+x -name 'stab_*')
[ "$n_exe" -ge 20 ] || fail "only $n_exe core test executables were built"

(cd "$B" && ctest -L unit --timeout 300 > "$B.ctest.log" 2>&1) || { tail -40 "$B.ctest.log"; fail "core unit tests failed"; }
passed="$(grep -Eo '[0-9]+ tests passed|100% tests passed, 0 tests failed out of [0-9]+' "$B.ctest.log" | grep -Eo '[0-9]+$')"
[ "${passed:-0}" -ge 20 ] || fail "only ${passed:-0} unit tests ran without DDS"
echo "sim_without_dds: core built without Cyclone DDS, $n_exe test executables, none links libddsc, $passed unit tests passed"
