#include "swarmbox/brain/loader.hpp"

#include <dlfcn.h>

#include <exception>
#include <utility>

namespace swarmbox::brain {
namespace {

using AbiVersionFn = int (*)();
using RegistryFn = const std::vector<Registration>* (*)();

Error LoadError(const std::string& path, std::string message) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), path);
}

std::string DlErrorText() {
  const char* text = dlerror();
  return text != nullptr ? text : "unknown dlopen error";
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// A ReplicatedState made by a library's brain, keeping the library loaded while it lives.
class LibraryState final : public ReplicatedState {
 public:
  LibraryState(std::shared_ptr<void> library, std::unique_ptr<ReplicatedState> inner)
      : library_(std::move(library)), inner_(std::move(inner)) {}
  void Apply(std::uint64_t index, std::span<const std::uint8_t> entry) override {
    inner_->Apply(index, entry);
  }
  std::vector<std::uint8_t> Snapshot() const override { return inner_->Snapshot(); }
  bool Restore(std::span<const std::uint8_t> snapshot) override { return inner_->Restore(snapshot); }
  const ReplicatedState* inner() const { return inner_.get(); }

 private:
  std::shared_ptr<void> library_;             // destroyed after inner_ (declared before it)
  std::unique_ptr<ReplicatedState> inner_;
};

struct OpenLibrary {
  std::shared_ptr<void> handle;
  std::vector<Registration> registry;
  std::vector<std::string> names;
};

Result<OpenLibrary> Open(const std::string& path) {
  dlerror();  // clear a stale error
  void* raw = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (raw == nullptr) return LoadError(path, "cannot load the brain library: " + DlErrorText());
  OpenLibrary lib;
  lib.handle = std::shared_ptr<void>(raw, [](void* h) { dlclose(h); });

  // dlsym on the handle searches this library (and its dependencies) only, never the agent.
  void* abi_sym = dlsym(raw, "swarmbox_brain_abi_version");
  void* registry_sym = dlsym(raw, "swarmbox_brain_registry");
  if (abi_sym == nullptr || registry_sym == nullptr) {
    return LoadError(path,
                     "not a SwarmBox brain library: it exports no swarmbox_brain_abi_version/"
                     "swarmbox_brain_registry (link it with swarmbox::brain, register its brain "
                     "with SWARMBOX_BRAIN, build it with swarmbox_add_brain)");
  }
  const int abi = reinterpret_cast<AbiVersionFn>(abi_sym)();
  if (abi != kAbiVersion) {
    return LoadError(path, "built against brain ABI " + std::to_string(abi) + ", this agent speaks ABI " +
                               std::to_string(kAbiVersion) +
                               ": rebuild the library against this SwarmBox's package");
  }
  const std::vector<Registration>* registry = reinterpret_cast<RegistryFn>(registry_sym)();
  if (registry != nullptr) lib.registry = *registry;
  for (const Registration& r : lib.registry) {
    const std::string name = r.name != nullptr ? r.name : "";
    for (const std::string& seen : lib.names) {
      if (seen == name) {
        return LoadError(path, "the library registers brain \"" + name +
                                   "\" twice (two SWARMBOX_BRAIN lines with one name)");
      }
    }
    lib.names.push_back(name);
  }
  return lib;
}

}  // namespace

LoadedBrain::LoadedBrain(std::shared_ptr<void> library, std::unique_ptr<Brain> brain,
                         std::string path, std::string name, std::vector<std::string> library_brains)
    : library_(std::move(library)),
      brain_(std::move(brain)),
      path_(std::move(path)),
      name_(std::move(name)),
      library_brains_(std::move(library_brains)) {}

LoadedBrain::~LoadedBrain() {
  brain_.reset();    // the brain's code lives in the library: destroy it first ...
  library_.reset();  // ... then close the library (unless a ReplicatedState still holds it)
}

std::unique_ptr<ReplicatedState> LoadedBrain::MakeReplicatedState() {
  std::unique_ptr<ReplicatedState> inner = brain_->MakeReplicatedState();
  if (inner == nullptr) return nullptr;
  auto wrapper = std::make_unique<LibraryState>(library_, std::move(inner));
  state_wrapper_ = wrapper.get();
  state_inner_ = wrapper->inner();
  return wrapper;
}

void LoadedBrain::Step(const Input& in, Output& out) {
  if (in.state != nullptr && in.state == state_wrapper_) {
    Input own = in;  // the brain casts Input::state to its own type: hand it the object it made
    own.state = state_inner_;
    brain_->Step(own, out);
    return;
  }
  brain_->Step(in, out);
}

Result<std::unique_ptr<LoadedBrain>> LoadBrain(const std::string& path, const std::string& name,
                                               const Context& ctx) {
  auto lib = Open(path);
  if (!lib) return lib.error();
  Factory make = nullptr;
  for (const Registration& r : lib->registry) {
    if (r.name != nullptr && name == r.name) make = r.make;
  }
  if (make == nullptr) {
    return LoadError(path, "no brain named \"" + name + "\" in the library; it has: " +
                               (lib->names.empty() ? std::string("none (no SWARMBOX_BRAIN line)")
                                                   : JoinNames(lib->names)));
  }
  std::unique_ptr<Brain> brain;
  try {
    brain = make(ctx);
  } catch (const std::exception& e) {
    return LoadError(path, "brain \"" + name + "\": constructor failed: " + e.what());
  } catch (...) {
    return LoadError(path, "brain \"" + name + "\": constructor failed with a non-std exception");
  }
  if (brain == nullptr) return LoadError(path, "brain \"" + name + "\": its factory made nothing");
  return std::unique_ptr<LoadedBrain>(new LoadedBrain(std::move(lib->handle), std::move(brain), path,
                                                      name, std::move(lib->names)));
}

Result<std::vector<std::string>> ListBrains(const std::string& path) {
  auto lib = Open(path);
  if (!lib) return lib.error();
  return std::move(lib->names);
}

}  // namespace swarmbox::brain
