#include "swarmbox/raft/mission_command.hpp"

#include "swarmbox/raft/detail/byte_io.hpp"
#include "swarmbox/raft/detail/mission_io.hpp"
#include "swarmbox/raft/detail/overloaded.hpp"

namespace swarmbox::raft {

using detail::Overloaded;

std::string_view CommandName(const MissionCommand& command) {
  static constexpr std::string_view kNames[] = {
      "start_search", "assign_sectors", "report_sighting", "confirm_victim", "converge_on",
      "begin_rescue", "mark_rescued",   "return_home",     "complete_mission", "report_miss",
      "request_revisit", "confirm_sighting", "reject_sighting"};
  return kNames[command.index()];
}

Bytes EncodeCommand(const MissionCommand& command) {
  Bytes out;
  detail::ByteWriter w(&out);
  w.U8(kCommandVersion);
  w.U8(static_cast<std::uint8_t>(command.index()));
  std::visit(Overloaded{
                 [](const StartSearch&) {},
                 [&](const AssignSectors& c) { detail::WriteSectors(w, c.sectors); },
                 [&](const ReportSighting& c) { detail::WriteSighting(w, c); },
                 [&](const ConfirmVictim& c) {
                   w.Str(c.by);
                   w.F64(c.x_m);
                   w.F64(c.y_m);
                 },
                 [&](const ConvergeOn& c) { w.Varint(c.victim_id); },
                 [&](const BeginRescue& c) {
                   w.Varint(c.victim_id);
                   w.Str(c.lifter);
                 },
                 [&](const MarkRescued& c) { w.Varint(c.victim_id); },
                 [](const ReturnHome&) {},
                 [](const CompleteMission&) {},
                 [&](const ReportMiss& c) {
                   w.Str(c.reporter);
                   w.Varint(c.seq);
                   w.Varint(c.candidate);
                   w.F64(c.viewer_x_m);
                   w.F64(c.viewer_y_m);
                   w.F64(c.viewer_height_m);
                   w.F64(c.t_s);
                 },
                 [&](const RequestRevisit& c) {
                   w.Varint(c.candidate);
                   w.Str(c.drone);
                   w.F64(c.t_s);
                 },
                 [&](const ConfirmSighting& c) {
                   w.Varint(c.candidate);
                   w.F64(c.belief);
                 },
                 [&](const RejectSighting& c) {
                   w.Varint(c.candidate);
                   w.F64(c.belief);
                 },
             },
             command);
  return out;
}

Result<MissionCommand> DecodeCommand(std::span<const std::uint8_t> bytes) {
  detail::ByteReader r(bytes);
  const std::uint8_t version = r.U8();
  const std::uint8_t kind = r.U8();
  if (!r.ok()) return Error(ErrorCode::kProtocol, r.error(), "mission command");
  if (version != kCommandVersion) {
    return Error(ErrorCode::kProtocol, "unsupported command version " + std::to_string(version),
                 "mission command");
  }
  auto victim_id = [&r]() {
    const std::uint64_t v = r.Varint();
    if (v > UINT32_MAX) r.Fail("victim id out of range");
    return static_cast<std::uint32_t>(v);
  };
  MissionCommand cmd;
  switch (kind) {
    case 0: cmd = StartSearch{}; break;
    case 1: cmd = AssignSectors{detail::ReadSectors(r)}; break;
    case 2: cmd = detail::ReadSighting<ReportSighting>(r); break;
    case 3: {
      ConfirmVictim c;
      c.by = r.Str();
      c.x_m = r.F64();
      c.y_m = r.F64();
      cmd = std::move(c);
      break;
    }
    case 4: cmd = ConvergeOn{victim_id()}; break;
    case 5: {
      BeginRescue c;
      c.victim_id = victim_id();
      c.lifter = r.Str();
      cmd = std::move(c);
      break;
    }
    case 6: cmd = MarkRescued{victim_id()}; break;
    case 7: cmd = ReturnHome{}; break;
    case 8: cmd = CompleteMission{}; break;
    case 9: {
      ReportMiss c;
      c.reporter = r.Str();
      c.seq = r.Varint();
      c.candidate = victim_id();
      c.viewer_x_m = r.F64();
      c.viewer_y_m = r.F64();
      c.viewer_height_m = r.F64();
      c.t_s = r.F64();
      cmd = std::move(c);
      break;
    }
    case 10: {
      RequestRevisit c;
      c.candidate = victim_id();
      c.drone = r.Str();
      c.t_s = r.F64();
      cmd = std::move(c);
      break;
    }
    case 11: {
      ConfirmSighting c;
      c.candidate = victim_id();
      c.belief = r.F64();
      cmd = c;
      break;
    }
    case 12: {
      RejectSighting c;
      c.candidate = victim_id();
      c.belief = r.F64();
      cmd = c;
      break;
    }
    default:
      return Error(ErrorCode::kProtocol, "unknown command kind " + std::to_string(kind),
                   "mission command");
  }
  if (!r.ok()) return Error(ErrorCode::kProtocol, r.error(), "mission command");
  if (!r.at_end()) {
    return Error(ErrorCode::kProtocol, std::to_string(r.remaining()) + " trailing bytes",
                 "mission command");
  }
  return cmd;
}

}  // namespace swarmbox::raft
