// LiveServer: a trial's channels over the Foxglove WebSocket protocol (subprotocol
// foxglove.websocket.v1, libwebsockets), and the built-in page at GET /. Foxglove connects to it;
// so does the page. A client that subscribes late first gets the channel's history (bounded in
// bytes), then the live stream. Write() never blocks on a slow client.
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
  std::size_t history_bytes = 256u << 20;  // per server; images are not kept
};

class LiveServer final : public Sink {
 public:
  static Result<std::unique_ptr<LiveServer>> Start(const LiveOptions& options);
  ~LiveServer() override;  // stops the server thread, closes the connections

  Result<ChannelId> AddChannel(const ChannelSpec& spec) override;
  Status Write(ChannelId channel, std::uint64_t log_time_ns, std::string_view json) override;
  std::string url() const;  // http://address:port/

 private:
  struct Impl;
  explicit LiveServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmbox::record
