// Test brain library B (brain_loader_test): one brain, loaded next to library A; its table must
// hold "beta" only.
#include <string>

#include "swarmbox/brain/brain.hpp"

namespace {

namespace sb = swarmbox::brain;

class Beta final : public sb::Brain {
 public:
  explicit Beta(const sb::Context& ctx) : self_(ctx.self) {}
  void Step(const sb::Input& /*in*/, sb::Output& out) override {
    std::string names;
    for (const sb::Registration& r : sb::LibraryRegistry()) names += (names.empty() ? "" : ",") + std::string(r.name);
    out.status = "beta/" + self_ + "/" + names;
  }

 private:
  std::string self_;
};

}  // namespace

SWARMBOX_BRAIN("beta", Beta)
