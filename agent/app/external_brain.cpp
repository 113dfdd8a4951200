#include "external_brain.hpp"

#include "brain_convert.hpp"
#include "swarmbox/bus/topics.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "wait_budget.hpp"

namespace swarmbox::agent {

Result<std::unique_ptr<ExternalBrain>> ExternalBrain::Create(bus::Participant& sim, ExternalBrainOptions options) {
  SWARMBOX_TRY(bus::ValidateDroneName(options.drone));
  std::unique_ptr<ExternalBrain> b(new ExternalBrain(std::move(options)));
  auto pub = sim.CreatePublisher<bus::BrainInput>(bus::OffboardInputTopic(b->options_.drone), bus::Qos::kLockstep);
  if (!pub) return pub.error().Context("publishing brain inputs");
  b->input_pub_ = std::move(*pub);
  auto sub = sim.CreateSubscriber<bus::BrainOutput>(bus::OffboardOutputTopic(b->options_.drone), bus::Qos::kLockstep);
  if (!sub) return sub.error().Context("subscribing to brain outputs");
  b->output_sub_ = std::move(*sub);
  return b;
}

void ExternalBrain::Log(double t_s, const char* event, double after_wall_s) {
  if (options_.log == nullptr) return;
  LogEvent e(t_s, options_.drone, event);
  if (after_wall_s >= 0.0) e.Add("after_wall_s", after_wall_s, 1);
  std::fprintf(options_.log, "%s\n", e.str().c_str());
  std::fflush(options_.log);
}

bool ExternalBrain::TakeAnswer(std::int64_t t_ns, std::chrono::milliseconds slice) {
  while (slice.count() > 0 ? output_sub_->TakeFor(wire_out_, slice) : output_sub_->Take(wire_out_)) {
    heard_ = true;
    if (wire_out_.sim_time_ns == t_ns) return true;
    // An answer to an earlier input (late, or a resent one answered twice): dropped.
  }
  return false;
}

void ExternalBrain::PublishInput(const brain::Input& in, double t_s) {
  ToBus(in, options_.drone, &wire_in_);
  if (Status s = input_pub_->Publish(wire_in_); !s && options_.log != nullptr) {
    std::fprintf(options_.log, "%s\n",
                 LogEvent(t_s, options_.drone, "bus_error").Add("what", "brain_input").Add("reason", s.error().ToString()).str().c_str());
  }
}

bool ExternalBrain::PollUnresponsive(std::int64_t t_ns, double t_s) {
  const bool got = TakeAnswer(t_ns, std::chrono::milliseconds(0));  // no waiting until it answers again
  if (heard_) {
    unresponsive_ = false;
    Log(t_s, "brain_responsive", -1.0);
  }
  return got;
}

bool ExternalBrain::WaitForAnswer(std::int64_t t_ns, double t_s) {
  const std::chrono::milliseconds bound = ever_answered_ ? options_.wait : options_.start;
  WaitBudget budget(bound);
  auto next_resend = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
  while (true) {
    if (options_.stop != nullptr && *options_.stop != 0) return false;
    if (budget.spent()) {
      const bool got = TakeAnswer(t_ns, std::chrono::milliseconds(0));  // once more before giving up
      if (!got) {
        unresponsive_ = true;
        Log(t_s, "brain_unresponsive", std::chrono::duration<double>(bound).count());
      }
      return got;
    }
    const auto slice = budget.Slice(std::chrono::milliseconds(50));
    const auto start = std::chrono::steady_clock::now();
    const bool got = TakeAnswer(t_ns, slice);
    const auto now = std::chrono::steady_clock::now();
    budget.Spend(now - start, slice);
    if (got) return true;
    if (!ever_answered_ && now >= next_resend) {
      // Not heard from yet: its reader may have matched after the input went out.
      (void)input_pub_->Publish(wire_in_);
      next_resend = now + std::chrono::milliseconds(100);
    }
  }
}

void ExternalBrain::Step(const brain::Input& in, brain::Output& out) {
  answered_ = false;
  const double t_s = static_cast<double>(in.t_ns) * 1e-9;
  PublishInput(in, t_s);
  heard_ = false;
  const bool got = unresponsive_ ? PollUnresponsive(in.t_ns, t_s) : WaitForAnswer(in.t_ns, t_s);
  if (!got) return;
  if (Status s = FromBus(wire_out_, &out); !s) {
    out = brain::Output{};
    if (options_.log != nullptr) {
      std::fprintf(options_.log, "%s\n",
                   LogEvent(t_s, options_.drone, "brain_bad_output").Add("reason", s.error().ToString()).str().c_str());
      std::fflush(options_.log);
    }
    return;
  }
  answered_ = true;
  ever_answered_ = true;
}

}  // namespace swarmbox::agent
