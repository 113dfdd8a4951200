// LiveServer on libwebsockets: one lws context with one vhost and two protocols, "http" (GET /: the
// page) and "foxglove.websocket.v1". Everything below the mutex is shared between the service
// thread (callbacks) and the writers (AddChannel, Write); lws calls other than
// lws_cancel_service() happen on the service thread only, as lws requires.
#include "swarmbox/record/live_server.hpp"

#include <libwebsockets.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::record {

// The page, generated from record/page/view.html at build time (record/CMakeLists.txt).
extern const unsigned char kViewPage[];
extern const std::size_t kViewPageSize;

namespace {

constexpr char kSubprotocol[] = "foxglove.websocket.v1";
constexpr std::uint8_t kOpMessageData = 0x01;
constexpr std::size_t kFrameHeader = 1 + 4 + 8;  // opcode, subscription id, log time
constexpr int kFramesPerWritable = 64;            // then the other clients get their turn
constexpr std::size_t kHttpChunk = 16u << 10;
constexpr std::size_t kMaxClientText = 1u << 20;  // a client's JSON message beyond this: closed

bool IsImageSchema(const std::string& schema_name) {
  return schema_name == "foxglove.CompressedImage" || schema_name == "foxglove.RawImage";
}

struct Message {
  ChannelId channel = 0;
  std::uint64_t log_time_ns = 0;
  std::uint64_t seq = 0;  // write order, to merge channels' histories
  std::shared_ptr<const std::string> json;
};

struct Frame {
  std::uint32_t subscription = 0;
  ChannelId channel = 0;
  std::uint64_t log_time_ns = 0;
  std::shared_ptr<const std::string> json;
  bool live = false;  // counted against client_queue_bytes (history replays are not)
};

struct Client {
  std::deque<std::string> text;                     // JSON ops to send, before any frame
  std::deque<Frame> frames;
  std::size_t live_bytes = 0;                       // bytes of live frames queued
  std::map<std::uint32_t, ChannelId> subscriptions;  // subscription id -> channel
  std::map<ChannelId, std::uint32_t> by_channel;
  std::uint64_t dropped = 0;
  bool drop_reported = false;  // a status warning is queued or sent for the current drop run
  bool wake_pending = false;   // in Impl::wake
  std::string incoming;        // a fragmented text message being received
  std::vector<unsigned char> buffer;  // LWS_PRE + one frame, reused
};

struct HttpSession {
  std::size_t sent = 0;
  bool page = false;
};

std::string AdvertiseJson(const std::vector<std::pair<ChannelId, const ChannelSpec*>>& channels) {
  std::string s = R"({"op":"advertise","channels":[)";
  bool first = true;
  for (const auto& [id, spec] : channels) {
    if (!first) s += ',';
    first = false;
    s += R"({"id":)" + std::to_string(id) + R"(,"topic":)" + yaml::JsonQuote(spec->topic) +
         R"(,"encoding":"json","schemaName":)" + yaml::JsonQuote(spec->schema_name) +
         R"(,"schema":)" + yaml::JsonQuote(spec->schema) + R"(,"schemaEncoding":"jsonschema"})";
  }
  return s + "]}";
}

std::string StatusJson(int level, const std::string& message) {
  return R"({"op":"status","level":)" + std::to_string(level) + R"(,"message":)" +
         yaml::JsonQuote(message) + "}";
}

void PutLe(unsigned char* p, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}

}  // namespace

struct LiveServer::Impl {
  LiveOptions options;
  lws_context* context = nullptr;
  lws_protocols protocols[3] = {};
  int port = 0;
  std::thread thread;
  std::atomic<bool> stop{false};

  mutable std::mutex mu;
  std::vector<ChannelSpec> channels;  // index = ChannelId - 1
  std::vector<bool> image;
  std::map<ChannelId, std::deque<Message>> history;
  std::size_t history_bytes = 0;
  std::uint64_t next_seq = 0;
  std::unordered_map<lws*, Client> clients;
  std::vector<lws*> wake;  // clients with something new to send (service thread asks lws)
  std::uint64_t dropped = 0;

  void Run() {
    while (!stop.load()) lws_service(context, 0);
  }

