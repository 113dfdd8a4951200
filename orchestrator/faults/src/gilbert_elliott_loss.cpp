#include "swarmbox/faults/gilbert_elliott_loss.hpp"

namespace swarmbox::faults {

GilbertElliottLoss::GilbertElliottLoss(const GilbertElliott& model, std::uint64_t seed)
    : model_(model), rng_(seed ^ 0x6765'6d6f'6465'6c00ULL) {}  // "gemodel": not the delay stream

bool GilbertElliottLoss::Chance(double probability) {
  if (probability <= 0.0) return false;
  if (probability >= 1.0) return true;
  return std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < probability;
}

bool GilbertElliottLoss::Lose() {
  // netem's loss_gilb_ell(): the transition is drawn first, the loss with the old state's odds.
  if (!bad_) {
    bad_ = Chance(model_.p);
    return Chance(model_.loss_good);
  }
  bad_ = !Chance(model_.r);
  return Chance(model_.loss_bad);
}

double StationaryLoss(const GilbertElliott& model) {
  const double sum = model.p + model.r;
  if (sum <= 0.0) return model.loss_good;
  return (model.r * model.loss_good + model.p * model.loss_bad) / sum;
}

}  // namespace swarmbox::faults
