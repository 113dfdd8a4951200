#include "swarmbox/brain/loader.hpp"

#include <dlfcn.h>

#include <exception>
#include <utility>

namespace swarmbox::brain {
namespace {

using AbiVersionFn = int (*)();
using CxxLibraryFn = const char* (*)();
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

// The library loaded, closed when the last owner lets go.
Result<std::shared_ptr<void>> DlOpen(const std::string& path) {
  dlerror();  // clear a stale error
  void* raw = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (raw == nullptr) {
    std::string message = "cannot load the brain library: " + DlErrorText();
    if (path.find('/') == std::string::npos) {
      message += " (a name without '/' is searched on the library path, not in the current folder: ./" +
                 path + " for that)";
    }
    return LoadError(path, message);
  }
  return std::shared_ptr<void>(raw, [](void* h) { dlclose(h); });
}

// dlsym on the handle searches this library (and its dependencies) only, never the agent.
Status CheckAbiVersion(const std::string& path, void* handle) {
  void* abi_sym = dlsym(handle, "swarmbox_brain_abi_version");
  if (abi_sym == nullptr) {
    return LoadError(path,
                     "not a SwarmBox brain library: it exports no swarmbox_brain_abi_version (link "
                     "it with swarmbox::brain, register its brain with SWARMBOX_BRAIN, build it "
                     "with swarmbox_add_brain)");
  }
  const int abi = reinterpret_cast<AbiVersionFn>(abi_sym)();
  if (abi != kAbiVersion) {
    return LoadError(path, "built against brain ABI " + std::to_string(abi) + ", this agent speaks ABI " +
                               std::to_string(kAbiVersion) +
                               ": rebuild the library against this SwarmBox's package");
  }
  return Ok{};
}

// The library's C++ standard library checked against the agent's; then its registry function
// into *registry_fn.
Status CheckCxxLibrary(const std::string& path, void* handle, RegistryFn* registry_fn) {
  void* cxx_sym = dlsym(handle, "swarmbox_brain_cxx_library");
  void* registry_sym = dlsym(handle, "swarmbox_brain_registry");
  if (cxx_sym == nullptr || registry_sym == nullptr) {
    return LoadError(path, "not a SwarmBox brain library: it exports swarmbox_brain_abi_version but no " +
                               std::string(cxx_sym == nullptr ? "swarmbox_brain_cxx_library"
                                                              : "swarmbox_brain_registry"));
  }
  const char* cxx = reinterpret_cast<CxxLibraryFn>(cxx_sym)();
  if (cxx == nullptr || std::string(cxx) != CxxLibrary()) {
    return LoadError(path, std::string("built against the C++ standard library ") +
                               (cxx != nullptr ? cxx : "(none)") + ", this agent uses " + CxxLibrary() +
                               ": rebuild it with the agent's compiler and standard library");
  }
  *registry_fn = reinterpret_cast<RegistryFn>(registry_sym);
  return Ok{};
}

// The registry's brains and their names, each name once.
Status ReadRegistry(const std::string& path, RegistryFn registry_fn, OpenLibrary* lib) {
  const std::vector<Registration>* registry = registry_fn();
  if (registry != nullptr) lib->registry = *registry;
  for (const Registration& r : lib->registry) {
    const std::string name = r.name != nullptr ? r.name : "";
    for (const std::string& seen : lib->names) {
      if (seen == name) {
        return LoadError(path, "the library registers brain \"" + name +
                                   "\" twice (two SWARMBOX_BRAIN lines with one name)");
      }
    }
    lib->names.push_back(name);
  }
  return Ok{};
}

Result<OpenLibrary> Open(const std::string& path) {
  auto handle = DlOpen(path);
  if (!handle) return handle.error();
  OpenLibrary lib;
  lib.handle = std::move(*handle);
  SWARMBOX_TRY(CheckAbiVersion(path, lib.handle.get()));
  RegistryFn registry_fn = nullptr;
  SWARMBOX_TRY(CheckCxxLibrary(path, lib.handle.get(), &registry_fn));
  SWARMBOX_TRY(ReadRegistry(path, registry_fn, &lib));
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
