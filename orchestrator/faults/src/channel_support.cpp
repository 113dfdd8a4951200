#include "swarmbox/faults/channel_support.hpp"

#include <set>
#include <string>
#include <variant>

namespace swarmbox::faults {

namespace {

constexpr std::string_view kUseNetem = "; radio.model: netem (the real network stack) does";

Error Refuse(const yaml::Mark& mark, std::string_view what, std::string_view key, std::string_view why) {
  return Error(ErrorCode::kInvalidArgument,
               std::string(what) + ": '" + std::string(key) +
                   "' is not carried out by the simulated radio channel (radio.model channel): " +
                   std::string(why) + std::string(kUseNetem),
               mark.ToString());
}

}  // namespace

Status CheckChannelSupports(const std::vector<RadioRule>& rules, std::string_view what) {
  if (rules.size() > 1) {
    return Refuse(rules[1].mark, what, "rules", "it impairs each sender's egress as a whole, with one rule");
  }
  for (const RadioRule& rule : rules) {
    const NetemSpec& s = rule.spec;
    auto refuse = [&](std::string_view key, std::string_view why) {
      return Refuse(rule.mark, what, key, why);
    };
    if (!rule.to.empty()) return refuse("to", "it impairs each sender's egress to every receiver alike");
    if (s.correlation > 0.0) return refuse("correlation", "it draws each frame's delay independently");
    if (s.loss_correlation > 0.0)
      return refuse("loss_correlation", "it draws each frame's loss independently");
    if (s.gilbert_elliott)
      return refuse("gilbert_elliott", "it draws each frame's loss independently (no burst states)");
    if (s.corrupt > 0.0) return refuse("corrupt", "a frame arrives whole or not at all");
    if (s.reorder > 0.0 || s.reorder_correlation > 0.0) {
      return refuse("reorder", "frames are reordered only by their drawn delays (jitter)");
    }
    if (s.reorder_gap > 0)
      return refuse("reorder_gap", "frames are reordered only by their drawn delays (jitter)");
    if (s.limit_packets) return refuse("limit", "each sender's queue is the radio profile's queue_frames");
  }
  return Ok{};
}

Status CheckChannelFaults(const std::vector<Fault>& faults) {
  std::set<std::string> names;
  for (const Fault& f : faults) {
    if (f.start.clock == FaultStart::Clock::kSim) {
      // The physics server reports these by name (event=drone_out ... fault=NAME): one logfmt word.
      bool word = !f.id.empty();
      for (char c : f.id) word = word && c > ' ' && c != '"' && c != '=' && c != '\\' && c != 0x7f;
      if (!word) {
        return Error(ErrorCode::kInvalidArgument,
                     "fault name '" + f.id +
                         "' must be one word without quotes or '=' (the physics server reports "
                         "faults at simulated times by name)",
                     f.mark.ToString());
      }
      if (!names.insert(f.id).second) {
        return Error(ErrorCode::kInvalidArgument,
                     "fault name '" + f.id +
                         "' is used twice (the physics server reports faults at simulated "
                         "times by name)",
                     f.mark.ToString());
      }
    }
    const auto* radio = std::get_if<RadioFault>(&f.action);
    const bool partition = std::holds_alternative<PartitionFault>(f.action);
    if (radio == nullptr && !partition) continue;
    if (f.start.clock != FaultStart::Clock::kSim) {
      return Error(
          ErrorCode::kInvalidArgument,
          "fault " + f.id + " (" + std::string(f.kind()) + ", " + f.start.ToString() +
              "): the simulated radio channel (radio.model channel) takes radio faults and partitions at "
              "simulated times only (at:); a log event or a wall time has no simulated time to land on" +
              std::string(kUseNetem),
          f.mark.ToString());
    }
    if (radio != nullptr) SWARMBOX_TRY(CheckChannelSupports(radio->rules, "fault " + f.id));
  }
  return Ok{};
}

}  // namespace swarmbox::faults
