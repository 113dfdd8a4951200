#include "swarmbox/dsl/trial.hpp"

#include <utility>

namespace swarmbox::dsl {

Trial::Trial(std::string name, std::string run_id)
    : Component(std::move(name)), run_id_(std::move(run_id)) {}

Trial& Trial::EndOn(std::string pattern, Outcome outcome, std::string reason,
                    std::string component) {
  end_.push_back({std::move(pattern), outcome, std::move(reason), std::move(component)});
  return *this;
}

Trial& Trial::SetTimeout(TimeoutPolicy policy) {
  timeout_ = std::move(policy);
  return *this;
}

Plugin* Trial::FindPlugin(std::string_view id) {
  for (Plugin* p : Plugins()) {
    if (p->id() == id) return p;
  }
  return nullptr;
}

Network* Trial::FindNetwork(std::string_view id) {
  for (Network* n : Networks()) {
    if (n->id() == id) return n;
  }
  return nullptr;
}

Verdict Trial::Start(Engine& engine) {
  Verdict v = Dispatch(EventKind::kBuild, engine);
  if (!v.ok()) return v;
  return Dispatch(EventKind::kRun, engine);
}

Verdict Trial::Stop(Engine& engine) { return Dispatch(EventKind::kStop, engine); }

Verdict Trial::Restart(Engine& engine) {
  ++restarts_;
  restart_requested_ = false;
  restart_reason_.clear();
  end_verdict_.reset();
  Verdict v = Stop(engine);
  if (!v.ok()) return v;
  return Start(engine);
}

bool Trial::OnShutdown(const Verdict& verdict) {
  if (!end_verdict_) end_verdict_ = verdict;
  return true;
}

bool Trial::OnRestart(const std::string& reason, const std::string& source) {
  if (!restart_requested_) {
    restart_requested_ = true;
    restart_reason_ = reason + " (" + source + ")";
  }
  return true;
}

}  // namespace swarmbox::dsl
