#include "swarmbox/raft/mission_command.hpp"

#include <optional>
#include <utility>
#include <variant>

#include "swarmbox/raft/detail/byte_io.hpp"
#include "swarmbox/raft/detail/mission_io.hpp"

namespace swarmbox::raft {

std::string_view CommandName(const MissionCommand& command) {
  static constexpr std::string_view kNames[] = {
      "start_search", "assign_sectors", "report_sighting", "confirm_victim", "converge_on",
      "begin_rescue", "mark_rescued",   "return_home",     "complete_mission", "report_miss",
      "request_revisit", "confirm_sighting", "reject_sighting"};
  return kNames[command.index()];
}

namespace {

using detail::ByteReader;
using detail::ByteWriter;

// One body writer and reader per command, in the order of the fields on the wire.
void WriteBody(ByteWriter&, const StartSearch&) {}
void WriteBody(ByteWriter& w, const AssignSectors& c) { detail::WriteSectors(w, c.sectors); }
void WriteBody(ByteWriter& w, const ReportSighting& c) { detail::WriteSighting(w, c); }
void WriteBody(ByteWriter& w, const ConfirmVictim& c) {
  w.Str(c.by);
  w.F64(c.x_m);
  w.F64(c.y_m);
}
void WriteBody(ByteWriter& w, const ConvergeOn& c) { w.Varint(c.victim_id); }
void WriteBody(ByteWriter& w, const BeginRescue& c) {
  w.Varint(c.victim_id);
  w.Str(c.lifter);
}
void WriteBody(ByteWriter& w, const MarkRescued& c) { w.Varint(c.victim_id); }
void WriteBody(ByteWriter&, const ReturnHome&) {}
void WriteBody(ByteWriter&, const CompleteMission&) {}
void WriteBody(ByteWriter& w, const ReportMiss& c) {
  w.Str(c.reporter);
  w.Varint(c.seq);
  w.Varint(c.candidate);
  detail::WriteViewpoint(w, c);
}
void WriteBody(ByteWriter& w, const RequestRevisit& c) {
  w.Varint(c.candidate);
  w.Str(c.drone);
  w.F64(c.t_s);
}
void WriteBody(ByteWriter& w, const ConfirmSighting& c) {
  w.Varint(c.candidate);
  w.F64(c.belief);
}
void WriteBody(ByteWriter& w, const RejectSighting& c) {
  w.Varint(c.candidate);
  w.F64(c.belief);
}

// A victim or candidate id: a varint that must fit 32 bits.
std::uint32_t ReadId(ByteReader& r) {
  const std::uint64_t v = r.Varint();
  if (v > UINT32_MAX) r.Fail("victim id out of range");
  return static_cast<std::uint32_t>(v);
}

void ReadBody(ByteReader&, StartSearch*) {}
void ReadBody(ByteReader& r, AssignSectors* c) { c->sectors = detail::ReadSectors(r); }
void ReadBody(ByteReader& r, ReportSighting* c) { *c = detail::ReadSighting<ReportSighting>(r); }
void ReadBody(ByteReader& r, ConfirmVictim* c) {
  c->by = r.Str();
  c->x_m = r.F64();
  c->y_m = r.F64();
}
void ReadBody(ByteReader& r, ConvergeOn* c) { c->victim_id = ReadId(r); }
void ReadBody(ByteReader& r, BeginRescue* c) {
  c->victim_id = ReadId(r);
  c->lifter = r.Str();
}
void ReadBody(ByteReader& r, MarkRescued* c) { c->victim_id = ReadId(r); }
void ReadBody(ByteReader&, ReturnHome*) {}
void ReadBody(ByteReader&, CompleteMission*) {}
void ReadBody(ByteReader& r, ReportMiss* c) {
  c->reporter = r.Str();
  c->seq = r.Varint();
  c->candidate = ReadId(r);
  detail::ReadViewpoint(r, c);
}
void ReadBody(ByteReader& r, RequestRevisit* c) {
  c->candidate = ReadId(r);
  c->drone = r.Str();
  c->t_s = r.F64();
}
void ReadBody(ByteReader& r, ConfirmSighting* c) {
  c->candidate = ReadId(r);
  c->belief = r.F64();
}
void ReadBody(ByteReader& r, RejectSighting* c) {
  c->candidate = ReadId(r);
  c->belief = r.F64();
}

// The command of variant index I (the wire's kind byte).
template <std::size_t I>
MissionCommand ReadKind(ByteReader& r) {
  std::variant_alternative_t<I, MissionCommand> c;
  ReadBody(r, &c);
  return c;
}

// The command whose kind byte is `kind`, read from `r`; nullopt for an unknown kind.
template <std::size_t... I>
std::optional<MissionCommand> ReadCommand(ByteReader& r, std::uint8_t kind, std::index_sequence<I...>) {
  std::optional<MissionCommand> cmd;
  ((kind == I ? (void)(cmd = ReadKind<I>(r)) : void()), ...);
  return cmd;
}

}  // namespace

Bytes EncodeCommand(const MissionCommand& command) {
  Bytes out;
  ByteWriter w(&out);
  w.U8(kCommandVersion);
  w.U8(static_cast<std::uint8_t>(command.index()));
  std::visit([&w](const auto& c) { WriteBody(w, c); }, command);
  return out;
}

Result<MissionCommand> DecodeCommand(std::span<const std::uint8_t> bytes) {
  ByteReader r(bytes);
  const std::uint8_t version = r.U8();
  const std::uint8_t kind = r.U8();
  if (!r.ok()) return Error(ErrorCode::kProtocol, r.error(), "mission command");
  if (version != kCommandVersion) {
    return Error(ErrorCode::kProtocol, "unsupported command version " + std::to_string(version),
                 "mission command");
  }
  std::optional<MissionCommand> cmd =
      ReadCommand(r, kind, std::make_index_sequence<std::variant_size_v<MissionCommand>>());
  if (!cmd) {
    return Error(ErrorCode::kProtocol, "unknown command kind " + std::to_string(kind),
                 "mission command");
  }
  if (!r.ok()) return Error(ErrorCode::kProtocol, r.error(), "mission command");
  if (!r.at_end()) {
    return Error(ErrorCode::kProtocol, std::to_string(r.remaining()) + " trailing bytes",
                 "mission command");
  }
  return std::move(*cmd);
}

}  // namespace swarmbox::raft