  // Keeps the history within its bound: the oldest message of any channel that has more than one.
  void TrimHistory() {
    while (history_bytes > options.history_bytes) {
      std::deque<Message>* oldest = nullptr;
      for (auto& [id, q] : history) {
        if (q.size() > 1 && (oldest == nullptr || q.front().seq < oldest->front().seq)) oldest = &q;
      }
      if (oldest == nullptr) return;
      history_bytes -= oldest->front().json->size();
      oldest->pop_front();
    }
  }

  // Under mu. The service thread asks lws for c's writable callback at its next wake-up; true when
  // that wake-up has to be requested (lws_cancel_service).
  bool Wake(lws* wsi, Client& c) {
    if (c.wake_pending) return false;
    c.wake_pending = true;
    wake.push_back(wsi);
    return true;
  }

  // Under mu. Queues `text` for every client; true when a wake-up is needed.
  bool Broadcast(const std::string& text) {
    bool any = false;
    for (auto& [wsi, c] : clients) {
      c.text.push_back(text);
      any = Wake(wsi, c) || any;
    }
    return any;
  }

  void OnConnect(lws* wsi) {
    std::lock_guard lock(mu);
    Client& c = clients[wsi];
    c.text.push_back(R"({"op":"serverInfo","name":)" + yaml::JsonQuote(options.name) +
                     R"(,"capabilities":[],"metadata":{"mode":)" +
                     yaml::JsonQuote(options.mode) + R"(},"sessionId":)" +
                     yaml::JsonQuote(std::to_string(reinterpret_cast<std::uintptr_t>(this))) + "}");
    std::vector<std::pair<ChannelId, const ChannelSpec*>> all;
    for (std::size_t i = 0; i < channels.size(); ++i) {
      all.emplace_back(static_cast<ChannelId>(i + 1), &channels[i]);
    }
    c.text.push_back(AdvertiseJson(all));
    lws_callback_on_writable(wsi);
  }

  void OnClientText(lws* wsi, Client& c, const std::string& text) {
    auto doc = yaml::Parse(text, "client message");
    const yaml::Node* op = doc && doc->is_mapping() ? doc->Find("op") : nullptr;
    if (op == nullptr || !op->is_scalar()) {
      c.text.push_back(StatusJson(2, "not a JSON object with an op: " + text.substr(0, 200)));
      return;
    }
    if (op->scalar() == "subscribe") {
      Subscribe(c, *doc);
    } else if (op->scalar() == "unsubscribe") {
      if (const yaml::Node* ids = doc->Find("subscriptionIds"); ids != nullptr && ids->is_sequence()) {
        for (const yaml::Node& n : ids->items()) {
          auto id = n.AsInt();
          if (!id) continue;
          auto it = c.subscriptions.find(static_cast<std::uint32_t>(*id));
          if (it == c.subscriptions.end()) continue;
          c.by_channel.erase(it->second);
          c.subscriptions.erase(it);
        }
      }
    } else {
      c.text.push_back(StatusJson(1, "op " + op->scalar() + " is not supported by this server"));
    }
    (void)wsi;
  }

