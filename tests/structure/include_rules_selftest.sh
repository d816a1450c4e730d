#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# include_rules_selftest.sh RULES_SCRIPT: the checker must find each kind of
# violation it promises in a small tree made here, and pass that tree once
# the violations are gone. Without this a checker that always says "no
# violation" would pass the structure label.
set -uo pipefail
RULES="$1"
T="$(mktemp -d)"
trap 'rm -rf "$T"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

mkdir -p "$T"/{common/dds,server/physics,server/cutting,server/runtime,server/session,client/viewer,client/dashboard,assets}
touch "$T"/common/verr.h "$T"/common/dds/vdds.h "$T"/server/physics/model.h "$T"/server/cutting/cut.h \
  "$T"/server/runtime/rt.h "$T"/server/session/server.h "$T"/client/viewer/scene_view.h
good() {
  rm -f "$T"/server/runtime/x.c "$T"/common/x.c
  printf '#include "verr.h"\n' > "$T"/server/physics/model.c
  printf '#include "physics/model.h"\n#include "verr.h"\n' > "$T"/server/cutting/cut.c
  printf '#include "runtime/rt.h"\n#include "viscera.h"\n#include <dds/dds.h>\n#include "dds/vdds.h"\n' > "$T"/server/session/server.c
  printf '#include "scene_view.h"\n#include "dds/vdds.h"\n' > "$T"/client/viewer/main.c
  printf '#include "verr.h"\n' > "$T"/client/dashboard/main.c
  printf 'add_executable(viscera-dashboard main.c)\n' > "$T"/client/dashboard/CMakeLists.txt
}
good
out="$(bash "$RULES" "$T")" || fail "a clean tree was refused: $out"

expect() { # $1 = file to break, $2 = content, $3 = text the report must hold
  good
  printf '%b' "$2" > "$T/$1"
  out="$(bash "$RULES" "$T")"
  rc=$?
  [ "$rc" = 1 ] || fail "$1 with '$2': exit $rc, expected 1 ($out)"
  echo "$out" | grep -qF "$3" || fail "$1 with '$2': report lacks '$3': $out"
  echo "ok: $3"
}
expect server/physics/model.c '#include "model.h"\n' 'name its folder'
expect server/physics/model.c '#include "cutting/cut.h"\n' 'a lower core layer includes a higher one'
expect server/physics/model.c '#include "viscera.h"\n' 'generated DDS types'
expect server/physics/model.c '#include <dds/dds.h>\n' 'DDS system header'
expect server/physics/model.c '#include "dds/vdds.h"\n' 'DDS library header'
expect server/runtime/x.c '#include "session/server.h"\n' 'the simulation core includes server/session/server.h'
expect client/dashboard/main.c '#include "../viewer/scene_view.h"\n' "another program's client/viewer/scene_view.h"
expect common/x.c '#include "../server/physics/model.h"\n' 'common/ includes server/physics/model.h'
expect common/x.c '#include "dds/vdds.h"\n' 'a DDS-free common library includes the DDS library header'
expect client/dashboard/CMakeLists.txt 'add_executable(d ${PROJECT_SOURCE_DIR}/client/viewer/a.c)\n' 'names a path outside its folder'
expect client/dashboard/main.c '#include "nowhere.h"\n' 'resolves under none'
echo "include_rules_selftest: every kind of violation found"
