// A Foxglove WebSocket client (the @foxglove/ws-protocol package Foxglove itself uses, on `ws`)
// that subscribes to a LiveServer's channels and prints what it received, for the C++ tests
// (tests/record/live_server_test.cpp) to check.
//
//   node ws_client.mjs ws://127.0.0.1:8765 [--want TOPIC=N ...] [--timeout-ms MS] [--ready FILE]
//
// Subscribes to every advertised channel (also those advertised later) and writes FILE (--ready)
// once it has subscribed to every TOPIC of --want. Ends when each TOPIC has received at least N
// messages, then prints one JSON object on stdout:
//   {"serverInfo": {...}, "channels": [{id, topic, encoding, schemaName, schemaEncoding}],
//    "statuses": [...], "received": {"TOPIC": [{"log_time_ns": "123", "data": {...}}, ...]}}
// Exit 0 when every --want was met, 1 on a timeout (the JSON then says what did arrive), 2 on
// bad usage or a connection error.
import fs from "node:fs";
import wsProtocol from "@foxglove/ws-protocol"; // CommonJS: no named exports in ESM
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

const args = process.argv.slice(2);
const url = args.shift();
const want = new Map();
let timeoutMs = 20000;
let readyFile = "";
while (args.length > 0) {
  const a = args.shift();
  if (a === "--want") {
    const [topic, n] = args.shift().split("=");
    want.set(topic, Number(n));
  } else if (a === "--timeout-ms") {
    timeoutMs = Number(args.shift());
  } else if (a === "--ready") {
    readyFile = args.shift();
  } else {
    console.error(`ws_client: unknown argument ${a}`);
    process.exit(2);
  }
}
if (!url) {
  console.error("usage: node ws_client.mjs ws://HOST:PORT [--want TOPIC=N ...] [--timeout-ms MS] [--ready FILE]");
  process.exit(2);
}

const result = { serverInfo: null, channels: [], statuses: [], received: {} };
const topicBySubscription = new Map();
const subscribedTopics = new Set();
const decoder = new TextDecoder();

const client = new FoxgloveClient({
  ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});

function done() {
  for (const [topic, n] of want) {
    if ((result.received[topic] ?? []).length < n) return false;
  }
  return true;
}

function finish(code) {
  process.stdout.write(JSON.stringify(result) + "\n");
  client.close();
  process.exit(code);
}

const timer = setTimeout(() => {
  console.error("ws_client: timeout; received " +
    JSON.stringify(Object.fromEntries(Object.entries(result.received).map(([t, m]) => [t, m.length]))));
  finish(1);
}, timeoutMs);

client.on("error", (error) => {
  console.error(`ws_client: ${error?.message ?? error}`);
  clearTimeout(timer);
  process.stdout.write(JSON.stringify(result) + "\n");
  process.exit(2);
});
client.on("serverInfo", (info) => {
  result.serverInfo = info;
});
client.on("status", (status) => {
  result.statuses.push(status);
});
client.on("advertise", (channels) => {
  for (const ch of channels) {
    result.channels.push({
      id: ch.id, topic: ch.topic, encoding: ch.encoding, schemaName: ch.schemaName,
      schemaEncoding: ch.schemaEncoding,
    });
    const subscription = client.subscribe(ch.id);
    topicBySubscription.set(subscription, ch.topic);
    subscribedTopics.add(ch.topic);
  }
  if (readyFile && [...want.keys()].every((t) => subscribedTopics.has(t))) {
    // The subscribe requests are sent by now (the client writes them synchronously).
    fs.writeFileSync(readyFile, "subscribed\n");
    readyFile = "";
  }
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const topic = topicBySubscription.get(subscriptionId);
  const text = decoder.decode(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  (result.received[topic] ??= []).push({ log_time_ns: timestamp.toString(), data: JSON.parse(text) });
  if (want.size > 0 && done()) {
    clearTimeout(timer);
    finish(0);
  }
});