  void Subscribe(Client& c, const yaml::Node& doc) {
    const yaml::Node* subs = doc.Find("subscriptions");
    if (subs == nullptr || !subs->is_sequence()) {
      c.text.push_back(StatusJson(2, "subscribe without a subscriptions array"));
      return;
    }
    std::vector<std::pair<std::uint32_t, ChannelId>> added;
    for (const yaml::Node& s : subs->items()) {
      const yaml::Node* id_node = s.is_mapping() ? s.Find("id") : nullptr;
      const yaml::Node* ch_node = s.is_mapping() ? s.Find("channelId") : nullptr;
      auto id = id_node != nullptr ? id_node->AsInt() : Result<std::int64_t>(Error(ErrorCode::kInvalidArgument, ""));
      auto ch = ch_node != nullptr ? ch_node->AsInt() : Result<std::int64_t>(Error(ErrorCode::kInvalidArgument, ""));
      if (!id || !ch || *id < 0 || *ch < 1 || static_cast<std::size_t>(*ch) > channels.size()) {
        c.text.push_back(StatusJson(2, "subscription without a valid id and channelId"));
        continue;
      }
      const auto sub = static_cast<std::uint32_t>(*id);
      const auto channel = static_cast<ChannelId>(*ch);
      if (c.subscriptions.count(sub) != 0 || c.by_channel.count(channel) != 0) {
        c.text.push_back(StatusJson(2, "subscription id " + std::to_string(sub) + " or channel " +
                                           std::to_string(channel) + " already subscribed"));
        continue;
      }
      c.subscriptions[sub] = channel;
      c.by_channel[channel] = sub;
      added.emplace_back(sub, channel);
    }
    // The history of the new subscriptions, merged in write order.
    std::vector<const Message*> replay;
    for (const auto& [sub, channel] : added) {
      auto it = history.find(channel);
      if (it == history.end()) continue;
      for (const Message& m : it->second) replay.push_back(&m);
    }
    std::sort(replay.begin(), replay.end(),
              [](const Message* a, const Message* b) { return a->seq < b->seq; });
    for (const Message* m : replay) {
      c.frames.push_back({c.by_channel[m->channel], m->channel, m->log_time_ns, m->json, false});
    }
  }

  // One writable callback: text first, then up to kFramesPerWritable frames. -1 closes.
  int OnWritable(lws* wsi) {
    std::unique_lock lock(mu);
    auto it = clients.find(wsi);
    if (it == clients.end()) return 0;
    Client& c = it->second;
    for (int n = 0; n < kFramesPerWritable && !lws_send_pipe_choked(wsi); ++n) {
      if (!c.text.empty()) {
        const std::string text = std::move(c.text.front());
        c.text.pop_front();
        c.buffer.resize(LWS_PRE + text.size());
        std::memcpy(c.buffer.data() + LWS_PRE, text.data(), text.size());
        if (lws_write(wsi, c.buffer.data() + LWS_PRE, text.size(), LWS_WRITE_TEXT) < 0) return -1;
        continue;
      }
      if (c.frames.empty()) break;
      Frame f = std::move(c.frames.front());
      c.frames.pop_front();
      if (f.live) c.live_bytes -= f.json->size();
      auto sub = c.subscriptions.find(f.subscription);
      if (sub == c.subscriptions.end() || sub->second != f.channel) continue;  // unsubscribed since
      const std::size_t size = kFrameHeader + f.json->size();
      c.buffer.resize(LWS_PRE + size);
      unsigned char* p = c.buffer.data() + LWS_PRE;
      p[0] = kOpMessageData;
      PutLe(p + 1, f.subscription, 4);
      PutLe(p + 5, f.log_time_ns, 8);
      std::memcpy(p + kFrameHeader, f.json->data(), f.json->size());
      if (lws_write(wsi, p, size, LWS_WRITE_BINARY) < 0) return -1;
    }
    if (c.live_bytes == 0 && c.drop_reported) c.drop_reported = false;
    if (!c.text.empty() || !c.frames.empty()) lws_callback_on_writable(wsi);
    return 0;
  }

  int OnReceive(lws* wsi, const void* in, std::size_t len) {
    std::lock_guard lock(mu);
    auto it = clients.find(wsi);
    if (it == clients.end()) return 0;
    Client& c = it->second;
    if (lws_frame_is_binary(wsi)) {
      c.text.push_back(StatusJson(1, "binary client messages are not supported by this server"));
    } else {
      c.incoming.append(static_cast<const char*>(in), len);
      if (c.incoming.size() > kMaxClientText) return -1;
      if (lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0) {
        const std::string text = std::move(c.incoming);
        c.incoming.clear();
        OnClientText(wsi, c, text);
      }
    }
    if (!c.text.empty() || !c.frames.empty()) lws_callback_on_writable(wsi);
    return 0;
  }

  void OnWake() {
    std::vector<lws*> pending;
    {
      std::lock_guard lock(mu);
      pending.swap(wake);
      std::erase_if(pending, [&](lws* w) {
        auto it = clients.find(w);
        if (it == clients.end()) return true;
        it->second.wake_pending = false;
        return false;
      });
    }
    for (lws* w : pending) lws_callback_on_writable(w);
  }

