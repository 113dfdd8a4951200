// Cyclone DDS backend of the bus: C API, idlc-generated C types, converted by cyclone_convert.hpp.
//
// Each domain id gets one Cyclone domain per process, created with dds_create_domain() and the
// XML configuration of cyclone_config.hpp (bound to the participant's interface, multicast forced
// on so loopback works for tests, discovery and message sizes tuned for 100 participants). Writers and readers each own their topic entity and hold a shared reference to
// the participant, so they may outlive the front-end Participant object.
#include <dds/dds.h>

#include <condition_variable>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "cyclone_convert.hpp"
#include "swarmbox/bus/cyclone_config.hpp"
#include "detail/backends.hpp"

namespace swarmbox::bus::cyclone_detail {
namespace {

Error DdsError(dds_return_t rc, const std::string& doing, const char* call) {
  const ErrorCode code = rc == DDS_RETCODE_TIMEOUT ? ErrorCode::kTimeout : ErrorCode::kInternal;
  return Error(code, doing + ": " + dds_strretcode(rc), std::string("cyclonedds ") + call);
}

// Process-wide: one Cyclone domain per domain id, bound to one interface.
class DomainRegistry {
 public:
  static DomainRegistry& Instance() {
    static DomainRegistry registry;
    return registry;
  }

  Status Acquire(int domain_id, const std::string& interface, int writer_linger_ms, int participant_index,
                 const std::vector<std::string>& peers) {
    std::lock_guard lock(mu_);
    auto it = domains_.find(domain_id);
    if (it != domains_.end()) {
      if (it->second.interface != interface) {
        return Error(ErrorCode::kInvalidArgument,
                     "cyclonedds domain " + std::to_string(domain_id) +
                         " is already bound to interface '" + it->second.interface +
                         "' in this process; a domain id can be bound to one interface only "
                         "(asked for '" + interface + "')");
      }
      ++it->second.refs;
      return Ok{};
    }
    const std::string xml = CycloneXml({.interface = interface,
                                        .writer_linger_ms = writer_linger_ms,
                                        .participant_index = participant_index,
                                        .peers = peers});
    const dds_entity_t domain = dds_create_domain(static_cast<dds_domainid_t>(domain_id), xml.c_str());
    if (domain < 0) {
      return DdsError(domain, "creating domain " + std::to_string(domain_id) + " on interface '" +
                                  interface + "'", "dds_create_domain");
    }
    domains_[domain_id] = Entry{interface, domain, 1};
    return Ok{};
  }

  void Release(int domain_id) {
    std::lock_guard lock(mu_);
    auto it = domains_.find(domain_id);
    if (it == domains_.end()) return;
    if (--it->second.refs == 0) {
      dds_delete(it->second.domain);
      domains_.erase(it);
    }
  }

 private:
  struct Entry {
    std::string interface;
    dds_entity_t domain;
    int refs;
  };
  std::mutex mu_;
  std::map<int, Entry> domains_;
};

// Owns the dds participant; shared by the participant backend and its writers/readers.
class ParticipantHandle {
 public:
  ParticipantHandle(int domain_id, dds_entity_t participant)
      : domain_id_(domain_id), participant_(participant) {}
  ~ParticipantHandle() {
    dds_delete(participant_);
    DomainRegistry::Instance().Release(domain_id_);
  }
  ParticipantHandle(const ParticipantHandle&) = delete;
  ParticipantHandle& operator=(const ParticipantHandle&) = delete;
  dds_entity_t get() const { return participant_; }

  // Cyclone DDS (with XTypes) lets one participant use a topic name with several types; the bus
  // does not (Fast DDS cannot, and it defeats interop), so the first type a name is used with
  // stays bound to it for the participant's life.
  Status ClaimTopic(const std::string& name, const char* type_name) {
    std::lock_guard lock(mu_);
    auto [it, inserted] = topic_types_.emplace(name, type_name);
    if (!inserted && it->second != type_name) {
      return Error(ErrorCode::kInvalidArgument,
                   "topic '" + name + "' already carries " + it->second +
                       " in this participant, not " + type_name,
                   "cyclonedds dds_create_topic");
    }
    return Ok{};
  }

