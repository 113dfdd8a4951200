// The vendor-free interface every bus backend (Cyclone DDS, Fast DDS) implements.
//
// Not for users: include swarmbox/bus/participant.hpp. The typed front end (Publisher<T>,
// Subscriber<T>) erases T to `const void*` / `void*` after checking, at creation, that the
// MessageType given to the backend is MessageTraits<T>::kType; a backend may therefore cast the
// pointers to the C++ struct of that MessageType.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "swarmbox/bus/messages.hpp"
#include "swarmbox/bus/topics.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::bus {
struct ParticipantConfig;
}

namespace swarmbox::bus::detail {

class WriterBackend {
 public:
  virtual ~WriterBackend() = default;
  // Thread-safe. `msg` points to the C++ struct of the writer's MessageType.
  virtual Status Write(const void* msg) = 0;
  virtual int MatchedCount() const = 0;
};

class ReaderBackend {
 public:
  virtual ~ReaderBackend() = default;
  // Moves the oldest unread sample into *out (the C++ struct of the reader's MessageType), reusing
  // its buffers. False if there is none (always false for a reader with a callback).
  virtual bool Take(void* out) = 0;
  // Blocks until unread data may be available or `timeout` passes; true if data may be there.
  virtual bool WaitForData(std::chrono::nanoseconds timeout) = 0;
  virtual int MatchedCount() const = 0;
};

// Called on a middleware thread with a pointer to the C++ struct, valid during the call only.
using SampleCallback = std::function<void(const void*)>;

class ParticipantBackend {
 public:
  virtual ~ParticipantBackend() = default;
  // The returned writers and readers keep the participant's middleware objects alive.
  virtual Result<std::unique_ptr<WriterBackend>> CreateWriter(MessageType type,
                                                              const std::string& topic, Qos qos) = 0;
  virtual Result<std::unique_ptr<ReaderBackend>> CreateReader(MessageType type,
                                                              const std::string& topic, Qos qos,
                                                              SampleCallback callback) = 0;
};

}  // namespace swarmbox::bus::detail