  static int WsCallback(lws* wsi, lws_callback_reasons reason, void* /*user*/, void* in,
                        std::size_t len) {
    auto* self = static_cast<Impl*>(lws_context_user(lws_get_context(wsi)));
    switch (reason) {
      case LWS_CALLBACK_ESTABLISHED:
        self->OnConnect(wsi);
        return 0;
      case LWS_CALLBACK_CLOSED: {
        std::lock_guard lock(self->mu);
        self->clients.erase(wsi);
        return 0;
      }
      case LWS_CALLBACK_RECEIVE:
        return self->OnReceive(wsi, in, len);
      case LWS_CALLBACK_SERVER_WRITEABLE:
        return self->OnWritable(wsi);
      case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        self->OnWake();
        return 0;
      default:
        return 0;
    }
  }

  // GET / (also /index.html, /view.html): the page's headers, then its body on writable; else 404.
  static int OnHttpRequest(lws* wsi, HttpSession* session, const void* in) {
    const std::string uri(static_cast<const char*>(in), std::strlen(static_cast<const char*>(in)));
    if (uri != "/" && uri != "/index.html" && uri != "/view.html") {
      if (lws_return_http_status(wsi, HTTP_STATUS_NOT_FOUND, nullptr) != 0) return -1;
      return lws_http_transaction_completed(wsi) != 0 ? -1 : 0;
    }
    unsigned char headers[LWS_PRE + 1024];
    unsigned char* start = headers + LWS_PRE;
    unsigned char* p = start;
    unsigned char* end = headers + sizeof(headers) - 1;
    if (lws_add_http_common_headers(wsi, HTTP_STATUS_OK, "text/html; charset=utf-8",
                                    kViewPageSize, &p, end) != 0) {
      return 1;
    }
    static constexpr char kNoCache[] = "no-store";
    if (lws_add_http_header_by_token(wsi, WSI_TOKEN_HTTP_CACHE_CONTROL,
                                     reinterpret_cast<const unsigned char*>(kNoCache),
                                     static_cast<int>(sizeof(kNoCache) - 1), &p, end) != 0) {
      return 1;
    }
    if (lws_finalize_write_http_header(wsi, start, &p, end) != 0) return 1;
    session->sent = 0;
    session->page = true;
    lws_callback_on_writable(wsi);
    return 0;
  }

  // The page's next chunk (kHttpChunk bytes at most); the transaction ends after the last.
  static int OnHttpWritable(lws* wsi, HttpSession* session) {
    if (session == nullptr || !session->page) return 0;
    const std::size_t n = std::min(kHttpChunk, kViewPageSize - session->sent);
    std::vector<unsigned char> buf(LWS_PRE + n);
    std::memcpy(buf.data() + LWS_PRE, kViewPage + session->sent, n);
    session->sent += n;
    const bool last = session->sent == kViewPageSize;
    if (lws_write(wsi, buf.data() + LWS_PRE, n, last ? LWS_WRITE_HTTP_FINAL : LWS_WRITE_HTTP) !=
        static_cast<int>(n)) {
      return 1;
    }
    if (last) {
      session->page = false;
      return lws_http_transaction_completed(wsi) != 0 ? -1 : 0;
    }
    lws_callback_on_writable(wsi);
    return 0;
  }

  static int HttpCallback(lws* wsi, lws_callback_reasons reason, void* user, void* in,
                          std::size_t len) {
    auto* session = static_cast<HttpSession*>(user);
    switch (reason) {
      case LWS_CALLBACK_HTTP:
        return OnHttpRequest(wsi, session, in);
      case LWS_CALLBACK_HTTP_WRITEABLE:
        return OnHttpWritable(wsi, session);
      case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        return 0;
      default:
        return lws_callback_http_dummy(wsi, reason, user, in, len);
    }
  }
};

