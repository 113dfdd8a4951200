// The SwarmBox publish/subscribe API: one Participant per DDS domain, bound to one network
// interface, with typed publishers and subscribers of the messages in messages.hpp.
//
// The middleware is chosen at run time by name: "cyclonedds" (default; Cyclone DDS C API with
// idlc-generated types) or "fastdds" (Fast DDS with fastddsgen-generated types). Both speak
// standard RTPS with the same type names and encodings, so a process on one backend talks to a
// process on the other. No vendor header is reachable from here.
//
//   auto sim = Participant::Create({.backend = "cyclonedds", .domain_id = 3, .interface = "eth1"});
//   if (!sim) return sim.error();                     // unknown backend, no such interface, ...
//   auto pub = (*sim)->CreatePublisher<ActuatorCommand>(kActuatorTopic, Qos::kLockstep);
//   auto sub = (*sim)->CreateSubscriber<SensorSample>(SensorTopic("scout_1"), Qos::kLockstep);
//   SensorSample s;                                   // reused: no allocation per step once warm
//   while ((*sub)->TakeFor(s, std::chrono::milliseconds(500))) { ...; (*pub)->Publish(cmd); }
//
// Lifetimes: publishers and subscribers share ownership of their participant's middleware objects,
// so they may outlive the Participant object. Domains: with Cyclone DDS a process binds a given
// domain id to one interface only (a second cyclonedds participant on the same domain id must name
// the same interface; the agent's `sim` and `mesh` domains therefore need different ids).
// Errors are Results; nothing here throws.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "swarmbox/bus/detail/backend.hpp"
#include "swarmbox/bus/messages.hpp"
#include "swarmbox/bus/topics.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::bus {

inline constexpr std::string_view kDefaultBackend = "cyclonedds";
// RTPS maps domain ids to UDP ports 7400 + 250 * id + ...; above 232 they overflow 65535.
inline constexpr int kMaxDomainId = 232;

struct ParticipantConfig {
  std::string backend = std::string(kDefaultBackend);  // "cyclonedds" or "fastdds"
  int domain_id = 0;                                    // [0, kMaxDomainId]
  std::string interface = "lo";                         // network interface name, must have IPv4
  // Cyclone DDS: how long a deleted writer waits for its unacknowledged samples to be acknowledged
  // (its reliable protocol's heartbeats, ~0.2 s on an idle link) before it goes; -1 = Cyclone's
  // default (1 s). A process that must leave at once on a stop request and needs nothing it sent
  // last sets it low. Set by the first participant of a domain id in the process. Fast DDS: unused.
  int writer_linger_ms = -1;
  // Cyclone DDS discovery (bus/cyclone_config.hpp; Fast DDS: unused). participant_index >= 0: the
  // well-known discovery port of that index (the physics server of a trial: 0). peers ("host:port",
  // e.g. the physics server's container and CycloneDiscoveryPort(domain, 0)): discovery by unicast
  // to them only, no multicast (a trial's agents). Set by the first participant of a domain id.
  int participant_index = -1;
  std::vector<std::string> peers = {};
};

// The backend names Participant::Create accepts, in order: {"cyclonedds", "fastdds"}.
const std::vector<std::string>& AvailableBackends();

// Publishes messages of type T on one topic. Thread-safe.
template <BusMessage T>
class Publisher {
 public:
  explicit Publisher(std::string topic, std::unique_ptr<detail::WriterBackend> impl)
      : topic_(std::move(topic)), impl_(std::move(impl)) {}

  // Sends `msg` to every matched subscriber. Does not keep a reference to `msg`. kUnavailable or
  // kInternal (with the middleware's code) on failure.
  Status Publish(const T& msg) { return impl_->Write(&msg); }

  // Number of subscribers currently matched (any process, either backend).
  int MatchedSubscribers() const { return impl_->MatchedCount(); }

  // Waits (polling every 5 ms) until at least `count` subscribers are matched; kTimeout otherwise.
  // Matching is seen per side: when this returns, a remote reader may not yet have matched this
  // writer, and a (volatile) reader misses what was written before it matched. A protocol that
  // needs its first sample (lockstep) resends until answered, e.g. step 0 every 100 ms.
  Status WaitForSubscribers(int count, std::chrono::milliseconds timeout) const {
    return WaitForMatch(count, timeout, "subscriber");
  }

  const std::string& topic() const { return topic_; }

 private:
  Status WaitForMatch(int count, std::chrono::milliseconds timeout, const char* what) const;
  std::string topic_;
  std::unique_ptr<detail::WriterBackend> impl_;
};

// Receives messages of type T from one topic.
//
// Without a callback: samples queue in the subscriber (bounded by the QoS depth) and are read
// with Take()/TakeFor() from one thread at a time.
// With a callback: every sample is handed to the callback, on a middleware thread (Cyclone DDS's
// receive thread, Fast DDS's listener thread), one call at a time per subscriber; the reference is
// valid during the call only. Take() then always returns false. The callback must not block for
// long and must not destroy its own subscriber; destroying the subscriber waits for a running
// callback to return.
template <BusMessage T>
class Subscriber {
 public:
  using Callback = std::function<void(const T&)>;

