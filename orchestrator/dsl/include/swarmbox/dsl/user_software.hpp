// The user's own software in a trial (issue #24): what flies each drone (`drones[].brain`) and the
// extra containers of the trial (`components:`). Part of the trial model (trial_spec.hpp); decoded
// by the loader (trial_loader.hpp, one function per section in src/user_software_keys.cpp), turned
// into containers by the runner (runner/plan.hpp) and exported by `swarmbox compose`.
//
//   drones:
//     - name: scout_1
//       airframe: x500
//       brain: {library: brains/librendezvous.so, name: rendezvous, args: {radius_m: 6}}
//     - name: scout_2
//       airframe: x500
//       brain: {program: bin/swarmbox_c_brain, args: [--radius-m, "6"], rate_hz: 50,
//               offboard: {timeout_ms: 1000, hold_ms: 5000}}
//   components:
//     - {name: ground, program: bin/ground_station, args: [--port, "14550"], networks: [sim],
//        priority: 10, ready: "event=ready", collect: [/tmp/ground.csv]}
//     - {name: recorder, image: "recorder:local", env: {LEVEL: debug}}
//
// Paths (library, program, dockerfile) are relative to the trial file's folder and checked when
// the trial is loaded: the file exists and has the right kind (an ELF shared object for a library,
// an ELF executable for a program, a regular file for a Dockerfile). Images are never pulled: an
// `image:` must be on the engine already, and a Dockerfile may only build FROM local images.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::dsl {

// --- drones[].brain ---------------------------------------------------------------------------

// builtin: the agent's own logic (`mission:`); library: a brain SDK module loaded by the agent
// (`--brain library`); program / dockerfile / image: a process in its own container
// `<trial>-<run>-<drone>-brain` speaking the offboard topics, the agent runs `--brain external`.
enum class BrainKind { kBuiltin, kLibrary, kProgram, kDockerfile, kImage };
std::string_view BrainKindName(BrainKind kind);  // "builtin", "library", "program", ...

// PX4-like offboard loss handling in the agent; unset = the agent's default (1000 ms, 5000 ms).
struct OffboardSpec {
  std::optional<int> timeout_ms;  // simulated silence before the drone holds [ms], > 0
  std::optional<int> hold_ms;     // simulated hold before it lands [ms], >= 0
};

struct BrainSpec {
  BrainKind kind = BrainKind::kBuiltin;
  std::string path;       // library/program/dockerfile as written; image: the reference
  std::string host_path;  // library/program/dockerfile: absolute on the host (loader-resolved)
  std::string name;       // library: the SWARMBOX_BRAIN name in it (required)
  yaml::Node args;        // library: a mapping (null = {}); the others: a list of strings (null = [])
  double rate_hz = 0;     // brain calls per simulated second; 0 = the agent's default
  OffboardSpec offboard;
  yaml::Mark mark;        // where `brain:` was written

  bool external() const {
    return kind == BrainKind::kProgram || kind == BrainKind::kDockerfile || kind == BrainKind::kImage;
  }
  // library: args as a JSON object ("{}" when none), what --brain-args takes.
  std::string ArgsJson() const;
  // program/dockerfile/image: args as strings, in order.
  std::vector<std::string> ArgList() const;

  static BrainSpec Library(std::string path, std::string name, yaml::Node args = {});
  static BrainSpec Program(std::string path, std::vector<std::string> args = {});
  static BrainSpec Dockerfile(std::string path, std::vector<std::string> args = {});
  static BrainSpec Image(std::string reference, std::vector<std::string> args = {});
};

// --- components: --------------------------------------------------------------------------------

// Where a component's image comes from: an image on the engine, a host program packed into a
// registry-free image (with its shared-library closure), or a Dockerfile built through the Engine
// API with its folder as the context.
enum class ComponentSource { kImage, kProgram, kDockerfile };
std::string_view ComponentSourceName(ComponentSource source);  // "image", "program", "dockerfile"

// The drones' run priority: components below it start before the physics server and the drones,
// equal ones start with the drones, higher ones after them.
inline constexpr int kDronesPriority = 100;
inline constexpr int kMinComponentPriority = -1000;
inline constexpr int kMaxComponentPriority = 1000;
inline constexpr std::size_t kMaxComponents = 32;

struct UserComponentSpec {
  std::string name;  // [a-z][a-z0-9_-]*, <= 32; unique, not a drone's nor a name the trial uses
  ComponentSource source = ComponentSource::kImage;
  std::string ref;        // image reference, or the program/Dockerfile path as written
  std::string host_path;  // program/dockerfile: absolute on the host (loader-resolved)
  std::vector<std::string> args;  // image/dockerfile: the command (CMD; ENTRYPOINT kept);
                                  // program: its arguments
  std::map<std::string, std::string> env;
  std::vector<std::string> networks;  // "sim", "mesh" (netem trials only); empty = none
  int priority = 0;                   // lower starts first; drones are kDronesPriority
  std::string ready;                  // regex on a log line; "" = ready once started
  std::vector<std::string> collect;   // absolute paths, copied to <trial>/components/<name>/
  yaml::Mark mark;

  static UserComponentSpec Image(std::string name, std::string reference);
  static UserComponentSpec Program(std::string name, std::string path);
  static UserComponentSpec Dockerfile(std::string name, std::string path);
};

// --- what a referenced file is (the loader's check) -------------------------------------------

enum class FileKind {
  kMissing,       // no such file
  kOther,         // a regular file that is not ELF (a script, a Dockerfile, text)
  kElfExecutable, // ET_EXEC, or ET_DYN with an interpreter (PT_INTERP: a PIE program)
  kElfShared,     // ET_DYN without an interpreter (a shared object)
  kElfOther,      // another ELF (relocatable object, core)
  kDirectory,
};
std::string_view FileKindName(FileKind kind);  // "no such file", "an ELF executable", ...

// Classifies the bytes at the start of a file (pure): at least the ELF header and its program
// headers are needed to tell a PIE program from a shared object (else kElfOther).
FileKind ClassifyFileBytes(std::string_view head);
// Reads the file (up to 64 KiB) and classifies it (I/O; the loader's default probe).
FileKind ProbeFileKind(const std::string& path);

// Encodes for ToDocument (the same keys the loader reads).
yaml::Node BrainToNode(const BrainSpec& brain);
yaml::Node ComponentToNode(const UserComponentSpec& component);

}  // namespace swarmbox::dsl
