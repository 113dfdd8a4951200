// The component tree of the DSL (the thesis design, kept): every part of a trial is a Component
// with an id, a parent and children; a Module is a Component with a life cycle; Plugin (a
// container) and Network are Modules; Trial is the root of one trial, Experiment groups trials.
//
// Lifecycle events (pure: every side effect goes through the Engine interface):
//   Build, Run  propagate DOWN: the component handles the event, then its children in run order
//               (run priority 0 first, 63 last; ties in the order they were added). The walk stops
//               at the first result that is not success (nothing is built on a broken base).
//   Stop        propagates DOWN in reverse run order (highest first, the component itself last) and is
//               best-effort: every module that was built is stopped even when others fail.
// Siblings of equal run priority form a level; a level is handed to Engine::RunSiblings, which
// may run its steps at once (the Docker engine does): a level then starts only once the level
// before it has finished (a container with a readiness pattern is ready), and a failure stops the
// walk after its level (its siblings of the same level may have run too; Stop undoes them).
//   Shutdown,   propagate UP from the component that raised them, through each ancestor's
//   Restart     OnShutdown()/OnRestart() until one consumes it (a Trial does).
// Every walk returns the worst Verdict of its steps (outcome.hpp).
//
//   Trial trial("demo");
//   auto& sim = trial.Add<Network>("sim", NetworkSpec::Subnet("demo-sim", "10.77.3.0/24"));
//   trial.Add<Plugin>("physics", ContainerSpec::Image("swarmbox/physics:1"), 1).On(sim, "10.77.3.2");
//   Verdict v = trial.Start(engine);   // creates sim, creates and starts physics
//
// Thread-safety: a tree is driven from one thread; during a walk, the steps of one level may run on
// several threads at once (Engine::RunSiblings), each on its own subtree.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "swarmbox/dsl/outcome.hpp"

namespace swarmbox::dsl {

enum class EventKind { kBuild, kRun, kStop, kShutdown, kRestart };
// "build", "run", "stop", "shutdown", "restart".
std::string_view EventName(EventKind event);

inline constexpr int kMinRunPriority = 0;
// Enough levels for a trial's own (networks, physics, sidecars, faults, drones) and one per
// distinct `components:` priority (at most 32 components).
inline constexpr int kMaxRunPriority = 63;

class Engine;
class Network;
class Plugin;

class Component {
 public:
  // Aborts (SWARMBOX_CHECK) on an empty id or a priority outside [0, kMaxRunPriority].
  explicit Component(std::string id, int run_priority = 0);
  virtual ~Component();
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;

  const std::string& id() const { return id_; }
  Component* parent() const { return parent_; }
  const std::vector<std::unique_ptr<Component>>& children() const { return children_; }
  int run_priority() const { return run_priority_; }
  void set_run_priority(int priority);
  // Ids from the root down, joined with '/': "sar-search/drones/scout_1".
  std::string Path() const;
  Component& Root();

  // Creates a child of type T (constructed from args), adopts it and returns it. Aborts when a
  // sibling already has the same id.
  template <typename T, typename... Args>
  T& Add(Args&&... args) {
    static_assert(std::is_base_of_v<Component, T>);
    auto child = std::make_unique<T>(std::forward<Args>(args)...);
    T& ref = *child;
    Adopt(std::move(child));
    return ref;
  }

  // The first component with this id in a depth-first walk (this one included); nullptr if none.
  Component* Find(std::string_view id);
  // Children in run order: priority ascending, ties in insertion order.
  std::vector<Component*> RunOrder() const;
  // Every descendant of type T (this one included) in run order, depth first.
  template <typename T>
  std::vector<T*> Collect() {
    std::vector<T*> out;
    Visit([&out](Component& c) {
      if (auto* t = dynamic_cast<T*>(&c)) out.push_back(t);
    });
    return out;
  }
  // Depth-first pre-order walk in run order.
  template <typename Fn>
  void Visit(Fn&& fn) {
    fn(*this);
    for (Component* c : RunOrder()) c->Visit(fn);
  }

  // Sends a downward event (Build, Run or Stop) through this subtree. Aborts on Shutdown/Restart.
  Verdict Dispatch(EventKind event, Engine& engine);

  // Upward events. `verdict.source` defaults to Path(). Returns true when an ancestor (or this
  // component) consumed it.
  bool RaiseShutdown(Verdict verdict);
  bool RaiseRestart(std::string reason);

 protected:
  // This component's own part of a downward event; the default does nothing (a grouping node).
  virtual Verdict Handle(EventKind event, Engine& engine);
  // Upward hooks: return true to consume the event, false to pass it to the parent.
  virtual bool OnShutdown(const Verdict& verdict);
  virtual bool OnRestart(const std::string& reason, const std::string& source);

 private:
  void Adopt(std::unique_ptr<Component> child);
  // One level (siblings of equal priority, in the order to go through them) through RunSiblings.
  static Verdict DispatchLevel(const std::vector<Component*>& level, EventKind event,
                               Engine& engine);

  std::string id_;
  int run_priority_;
  Component* parent_ = nullptr;
  std::vector<std::unique_ptr<Component>> children_;
};

// A Component with a life cycle: declared -> built -> running -> stopped (-> built again on a
// restart). Events that do not fit the state are answered without side effects: Stop of a module
// that was never built does nothing; Run of a module that is not built is an error.
class Module : public Component {
 public:
  enum class State { kDeclared, kBuilt, kRunning, kStopped };
  using Component::Component;

  State state() const { return state_; }

 protected:
  Verdict Handle(EventKind event, Engine& engine) final;
  virtual Verdict DoBuild(Engine& engine) = 0;
  virtual Verdict DoRun(Engine& engine) = 0;
  virtual Verdict DoStop(Engine& engine) = 0;

 private:
  State state_ = State::kDeclared;
};

std::string_view StateName(Module::State state);

// The side effects a tree needs. The runner implements it on DockerApi; tests use fakes. Every
// method returns the outcome of its step; infrastructure problems are Outcome::kError.
class Engine {
 public:
  virtual ~Engine() = default;
  virtual Verdict CreateNetwork(Network& network) = 0;
  virtual Verdict RemoveNetwork(Network& network) = 0;
  virtual Verdict CreateContainer(Plugin& plugin) = 0;
  // Starts the container and, when the plugin has a readiness pattern, waits for it.
  virtual Verdict StartContainer(Plugin& plugin) = 0;
  // Stops the container, collects its logs and artifacts, removes it.
  virtual Verdict StopContainer(Plugin& plugin) = 0;
  // Called after each Module handled a downward event, with its result (for events.jsonl).
  virtual void Trace(const Component& component, EventKind event, const Verdict& verdict);
  // Runs the steps of one level (siblings of equal run priority, independent of each other) and
  // returns the worst verdict. The default runs them one after another on the calling thread and,
  // with `stop_on_failure` (Build, Run), stops after the first that is not success. An engine may
  // run them at once instead (then every step runs); it must then accept concurrent calls of its
  // methods (and of Trace) for different components.
  virtual Verdict RunSiblings(const std::vector<std::function<Verdict()>>& steps,
                              bool stop_on_failure);
};

}  // namespace swarmbox::dsl
