#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# include_rules.sh ROOT: checks the include and build rules of
# docs/architecture.md over the source tree at ROOT and prints one line per
# violation ("file:line: what is wrong"). Exit 0 when there is none, 1 when
# there is at least one, 2 on a usage error.
#
# Rules (docs/architecture.md, "What may include what"):
#   1. Every quoted include resolves against the include roots of the
#      including file's library (common/ for everyone, server/ inside server/,
#      the program's own folder inside client/PROGRAM/), naming its folder:
#      "physics/model.h", never a bare "model.h" found only next to the file.
#   2. Layers: common/ includes nothing from server/ or client/; client/P
#      includes nothing from server/ or another program's folder; server/
#      includes nothing from client/.
#   3. The simulation core (server/physics, collision, haptics, cutting,
#      interaction, runtime) includes no DDS header, no generated IDL type, and
#      nothing from server/session or server/resim; inside the core a lower
#      layer never includes a higher one (physics, collision < haptics <
#      cutting < interaction < runtime).
#   4. Neutral common/ libraries stay DDS-free unless they are DDS libraries
#      (common/dds, common/recording, common/view, common/window).
#   5. No CMakeLists.txt or .cmake file under server/, client/, common/ or
#      assets/ names a path outside its own folder (no program compiles
#      another program's sources, no include root reaches sideways).
set -uo pipefail
ROOT="${1:-}"
if [ -z "$ROOT" ] || [ ! -d "$ROOT/server" ]; then
  echo "usage: include_rules.sh SOURCE_ROOT (the folder with server/, client/, common/)" >&2
  exit 2
fi
cd "$ROOT" || exit 2

bad=0
say() { echo "$1"; bad=$((bad + 1)); }

core_rank() { # rank of a simulation-core folder, 0 when not in the core
  case "$1" in
    server/physics/* | server/collision/*) echo 1 ;;
    server/haptics/*) echo 2 ;;
    server/cutting/*) echo 3 ;;
    server/interaction/*) echo 4 ;;
    server/runtime/*) echo 5 ;;
    *) echo 0 ;;
  esac
}

dds_common() { # common libraries that may use DDS
  case "$1" in
    common/dds/* | common/recording/* | common/view/* | common/window/*) return 0 ;;
  esac
  return 1
}

while IFS= read -r file; do
  dir="$(dirname "$file")"
  case "$file" in
    server/*) roots=(server common) ;;
    client/*)
      prog="$(echo "$file" | cut -d/ -f1-2)"
      roots=("$prog" common)
      ;;
    *) roots=(common) ;;
  esac
  rank="$(core_rank "$file")"
  while IFS= read -r hit; do
    line="${hit%%:*}"
    inc="$(echo "$hit" | sed -E 's/^[0-9]+:[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]+)".*/\1/')"
    where="$file:$line"
    # Generated IDL types.
    # (viscera.h, and viscera_format1.h: every idl/NAME.idl generates NAME.h)
    if [ "$inc" = "viscera.h" ] || { [ "${inc%.h}" != "$inc" ] && [ -f "idl/${inc%.h}.idl" ]; }; then
      if [ "$rank" != 0 ]; then say "$where: the simulation core includes the generated DDS types \"$inc\""; fi
      if case "$file" in common/*) ! dds_common "$file" ;; *) false ;; esac then
        say "$where: a DDS-free common library includes \"$inc\""
      fi
      continue
    fi
    target=""
    for r in "${roots[@]}"; do
      if [ -f "$r/$inc" ]; then target="$r/$inc"; break; fi
    done
    if [ -z "$target" ]; then
      if [ -f "$dir/$inc" ]; then
        say "$where: \"$inc\" is found only next to the file: name its folder (\"${dir#*/}/$inc\" from its library's root)"
      else
        say "$where: \"$inc\" resolves under none of this library's include roots (${roots[*]})"
      fi
      continue
    fi
    target="$(realpath -m --relative-to=. "$target")"
    case "$file" in
      common/*)
        case "$target" in server/* | client/*) say "$where: common/ includes $target" ;; esac
        if ! dds_common "$file" && dds_common "$target"; then
          say "$where: a DDS-free common library includes the DDS library header $target"
        fi
        ;;
      client/*)
        case "$target" in
          server/*) say "$where: a client includes the server's $target" ;;
          client/*) case "$target" in "$prog"/*) ;; *) say "$where: $prog includes another program's $target" ;; esac ;;
        esac
        ;;
      server/*)
        case "$target" in client/*) say "$where: the server includes the client's $target" ;; esac
        ;;
    esac
    if [ "$rank" != 0 ]; then
      case "$target" in
        server/session/* | server/resim/*) say "$where: the simulation core includes $target" ;;
      esac
      if dds_common "$target"; then say "$where: the simulation core includes the DDS library header $target"; fi
      trank="$(core_rank "$target")"
      if [ "$trank" -gt "$rank" ]; then say "$where: a lower core layer includes a higher one ($target)"; fi
    fi
  done < <(grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file")
  # System DDS headers.
  while IFS= read -r hit; do
    line="${hit%%:*}"
    if [ "$rank" != 0 ]; then say "$file:$line: the simulation core includes a DDS system header"; fi
    if case "$file" in common/*) ! dds_common "$file" ;; *) false ;; esac then
      say "$file:$line: a DDS-free common library includes a DDS system header"
    fi
  done < <(grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*<dds/' "$file")
done < <(find server client common assets -type f \( -name '*.c' -o -name '*.h' -o -name '*.cpp' \) | sort)

# Rule 5: build files name nothing outside their own folder.
while IFS= read -r cm; do
  while IFS= read -r hit; do
    say "$cm:${hit%%:*}: names a path outside its folder: ${hit#*:}"
  done < <(grep -nE '\$\{(PROJECT|CMAKE)_SOURCE_DIR\}/|\.\./' "$cm" | grep -v '^[0-9]*:[[:space:]]*#')
done < <(find server client common assets -type f \( -name CMakeLists.txt -o -name '*.cmake' \) | sort)

if [ "$bad" -gt 0 ]; then
  echo "include_rules: $bad violation(s)"
  exit 1
fi
echo "include_rules: $(find server client common assets -type f \( -name '*.c' -o -name '*.h' -o -name '*.cpp' \) | wc -l) files, no violation"
exit 0
