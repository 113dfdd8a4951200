// ExternalBrain: a brain in its own process (`--brain external`, a trial's `brain: {program: ..}`),
// reached over the offboard topics on the sim bus (bus/messages.hpp, agent/brain/README.md):
// each Step publishes one bus::BrainInput on OffboardInputTopic(drone) and waits for the
// bus::BrainOutput with the same sim_time_ns on OffboardOutputTopic(drone). The lockstep waits
// with it, so a brain that keeps up gives the same run at any speed.
//
//   ExternalBrainOptions o;  o.drone = "scout_2";  o.log = stdout;
//   auto brain = ExternalBrain::Create(*sim, o);            // bus errors: an error
//   BrainHost host(..., std::move(*brain), ...);            // BrainHost asks answered()
//
// Liveness (the agent's only wall-clock reads around a brain): the first answer is waited for up
// to `start` (its input resent every 100 ms meanwhile: a reader that matched late misses what was
// written before), every later one up to `wait`, both as WaitBudgets (slices of 50 ms, a stopped
// process keeps its budget). When a bound fires: `event=brain_unresponsive after_wall_s=..` once,
// and from then on each Step publishes its input but does not wait (answered() false unless the
// answer is already there) until an output arrives again: `event=brain_responsive`, and the next
// Steps wait again. What the drone does meanwhile is the offboard failsafe's (BrainHost), on
// simulated time. Outputs of earlier inputs are dropped; an output that does not convert (an
// unknown command) is logged (event=brain_bad_output reason=..) and is no answer.
// Thread-safety: one thread (the control loop). Ownership: `sim` outlives the brain.
#pragma once

#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>

#include "brain_host.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::agent {

struct ExternalBrainOptions {
  std::string drone;
  std::chrono::milliseconds wait{3000};    // --brain-wait-ms: wall-clock bound per answer
  std::chrono::milliseconds start{30000};  // --brain-start-ms: wall-clock bound for the first
  const volatile std::sig_atomic_t* stop = nullptr;  // set: stop waiting (no answer)
  std::FILE* log = stdout;                 // brain_unresponsive / brain_responsive lines
};

class ExternalBrain final : public RemoteBrain {
 public:
  static Result<std::unique_ptr<ExternalBrain>> Create(bus::Participant& sim, ExternalBrainOptions options);

  void Step(const brain::Input& in, brain::Output& out) override;
  bool answered() const override { return answered_; }
  bool responsive() const { return !unresponsive_; }

 private:
  explicit ExternalBrain(ExternalBrainOptions options) : options_(std::move(options)) {}
  // Takes outputs (waiting up to `slice`, 0: not at all) until the one for `t_ns`; true with it
  // in wire_out_.
  bool TakeAnswer(std::int64_t t_ns, std::chrono::milliseconds slice);
  void Log(double t_s, const char* event, double after_wall_s);
  void PublishInput(const brain::Input& in, double t_s);  // a bus error is logged, not fatal
  // The answer to the input at t_ns, into wire_out_: unresponsive, only what has arrived (and
  // back to responsive once anything arrives); otherwise waiting up to the wall-clock bound,
  // resending until the first answer ever. false: none (or options_.stop was set).
  bool PollUnresponsive(std::int64_t t_ns, double t_s);
  bool WaitForAnswer(std::int64_t t_ns, double t_s);

  ExternalBrainOptions options_;
  std::unique_ptr<bus::Publisher<bus::BrainInput>> input_pub_;
  std::unique_ptr<bus::Subscriber<bus::BrainOutput>> output_sub_;
  bus::BrainInput wire_in_;
  bus::BrainOutput wire_out_;
  bool answered_ = false;
  bool ever_answered_ = false;
  bool unresponsive_ = false;
  bool heard_ = false;  // some output arrived in the last TakeAnswer
};

}  // namespace swarmbox::agent
