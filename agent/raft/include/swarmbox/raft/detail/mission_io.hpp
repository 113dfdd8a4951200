// The field layouts that mission commands (mission_command.cpp) and mission snapshots
// (mission_state.cpp) share, so both encodings stay byte-for-byte the same where they overlap:
//   sector list: varint count | per sector: str drone | f64 x_min y_min x_max y_max
//   sighting:    str reporter | varint seq | f64 x | f64 y | f64 confidence | viewpoint
//   viewpoint:   f64 viewer_x | f64 viewer_y | f64 viewer_height | f64 t  (a sighting's, a miss's)
// The readers follow ByteReader's rule: on malformed input they stop and leave the error latched
// in the reader (check r.ok() afterwards).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "swarmbox/raft/detail/byte_io.hpp"
#include "swarmbox/raft/mission_command.hpp"

namespace swarmbox::raft::detail {

inline void WriteSectors(ByteWriter& w, const std::vector<Sector>& sectors) {
  w.Varint(sectors.size());
  for (const Sector& s : sectors) {
    w.Str(s.drone);
    w.F64(s.x_min_m);
    w.F64(s.y_min_m);
    w.F64(s.x_max_m);
    w.F64(s.y_max_m);
  }
}

inline std::vector<Sector> ReadSectors(ByteReader& r) {
  std::vector<Sector> sectors;
  const std::uint64_t n = r.Count(33, "sector");
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    Sector s;
    s.drone = r.Str();
    s.x_min_m = r.F64();
    s.y_min_m = r.F64();
    s.x_max_m = r.F64();
    s.y_max_m = r.F64();
    sectors.push_back(std::move(s));
  }
  return sectors;
}

// Where the camera was and when: S is ReportSighting, SightingView or ReportMiss.
template <class S>
void WriteViewpoint(ByteWriter& w, const S& s) {
  w.F64(s.viewer_x_m);
  w.F64(s.viewer_y_m);
  w.F64(s.viewer_height_m);
  w.F64(s.t_s);
}

template <class S>
void ReadViewpoint(ByteReader& r, S* s) {
  s->viewer_x_m = r.F64();
  s->viewer_y_m = r.F64();
  s->viewer_height_m = r.F64();
  s->t_s = r.F64();
}

// S is ReportSighting (a command) or SightingView (evidence in the snapshot): same fields.
template <class S>
void WriteSighting(ByteWriter& w, const S& s) {
  w.Str(s.reporter);
  w.Varint(s.seq);
  w.F64(s.x_m);
  w.F64(s.y_m);
  w.F64(s.confidence);
  WriteViewpoint(w, s);
}

template <class S>
S ReadSighting(ByteReader& r) {
  S s;
  s.reporter = r.Str();
  s.seq = r.Varint();
  s.x_m = r.F64();
  s.y_m = r.F64();
  s.confidence = r.F64();
  ReadViewpoint(r, &s);
  return s;
}

}  // namespace swarmbox::raft::detail