  explicit Subscriber(std::string topic, std::unique_ptr<detail::ReaderBackend> impl)
      : topic_(std::move(topic)), impl_(std::move(impl)) {}

  // Non-blocking: moves the oldest unread sample into `out` (reusing its string/vector
  // capacity) and returns true, or returns false if there is none.
  bool Take(T& out) { return impl_->Take(&out); }

  // Like Take(T&) but waits up to `timeout` for a sample to arrive.
  bool TakeFor(T& out, std::chrono::nanoseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (true) {
      if (impl_->Take(&out)) return true;
      const auto left = deadline - std::chrono::steady_clock::now();
      if (left <= std::chrono::nanoseconds::zero()) return false;
      impl_->WaitForData(std::chrono::duration_cast<std::chrono::nanoseconds>(left));
    }
  }

  // Convenience form that allocates a fresh T.
  std::optional<T> Take() {
    T out;
    if (!Take(out)) return std::nullopt;
    return out;
  }

  // Number of publishers currently matched (any process, either backend).
  int MatchedPublishers() const { return impl_->MatchedCount(); }

  // Waits (polling every 5 ms) until at least `count` publishers are matched; kTimeout otherwise.
  Status WaitForPublishers(int count, std::chrono::milliseconds timeout) const;

  const std::string& topic() const { return topic_; }

 private:
  std::string topic_;
  std::unique_ptr<detail::ReaderBackend> impl_;
};

// One DDS domain participant on one backend, bound to one interface.
class Participant {
 public:
  // Errors (kInvalidArgument / kNotFound, the message names the bad value and what is accepted):
  //   unknown backend name, domain id out of [0, kMaxDomainId], interface that does not exist or
  //   has no IPv4 address, the domain id already bound to another interface in this process;
  // kInternal when the middleware refuses to create the participant.
  static Result<std::unique_ptr<Participant>> Create(const ParticipantConfig& config);

  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  // kInvalidArgument for a bad topic name (see topics.hpp); kInternal if the middleware refuses
  // (e.g. the topic exists in this participant with another type).
  template <BusMessage T>
  Result<std::unique_ptr<Publisher<T>>> CreatePublisher(std::string_view topic, Qos qos) {
    auto w = CreateWriter(MessageTraits<T>::kType, topic, qos);
    if (!w) return std::move(w).error();
    return std::make_unique<Publisher<T>>(std::string(topic), std::move(*w));
  }

  template <BusMessage T>
  Result<std::unique_ptr<Subscriber<T>>> CreateSubscriber(
      std::string_view topic, Qos qos, typename Subscriber<T>::Callback on_sample = {}) {
    detail::SampleCallback erased;
    if (on_sample) {
      erased = [cb = std::move(on_sample)](const void* msg) { cb(*static_cast<const T*>(msg)); };
    }
    auto r = CreateReader(MessageTraits<T>::kType, topic, qos, std::move(erased));
    if (!r) return std::move(r).error();
    return std::make_unique<Subscriber<T>>(std::string(topic), std::move(*r));
  }

  const ParticipantConfig& config() const { return config_; }
  // The IPv4 address of config().interface the participant is bound to, e.g. "127.0.0.1".
  const std::string& address() const { return address_; }

 private:
  Participant(ParticipantConfig config, std::string address,
              std::unique_ptr<detail::ParticipantBackend> impl);
  Result<std::unique_ptr<detail::WriterBackend>> CreateWriter(MessageType type,
                                                              std::string_view topic, Qos qos);
  Result<std::unique_ptr<detail::ReaderBackend>> CreateReader(MessageType type,
                                                              std::string_view topic, Qos qos,
                                                              detail::SampleCallback callback);

  ParticipantConfig config_;
  std::string address_;
  std::unique_ptr<detail::ParticipantBackend> impl_;
};

namespace detail {
// Polls `matched` every 5 ms until it reaches `count` or `timeout` passes.
Status WaitForMatched(const std::function<int()>& matched, int count,
                      std::chrono::milliseconds timeout, std::string_view what,
                      std::string_view topic);
}  // namespace detail

template <BusMessage T>
Status Publisher<T>::WaitForMatch(int count, std::chrono::milliseconds timeout,
                                  const char* what) const {
  return detail::WaitForMatched([this] { return impl_->MatchedCount(); }, count, timeout, what,
                                topic_);
}

template <BusMessage T>
Status Subscriber<T>::WaitForPublishers(int count, std::chrono::milliseconds timeout) const {
  return detail::WaitForMatched([this] { return impl_->MatchedCount(); }, count, timeout,
                                "publisher", topic_);
}

}  // namespace swarmbox::bus
