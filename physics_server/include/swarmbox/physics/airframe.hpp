// The physics server's names for the shared airframe model (airframe/: parsed and validated once,
// for the physics server and the agent alike). What the world simulates of it: see
// swarmbox/airframe/airframe.hpp and physics_server/README.md.
#pragma once

#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

using airframe::Airframe;
using airframe::BaroSpec;
using airframe::CameraSpec;
using airframe::GpsFix;
using airframe::GpsSpec;
using airframe::ImuSpec;
using airframe::kRtkMaxRateHz;
using airframe::LoadAirframe;
using airframe::MagSpec;
using airframe::MotorSpec;
using airframe::ParseAirframe;
using airframe::PayloadSpec;
using airframe::RotorSpec;
using airframe::SetRtkFix;

}  // namespace swarmbox::physics
