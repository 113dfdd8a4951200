// Loading a brain from a shared library (the agent's `--brain library`): dlopen, the ABI check,
// the name lookup and the construction, each failure an Error that says what to fix.
//
//   auto brain = brain::LoadBrain("/swarmbox/brains/librendezvous.so", "rendezvous", ctx);
//   if (!brain) return brain.error();          // exit 2 with brain.error().ToString()
//   std::unique_ptr<brain::Brain> b = std::move(*brain);
//   b->Step(in, out);
//
// Errors (all ErrorCode::kInvalidArgument, where = the library's path):
//   - the library does not load: dlerror()'s text (no such file, not an ELF object, an undefined
//     symbol: RTLD_NOW resolves everything at load time, not at the first call);
//   - it is not a brain library (no swarmbox_brain_abi_version/swarmbox_brain_registry exported);
//   - it was built against another brain ABI: both numbers;
//   - no brain of that name: the names the library has;
//   - the constructor threw: the brain's name and the exception's message.
//
// Lifetime: the returned LoadedBrain owns the library handle (dlopen RTLD_NOW | RTLD_LOCAL) and
// the brain; destroying it destroys the brain first, then closes the library. A ReplicatedState it
// makes keeps the library loaded too, so the two can be destroyed in any order. Loading the same
// path twice gives two brains sharing one loaded copy of the library (dlopen counts references):
// a library's globals are shared by its brains; separate libraries never share anything
// (brain.hpp, LibraryRegistry).
//
// Threading: LoadBrain runs static constructors of the library (its SWARMBOX_BRAIN lines) and the
// brain's constructor on the calling thread; call it before the lockstep starts.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "swarmbox/brain/brain.hpp"
#include "swarmbox/common/result.hpp"

namespace swarmbox::brain {

class LoadedBrain final : public Brain {
 public:
  ~LoadedBrain() override;
  LoadedBrain(const LoadedBrain&) = delete;
  LoadedBrain& operator=(const LoadedBrain&) = delete;

  // The library's brain: its own replicated state, wrapped so that it keeps the library loaded.
  // Step hands the brain its own object in Input::state (the one it made, not the wrapper).
  std::unique_ptr<ReplicatedState> MakeReplicatedState() override;
  void Step(const Input& in, Output& out) override;

  const std::string& path() const { return path_; }
  const std::string& name() const { return name_; }
  // Every name the library registered (SWARMBOX_BRAIN), in registration order.
  const std::vector<std::string>& library_brains() const { return library_brains_; }

 private:
  friend Result<std::unique_ptr<LoadedBrain>> LoadBrain(const std::string& path,
                                                        const std::string& name, const Context& ctx);
  LoadedBrain(std::shared_ptr<void> library, std::unique_ptr<Brain> brain, std::string path,
              std::string name, std::vector<std::string> library_brains);

  std::shared_ptr<void> library_;         // the dlopen handle; dlclose when the last owner goes
  std::unique_ptr<Brain> brain_;          // declared after library_: destroyed before it
  std::string path_;
  std::string name_;
  std::vector<std::string> library_brains_;
  const ReplicatedState* state_wrapper_ = nullptr;  // what MakeReplicatedState returned ...
  const ReplicatedState* state_inner_ = nullptr;    // ... and the brain's own object inside it
};

// Loads the library at `path` (a path without '/' is searched as dlopen(3) does) and constructs
// its brain `name` from `ctx` (the brain may copy what it needs; ctx need not outlive the call).
Result<std::unique_ptr<LoadedBrain>> LoadBrain(const std::string& path, const std::string& name,
                                               const Context& ctx);

// The names a library registers, without constructing anything (the same errors as LoadBrain for
// a library that does not load, is no brain library or has another ABI).
Result<std::vector<std::string>> ListBrains(const std::string& path);

}  // namespace swarmbox::brain
