#!/usr/bin/env node
// An independent reader of SwarmBox recordings: reads an MCAP file with @mcap/core (the Foxglove
// reference implementation in TypeScript), not with SwarmBox's own McapReader, and prints what it
// found as one JSON object:
//
//   node tests/js/verify_mcap.mjs RUN_DIR/recording.mcap
//   {"file":..., "size_bytes":..., "profile":"", "library":"swarmbox 0.1.0", "compression":["zstd"],
//    "chunks":3, "message_count":1234, "start_ns":0, "end_ns":60000000000,
//    "channels":[{"id":0, "topic":"/tf", "schema_name":"foxglove.FrameTransforms",
//                 "schema_encoding":"jsonschema", "message_encoding":"json",
//                 "count":600, "first_ns":0, "last_ns":59900000000}, ...]}
//
// It checks on the way, and exits 1 with the reason on stderr when one fails:
//   - the summary CRC (McapIndexedReader), the data section CRC (recomputed here over every byte
//     before DataEnd), every chunk's CRC (readMessages with validateCrcs);
//   - messages come out of the index in non-decreasing log time, each parses as JSON, each channel's
//     message encoding is json and its schema (jsonschema) parses as JSON;
//   - the Statistics record agrees with what was read (total and per channel);
//   - a second, linear pass with McapStreamReader (record by record from the magic to the footer)
//     finds the same number of messages.
// Times are integers of ns (printed exactly, as JSON numbers). Needs `npm ci` in tests/js.
import { open } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { decompress as zstdDecompress } from "fzstd";
import lz4 from "lz4js";

const decompressHandlers = {
  zstd: (data, size) => {
    const out = zstdDecompress(data, new Uint8Array(Number(size)));
    if (out.byteLength !== Number(size)) throw new Error(`zstd chunk gave ${out.byteLength} of ${size} bytes`);
    return out;
  },
  lz4: (data, size) => {
    const out = lz4.decompress(data, Number(size));
    if (out.byteLength !== Number(size)) throw new Error(`lz4 chunk gave ${out.byteLength} of ${size} bytes`);
    return out;
  },
};

// CRC-32 (ISO-HDLC), written here so the check does not share code with either writer or reader.
const CRC_TABLE = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[n] = c >>> 0;
  }
  return t;
})();
function crc32Update(crc, bytes) {
  let c = ~crc >>> 0;
  for (let i = 0; i < bytes.length; i++) c = CRC_TABLE[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
  return ~c >>> 0;
}

function fail(message) {
  process.stderr.write(`verify_mcap: ${message}\n`);
  process.exit(1);
}

async function main() {
  const path = process.argv[2];
  if (!path || process.argv.length > 3) fail("usage: node verify_mcap.mjs FILE.mcap");
  const handle = await open(path, "r");
  const size = BigInt((await handle.stat()).size);
  const readable = {
    size: async () => size,
    read: async (offset, length) => {
      const buf = new Uint8Array(Number(length));
      const { bytesRead } = await handle.read(buf, 0, buf.length, Number(offset));
      if (bytesRead !== buf.length) throw new Error(`short read at ${offset}`);
      return buf;
    },
  };

  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });

  // Data section CRC: every byte before the DataEnd record.
  if (reader.dataSectionCrc !== undefined && reader.dataSectionCrc !== 0) {
    let crc = 0;
    const block = 1 << 20;
    for (let at = 0n; at < reader.dataEndOffset; at += BigInt(block)) {
      const n = reader.dataEndOffset - at < BigInt(block) ? reader.dataEndOffset - at : BigInt(block);
      crc = crc32Update(crc, await readable.read(at, n));
    }
    if (crc !== reader.dataSectionCrc) fail(`data section CRC ${crc} != DataEnd's ${reader.dataSectionCrc}`);
  }

  const channels = new Map();
  for (const [id, ch] of reader.channelsById) {
    const schema = reader.schemasById.get(ch.schemaId);
    if (ch.messageEncoding !== "json") fail(`channel ${ch.topic}: message encoding "${ch.messageEncoding}", not json`);
    if (schema && schema.encoding === "jsonschema") {
      try {
        JSON.parse(new TextDecoder().decode(schema.data));
      } catch (e) {
        fail(`schema ${schema.name}: not JSON (${e.message})`);
      }
    }
    channels.set(id, {
      id,
      topic: ch.topic,
      schema_name: schema ? schema.name : "",
      schema_encoding: schema ? schema.encoding : "",
      message_encoding: ch.messageEncoding,
      count: 0,
      first_ns: null,
      last_ns: null,
    });
  }

  let count = 0;
  let start = null;
  let end = null;
  let last = -1n;
  const decoder = new TextDecoder("utf-8", { fatal: true });
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const ch = channels.get(m.channelId);
    if (!ch) fail(`message on unknown channel ${m.channelId}`);
    if (m.logTime < last) fail(`log time goes back: ${m.logTime} after ${last} (${ch.topic})`);
    last = m.logTime;
    try {
      JSON.parse(decoder.decode(m.data));
    } catch (e) {
      fail(`${ch.topic} at ${m.logTime}: message is not JSON (${e.message})`);
    }
    ch.count++;
    if (ch.first_ns === null) ch.first_ns = m.logTime;
    ch.last_ns = m.logTime;
    if (start === null) start = m.logTime;
    end = m.logTime;
    count++;
  }

  const stats = reader.statistics;
  if (!stats) fail("no Statistics record in the summary");
  if (stats.messageCount !== BigInt(count)) fail(`Statistics says ${stats.messageCount} messages, read ${count}`);
  for (const [id, n] of stats.channelMessageCounts) {
    const ch = channels.get(id);
    if (!ch) fail(`Statistics counts channel ${id}, which the summary lacks`);
    if (BigInt(ch.count) !== n) fail(`Statistics says ${n} messages on ${ch.topic}, read ${ch.count}`);
  }
  if (count > 0 && (stats.messageStartTime !== start || stats.messageEndTime !== end)) {
    fail(`Statistics time range ${stats.messageStartTime}..${stats.messageEndTime} != read ${start}..${end}`);
  }

  // Linear pass: every record from the magic to the footer, chunks decompressed and CRC-checked.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  let streamed = 0;
  const block = 1 << 20;
  for (let at = 0n; at < size; at += BigInt(block)) {
    stream.append(await readable.read(at, size - at < BigInt(block) ? size - at : BigInt(block)));
    for (let r; (r = stream.nextRecord()); ) if (r.type === "Message") streamed++;
  }
  if (!stream.done()) fail("the linear read did not reach a valid footer and closing magic");
  if (streamed !== count) fail(`the linear read found ${streamed} messages, the indexed read ${count}`);
  await handle.close();

  const out = {
    file: path,
    size_bytes: size,
    profile: reader.header.profile,
    library: reader.header.library,
    compression: [...new Set(reader.chunkIndexes.map((c) => c.compression))].sort(),
    chunks: reader.chunkIndexes.length,
    message_count: count,
    start_ns: start ?? 0n,
    end_ns: end ?? 0n,
    channels: [...channels.values()].sort((a, b) => a.id - b.id),
  };
  // BigInts as exact JSON numbers.
  const text = JSON.stringify(out, (_k, v) => (typeof v === "bigint" ? `__bigint__${v}` : v));
  process.stdout.write(text.replace(/"__bigint__(\d+)"/g, "$1") + "\n");
}

main().catch((e) => fail(e && e.stack ? e.stack : String(e)));
