// Physics events and where they go. The server prints them as logfmt lines
// (`t=12.340 node=physics event=collision a=drone_1 b=drone_2 speed=3.20`), tests collect them.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::physics {

enum class EventKind {
  kCollision,         // drone-drone (a, b) or drone-obstacle (a, b = obstacle id)
  kCrash,             // impact faster than the airframe's crash_speed_m_s: motors dead
  kHardLanding,       // ground impact between hard_landing_speed_m_s and crash_speed_m_s
  kPayloadAttached,   // a = drone, b = payload name
  kPayloadReleased,
  kDroneLost,         // lockstep timeout: motors off (a = drone)
  kDroneRejoined,     // a lost drone answered again
  kGeofence,          // a drone left the world's geofence
};

const char* EventName(EventKind kind);  // "collision", "crash", "hard_landing", ...

struct PhysicsEvent {
  double t_s = 0;              // simulated time [s]
  EventKind kind = EventKind::kCollision;
  std::string a;               // drone name
  std::string b;               // other party (drone, obstacle id, "ground", payload) or ""
  double speed_m_s = 0;        // impact speed where it applies [m/s]

  // `t=.. node=physics event=<kind> a=.. [b=..] [speed=..]`.
  LogEvent ToLogEvent(const std::string& node = "physics") const;
};

// Receives events after each World::Step() (never from inside the physics sub-steps).
class EventSink {
 public:
  virtual ~EventSink() = default;
  virtual void OnEvent(const PhysicsEvent& event) = 0;
};

// Keeps every event (tests).
class CollectingEventSink final : public EventSink {
 public:
  void OnEvent(const PhysicsEvent& event) override { events.push_back(event); }
  std::vector<PhysicsEvent> events;
};

}  // namespace swarmbox::physics
