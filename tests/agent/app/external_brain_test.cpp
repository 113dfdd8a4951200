// ExternalBrain over real DDS (integration; Cyclone on lo, one process): a responder thread plays
// the brain process. It answers each input with the output of the same sim_time_ns (converted
// back field for field); an answer to an older input is not taken for the current one; a brain
// silent past --brain-wait-ms is reported once (brain_unresponsive), not waited for again, and
// waited for again once it answers (brain_responsive). DDS domains 48-49.
#include "external_brain.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "brain_convert.hpp"
#include "swarmbox/bus/topics.hpp"

namespace swarmbox::agent {
namespace {

using namespace std::chrono_literals;

int Domain() { return 48 + static_cast<int>(getpid() % 2); }

// The brain process: answers inputs while `answering`, each with status "s<t_ns>" and, for the
// first one, a takeoff; with `stale`, answers with the previous input's time instead.
class Responder {
 public:
  explicit Responder(bus::Participant& sim) {
    in_ = std::move(*sim.CreateSubscriber<bus::BrainInput>(bus::OffboardInputTopic("scout_1"), bus::Qos::kLockstep));
    out_ = std::move(*sim.CreatePublisher<bus::BrainOutput>(bus::OffboardOutputTopic("scout_1"), bus::Qos::kLockstep));
    thread_ = std::thread([this] { Run(); });
  }
  ~Responder() {
    stop_ = true;
    thread_.join();
  }
  std::atomic<bool> answering{true};
  std::atomic<bool> stale{false};
  std::atomic<int> inputs{0};

 private:
  void Run() {
    bus::BrainInput in;
    std::int64_t previous = -1;
    while (!stop_) {
      if (!in_->TakeFor(in, 20ms)) continue;
      ++inputs;
      if (!answering) continue;
      brain::Output o;
      o.status = "s" + std::to_string(in.sim_time_ns);
      if (previous < 0) o.commands.push_back(brain::Command::Takeoff(5));
      bus::BrainOutput wire;
      ToBus(o, "scout_1", stale ? previous : in.sim_time_ns, &wire);
      previous = in.sim_time_ns;
      (void)out_->Publish(wire);
    }
  }
  std::unique_ptr<bus::Subscriber<bus::BrainInput>> in_;
  std::unique_ptr<bus::Publisher<bus::BrainOutput>> out_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

class Lines {
 public:
  Lines() : file_(std::tmpfile()) {}
  ~Lines() { std::fclose(file_); }
  std::FILE* file() { return file_; }
  std::string Read() {
    std::fflush(file_);
    std::rewind(file_);
    std::string out;
    char buf[512];
    while (std::fgets(buf, sizeof buf, file_) != nullptr) out += buf;
    return out;
  }

 private:
  std::FILE* file_;
};

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(ExternalBrain, WaitsForTheAnswerOfEachInputAndBoundsTheWait) {
  auto sim = bus::Participant::Create({.backend = "cyclonedds", .domain_id = Domain(), .interface = "lo"});
  ASSERT_TRUE(sim) << sim.error().ToString();
  Lines lines;
  ExternalBrainOptions o;
  o.drone = "scout_1";
  o.wait = 300ms;
  o.start = 10s;
  o.log = lines.file();
  auto made = ExternalBrain::Create(**sim, o);
  ASSERT_TRUE(made) << made.error().ToString();
  ExternalBrain& brain = **made;
  Responder responder(**sim);
  brain::Input in;
  brain::Output out;
  std::int64_t t = 0;
  const auto step = [&] {
    t += 20'000'000;
    in.t_ns = t;
    out.Clear();
    brain.Step(in, out);
  };

  // Answered, input by input (the first after discovery: the input is resent until then).
  for (int i = 0; i < 5; ++i) {
    step();
    ASSERT_TRUE(brain.answered()) << i << lines.Read();
    EXPECT_EQ(out.status, "s" + std::to_string(t));
  }
  // Answers to the previous input only: none is this one's; after the bound, one line.
  responder.stale = true;
  const auto before = std::chrono::steady_clock::now();
  step();
  EXPECT_FALSE(brain.answered());
  EXPECT_GE(std::chrono::steady_clock::now() - before, 250ms);
  EXPECT_FALSE(brain.responsive());  // it gave up waiting
  // Silent: inputs still go out, without waiting.
  responder.stale = false;
  responder.answering = false;
  const int inputs_before = responder.inputs;
  const auto quick = std::chrono::steady_clock::now();
  for (int i = 0; i < 3; ++i) step();
  EXPECT_LT(std::chrono::steady_clock::now() - quick, 250ms);
  EXPECT_FALSE(brain.answered());
  for (int i = 0; i < 100 && responder.inputs < inputs_before + 3; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_GE(responder.inputs, inputs_before + 3);
  // It answers again: responsive, and waited for from the next input on.
  responder.answering = true;
  for (int i = 0; i < 100 && !brain.answered(); ++i) {
    std::this_thread::sleep_for(20ms);
    step();
  }
  step();
  EXPECT_TRUE(brain.answered()) << lines.Read();
  EXPECT_TRUE(brain.responsive());
  EXPECT_EQ(out.status, "s" + std::to_string(t));
  const std::string log = lines.Read();
  EXPECT_EQ(Count(log, "event=brain_unresponsive"), 1u) << log;
  EXPECT_NE(log.find("after_wall_s=0.3"), std::string::npos) << log;
  EXPECT_EQ(Count(log, "event=brain_responsive"), 1u) << log;
}

}  // namespace
}  // namespace swarmbox::agent
