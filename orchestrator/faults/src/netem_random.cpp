#include "swarmbox/faults/netem_random.hpp"

#include <algorithm>
#include <cmath>

namespace swarmbox::faults {
namespace {

constexpr double kTableClamp = 32767.0 / 8192.0;  // netem tables are int16 scaled by 8192

// Acklam's rational approximation of the standard normal quantile (|error| < 1.2e-9).
double NormalQuantile(double p) {
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                                 1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                                 6.680131188771972e+01,  -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                                 -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                                 3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  if (p < kLow) {
    const double q = std::sqrt(-2 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  if (p > 1 - kLow) {
    const double q = std::sqrt(-2 * std::log(1 - p));
    return -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  const double q = p - 0.5;
  const double r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
}

// iproute2 paretonormal.c / pareto.c: a = 3, x = 1 / (1 - u)^(1/a), (x - 1.5) * 4/3.
double ParetoQuantile(double u) { return (1.0 / std::pow(1.0 - u, 1.0 / 3.0) - 1.5) * (4.0 / 3.0); }

}  // namespace

CorrelatedUniform::CorrelatedUniform(double correlation, std::mt19937& rng)
    : rho_(static_cast<std::uint64_t>(std::clamp(correlation, 0.0, 1.0) * 4294967295.0)),
      last_(static_cast<std::uint32_t>(rng())),
      rng_(rng) {}

std::uint32_t CorrelatedUniform::Next() {
  const std::uint64_t value = rng_();
  if (rho_ == 0) return static_cast<std::uint32_t>(value);
  const std::uint64_t rho = rho_ + 1;  // as netem: rho in [1, 2^32]
  const std::uint64_t answer = (value * ((1ULL << 32) - rho) + static_cast<std::uint64_t>(last_) * rho) >> 32;
  last_ = static_cast<std::uint32_t>(answer);
  return last_;
}

double DistributionQuantile(DelayDistribution distribution, double u) {
  u = std::clamp(u, 1e-9, 1.0 - 1e-9);
  double z = 0.0;
  switch (distribution) {
    case DelayDistribution::kUniform: return 2.0 * u - 1.0;
    case DelayDistribution::kNormal: z = NormalQuantile(u); break;
    case DelayDistribution::kPareto: z = ParetoQuantile(u); break;
    case DelayDistribution::kParetoNormal: z = (3.0 * ParetoQuantile(u) + NormalQuantile(u)) / 4.0; break;
  }
  return std::clamp(z, -kTableClamp, kTableClamp);
}

std::int64_t SampleDelayUs(std::int64_t mu_us, std::int64_t sigma_us, DelayDistribution distribution,
                           std::uint32_t rnd) {
  if (sigma_us <= 0) return std::max<std::int64_t>(mu_us, 0);
  const double u = (static_cast<double>(rnd) + 0.5) / 4294967296.0;
  const double delay = static_cast<double>(mu_us) +
                       static_cast<double>(sigma_us) * DistributionQuantile(distribution, u);
  return std::max<std::int64_t>(0, std::llround(delay));
}

}  // namespace swarmbox::faults
