#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# viscera-recinfo --export mcap against an independent reader (issue 16
# items 4 and 6): records the demo session (deploy/session.sh: default
# scene, palpate_kidney trajectory), exports it to MCAP and reads the file
# with the MCAP packages published on the npm registry (@mcap/core, the
# format's reference TypeScript reader, plus Foxglove's OMG IDL parser and
# CDR deserializer), installed at test time into the build directory:
# stream and indexed reading with CRC checks, every message decoded with
# its channel's IDL schema, the messages per topic equal to recinfo's
# sample counts, and the decoded force equal to the server's PALPATION line;
# with --foxglove-scene, the organ surface as scene updates (JSON) whose
# triangles index points that exist. Skips (77) when node or npm is missing or the packages
# cannot be installed (no registry).
# usage: recinfo_mcap_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"; OUT="$3"
RECINFO="$BUILD/client/recorder/viscera-recinfo"
fail() { echo "FAIL: $*" >&2; for f in "$OUT"/demo/*.log "$OUT"/*.err; do [ -f "$f" ] && { echo "--- $f"; tail -5 "$f"; }; done >&2; exit 1; }
command -v node >/dev/null && command -v npm >/dev/null || { echo "SKIP: node or npm not installed"; exit 77; }
NPM="$BUILD/tests/npm-mcap"
if [ ! -d "$NPM/node_modules/@mcap/core" ] || [ ! -d "$NPM/node_modules/@foxglove/omgidl-serialization" ]; then
  mkdir -p "$NPM"; echo '{"private":true}' > "$NPM/package.json"
  # Without a reachable registry npm retries for minutes: ask it once, briefly.
  (cd "$NPM" && timeout 30 npm ping) > "$NPM/install.log" 2>&1 \
    || { echo "SKIP: the npm registry does not answer:"; tail -3 "$NPM/install.log"; exit 77; }
  (cd "$NPM" && timeout 120 npm install --no-audit --no-fund --silent @mcap/core@2 @foxglove/omgidl-parser@1 \
    @foxglove/omgidl-serialization@1) > "$NPM/install.log" 2>&1 \
    || { echo "SKIP: npm could not install @mcap/core (no registry?):"; tail -3 "$NPM/install.log"; exit 77; }
fi
rm -rf "$OUT"; mkdir -p "$OUT"
VIEWER_ARGS="--interval-ms 1000" bash "$SRC/deploy/session.sh" "$BUILD" "$OUT/demo" > "$OUT/session.out" 2>&1 \
  || { cat "$OUT/session.out"; fail "demo session did not run"; }
REC="$OUT/demo/session.db"
"$RECINFO" "$REC" --export mcap --foxglove-scene "$OUT/demo.mcap" 2> "$OUT/export.err" \
  || { cat "$OUT/export.err"; fail "export failed"; }
cat "$OUT/export.err"
# The recording holds XCDR2 (@appendable types); the export re-encodes every
# message as XCDR1, which Foxglove's reader decodes (docs/dds.md "Schema evolution").
grep -q ' XCDR2 messages re-encoded as XCDR1, 0 exported as recorded$' "$OUT/export.err" \
  || fail "not every recorded XCDR2 message was re-encoded as XCDR1"
# recinfo's own table: topic and data samples (notes under a topic are indented)
"$RECINFO" "$REC" | awk '/^topic /{ t = 1; next } /^total:/{ t = 0 } t && NF > 3 && $0 !~ /^ / { print $1, $3 }' > "$OUT/counts.txt"
[ "$(wc -l < "$OUT/counts.txt")" -ge 8 ] || fail "recinfo listed too few topics: $(cat "$OUT/counts.txt")"
NODE_PATH="$NPM/node_modules" node "$SRC/tests/integration/mcap_read.js" "$OUT/demo.mcap" "$OUT/counts.txt" \
  > "$OUT/read.out" || { cat "$OUT/read.out"; fail "the MCAP reader rejected the export (above)"; }
cat "$OUT/read.out"
# The decoded values are the session's: the probe's peak force and time in
# contact (each sample counting the simulated time since the previous one)
# against the server's PALPATION line.
srv() { grep '^PALPATION tool=probe ' "$OUT/demo/server.out" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
got() { tr ' ' '\n' < "$OUT/read.out" | sed -n "s/^$1=//p"; }
# ToolMetrics carries the server's running peak (reliable, printed to 4
# decimals like the PALPATION line); the peak of the ContactFeedback samples
# may miss the top when a loaded recorder lost samples near it (seen: 0.7395
# against 0.7736 N at load 12), never exceed it.
awk -v g="$(got tool0_metrics_peak)" -v w="$(srv peak_force)" 'BEGIN { d = g - w; exit !(g != "" && d < 0.0002 && d > -0.0002) }' \
  || fail "decoded ToolMetrics peak force $(got tool0_metrics_peak), server $(srv peak_force)"
awk -v g="$(got tool0_peak_force)" -v w="$(srv peak_force)" 'BEGIN { exit !(g != "" && g <= w + 0.02 && g >= 0.9 * w) }' \
  || fail "decoded ContactFeedback peak force $(got tool0_peak_force), server $(srv peak_force)"
awk -v g="$(got tool0_contact_time)" -v w="$(srv contact_time)" \
  'BEGIN { d = g - w; t = 0.03 * w; if (t < 0.05) t = 0.05; exit !(g != "" && d <= t && -d <= t) }' \
  || fail "decoded contact time $(got tool0_contact_time), server $(srv contact_time)"
grep -q '^scene_updates=[1-9]' "$OUT/read.out" || fail "no Foxglove scene update in the export"
echo "ok: decoded peak $(got tool0_peak_force) N, contact $(got tool0_contact_time) s = the server's PALPATION line"
# The recordings every build must read (tests/data: formats 1 and 2 final
# types in XCDR1, format 3 @appendable in XCDR2) export and decode as well.
for db in "$SRC"/tests/data/*.db; do
  n=$(basename "$db" .db)
  "$RECINFO" "$db" --export mcap "$OUT/$n.mcap" 2> "$OUT/$n.err" || { cat "$OUT/$n.err"; fail "$n: export failed"; }
  "$RECINFO" "$db" | awk '/^topic /{ t = 1; next } /^total:/{ t = 0 } t && NF > 3 && $0 !~ /^ / { print $1, $3 }' \
    > "$OUT/$n.counts"
  NODE_PATH="$NPM/node_modules" node "$SRC/tests/integration/mcap_read.js" "$OUT/$n.mcap" "$OUT/$n.counts" \
    > "$OUT/$n.read" || { cat "$OUT/$n.read"; fail "$n: the MCAP reader rejected the export"; }
  echo "ok: tests/data/$n.db: $(tail -1 "$OUT/$n.read")"
done
# A damaged export is caught: the reader must fail on a flipped byte in a chunk.
cp "$OUT/demo.mcap" "$OUT/bad.mcap"
# (the middle of the file lies inside a chunk: its CRC must catch the change)
half=$(( $(stat -c %s "$OUT/bad.mcap") / 2 ))
byte=$(od -An -tu1 -j "$half" -N1 "$OUT/bad.mcap" | tr -d ' ')
printf "\\$(printf '%03o' $(( 255 - byte )))" | dd of="$OUT/bad.mcap" bs=1 seek="$half" conv=notrunc status=none
if NODE_PATH="$NPM/node_modules" node "$SRC/tests/integration/mcap_read.js" "$OUT/bad.mcap" "$OUT/counts.txt" \
  > "$OUT/bad.out" 2>&1; then fail "the reader accepted a damaged file: the check cannot fail"; fi
echo "ok: a damaged copy is rejected ($(tail -1 "$OUT/bad.out" | cut -c1-100))"
echo "PASS"
