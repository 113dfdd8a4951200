// Physics events and where they go. The server prints them as logfmt lines
// (`t=12.340 node=physics event=collision a=drone_1 b=drone_2 speed=3.20`), tests collect them.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/physics/types.hpp"

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
  // A released payload came to rest (speed < kPayloadRestSpeed_m_s for kPayloadRestTime_s of
  // simulated time), once per release: a = the drone that released it; position_m its centre,
  // tilt_deg the angle between its up axis and world up (0: flat; 180: upside down). So a trial
  // can judge where and how a stretcher was set down.
  kPayloadAtRest,
};

inline constexpr double kPayloadRestSpeed_m_s = 0.05;
inline constexpr double kPayloadRestTime_s = 1.0;

const char* EventName(EventKind kind);  // "collision", "crash", "hard_landing", ...

struct PhysicsEvent {
  double t_s = 0;              // simulated time [s]
  EventKind kind = EventKind::kCollision;
  std::string a;               // drone name
  std::string b;               // other party (drone, obstacle id, "ground", payload) or ""
  double speed_m_s = 0;        // impact speed where it applies [m/s]
  Vec3 position_m;             // kPayloadAtRest: the payload's centre [m, ENU]
  double tilt_deg = 0;         // kPayloadAtRest: its up axis from world up [deg]

  // `t=.. node=physics event=<kind> a=.. [b=..] [speed=..]`; kPayloadAtRest:
  // `t=.. node=physics event=payload_at_rest drone=.. x=.. y=.. z=.. tilt_deg=..`.
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
