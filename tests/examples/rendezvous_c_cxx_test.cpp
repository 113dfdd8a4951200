// The two rendezvous brains agree bit for bit: the C program's protocol (examples/c_brain/
// rendezvous.c, linked here as C) and the C++ example brain (examples/brains/rendezvous), given the
// same committed `pos` entries, compute the same rendezvous point and the same slot for every
// member, to the last bit. Both directly (rv_place_ring against PlaceRing on the same doubles) and
// through the brains (the entries' text parsed by each, the slot setpoint each answers with), on
// hand-picked layouts (two drones on a line, "-0.000", a drone on the point, equal bearings, one
// spot, 64 members) and 600 seeded random ones (scattered, clustered within centimetres, with
// repeated positions). Built with -ffp-contract=off as both brains are.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "rendezvous.h"
#include "rendezvous_brain.hpp"

namespace swarmbox {
namespace {

namespace sb = swarmbox::brain;

struct Layout {
  std::string what;
  std::vector<double> x;  // as written in the `pos` entries (%.3f) and read back
  std::vector<double> y;
};

std::string Hex(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

std::string Fixed3(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// Member i's name: "m00", "m01", ... (sorted order = index order).
std::string Name(std::size_t i) { return (i < 10 ? "m0" : "m") + std::to_string(i); }

std::vector<std::string> PosEntries(const Layout& l) {
  std::vector<std::string> entries;
  for (std::size_t i = 0; i < l.x.size(); ++i) {
    entries.push_back("pos " + Name(i) + " " + Fixed3(l.x[i]) + " " + Fixed3(l.y[i]));
  }
  return entries;
}

// The coordinates as both brains read them back from the entries.
Layout ReadBack(Layout l) {
  for (double& v : l.x) v = std::strtod(Fixed3(v).c_str(), nullptr);
  for (double& v : l.y) v = std::strtod(Fixed3(v).c_str(), nullptr);
  return l;
}

std::vector<Layout> HandPicked() {
  std::vector<Layout> layouts = {
      {"two on a line", {0.0, 8.0}, {0.0, 0.0}},
      {"two on a line, -0.000", {0.0, 8.0}, {-0.0, 0.0}},
      {"two north-south", {0.0, 0.0}, {8.0, 0.0}},
      {"one alone", {3.0, 0.0}, {4.0, 0.0}},
      {"a drone on the point", {0.0, 5.0, 10.0}, {0.0, 0.0, 0.0}},
      {"just off the point", {0.0, 5.0, 10.0}, {0.01, 0.03, -0.04}},
      {"equal bearings", {1.0, 2.0, -3.0}, {1.0, 2.0, -3.0}},
      {"all on one spot", {1.0, 1.0, 1.0}, {1.0, 1.0, 1.0}},
      {"c_brain_test's three", {0.0, 1.234, 3.0}, {0.0, -2.5, 6.0}},
      {"c_brain_rendezvous_test's three", {0.0, 0.0, 30.0}, {0.0, 30.0, 0.0}},
  };
  layouts[3].x.resize(1);
  layouts[3].y.resize(1);
  Layout many{"64 on a spiral", {}, {}};
  for (std::size_t i = 0; i < RV_MAX_MEMBERS; ++i) {
    const double fi = static_cast<double>(i);
    many.x.push_back(fi * std::cos(fi));
    many.y.push_back(-fi * std::sin(fi) + 100.0);
  }
  layouts.push_back(many);
  return layouts;
}

// Seeded: scattered over +-100 m, clustered within +-2 cm (the 0.01 m rule at work), or with some
// members on the same spot as another (equal bearings, several centred).
std::vector<Layout> Random(std::size_t count) {
  std::mt19937_64 rng(24);
  std::vector<Layout> layouts;
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t n = 1 + static_cast<std::size_t>(rng() % 12);
    const int kind = static_cast<int>(k % 3);
    Layout l{"random " + std::to_string(k), {}, {}};
    for (std::size_t i = 0; i < n; ++i) {
      const auto mm = [&](std::uint64_t span) {
        const auto mm_from_zero =
            static_cast<std::int64_t>(rng() % (2 * span + 1)) - static_cast<std::int64_t>(span);
        return static_cast<double>(mm_from_zero) / 1000.0;
      };
      if (kind == 2 && i > 0 && rng() % 3 == 0) {
        const std::size_t twin = static_cast<std::size_t>(rng() % i);
        l.x.push_back(l.x[twin]);
        l.y.push_back(l.y[twin]);
      } else {
        const std::uint64_t span = kind == 1 ? 20 : 100'000;
        l.x.push_back(mm(span));
        l.y.push_back(mm(span));
      }
    }
    layouts.push_back(l);
  }
  return layouts;
}

// The C brain's answer for member `self` once every entry is committed: its slot and P's text.
struct Answer {
  double slot_x = 0.0;
  double slot_y = 0.0;
  std::string point;
};

Answer CBrain(const std::vector<std::string>& entries, std::size_t n, std::size_t self) {
  rv_config c{};
  c.altitude_m = 10.0;
  c.radius_m = 6.0;
  c.hold_s = 5.0;
  c.n_members = n;
  for (std::size_t i = 0; i < n; ++i) std::snprintf(c.members[i], sizeof c.members[i], "%s", Name(i).c_str());
  c.self = self;
  rv_state s;
  rv_init(&s, &c);
  for (const std::string& e : entries) {
    rv_apply_entry(&s, reinterpret_cast<const std::uint8_t*>(e.data()), e.size());
  }
  rv_input in{.t_ns = 0,
              .position_enu_m = {0.0, 0.0, 0.0},
              .flight_mode = "idle",
              .landed = true,
              .hover_event = false,
              .rejected_event = false,
              .landed_event = false};
  rv_output out;
  rv_step(&s, &in, &out);  // takeoff
  in = {.t_ns = 20'000'000,
        .position_enu_m = {0.0, 0.0, 10.0},
        .flight_mode = "hold",
        .landed = false,
        .hover_event = true,
        .rejected_event = false,
        .landed_event = false};
  rv_step(&s, &in, &out);
  EXPECT_TRUE(out.has_setpoint);
  EXPECT_EQ(out.n_events, 1u);
  if (!out.has_setpoint || out.n_events != 1) return {};
  return {out.setpoint_enu_m[0], out.setpoint_enu_m[1],
          std::string(out.events[0].fields[0].value) + "," + out.events[0].fields[1].value};
}

Answer CxxBrain(const std::vector<std::string>& entries, std::size_t n, std::size_t self) {
  sb::Context ctx;
  ctx.self = Name(self);
  for (std::size_t i = n; i-- > 0;) ctx.members.push_back(Name(i));  // unsorted: it sorts them
  ctx.args = {{"altitude_m", "10"}, {"radius_m", "6"}, {"hold_s", "5"}};
  rendezvous::RendezvousBrain brain(ctx);
  sb::Input in;
  in.self.landed = true;
  in.self.flight_mode = "idle";
  sb::Output out;
  brain.Step(in, out);  // takeoff
  std::vector<sb::Entry> committed;
  committed.reserve(entries.size());
  std::uint64_t index = 0;
  for (const std::string& e : entries) committed.push_back({++index, {e.begin(), e.end()}});
  const std::vector<sb::FlightEvent> hover = {{"hover", 0, {}}};
  in.committed = committed;
  in.flight_events = hover;
  in.t_ns = 20'000'000;
  in.self.landed = false;
  in.self.flight_mode = "hold";
  in.self.position_m = {0.0, 0.0, 10.0};
  out.Clear();
  brain.Step(in, out);
  EXPECT_EQ(out.setpoint.size(), 1u);
  EXPECT_EQ(out.events.size(), 1u);
  if (out.setpoint.size() != 1 || out.events.size() != 1) return {};
  return {out.setpoint[0].position_m.x, out.setpoint[0].position_m.y,
          out.events[0].fields[0].second + "," + out.events[0].fields[1].second};
}

// Compares both ways on `l`; returns how many slots were compared.
std::size_t ExpectSameRing(const Layout& written) {
  SCOPED_TRACE(written.what);
  const Layout l = ReadBack(written);
  const std::size_t n = l.x.size();

  double point[2];
  std::vector<double> cx(n);
  std::vector<double> cy(n);
  rv_place_ring(n, l.x.data(), l.y.data(), 6.0, point, cx.data(), cy.data());
  const rendezvous::Ring ring = rendezvous::PlaceRing(l.x, l.y, 6.0, 10.0);
  EXPECT_EQ(Hex(point[0]), Hex(ring.px));
  EXPECT_EQ(Hex(point[1]), Hex(ring.py));
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(cx[i]), std::bit_cast<std::uint64_t>(ring.slots[i].x))
        << "member " << i << ": C " << Hex(cx[i]) << ", C++ " << Hex(ring.slots[i].x);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(cy[i]), std::bit_cast<std::uint64_t>(ring.slots[i].y))
        << "member " << i << ": C " << Hex(cy[i]) << ", C++ " << Hex(ring.slots[i].y);
  }

