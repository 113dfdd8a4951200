// Helpers for bus tests: participants that fail the test loudly, and a publish-until-received
// round trip that works for reliable and best-effort QoS alike.
//
// Domain ids: every test case uses its own domain id (ctest runs test cases in parallel
// processes), from the bus tests' blocks:
//   140..143 two-process, 144..146 hot path, 150..169 round trips, 170..189 interop,
//   190..199 API behaviour;
//   the bench uses 200..209 unless told otherwise.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "swarmbox/bus/participant.hpp"

namespace swarmbox::bus::testing {

inline constexpr std::chrono::seconds kMatchTimeout{10};

// Creates a participant on `backend` bound to lo; ADD_FAILURE with the error otherwise.
inline std::unique_ptr<Participant> MakeParticipant(const std::string& backend, int domain_id) {
  auto p = Participant::Create({.backend = backend, .domain_id = domain_id, .interface = "lo"});
  if (!p) {
    ADD_FAILURE() << "Participant::Create(" << backend << ", " << domain_id
                  << ", lo): " << p.error().ToString();
    return nullptr;
  }
  return std::move(*p);
}

// Publishes `value` on `topic` from `pub_side` until `sub_side` receives a sample (every 100 ms,
// at most for kMatchTimeout: best-effort samples sent before the reader has matched the writer
// may be dropped), then checks the received sample equals `value`.
template <BusMessage T>
::testing::AssertionResult RoundTrip(Participant& pub_side, Participant& sub_side,
                                     const std::string& topic, Qos qos, const T& value) {
  auto sub = sub_side.CreateSubscriber<T>(topic, qos);
  if (!sub) return ::testing::AssertionFailure() << "subscriber: " << sub.error().ToString();
  auto pub = pub_side.CreatePublisher<T>(topic, qos);
  if (!pub) return ::testing::AssertionFailure() << "publisher: " << pub.error().ToString();
  if (auto s = (*pub)->WaitForSubscribers(1, kMatchTimeout); !s) {
    return ::testing::AssertionFailure() << s.error().ToString();
  }
  if (auto s = (*sub)->WaitForPublishers(1, kMatchTimeout); !s) {
    return ::testing::AssertionFailure() << s.error().ToString();
  }
  T received;
  const auto deadline = std::chrono::steady_clock::now() + kMatchTimeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (auto s = (*pub)->Publish(value); !s) {
      return ::testing::AssertionFailure() << "publish: " << s.error().ToString();
    }
    if ((*sub)->TakeFor(received, std::chrono::milliseconds(100))) {
      if (received == value) return ::testing::AssertionSuccess();
      return ::testing::AssertionFailure() << "received a sample that differs from the one sent";
    }
  }
  return ::testing::AssertionFailure() << "nothing received on '" << topic << "' within "
                                       << kMatchTimeout.count() << " s";
}

}  // namespace swarmbox::bus::testing
