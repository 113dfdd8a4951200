// What the simulated radio channel (`radio.model: channel`) carries out of the trial's radio
// impairments, checked before anything starts (ARCHITECTURE.md "Two networks per trial, two radio
// models"; the radio plan the physics server reads: runner/radio_schedule.hpp).
//
// The channel impairs each sender's egress, one draw per frame, as netem does on an interface:
// delay_ms, jitter_ms with its distribution, loss, duplicate, rate_kbit. It refuses, with the
// reason, what it does not model: per-destination rules (`to`, `rules:`), delay and loss
// correlation, Gilbert-Elliott loss, reordering (reorder, reorder_gap, reorder_correlation),
// corruption (a frame arrives whole or not at all), a netem queue `limit` (the profile's
// queue_frames bounds each sender's queue). And it takes radio faults and partitions at simulated
// times only (`at:`): one triggered by a log event (`on:`) or a wall time (`at_wall:`) has no
// simulated time to land on. `radio.model: netem` does all of these.
//
//   SWARMBOX_TRY(CheckChannelSupports(spec.mesh.rules, "network.mesh"));
//   SWARMBOX_TRY(CheckChannelFaults(spec.faults));
//
// Errors are kInvalidArgument at the rule's (or fault's) file:line:col.
#pragma once

#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/faults/fault_spec.hpp"
#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

// Rules of one impairment (network.mesh, or one radio fault): at most one, for all traffic.
// `what` names it in messages ("network.mesh", "fault scout_1_fade").
Status CheckChannelSupports(const std::vector<RadioRule>& rules, std::string_view what);

// Every radio fault's rules, that radio faults and partitions start at a simulated time, and that
// the faults at simulated times (the radio plan's entries) have unique one-word names.
Status CheckChannelFaults(const std::vector<Fault>& faults);

}  // namespace swarmbox::faults
