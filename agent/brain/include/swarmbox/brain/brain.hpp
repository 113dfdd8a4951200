// The brain SDK: the interface between a drone's flight stack (swarmbox-agent) and the swarm
// software that decides where it flies. SwarmBox's own search-and-rescue logic is one brain
// (`builtin`); a user's is another, loaded from a shared library (`brain: {library: ...}` in a
// trial) or run as its own process over the offboard topics (`brain: {program: ...}`,
// bus/idl/swarmbox.idl, BrainInput/BrainOutput: the same data as below, field for field).
//
//   class Hover : public swarmbox::brain::Brain {
//    public:
//     explicit Hover(const swarmbox::brain::Context& ctx) : height_m_(ctx.ArgDouble("height_m", 10)) {}
//     void Step(const swarmbox::brain::Input& in, swarmbox::brain::Output& out) override {
//       if (in.self.landed && in.self.flight_mode != "init" && !asked_) {  // "init": estimator not ready
//         out.commands.push_back(swarmbox::brain::Command::Takeoff(height_m_));
//         asked_ = true;
//       }
//     }
//    private:
//     double height_m_; bool asked_ = false;
//   };
//   SWARMBOX_BRAIN("hover", Hover)          // once per brain, in one .cpp of the library
//
//   # CMakeLists.txt: find_package(swarmbox 0.1 REQUIRED COMPONENTS brain)
//   #                 swarmbox_add_brain(hover SOURCES hover.cpp)        -> libhover.so
// (agent/brain/README.md: the whole contract; loader.hpp: how the agent loads it.)
//
// Contract (every brain, in-process or not):
//   - Time. Input::t_ns is the lockstep's simulated time, the brain's only clock. A brain that
//     reads a wall clock, sleeps, or draws randomness not seeded from Context::seed is not
//     deterministic: the same trial and seed would no longer give the same run at any speed.
//   - Calls. Make (the factory) once, then Step every Context::period_ns of simulated time (the
//     trial's brain.rate_hz; default every lockstep step, 4 ms), from one thread, never
//     concurrently, with `out` cleared. Step must return promptly: the whole swarm's lockstep
//     waits for it; it must not throw. The constructor may throw (a bad argument): the agent exits
//     with its message. The Context is valid during construction only: copy what you keep.
//   - Frames and units. World ENU (x east, y north, z up) [m], body FLU, quaternions (w,x,y,z)
//     rotating body to world, SI units with the unit in the name, simulated time in ns.
//   - Setpoints have PX4 TrajectorySetpoint semantics (Setpoint below). Output::setpoint empty
//     keeps the last one. Commands go first, in order, then the setpoint.
//   - Consensus. Proposals go to the swarm's Raft log; each committed entry comes back once, in
//     index order, on every drone (Input::committed), also the drone's own. A proposal can be
//     lost (a leader change) and is then never committed: re-propose what matters until it shows.
//     Every drone of a trial must run brains that agree on what the entries mean.
//     A brain that keeps a replicated state of its own makes one (MakeReplicatedState): Raft then
//     snapshots it and restores it on a drone that fell behind or restarted.
//   - Radio. Messages are best effort, delayed and lost by the trial's radio model; `to` empty
//     broadcasts to every drone in range. Neighbours are the latest state heard from the nearest
//     drones: at most the agent's --brain-neighbours (default 32), chosen anew every 200 ms of
//     simulated time, a drone silent for 3 s dropped.
//   - ABI. A library brain is C++ loaded with dlopen into the agent: build it with the same
//     compiler major version and C++ standard library as the installed SwarmBox
//     (find_package(swarmbox) does), and export it with SWARMBOX_BRAIN. The loader refuses a
//     library whose kAbiVersion differs, and says so.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace swarmbox::brain {

// Bumped whenever a type below changes layout; the loader refuses a library built against another.
inline constexpr int kAbiVersion = 1;

inline constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

// The flight stack's estimate of its own drone (estimated, not true, state).
struct Vehicle {
  std::string name;
  std::uint64_t step = 0;                 // the lockstep step of this estimate
  Vec3 position_m;                        // world ENU [m]
  Vec3 velocity_m_s;                      // world ENU [m/s]
  double attitude_wxyz[4] = {1.0, 0.0, 0.0, 0.0};  // body FLU -> world ENU
  Vec3 angular_rate_rad_s;                // body FLU [rad/s]
  double heading_rad = 0.0;               // yaw, ENU: 0 = east, counter-clockwise positive
  double battery_fraction = 1.0;          // [0, 1]
  double battery_voltage_v = 0.0;
  // init, idle, takeoff, hold, position, velocity, trajectory, land, landed
  // (flight::FlightModeName); "init" until the estimator is ready.
  std::string flight_mode;
  bool armed = false;
  bool landed = true;
  double payload_mass_kg = 0.0;           // what this brain last attached (0: none)
  double mass_estimate_kg = 0.0;          // the hover-thrust estimator's total mass [kg]
};

