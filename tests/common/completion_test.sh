#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# bash completion (deploy/completion/viscera.bash, installed once per binary):
# for every binary this build has, "BIN --<TAB>" offers --help, --version and
# every --option of its --help; "viscera-control pa<TAB>" offers pause;
# "viscera-asset <TAB>" its sub-commands; "viscera-server --scene
# assets/scenes/def<TAB>" completes the file name.
# usage: completion_test.sh SRC BINARY...
set -uo pipefail
SRC="$1"; shift
fail() { echo "FAIL: $*"; exit 1; }
# shellcheck source=../../deploy/completion/viscera.bash
. "$SRC/deploy/completion/viscera.bash"
complete_words() { # complete_words WORD... : COMPREPLY for the last word
  COMP_WORDS=("$@")
  COMP_CWORD=$(($# - 1))
  COMPREPLY=()
  _viscera
  printf '%s\n' "${COMPREPLY[@]}"
}
for bin in "$@"; do
  name=$(basename "$bin")
  complete -p "$name" > /dev/null 2>&1 || fail "$name: no completion registered"
  got=$(complete_words "$bin" --)
  for want in --help --version; do
    grep -qx -- "$want" <<< "$got" || fail "$name --<TAB> does not offer $want"
  done
  for opt in $("$bin" --help | grep -oE -- '(^|[ ,[])--[a-z][a-z0-9-]*' | grep -oE -- '--[a-z][a-z0-9-]*' | sort -u); do
    grep -qx -- "$opt" <<< "$got" || fail "$name --<TAB> does not offer $opt (in its --help)"
  done
  echo "ok: $name: $(wc -l <<< "$got") options"
done
for bin in "$@"; do
  case "$(basename "$bin")" in
    viscera-control) grep -qx pause <<< "$(complete_words "$bin" pa)" || fail "viscera-control pa<TAB> does not offer pause" ;;
    viscera-asset) [ "$(complete_words "$bin" "" | sort | tr '\n' ' ')" = "convert info tet " ] ||
      fail "viscera-asset <TAB> does not offer its sub-commands" ;;
    viscera-server)
      (cd "$SRC" && grep -qx assets/scenes/default.yaml <<< "$(complete_words "$bin" --scene assets/scenes/def)") ||
        fail "viscera-server --scene assets/scenes/def<TAB> does not complete the file" ;;
  esac
done
echo PASS
