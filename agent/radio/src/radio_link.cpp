#include "swarmbox/radio/radio_link.hpp"

#include <algorithm>
#include <utility>

namespace swarmbox::radio {
namespace {

std::int64_t SteadyNs(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

}  // namespace

RadioLink::RadioLink(std::string self, std::vector<std::string> peers, RadioLinkOptions options)
    : self_(std::move(self)),
      monitor_(std::move(peers),
               LinkMonitorOptions{.ping_every = options.ping_every,
                                  .timeout = options.timeout,
                                  .report_every = options.report_every},
               std::chrono::steady_clock::now()) {}

RadioLink::~RadioLink() {
  {
    std::lock_guard<std::mutex> lk(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  if (sender_.joinable()) sender_.join();
  subscriber_.reset();  // waits for a running callback; none after this
  ping_writers_.clear();
  pong_writers_.clear();
  other_pong_writer_.reset();
}

Result<std::unique_ptr<RadioLink>> RadioLink::Create(bus::Participant& mesh, std::string self,
                                                     std::vector<std::string> peers,
                                                     RadioLinkOptions options) {
  if (auto s = bus::ValidateDroneName(self); !s) return s.error().Context("radio link");
  if (options.ping_every.count() <= 0 || options.timeout.count() <= 0 ||
      options.report_every.count() <= 0) {
    return Error(ErrorCode::kInvalidArgument,
                 "radio link: ping_every, timeout and report_every must be positive (got " +
                     std::to_string(options.ping_every.count()) + " ms, " +
                     std::to_string(options.timeout.count()) + " ms, " +
                     std::to_string(options.report_every.count()) + " ms)");
  }
  std::vector<std::string> unique;
  for (std::string& p : peers) {
    if (auto s = bus::ValidateDroneName(p); !s) return s.error().Context("radio link: peer");
    if (p == self || std::find(unique.begin(), unique.end(), p) != unique.end()) continue;
    unique.push_back(std::move(p));
  }
  if (unique.empty()) {
    return Error(ErrorCode::kInvalidArgument,
                 "radio link: no peer to ping besides '" + self + "'");
  }
  std::unique_ptr<RadioLink> link(new RadioLink(std::move(self), std::move(unique), options));
  // One writer per peer and direction (see the header: a best-effort reader drops what arrives
  // out of order within one writer's stream).
  auto writer = [&mesh]() {
    return mesh.CreatePublisher<bus::RadioPing>(bus::kRadioPingTopic, bus::Qos::kRadio);
  };
  for (std::size_t i = 0; i < link->monitor_.peers().size(); ++i) {
    auto ping = writer();
    if (!ping) return std::move(ping).error().Context("radio link: creating a ping writer");
    link->ping_writers_.push_back(std::move(*ping));
    auto pong = writer();
    if (!pong) return std::move(pong).error().Context("radio link: creating a pong writer");
    link->pong_writers_.push_back(std::move(*pong));
  }
  auto other = writer();
  if (!other) return std::move(other).error().Context("radio link: creating the writer");
  link->other_pong_writer_ = std::move(*other);
  RadioLink* raw = link.get();
  auto sub = mesh.CreateSubscriber<bus::RadioPing>(
      bus::kRadioPingTopic, bus::Qos::kRadio, [raw](const bus::RadioPing& m) { raw->OnSample(m); });
  if (!sub) return std::move(sub).error().Context("radio link: creating the reader");
  link->subscriber_ = std::move(*sub);
  link->sender_ = std::thread([raw] { raw->SenderLoop(); });
  return link;
}

std::vector<LogEvent> RadioLink::Poll(std::chrono::steady_clock::time_point now, double sim_t_s) {
  std::optional<std::vector<LinkWindow>> report;
  {
    std::lock_guard<std::mutex> lk(mu_);
    report = monitor_.TakeReport(now);
  }
  std::vector<LogEvent> lines;
  if (!report) return lines;
  lines.reserve(report->size());
  for (const LinkWindow& w : *report) {
    if (w.sent == 0) continue;
    lines.push_back(FormatLinkEvent(sim_t_s, self_, w));
  }
  return lines;
}

void RadioLink::SenderLoop() {
  std::vector<PingToSend> due;
  due.reserve(monitor_.peers().size());
  std::vector<PongRequest> pongs;
  bus::RadioPing msg;
  msg.from = self_;
  std::unique_lock<std::mutex> lk(mu_);
  while (true) {
    wake_.wait_until(lk, monitor_.next_ping_due(), [this] {
      return stop_ || !pong_queue_.empty() ||
             std::chrono::steady_clock::now() >= monitor_.next_ping_due();
    });
    if (stop_) return;
    pongs.swap(pong_queue_);  // the queue keeps the capacity of the batch sent last time
    const auto now = std::chrono::steady_clock::now();
    due.clear();
    monitor_.DuePings(now, due);  // recorded as sent at `now`
    lk.unlock();
    // Published without the lock: in-process readers get the sample synchronously, in this thread.
    msg.is_pong = true;
    for (const PongRequest& p : pongs) {
      msg.to = p.to;
      msg.seq = p.seq;
      msg.sent_ns = p.sent_wall_ns;
      Publish(PongWriter(p.to), msg);
      pings_answered_.fetch_add(1, std::memory_order_relaxed);
    }
    pongs.clear();
    msg.is_pong = false;
    for (const PingToSend& p : due) {
      msg.to = monitor_.peers()[p.peer];  // peers() never changes after construction
      msg.seq = p.seq;
      msg.sent_ns = SteadyNs(now);
      Publish(*ping_writers_[p.peer], msg);
      pings_sent_.fetch_add(1, std::memory_order_relaxed);
    }
    lk.lock();
  }
}

void RadioLink::Publish(bus::Publisher<bus::RadioPing>& writer, const bus::RadioPing& m) {
  // Best effort like the radio: a failed publish is not retried; the monitor then sees the ping
  // (or the peer's ping, for a pong) as lost.
  if (!writer.Publish(m)) send_errors_.fetch_add(1, std::memory_order_relaxed);
}

bus::Publisher<bus::RadioPing>& RadioLink::PongWriter(const std::string& to) {
  const std::vector<std::string>& peers = monitor_.peers();  // never changes after construction
  for (std::size_t i = 0; i < peers.size(); ++i) {
    if (peers[i] == to) return *pong_writers_[i];
  }
  return *other_pong_writer_;
}

void RadioLink::OnSample(const bus::RadioPing& m) {
  const auto received = std::chrono::steady_clock::now();
  if (m.to != self_ || m.from == self_) {
    ignored_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (!m.is_pong) {
    {
      std::lock_guard<std::mutex> lk(mu_);
      pong_queue_.push_back(PongRequest{m.from, m.seq, m.sent_ns});
    }
    wake_.notify_one();
    return;
  }
  pongs_received_.fetch_add(1, std::memory_order_relaxed);
  PongResult r;
  {
    std::lock_guard<std::mutex> lk(mu_);
    r = monitor_.OnPong(m.from, m.seq, received);
  }
  if (r == PongResult::kUnknownPeer || r == PongResult::kUnknownSeq) {
    ignored_.fetch_add(1, std::memory_order_relaxed);
  }
}

RadioLink::Counters RadioLink::counters() const {
  Counters c;
  c.pings_sent = pings_sent_.load(std::memory_order_relaxed);
  c.send_errors = send_errors_.load(std::memory_order_relaxed);
  c.pings_answered = pings_answered_.load(std::memory_order_relaxed);
  c.pongs_received = pongs_received_.load(std::memory_order_relaxed);
  c.ignored = ignored_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace swarmbox::radio