// Something the flight stack reported since the previous Step, by flight::FlightEventName:
// flight_ready, takeoff, hover, arrived, landing, landed, mode, gps_lost, gps_recovered,
// setpoint_rejected (a command or setpoint the mode could not take), and the offboard failsafe's
// offboard_lost.
struct FlightEvent {
  std::string name;
  std::int64_t t_ns = 0;
  std::map<std::string, std::string> fields;
};

// The latest state heard on the radio from another drone.
struct Neighbour {
  std::string name;
  std::int64_t t_ns = 0;                  // simulated time the state was sent
  Vec3 position_m;
  Vec3 velocity_m_s;
  double heading_rad = 0.0;
  double battery_fraction = 0.0;
  std::string status;                     // that drone's brain's Output::status
};

struct Message {
  std::string from;
  std::string to;                         // "" = broadcast
  std::string topic;                      // the brain's name for the kind, e.g. "rendezvous/vote"
  std::vector<std::uint8_t> payload;
};

struct Entry {
  std::uint64_t index = 0;                // the Raft log index (increasing, not contiguous)
  std::vector<std::uint8_t> data;
};

// A perception result of this drone (geolocated with its estimated pose at capture).
struct Detection {
  std::int64_t t_ns = 0;                  // capture time
  std::string label;                      // "victim"
  double confidence = 0.0;                // [0, 1]
  Vec3 position_m;                        // world ENU [m]
  double sigma_m = 0.0;                   // 1-sigma horizontal uncertainty [m]
};

class ReplicatedState;

struct Input {
  std::int64_t t_ns = 0;                  // simulated time of this step
  Vehicle self;
  std::span<const FlightEvent> flight_events;
  bool is_leader = false;                 // this drone leads the consensus
  std::string leader;                     // who leads, as far as this drone knows ("": nobody)
  std::span<const Neighbour> neighbours;  // the nearest (at most --brain-neighbours, 32), sorted by name
  std::span<const Message> messages;      // delivered since the previous Step, in delivery order
  std::span<const Entry> committed;       // committed since the previous Step, in index order
  std::span<const Detection> detections;  // since the previous Step
  // The brain's own replicated state (MakeReplicatedState), with `committed` already applied;
  // null when the brain made none.
  const ReplicatedState* state = nullptr;
};

// PX4 TrajectorySetpoint semantics in world ENU; kUnset (NaN) = unset. Per axis: a position
// controls it (velocity and acceleration then feed forward); else a velocity; else an
// acceleration. yaw [rad, ENU], else yawspeed [rad/s]; both unset keep the heading.
struct Setpoint {
  Vec3 position_m{kUnset, kUnset, kUnset};
  Vec3 velocity_m_s{kUnset, kUnset, kUnset};
  Vec3 acceleration_m_s2{kUnset, kUnset, kUnset};
  double yaw_rad = kUnset;
  double yawspeed_rad_s = kUnset;

  static Setpoint Position(const Vec3& p, double yaw = kUnset) {
    Setpoint s;
    s.position_m = p;
    s.yaw_rad = yaw;
    return s;
  }
  static Setpoint Velocity(const Vec3& v, double yaw = kUnset) {
    Setpoint s;
    s.velocity_m_s = v;
    s.yaw_rad = yaw;
    return s;
  }
};

struct Command {
  enum class Kind : std::uint8_t { kArm, kDisarm, kTakeoff, kLand, kHold, kPayloadAttach, kPayloadRelease };
  Kind kind = Kind::kHold;
  double param = 0.0;  // takeoff: height above the start [m]; payload_attach: mass [kg]

  static Command Takeoff(double height_m) { return {Kind::kTakeoff, height_m}; }
  static Command Land() { return {Kind::kLand, 0.0}; }
  static Command Hold() { return {Kind::kHold, 0.0}; }
  static Command PayloadAttach(double mass_kg) { return {Kind::kPayloadAttach, mass_kg}; }
  static Command PayloadRelease() { return {Kind::kPayloadRelease, 0.0}; }
};
// "arm", "disarm", "takeoff", "land", "hold", "payload_attach", "payload_release": the names on
// the offboard topics (VehicleCommand::command).
const char* CommandName(Command::Kind kind);

// One logfmt line in the agent's log: `t=<sim s> node=<drone> event=<name> k=v ...`.
struct Event {
  std::string name;
  std::vector<std::pair<std::string, std::string>> fields;
};

struct Output {
  std::vector<Setpoint> setpoint;         // empty: keep the last one; at most one element
  std::vector<Command> commands;
  std::vector<Message> messages;
  std::vector<std::vector<std::uint8_t>> proposals;
  std::string status;                     // broadcast to the neighbours (Neighbour::status)
  std::vector<Event> events;
  void Clear();
};

// A brain's deterministic state machine over the committed entries, replicated by Raft. Apply is
// called once per committed entry in index order, on every drone; Snapshot/Restore let Raft
// compact its log and bring a lagging or restarted drone up to date. Same entries in, same state
// out: no clocks, no randomness.
class ReplicatedState {
 public:
  virtual ~ReplicatedState() = default;
  virtual void Apply(std::uint64_t index, std::span<const std::uint8_t> entry) = 0;
  virtual std::vector<std::uint8_t> Snapshot() const = 0;
  // false: the snapshot is not one of this state's (the agent then stops with the reason).
  virtual bool Restore(std::span<const std::uint8_t> snapshot) = 0;
};

