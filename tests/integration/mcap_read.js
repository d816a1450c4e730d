/* SPDX-License-Identifier: Apache-2.0 */
// Independent check of viscera-recinfo --export mcap: reads the file with
// the MCAP reference reader published on the npm registry (@mcap/core),
// once as a stream and once through its summary and chunk index, with CRC
// validation; decodes every message with its channel's schema (the OMG
// IDL text, @foxglove/omgidl-parser + @foxglove/omgidl-serialization);
// and compares the messages per DDS topic with the counts given.
// usage: node mcap_read.js FILE.mcap COUNTS   (COUNTS: lines "topic count")
"use strict";
const fs = require("fs");
const { McapStreamReader, McapIndexedReader } = require("@mcap/core");
const { parseIDL } = require("@foxglove/omgidl-parser");
const { MessageReader } = require("@foxglove/omgidl-serialization");

function fail(msg) {
  console.error("FAIL: " + msg);
  process.exit(1);
}

async function main() {
  const [file, countsFile] = process.argv.slice(2);
  const bytes = fs.readFileSync(file);
  const want = new Map();
  for (const line of fs.readFileSync(countsFile, "utf8").split("\n")) {
    const [t, n] = line.trim().split(/\s+/);
    if (t) want.set(t, Number(n));
  }

  // 1. Stream: every record in order, CRCs (chunks, data section) checked.
  const stream = new McapStreamReader({ validateCrcs: true });
  stream.append(bytes);
  const schemas = new Map(), channels = new Map(), streamCount = new Map();
  let rec, sawFooter = false, sawDataEnd = false, stats;
  while ((rec = stream.nextRecord())) {
    if (rec.type === "Schema") schemas.set(rec.id, rec);
    else if (rec.type === "Channel") channels.set(rec.id, rec);
    else if (rec.type === "Message") streamCount.set(rec.channelId, (streamCount.get(rec.channelId) || 0) + 1);
    else if (rec.type === "DataEnd") sawDataEnd = true;
    else if (rec.type === "Footer") sawFooter = true;
    else if (rec.type === "Statistics") stats = rec;
  }
  if (!stream.done()) fail("stream reader did not reach the end of the file");
  if (!sawDataEnd || !sawFooter) fail("no DataEnd or Footer record");

  // 2. Indexed: summary, chunk indexes, message indexes.
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable });
  if (indexed.chunkIndexes.length === 0) fail("no chunk index in the summary");
  const readers = new Map();
  for (const [id, s] of indexed.schemasById) {
    if (s.name === "foxglove.SceneUpdate" && s.encoding === "jsonschema") continue; // --foxglove-scene
    if (s.encoding !== "omgidl") fail(`schema ${s.name}: encoding ${s.encoding}`);
    const text = new TextDecoder().decode(s.data);
    try {
      readers.set(id, new MessageReader(s.name, parseIDL(text)));
    } catch (e) {
      fail(`schema ${s.name} does not parse as OMG IDL: ${e.message}\n${text}`);
    }
  }
  const perTopic = new Map(), indexedCount = new Map();
  let decoded = 0, total = 0, peak = 0, metricsPeak = -1, inContact = 0, sceneUpdates = 0, lastT;
  for await (const m of indexed.readMessages({ validateCrcs: true })) {
    const ch = indexed.channelsById.get(m.channelId);
    if (ch.topic === "/viscera/scene") { // Foxglove scene primitives: one organ surface per message
      const u = JSON.parse(new TextDecoder().decode(m.data));
      const t = u.entities[0].triangles[0];
      if (!t.points.length || t.indices.length % 3 || t.indices.some((i) => i >= t.points.length))
        fail(`scene update ${m.sequence}: ${t.points.length} points, ${t.indices.length} indices out of range`);
      sceneUpdates++;
      total++;
      indexedCount.set(m.channelId, (indexedCount.get(m.channelId) || 0) + 1);
      continue;
    }
    if (ch.messageEncoding !== "cdr") fail(`channel ${ch.topic}: encoding ${ch.messageEncoding}`);
    if (m.logTime !== m.publishTime) fail(`channel ${ch.topic}: log time differs from publish time`);
    const reader = readers.get(ch.schemaId);
    if (!reader) fail(`channel ${ch.topic} has no schema`);
    let msg;
    try {
      msg = reader.readMessage(m.data);
    } catch (e) {
      fail(`${ch.topic} message ${m.sequence} does not decode: ${e.message}`);
    }
    if (typeof msg !== "object" || msg === null) fail(`${ch.topic}: decoded to nothing`);
    // the server's own running peak (ToolMetrics is reliable: a loaded
    // recorder may lose ContactFeedback samples near the peak, not these)
    if (ch.metadata.get("dds_topic") === "viscera_ToolMetrics" && msg.tool_id === 0 && msg.peak_force > metricsPeak)
      metricsPeak = msg.peak_force;
    if (ch.metadata.get("dds_topic") === "viscera_ContactFeedback" && msg.tool_id === 0) {
      const f = Math.hypot(msg.force[0], msg.force[1], msg.force[2]);
      if (f > peak) peak = f;
      // each sample stands for the simulated time since the previous one
      // (as the report counts), so samples a loaded recorder lost do not count
      const t = Number(msg.sim_time_ns) * 1e-9;
      // (two samples of one simulated instant, an early answer and the
      // previous step's, take no time)
      const dt = lastT !== undefined && t === lastT ? 0 : lastT !== undefined && t > lastT && t - lastT <= 0.5 ? t - lastT : 0.001;
      if (msg.in_contact) inContact += dt;
      lastT = t;
    }
    decoded++;
    total++;
    indexedCount.set(m.channelId, (indexedCount.get(m.channelId) || 0) + 1);
    const topic = ch.metadata.get("dds_topic");
    perTopic.set(topic, (perTopic.get(topic) || 0) + 1);
  }
  for (const [id] of indexed.channelsById)
    if ((indexedCount.get(id) || 0) !== (streamCount.get(id) || 0))
      fail(`channel ${id}: indexed reader ${indexedCount.get(id) || 0} messages, stream reader ${streamCount.get(id) || 0}`);
  if (indexed.statistics && Number(indexed.statistics.messageCount) !== total)
    fail(`Statistics say ${indexed.statistics.messageCount} messages, the file holds ${total}`);
  if (!stats) fail("no Statistics record");

  let bad = 0;
  for (const [t, n] of want) {
    const got = perTopic.get(t) || 0;
    console.log(`${t.padEnd(28)} recinfo ${String(n).padStart(7)}  mcap ${String(got).padStart(7)}`);
    if (got !== n) bad++;
  }
  for (const [t] of perTopic) if (!want.has(t)) fail(`topic ${t} in the MCAP file but not in the recording`);
  const hasScene = [...indexed.channelsById.values()].some((c) => c.topic === "/viscera/scene");
  if (hasScene && !sceneUpdates) fail("a /viscera/scene channel without scene updates");
  if (hasScene) console.log(`scene_updates=${sceneUpdates}`);
  if (bad) fail(`${bad} topic(s) differ`);
  // decoded values, for the caller to compare with the server's figures
  console.log(`tool0_peak_force=${peak.toFixed(4)} tool0_metrics_peak=${metricsPeak.toFixed(4)} tool0_contact_time=${inContact.toFixed(3)}`);
  console.log(`ok: ${total} messages in ${indexed.channelsById.size} channels, ${indexed.chunkIndexes.length} chunks, ` +
              `all ${decoded} DDS samples decoded with their OMG IDL schema`);
}
main().catch((e) => fail(e.stack || String(e)));
