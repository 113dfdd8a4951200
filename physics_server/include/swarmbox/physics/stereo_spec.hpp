// The physics server's names for the airframe's `stereo:` section (the OAK-D Pro's stereo pair and
// dot projector): swarmbox/airframe/stereo_spec.hpp, parsed with the rest of the airframe.
#pragma once

#include "swarmbox/airframe/stereo_spec.hpp"
#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

using airframe::ParseStereoSpec;
using airframe::ProjectorSpec;
using airframe::StereoSpec;

}  // namespace swarmbox::physics
