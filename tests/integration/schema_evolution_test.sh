#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# @appendable schema evolution over real Cyclone DDS (issue 16 item 5): a
# writer of version 1 of a type and a reader of version 2 (one member
# appended to the topic struct and to the struct its sequence holds), and
# the other way round, in two processes on loopback. The newer reader gets
# the appended members at their default (0) in an older sample; the older
# reader drops what a newer writer appended and still reads every member it
# knows, including those after the sequence of grown structs. The same
# version on both sides carries the appended values (so a reader that
# zeroed them regardless would fail here).
# usage: schema_evolution_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; OUT="$3"
D="${VISCERA_DOMAIN:-185}"
P="$BUILD/tests/integration/evo_peer_v"
rm -rf "$OUT"; mkdir -p "$OUT"
fail() { echo "FAIL: $*" >&2; exit 1; }
COMMON="sensor=3 seq=77 items=2 samples=3 item0.id=11 item0.v=1.5,-2.5 item1.id=12 item1.v=3.5,4.5 sample0=0.25 sample1=0.5 sample2=0.75"
pair() { # writer-version reader-version: the reader's line
  local w=$1 r=$2 log="$OUT/w$1_r$2"
  "${P}$r" read "$D" > "$log.read" 2> "$log.read.err" &
  local rpid=$!
  for _ in $(seq 100); do grep -q ready "$log.read" 2>/dev/null && break; sleep 0.1; done
  timeout 30 "${P}$w" write "$D" > "$log.write" 2>&1 || { cat "$log.write" >&2; kill "$rpid" 2>/dev/null; fail "writer v$w to reader v$r: $(cat "$log.write")"; }
  wait "$rpid" || fail "reader v$r got nothing from writer v$w: $(cat "$log.read.err")"
  grep '^reader=' "$log.read"
}
has() { # line word...
  local line=" $1 "; shift
  for w in "$@"; do [[ "$line" == *" $w "* ]] || fail "expected '$w' in: $line"; done
}
l=$(pair 1 2); echo "v1 -> v2: $l"
has "$l" $COMMON note=v1 item0.tag=0 item1.tag=0 grown=0
l=$(pair 2 1); echo "v2 -> v1: $l"
has "$l" $COMMON note=v2
[[ "$l" != *grown* && "$l" != *tag* ]] || fail "the v1 reader printed a v2 member: $l"
l=$(pair 2 2); echo "v2 -> v2: $l"
has "$l" $COMMON note=v2 item0.tag=7 item1.tag=8 grown=42.5
l=$(pair 1 1); echo "v1 -> v1: $l"
has "$l" $COMMON note=v1
echo "PASS"