Result<std::unique_ptr<LiveServer>> LiveServer::Start(const LiveOptions& options) {
  const std::string where = options.address + ":" + std::to_string(options.port);
  if (options.port < 0 || options.port > 65535) {
    return Error(ErrorCode::kInvalidArgument, "port out of range", where);
  }
  static std::once_flag log_once;
  std::call_once(log_once, [] { lws_set_log_level(LLL_ERR, nullptr); });

  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->protocols[0] = {"http", &Impl::HttpCallback, sizeof(HttpSession), 0, 0, nullptr, 0};
  impl->protocols[1] = {kSubprotocol, &Impl::WsCallback, 0, 64u << 10, 0, nullptr, 0};
  impl->protocols[2] = {nullptr, nullptr, 0, 0, 0, nullptr, 0};

  lws_context_creation_info info;
  std::memset(&info, 0, sizeof(info));
  info.port = options.port;
  info.iface = options.address.c_str();
  info.protocols = impl->protocols;
  info.user = impl.get();
  info.gid = -1;
  info.uid = -1;
  info.options = LWS_SERVER_OPTION_DISABLE_IPV6;
  impl->context = lws_create_context(&info);
  if (impl->context == nullptr) {
    return Error(ErrorCode::kUnavailable,
                 "the live view cannot listen there (address not on this host, or port in use)",
                 where);
  }
  lws_vhost* vhost = lws_get_vhost_by_name(impl->context, "default");
  impl->port = vhost != nullptr ? lws_get_vhost_listen_port(vhost) : options.port;
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->Run(); });
  return std::unique_ptr<LiveServer>(new LiveServer(std::move(impl)));
}

LiveServer::LiveServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LiveServer::~LiveServer() {
  impl_->stop.store(true);
  lws_cancel_service(impl_->context);
  impl_->thread.join();
  lws_context_destroy(impl_->context);
}

Result<ChannelId> LiveServer::AddChannel(const ChannelSpec& spec) {
  if (spec.topic.empty()) return Error(ErrorCode::kInvalidArgument, "a channel needs a topic");
  std::lock_guard lock(impl_->mu);
  for (const ChannelSpec& c : impl_->channels) {
    if (c.topic == spec.topic) {
      return Error(ErrorCode::kAlreadyExists, "channel already added", spec.topic);
    }
  }
  impl_->channels.push_back(spec);
  impl_->image.push_back(IsImageSchema(spec.schema_name));
  const auto id = static_cast<ChannelId>(impl_->channels.size());
  if (impl_->Broadcast(AdvertiseJson({{id, &impl_->channels.back()}}))) {
    lws_cancel_service(impl_->context);
  }
  return id;
}

Status LiveServer::Write(ChannelId channel, std::uint64_t log_time_ns, std::string_view json) {
  Impl& s = *impl_;
  auto data = std::make_shared<const std::string>(json);
  std::lock_guard lock(s.mu);
  if (channel < 1 || channel > s.channels.size()) {
    return Error(ErrorCode::kInvalidArgument, "no such channel: " + std::to_string(channel));
  }
  std::deque<Message>& kept = s.history[channel];
  if (s.image[channel - 1] && !s.options.history_images && !kept.empty()) {
    // Of an image channel only the newest frame is kept, for the thumbnail of a late client.
    s.history_bytes -= kept.front().json->size();
    kept.pop_front();
  }
  kept.push_back({channel, log_time_ns, s.next_seq++, data});
  s.history_bytes += data->size();
  s.TrimHistory();
  bool any = false;
  for (auto& [wsi, c] : s.clients) {
    auto sub = c.by_channel.find(channel);
    if (sub == c.by_channel.end()) continue;
    if (c.live_bytes + data->size() > s.options.client_queue_bytes) {
      ++c.dropped;
      ++s.dropped;
      if (!c.drop_reported) {
        c.drop_reported = true;
        c.text.push_back(StatusJson(1, "this client reads too slowly: live messages are dropped"));
        any = s.Wake(wsi, c) || any;
      }
      continue;
    }
    c.frames.push_back({sub->second, channel, log_time_ns, data, true});
    c.live_bytes += data->size();
    any = s.Wake(wsi, c) || any;
  }
  if (any) lws_cancel_service(s.context);
  return Ok{};
}

std::string LiveServer::url() const {
  return "http://" + impl_->options.address + ":" + std::to_string(impl_->port) + "/";
}

int LiveServer::port() const { return impl_->port; }

std::uint64_t LiveServer::dropped_messages() const {
  std::lock_guard lock(impl_->mu);
  return impl_->dropped;
}

}  // namespace swarmbox::record