// What a brain knows before its first Step.
struct Context {
  std::string self;                       // this drone's name
  std::vector<std::string> members;       // every drone of the trial (same list, same order on each)
  std::uint64_t seed = 0;                 // the trial's seed: the only source of randomness
  std::int64_t period_ns = 4'000'000;     // simulated time between Steps
  std::string airframe;                   // e.g. "x500"
  std::string airframe_path;              // the airframe file (YAML) as the agent sees it
  std::string world_path;                 // the world file (YAML); "" when the trial has none
  std::string payload;                    // the airframe payload this drone carries ("": none)
  // brain.args of the trial, scalars as text (nested values as their JSON text).
  std::map<std::string, std::string> args;
  // Writes one event line now (for a ReplicatedState, whose Apply has no Output).
  std::function<void(const Event&)> log;

  // args[key] as a number / text; `fallback` when absent. A present but malformed value throws
  // std::invalid_argument naming the key (Make's caller turns it into a usage error).
  double ArgDouble(const std::string& key, double fallback) const;
  std::string ArgString(const std::string& key, const std::string& fallback) const;
};

class Brain {
 public:
  virtual ~Brain() = default;
  // Called once, before the first Step; null: the committed entries arrive only in Input.
  virtual std::unique_ptr<ReplicatedState> MakeReplicatedState() { return nullptr; }
  virtual void Step(const Input& in, Output& out) = 0;
};

// ---- registration (library brains) -------------------------------------------------------------
//
// SWARMBOX_BRAIN("name", Class) registers Class (constructed from `const Context&`) under "name"
// in the library's table; the agent's loader (loader.hpp) looks the name up. A constructor that
// throws (e.g. a bad argument) is reported with the brain's name and the exception's message.

using Factory = std::unique_ptr<Brain> (*)(const Context&);

struct Registration {
  const char* name;
  Factory make;
};

// The library's table: every SWARMBOX_BRAIN of the library, in registration order.
//
// One table per shared object: swarmbox::brain is a static library that every brain library (and
// the agent) links its own copy of, and this function has hidden visibility, so a brain library's
// SWARMBOX_BRAIN always fills that library's table, never the agent's or another library's (even
// when the agent exports its symbols, or another library was loaded RTLD_GLOBAL). The three
// extern "C" functions below are the only symbols a brain library must export.
#if defined(__GNUC__)
#define SWARMBOX_BRAIN_LOCAL __attribute__((visibility("hidden")))
#define SWARMBOX_BRAIN_EXPORT __attribute__((visibility("default")))
#else
#define SWARMBOX_BRAIN_LOCAL
#define SWARMBOX_BRAIN_EXPORT
#endif
SWARMBOX_BRAIN_LOCAL std::vector<Registration>& LibraryRegistry();

// The C++ standard library this translation unit is compiled against: "libstdc++/cxx11",
// "libstdc++/cow" (_GLIBCXX_USE_CXX11_ABI=0), "libc++" or "unknown". std::string, std::vector and
// std::function cross the boundary, so the loader refuses a library built against another one.
inline const char* CxxLibrary() {
#if defined(_LIBCPP_VERSION)
  return "libc++";
#elif defined(__GLIBCXX__) && defined(_GLIBCXX_USE_CXX11_ABI) && _GLIBCXX_USE_CXX11_ABI
  return "libstdc++/cxx11";
#elif defined(__GLIBCXX__)
  return "libstdc++/cow";
#else
  return "unknown";
#endif
}

}  // namespace swarmbox::brain

// What the loader finds in a library with dlsym: the ABI version (kAbiVersion of the SwarmBox the
// library was built against), the C++ standard library it was built with (CxxLibrary), and the table.
extern "C" SWARMBOX_BRAIN_EXPORT int swarmbox_brain_abi_version();
extern "C" SWARMBOX_BRAIN_EXPORT const char* swarmbox_brain_cxx_library();
extern "C" SWARMBOX_BRAIN_EXPORT const std::vector<swarmbox::brain::Registration>*
swarmbox_brain_registry();

#define SWARMBOX_BRAIN_CONCAT_(a, b) a##b
#define SWARMBOX_BRAIN_CONCAT(a, b) SWARMBOX_BRAIN_CONCAT_(a, b)
#define SWARMBOX_BRAIN(NAME, CLASS)                                                          \
  namespace {                                                                               \
  const bool SWARMBOX_BRAIN_CONCAT(swarmbox_brain_registered_, __LINE__) = [] {             \
    ::swarmbox::brain::LibraryRegistry().push_back(                                         \
        {NAME, [](const ::swarmbox::brain::Context& ctx) -> std::unique_ptr<::swarmbox::brain::Brain> { \
           return std::make_unique<CLASS>(ctx);                                             \
         }});                                                                               \
    return true;                                                                            \
  }();                                                                                      \
  }
