#!/usr/bin/env node
// The other direction of the independent check: @mcap/core's own McapWriter writes a recording
// that SwarmBox's McapReader must read (tests/record/mcap_node_test.cpp). Deterministic: three JSON
// channels (MCAP channel ids from 5, so readers must map ids), 600 messages whose log times go back
// and forth, small chunks (many of them, overlapping in time), lz4 (lz4js frames) or no
// compression. Prints what it wrote as one JSON object: the channels in the order registered and
// every message in write order as [channel index, log time ns, data].
//
//   node tests/js/write_mcap_sample.mjs OUT.mcap lz4|none
import { open } from "node:fs/promises";
import { McapWriter } from "@mcap/core";
import lz4 from "lz4js";

const [path, compression] = process.argv.slice(2);
if (!path || !["lz4", "none"].includes(compression)) {
  process.stderr.write("usage: node write_mcap_sample.mjs OUT.mcap lz4|none\n");
  process.exit(2);
}

const handle = await open(path, "w");
let position = 0n;
const writable = {
  write: async (buffer) => {
    await handle.write(buffer);
    position += BigInt(buffer.byteLength);
  },
  position: () => position,
};
const writer = new McapWriter({
  writable,
  chunkSize: 2048,
  startChannelId: 5,
  compressChunk:
    compression === "lz4" ? (data) => ({ compression: "lz4", compressedData: lz4.compress(data) }) : undefined,
});
await writer.start({ profile: "", library: "@mcap/core sample" });
const encoder = new TextEncoder();
const topics = ["/alpha", "/beta", "/gamma"];
const channels = [];
const ids = [];
for (const [i, topic] of topics.entries()) {
  const schema = { type: "object", properties: { i: { type: "integer" } } };
  const schemaName = `sample.S${i % 2}`;
  const schemaId = await writer.registerSchema({
    name: schemaName,
    encoding: "jsonschema",
    data: encoder.encode(JSON.stringify(schema)),
  });
  ids.push(await writer.registerChannel({ topic, schemaId, messageEncoding: "json", metadata: new Map() }));
  channels.push({ topic, schema_name: schemaName });
}
const messages = [];
for (let i = 0; i < 600; i++) {
  const channel = i % 3;
  const t = BigInt(1_000_000 * (i % 2 === 0 ? i : 600 - i)) / 3_000_000n * 3_000_000n;  // ties, reversals
  const data = JSON.stringify({ i, topic: topics[channel] });
  await writer.addMessage({ channelId: ids[channel], sequence: i, logTime: t, publishTime: t, data: encoder.encode(data) });
  messages.push([channel, t, data]);
}
await writer.end();
await handle.close();

const text = JSON.stringify({ channels, messages }, (_k, v) => (typeof v === "bigint" ? `__bigint__${v}` : v));
process.stdout.write(text.replace(/"__bigint__(\d+)"/g, "$1") + "\n");
