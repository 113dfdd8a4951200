// Test brain library A (brain_loader_test): three brains in one library.
//   alpha     echoes its Context, and what this library's own table holds, into its Output;
//   stateful  makes a ReplicatedState and checks that Step hands it back as its own type;
//   thrower   throws from its constructor (a bad argument, as Context::ArgDouble reports it).
#include <cstdint>
#include <stdexcept>
#include <string>

#include "swarmbox/brain/brain.hpp"

namespace {

namespace sb = swarmbox::brain;

std::string TableNames() {
  std::string names;
  for (const sb::Registration& r : sb::LibraryRegistry()) names += (names.empty() ? "" : ",") + std::string(r.name);
  return names;
}

class Alpha final : public sb::Brain {
 public:
  explicit Alpha(const sb::Context& ctx)
      : self_(ctx.self), height_m_(ctx.ArgDouble("height_m", 7.5)), label_(ctx.ArgString("label", "none")) {}
  void Step(const sb::Input& in, sb::Output& out) override {
    out.status = "alpha/" + self_ + "/" + label_;
    out.commands.push_back(sb::Command::Takeoff(height_m_));
    out.events.push_back({"table", {{"names", TableNames()}, {"t_ns", std::to_string(in.t_ns)}}});
  }

 private:
  std::string self_;
  double height_m_;
  std::string label_;
};

class Counter final : public sb::ReplicatedState {
 public:
  void Apply(std::uint64_t /*index*/, std::span<const std::uint8_t> entry) override { bytes_ += entry.size(); }
  std::vector<std::uint8_t> Snapshot() const override { return {static_cast<std::uint8_t>(bytes_)}; }
  bool Restore(std::span<const std::uint8_t> snapshot) override {
    if (snapshot.size() != 1) return false;
    bytes_ = snapshot[0];
    return true;
  }
  std::size_t bytes() const { return bytes_; }

 private:
  std::size_t bytes_ = 0;
};

class Stateful final : public sb::Brain {
 public:
  explicit Stateful(const sb::Context& /*ctx*/) {}
  std::unique_ptr<sb::ReplicatedState> MakeReplicatedState() override { return std::make_unique<Counter>(); }
  void Step(const sb::Input& in, sb::Output& out) override {
    const auto* own = dynamic_cast<const Counter*>(in.state);
    out.status = own != nullptr ? "own state, " + std::to_string(own->bytes()) + " bytes" : "not my state";
  }
};

class Thrower final : public sb::Brain {
 public:
  explicit Thrower(const sb::Context& ctx) { ctx.ArgDouble("speed_m_s", 1.0); }
  void Step(const sb::Input& /*in*/, sb::Output& /*out*/) override {}
};

}  // namespace

SWARMBOX_BRAIN("alpha", Alpha)
SWARMBOX_BRAIN("stateful", Stateful)
SWARMBOX_BRAIN("thrower", Thrower)
