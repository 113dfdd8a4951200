// netem's random numbers, for the userspace delayer: correlated uniforms and the delay
// distributions (uniform, normal, pareto, paretonormal), as the kernel's sch_netem draws them.
//
// - CorrelatedUniform is netem's get_crandom(): next = (u * (2^32 - rho) + last * rho) >> 32 with
//   rho = correlation * 2^32, so correlation 0 gives independent draws and 1 repeats the first.
// - DelayDistribution shapes jitter around the mean like netem's tabledist(): uniform is
//   mu +- sigma; normal, pareto and paretonormal invert the distribution iproute2's tables were
//   generated from (normal(0,1); pareto with a = 3 normalised as (x - 1.5) * 4/3;
//   paretonormal = (3 * pareto + normal) / 4 at the same quantile), clamped to +-4 sigma as the
//   16-bit tables are. A negative result is clamped to 0 (sent at once).
//
// The generator is std::mt19937 (its output is fixed by the C++ standard), so a seed gives the same
// sequence everywhere.
#pragma once

#include <cstdint>
#include <random>

#include "swarmbox/faults/netem_spec.hpp"

namespace swarmbox::faults {

class CorrelatedUniform {
 public:
  CorrelatedUniform(double correlation, std::mt19937& rng);
  std::uint32_t Next();

 private:
  std::uint64_t rho_;
  std::uint32_t last_;
  std::mt19937& rng_;
};

// The standardised quantile z(u) of `distribution` for u in (0, 1) (uniform: 2u - 1, in [-1, 1]).
double DistributionQuantile(DelayDistribution distribution, double u);

// One delay [us]: mean mu_us, spread sigma_us, from the 32-bit (possibly correlated) draw `rnd`.
// Never negative.
std::int64_t SampleDelayUs(std::int64_t mu_us, std::int64_t sigma_us, DelayDistribution distribution,
                           std::uint32_t rnd);

}  // namespace swarmbox::faults