 private:
  int domain_id_;
  dds_entity_t participant_;
  std::mutex mu_;
  std::map<std::string, std::string> topic_types_;
};

// QoS of a preset; the caller deletes it.
dds_qos_t* MakeQos(Qos qos, bool writer) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  switch (qos) {
    case Qos::kLockstep:
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 16);
      break;
    case Qos::kRadio:
      dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 256);
      break;
    case Qos::kState:
      dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
      dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
      break;
  }
  if (writer) {
    // Plain CDR (XCDR1): the encoding Fast DDS 2.9 reads.
    const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
    dds_qset_data_representation(q, 1, &xcdr1);
  }
  return q;
}

// A topic entity owned by one writer or reader.
Result<dds_entity_t> CreateTopic(ParticipantHandle& participant,
                                 const dds_topic_descriptor_t* desc, const std::string& name) {
  SWARMBOX_TRY(participant.ClaimTopic(name, desc->m_typename));
  const dds_entity_t topic =
      dds_create_topic(participant.get(), desc, name.c_str(), nullptr, nullptr);
  if (topic < 0) {
    return DdsError(topic, "creating topic '" + name + "' of type " + desc->m_typename +
                               " (a topic of that name with another type exists?)",
                    "dds_create_topic");
  }
  return topic;
}

template <typename Cpp, typename C>
class Writer final : public detail::WriterBackend {
 public:
  Writer(std::shared_ptr<ParticipantHandle> participant, std::string topic_name,
         dds_entity_t topic, dds_entity_t writer)
      : participant_(std::move(participant)),
        topic_name_(std::move(topic_name)),
        topic_(topic),
        writer_(writer) {}
  ~Writer() override {
    dds_delete(writer_);
    dds_delete(topic_);
  }
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  Status Write(const void* msg) override {
    std::lock_guard lock(mu_);
    arena_.Reset();
    C sample{};
    ToC(*static_cast<const Cpp*>(msg), sample, arena_);
    const dds_return_t rc = dds_write(writer_, &sample);
    if (rc < 0) return DdsError(rc, "publishing on topic '" + topic_name_ + "'", "dds_write");
    return Ok{};
  }

  int MatchedCount() const override {
    dds_publication_matched_status_t st{};
    if (dds_get_publication_matched_status(writer_, &st) < 0) return 0;
    return static_cast<int>(st.current_count);
  }

 private:
  std::shared_ptr<ParticipantHandle> participant_;
  std::string topic_name_;
  dds_entity_t topic_;
  dds_entity_t writer_;
  std::mutex mu_;
  Arena arena_;
};

template <typename Cpp, typename C>
class Reader final : public detail::ReaderBackend {
 public:
  Reader(std::shared_ptr<ParticipantHandle> participant, const dds_topic_descriptor_t* desc,
         detail::SampleCallback callback)
      : participant_(std::move(participant)), desc_(desc), callback_(std::move(callback)) {}