  // Through the brains, from the entries' text: every member for up to 12, some for more.
  const std::vector<std::string> entries = PosEntries(written);
  const std::size_t step = n <= 12 ? 1 : 7;
  for (std::size_t self = 0; self < n; self += step) {
    const Answer c = CBrain(entries, n, self);
    const Answer cxx = CxxBrain(entries, n, self);
    EXPECT_EQ(Hex(c.slot_x), Hex(cxx.slot_x)) << Name(self);
    EXPECT_EQ(Hex(c.slot_y), Hex(cxx.slot_y)) << Name(self);
    EXPECT_EQ(Hex(c.slot_x), Hex(cx[self])) << Name(self);
    EXPECT_EQ(Hex(c.slot_y), Hex(cy[self])) << Name(self);
    EXPECT_EQ(c.point, cxx.point) << Name(self);
  }
  return n;
}

TEST(RendezvousCAndCxx, HandPickedLayoutsGiveTheSameRingBitForBit) {
  std::size_t slots = 0;
  for (const Layout& l : HandPicked()) slots += ExpectSameRing(l);
  EXPECT_GT(slots, 80u);
}

TEST(RendezvousCAndCxx, SeededRandomLayoutsGiveTheSameRingBitForBit) {
  std::size_t slots = 0;
  const std::vector<Layout> layouts = Random(600);
  for (const Layout& l : layouts) slots += ExpectSameRing(l);
  std::cout << layouts.size() << " random layouts: " << slots << " slots equal bit for bit in C and C++\n";
}

}  // namespace
}  // namespace swarmbox
