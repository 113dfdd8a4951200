#include "swarmbox/dsl/component.hpp"

#include <algorithm>

namespace swarmbox::dsl {

std::string_view EventName(EventKind event) {
  switch (event) {
    case EventKind::kBuild: return "build";
    case EventKind::kRun: return "run";
    case EventKind::kStop: return "stop";
    case EventKind::kShutdown: return "shutdown";
    case EventKind::kRestart: return "restart";
  }
  return "?";
}

std::string_view StateName(Module::State state) {
  switch (state) {
    case Module::State::kDeclared: return "declared";
    case Module::State::kBuilt: return "built";
    case Module::State::kRunning: return "running";
    case Module::State::kStopped: return "stopped";
  }
  return "?";
}

Component::Component(std::string id, int run_priority)
    : id_(std::move(id)), run_priority_(run_priority) {
  SWARMBOX_CHECK(!id_.empty());
  SWARMBOX_CHECK(run_priority_ >= kMinRunPriority && run_priority_ <= kMaxRunPriority);
}

Component::~Component() = default;

void Component::set_run_priority(int priority) {
  SWARMBOX_CHECK(priority >= kMinRunPriority && priority <= kMaxRunPriority);
  run_priority_ = priority;
}

std::string Component::Path() const {
  return parent_ == nullptr ? id_ : parent_->Path() + "/" + id_;
}

Component& Component::Root() {
  Component* c = this;
  while (c->parent_ != nullptr) c = c->parent_;
  return *c;
}

void Component::Adopt(std::unique_ptr<Component> child) {
  for (const auto& c : children_) SWARMBOX_CHECK(c->id() != child->id());
  child->parent_ = this;
  children_.push_back(std::move(child));
}

Component* Component::Find(std::string_view id) {
  if (id_ == id) return this;
  for (const auto& c : children_) {
    if (Component* found = c->Find(id)) return found;
  }
  return nullptr;
}

std::vector<Component*> Component::RunOrder() const {
  std::vector<Component*> order;
  order.reserve(children_.size());
  for (const auto& c : children_) order.push_back(c.get());
  std::stable_sort(order.begin(), order.end(), [](const Component* a, const Component* b) {
    return a->run_priority() < b->run_priority();
  });
  return order;
}

namespace {

// Consecutive runs of equal priority in a run order.
std::vector<std::vector<Component*>> Levels(const std::vector<Component*>& order) {
  std::vector<std::vector<Component*>> levels;
  for (Component* c : order) {
    if (levels.empty() || levels.back().front()->run_priority() != c->run_priority()) {
      levels.emplace_back();
    }
    levels.back().push_back(c);
  }
  return levels;
}

}  // namespace

Verdict Component::DispatchLevel(const std::vector<Component*>& level, EventKind event,
                                 Engine& engine) {
  if (level.size() == 1) return level.front()->Dispatch(event, engine);
  std::vector<std::function<Verdict()>> steps;
  steps.reserve(level.size());
  for (Component* c : level) {
    steps.emplace_back([c, event, &engine] { return c->Dispatch(event, engine); });
  }
  return engine.RunSiblings(steps, /*stop_on_failure=*/event != EventKind::kStop);
}

Verdict Component::Dispatch(EventKind event, Engine& engine) {
  SWARMBOX_CHECK(event == EventKind::kBuild || event == EventKind::kRun ||
                 event == EventKind::kStop);
  const std::vector<std::vector<Component*>> levels = Levels(RunOrder());
  if (event == EventKind::kStop) {
    Verdict v;
    for (auto level = levels.rbegin(); level != levels.rend(); ++level) {
      // Within a level too, the last added stops first (when the engine goes one by one).
      v.KeepWorse(DispatchLevel(std::vector<Component*>(level->rbegin(), level->rend()), event,
                                engine));
    }
    v.KeepWorse(Handle(event, engine));
    return v;
  }
  Verdict v = Handle(event, engine);
  if (!v.ok()) return v;
  for (const std::vector<Component*>& level : levels) {
    v.KeepWorse(DispatchLevel(level, event, engine));
    if (!v.ok()) break;
  }
  return v;
}

bool Component::RaiseShutdown(Verdict verdict) {
  if (verdict.source.empty()) verdict.source = Path();
  for (Component* c = this; c != nullptr; c = c->parent_) {
    if (c->OnShutdown(verdict)) return true;
  }
  return false;
}

bool Component::RaiseRestart(std::string reason) {
  const std::string source = Path();
  for (Component* c = this; c != nullptr; c = c->parent_) {
    if (c->OnRestart(reason, source)) return true;
  }
  return false;
}

Verdict Component::Handle(EventKind /*event*/, Engine& /*engine*/) { return Verdict::Success(); }
bool Component::OnShutdown(const Verdict& /*verdict*/) { return false; }
bool Component::OnRestart(const std::string& /*reason*/, const std::string& /*source*/) {
  return false;
}

Verdict Module::Handle(EventKind event, Engine& engine) {
  Verdict v;
  switch (event) {
    case EventKind::kBuild:
      if (state_ != State::kDeclared && state_ != State::kStopped) {
        v = Verdict::Err("cannot build " + Path() + ": it is " + std::string(StateName(state_)),
                         Path());
        break;
      }
      v = DoBuild(engine);
      if (v.ok()) state_ = State::kBuilt;
      break;
    case EventKind::kRun:
      if (state_ != State::kBuilt) {
        v = Verdict::Err("cannot run " + Path() + ": it is " + std::string(StateName(state_)),
                         Path());
        break;
      }
      v = DoRun(engine);
      // A failed start may still have left a process behind: Stop must see it.
      state_ = State::kRunning;
      break;
    case EventKind::kStop:
      if (state_ != State::kBuilt && state_ != State::kRunning) return v;  // nothing to undo
      v = DoStop(engine);
      state_ = State::kStopped;
      break;
    case EventKind::kShutdown:
    case EventKind::kRestart:
      SWARMBOX_CHECK(false);
  }
  if (!v.ok() && v.source.empty()) v.source = Path();
  engine.Trace(*this, event, v);
  return v;
}

void Engine::Trace(const Component& /*component*/, EventKind /*event*/,
                   const Verdict& /*verdict*/) {}

Verdict Engine::RunSiblings(const std::vector<std::function<Verdict()>>& steps,
                            bool stop_on_failure) {
  Verdict v;
  for (const auto& step : steps) {
    v.KeepWorse(step());
    if (stop_on_failure && !v.ok()) break;
  }
  return v;
}

}  // namespace swarmbox::dsl