  ~Reader() override {
    {
      std::lock_guard lock(mu_);  // waits for a running callback
      alive_ = false;
    }
    if (waitset_ > 0) dds_delete(waitset_);
    if (reader_ > 0) dds_delete(reader_);
    if (topic_ > 0) dds_delete(topic_);
    dds_sample_free(&c_sample_, desc_, DDS_FREE_CONTENTS);
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  Status Init(const std::string& topic_name, Qos qos) {
    const dds_entity_t pp = participant_->get();
    auto topic = CreateTopic(*participant_, desc_, topic_name);
    if (!topic) return topic.error();
    topic_ = *topic;
    dds_qos_t* q = MakeQos(qos, /*writer=*/false);
    handoff_ = !callback_ && qos == Qos::kLockstep;
    if (handoff_) ring_.resize(kHandoffDepth);
    dds_listener_t* listener = nullptr;
    if (callback_ || handoff_) {
      listener = dds_create_listener(this);
      dds_lset_data_available(listener, &Reader::OnDataAvailable);
    }
    reader_ = dds_create_reader(pp, topic_, q, listener);
    dds_delete_qos(q);
    if (listener != nullptr) dds_delete_listener(listener);
    if (reader_ < 0) {
      const dds_return_t rc = reader_;
      reader_ = 0;
      return DdsError(rc, "creating reader on topic '" + topic_name + "'", "dds_create_reader");
    }
    if (handoff_) return Ok{};  // no waitset: WaitForData waits on cv_
    waitset_ = dds_create_waitset(pp);
    if (waitset_ < 0) {
      const dds_return_t rc = waitset_;
      waitset_ = 0;
      return DdsError(rc, "creating waitset for topic '" + topic_name + "'", "dds_create_waitset");
    }
    const dds_entity_t cond = dds_create_readcondition(reader_, DDS_ANY_STATE);
    if (cond < 0) return DdsError(cond, "creating read condition", "dds_create_readcondition");
    const dds_return_t rc = dds_waitset_attach(waitset_, cond, 0);
    if (rc < 0) return DdsError(rc, "attaching read condition", "dds_waitset_attach");
    return Ok{};
  }

  bool Take(void* out) override {
    if (callback_) return false;
    std::lock_guard lock(mu_);
    if (!handoff_) return TakeOne(reader_, *static_cast<Cpp*>(out));
    if (count_ == 0) return false;
    // The caller's old buffers go into the slot, to be reused by a later sample: no allocation.
    std::swap(*static_cast<Cpp*>(out), ring_[head_]);
    head_ = (head_ + 1) % ring_.size();
    --count_;
    return true;
  }

  bool WaitForData(std::chrono::nanoseconds timeout) override {
    if (handoff_) {
      std::unique_lock lock(mu_);
      return cv_.wait_for(lock, timeout, [this] { return count_ > 0; });
    }
    return dds_waitset_wait(waitset_, nullptr, 0, static_cast<dds_duration_t>(timeout.count())) > 0;
  }

  int MatchedCount() const override {
    dds_subscription_matched_status_t st{};
    if (dds_get_subscription_matched_status(reader_, &st) < 0) return 0;
    return static_cast<int>(st.current_count);
  }

 private:
  // Takes one valid sample (skipping dispose/unregister notifications) into `out`. Cyclone
  // deserializes into c_sample_, which keeps its string and sequence buffers between takes
  // (Cyclone reallocates them only when a sample needs more room), so a warm reader does not
  // allocate here. Caller holds mu_.
  bool TakeOne(dds_entity_t reader, Cpp& out) {
    while (true) {
      void* samples[1] = {&c_sample_};
      dds_sample_info_t info;
      const dds_return_t n = dds_take(reader, samples, &info, 1, 1);
      if (n <= 0) return false;
      if (info.valid_data) {
        FromC(c_sample_, out);
        return true;
      }
    }
  }

  // Cyclone's listener thread (the receive thread, or the delivery thread for local writers).
  static void OnDataAvailable(dds_entity_t reader, void* arg) {
    auto* self = static_cast<Reader*>(arg);
    bool queued = false;
    {
      std::lock_guard lock(self->mu_);
      if (!self->alive_) return;
      if (self->callback_) {
        while (self->TakeOne(reader, self->scratch_)) self->callback_(&self->scratch_);
        return;
      }
      // Hand-off: move the samples out of Cyclone here, on the thread that received them, so the
      // reading thread wakes to a sample it can take without contending for Cyclone's reader.
      while (self->TakeOne(reader, self->scratch_)) {
        const std::size_t cap = self->ring_.size();
        if (self->count_ == cap) {  // keep-last: the oldest goes
          self->head_ = (self->head_ + 1) % cap;
          --self->count_;
        }
        std::swap(self->ring_[(self->head_ + self->count_) % cap], self->scratch_);
        ++self->count_;
        queued = true;
      }
    }
    if (queued) self->cv_.notify_one();  // after unlocking: the woken thread does not block on mu_
  }

  std::shared_ptr<ParticipantHandle> participant_;
  const dds_topic_descriptor_t* desc_;
  detail::SampleCallback callback_;
  dds_entity_t topic_ = 0;
  dds_entity_t reader_ = 0;
  dds_entity_t waitset_ = 0;
  std::mutex mu_;  // guards c_sample_, scratch_, alive_, the ring; held during the callback
  bool alive_ = true;
  C c_sample_{};  // Cyclone deserializes into this; owns its buffers (freed in the destructor)
  Cpp scratch_;   // the sample handed to the callback, or on its way into the ring; reused
  // Hand-off mode (Qos::kLockstep without callback: sensor samples, camera frames): the listener
  // moves each sample into this ring (keep-last kHandoffDepth, the preset's depth, in arrival
  // order) and wakes WaitForData through cv_. Measured with `swarmbox-bench bus
  // --scenario=agent_step` (bus/README.md): a waitset woke the reading thread while the receive
  // thread still held Cyclone's reader, ~3 sleeps per sample instead of 1.
  static constexpr std::size_t kHandoffDepth = 16;
  bool handoff_ = false;
  std::vector<Cpp> ring_;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::condition_variable cv_;
};

class CycloneParticipant final : public detail::ParticipantBackend {
 public:
  explicit CycloneParticipant(std::shared_ptr<ParticipantHandle> handle)
      : handle_(std::move(handle)) {}

