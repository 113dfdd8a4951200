// LiveServer: a trial's channels over the Foxglove WebSocket protocol (subprotocol
// foxglove.websocket.v1, libwebsockets), and the built-in page at GET /. Foxglove connects to it;
// so does the page. A client that subscribes late first gets the channel's history (bounded in
// bytes), then the live stream. Write() never blocks on a slow client.
//
//   auto server = LiveServer::Start({.address = "0.0.0.0", .port = 8765});
//   if (!server) return server.error();
//   ChannelId tf = *(*server)->AddChannel({"/tf", "foxglove.FrameTransforms", schema});
//   (*server)->Write(tf, sim_time_ns, R"({"timestamp":{"sec":1,"nsec":0},"transforms":[]})");
//
// Protocol (https://github.com/foxglove/ws-protocol, docs/spec.md): on connect the server sends
// serverInfo (no optional capabilities) and advertise (every channel: encoding "json",
// schemaEncoding "jsonschema"); channels added later are advertised to everyone connected. The
// client's subscribe/unsubscribe are honoured; every message goes out as binary messageData
// (opcode 0x01, subscription id u32 LE, log time u64 LE [ns], the JSON). Other client ops get a
// status warning. The channel id a client sees is the ChannelId AddChannel returned (from 1).
//
// History: every message of every channel is kept (of an image channel only the newest frame,
// unless history_images) until the history holds history_bytes; then the oldest go first, but the
// latest message of each channel is always kept (so /world, written once at t=0, reaches a client
// that comes an hour later, and a late client has the current camera frames).
// A subscription first gets the history of its channels in log-time order, then the live stream.
//
// Threads: one service thread owns the sockets. AddChannel() and Write() are thread-safe and never
// wait for a client: each client has a queue of live messages bounded by client_queue_bytes; a
// message that does not fit is dropped for that client and counted (dropped_messages(); the
// client gets a status warning).
//
// Errors: Start() fails (kUnavailable, where = address:port) when the port cannot be bound.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "swarmbox/record/sink.hpp"

namespace swarmbox::record {

struct LiveOptions {
  std::string address = "127.0.0.1";
  int port = 8765;
  std::string name = "swarmbox";
  std::string mode = "live";  // serverInfo metadata "mode": "live" (a trial running) or "replay"
                              // (swarmbox view): the page follows the head or starts at t=0
  std::size_t history_bytes = 256u << 20;  // per server; images: the newest frame only
  bool history_images = false;             // keep foxglove.CompressedImage/RawImage too (replays)
  std::size_t client_queue_bytes = 32u << 20;  // live messages waiting for one client
};

class LiveServer final : public Sink {
 public:
  static Result<std::unique_ptr<LiveServer>> Start(const LiveOptions& options);
  ~LiveServer() override;  // stops the server thread, closes the connections

  Result<ChannelId> AddChannel(const ChannelSpec& spec) override;
  Status Write(ChannelId channel, std::uint64_t log_time_ns, std::string_view json) override;
  std::string url() const;  // http://address:port/ (the port bound, when options.port was 0)
  int port() const;         // the port bound
  // Messages dropped for slow clients (one per client it was not queued for), since Start().
  std::uint64_t dropped_messages() const;

 private:
  struct Impl;
  explicit LiveServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmbox::record