  Result<std::unique_ptr<detail::WriterBackend>> CreateWriter(MessageType type,
                                                              const std::string& topic,
                                                              Qos qos) override {
    switch (type) {
#define SWARMBOX_CYCLONE_WRITER_CASE(Name) \
  case MessageType::k##Name:               \
    return MakeWriter<Name, swarmbox_msg_##Name>(&swarmbox_msg_##Name##_desc, topic, qos);
      SWARMBOX_BUS_MESSAGES(SWARMBOX_CYCLONE_WRITER_CASE)
#undef SWARMBOX_CYCLONE_WRITER_CASE
    }
    return Error(ErrorCode::kInvalidArgument, "unknown message type", "cyclonedds");
  }

  Result<std::unique_ptr<detail::ReaderBackend>> CreateReader(
      MessageType type, const std::string& topic, Qos qos,
      detail::SampleCallback callback) override {
    switch (type) {
#define SWARMBOX_CYCLONE_READER_CASE(Name)                                                  \
  case MessageType::k##Name:                                                                \
    return MakeReader<Name, swarmbox_msg_##Name>(&swarmbox_msg_##Name##_desc, topic, qos, \
                                                 std::move(callback));
      SWARMBOX_BUS_MESSAGES(SWARMBOX_CYCLONE_READER_CASE)
#undef SWARMBOX_CYCLONE_READER_CASE
    }
    return Error(ErrorCode::kInvalidArgument, "unknown message type", "cyclonedds");
  }

 private:
  template <typename Cpp, typename C>
  Result<std::unique_ptr<detail::WriterBackend>> MakeWriter(const dds_topic_descriptor_t* desc,
                                                            const std::string& topic_name,
                                                            Qos qos) {
    auto topic = CreateTopic(*handle_, desc, topic_name);
    if (!topic) return topic.error();
    dds_qos_t* q = MakeQos(qos, /*writer=*/true);
    const dds_entity_t writer = dds_create_writer(handle_->get(), *topic, q, nullptr);
    dds_delete_qos(q);
    if (writer < 0) {
      dds_delete(*topic);
      return DdsError(writer, "creating writer on topic '" + topic_name + "'", "dds_create_writer");
    }
    return std::unique_ptr<detail::WriterBackend>(
        new Writer<Cpp, C>(handle_, topic_name, *topic, writer));
  }

  template <typename Cpp, typename C>
  Result<std::unique_ptr<detail::ReaderBackend>> MakeReader(const dds_topic_descriptor_t* desc,
                                                            const std::string& topic_name, Qos qos,
                                                            detail::SampleCallback callback) {
    auto reader = std::make_unique<Reader<Cpp, C>>(handle_, desc, std::move(callback));
    SWARMBOX_TRY(reader->Init(topic_name, qos));
    return std::unique_ptr<detail::ReaderBackend>(std::move(reader));
  }

  std::shared_ptr<ParticipantHandle> handle_;
};

}  // namespace
}  // namespace swarmbox::bus::cyclone_detail

namespace swarmbox::bus::detail {

Result<std::unique_ptr<ParticipantBackend>> CreateCycloneBackend(const ParticipantConfig& config,
                                                                 const std::string& ipv4) {
  (void)ipv4;  // Cyclone binds by interface name (the XML config); the address is for Fast DDS
  using cyclone_detail::DomainRegistry;
  SWARMBOX_TRY(DomainRegistry::Instance().Acquire(config.domain_id, config.interface, config.writer_linger_ms,
                                                   config.participant_index, config.peers));
  const dds_entity_t pp =
      dds_create_participant(static_cast<dds_domainid_t>(config.domain_id), nullptr, nullptr);
  if (pp < 0) {
    DomainRegistry::Instance().Release(config.domain_id);
    return cyclone_detail::DdsError(pp,
                                    "creating participant on domain " +
                                        std::to_string(config.domain_id),
                                    "dds_create_participant");
  }
  auto handle = std::make_shared<cyclone_detail::ParticipantHandle>(config.domain_id, pp);
  return std::unique_ptr<ParticipantBackend>(new cyclone_detail::CycloneParticipant(handle));
}

}  // namespace swarmbox::bus::detail
