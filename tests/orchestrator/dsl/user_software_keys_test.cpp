// The user's software in a trial (`drones[].brain`, `components:`): every key, the paths relative
// to the trial file, the file-kind checks, and every error at its file:line:col; ToDocument writes
// the same keys back, and the C++ builder makes the same value.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/dsl/user_software.hpp"

namespace swarmbox::dsl {
namespace {

using ::testing::HasSubstr;

constexpr const char* kTrial = R"(name: byo
world: worlds/open_field.yaml
drones:
  - {name: scout_1, airframe: x500, brain: {library: brains/librendezvous.so, name: rendezvous, args: {radius_m: 6, label: ring}}}
  - {name: scout_2, airframe: x500, brain: {program: bin/c_brain, args: [--radius-m, 6], rate_hz: 50, offboard: {timeout_ms: 800, hold_ms: 0}}}
  - {name: scout_3, airframe: x500}
components:
  - {name: ground, program: bin/ground, args: [--out, /tmp/ground.csv], env: {LEVEL: debug, N: 3}, networks: [sim], priority: 10, ready: "event=ready", collect: [/tmp/ground.csv, /out/log]}
  - {name: recorder, image: "recorder:local"}
mission: {kind: plan, plan: "takeoff:5,hover:2,land"}
timeout: {sim: 60s}
)";

// The files a fake trial folder /home/u/exp holds, by absolute path.
std::map<std::string, FileKind> Files() {
  return {{"/home/u/exp/brains/librendezvous.so", FileKind::kElfShared},
          {"/home/u/exp/bin/c_brain", FileKind::kElfExecutable},
          {"/home/u/exp/bin/ground", FileKind::kElfExecutable},
          {"/home/u/exp/bin/script.sh", FileKind::kOther},
          {"/home/u/exp/docker/Dockerfile", FileKind::kOther},
          {"/home/u/exp/docker", FileKind::kDirectory}};
}

LoadOptions Opts() {
  LoadOptions o;
  o.trials_dir = "/trials";
  o.file_exists = [](const std::string& p) {
    return p == "/trials/worlds/open_field.yaml" || p == "/trials/airframes/x500.yaml";
  };
  o.file_kind = [](const std::string& p) {
    const auto files = Files();
    auto it = files.find(p);
    return it == files.end() ? FileKind::kMissing : it->second;
  };
  return o;
}

std::string With(std::string_view find, std::string_view replace) {
  std::string text = kTrial;
  const auto pos = text.find(find);
  EXPECT_NE(pos, std::string::npos) << find;
  if (pos != std::string::npos) text.replace(pos, find.size(), replace);
  return text;
}

Result<TrialSpec> Load(const std::string& text) { return LoadTrialText(text, "/home/u/exp/byo.yaml", Opts()); }

// The error's text, where included.
std::string ErrorOf(const std::string& text) {
  auto spec = Load(text);
  EXPECT_FALSE(spec) << "loaded";
  return spec ? std::string() : spec.error().ToString();
}

TEST(UserSoftwareKeys, BrainsOfEveryKindResolveAgainstTheTrialFilesFolder) {
  auto spec = Load(kTrial);
  ASSERT_TRUE(spec) << spec.error().ToString();
  const BrainSpec& lib = spec->drones[0].brain;
  EXPECT_EQ(lib.kind, BrainKind::kLibrary);
  EXPECT_EQ(lib.path, "brains/librendezvous.so");
  EXPECT_EQ(lib.host_path, "/home/u/exp/brains/librendezvous.so");
  EXPECT_EQ(lib.name, "rendezvous");
  EXPECT_EQ(lib.ArgsJson(), R"({"radius_m":6,"label":"ring"})");
  EXPECT_FALSE(lib.external());

  const BrainSpec& prog = spec->drones[1].brain;
  EXPECT_EQ(prog.kind, BrainKind::kProgram);
  EXPECT_EQ(prog.host_path, "/home/u/exp/bin/c_brain");
  EXPECT_THAT(prog.ArgList(), ::testing::ElementsAre("--radius-m", "6"));
  EXPECT_DOUBLE_EQ(prog.rate_hz, 50);
  EXPECT_EQ(prog.offboard.timeout_ms, 800);
  EXPECT_EQ(prog.offboard.hold_ms, 0);
  EXPECT_TRUE(prog.external());

  EXPECT_EQ(spec->drones[2].brain.kind, BrainKind::kBuiltin);
  EXPECT_TRUE(spec->HasExternalBrain());
}

// Every drone is a member of the one Raft log, and the SAR planner runs on its leader only: a sar
// mission beside other brains is refused at the first drone on another brain.
TEST(UserSoftwareKeys, ASarMissionBesideOtherBrainsIsRefused) {
  const std::string text = With("mission: {kind: plan, plan: \"takeoff:5,hover:2,land\"}\n", "");
  const std::string error = ErrorOf(text);
  EXPECT_THAT(error, HasSubstr("byo.yaml:4:"));  // scout_1's entry
  EXPECT_THAT(error, HasSubstr("drone 'scout_1' flies its own brain while 'scout_3' flies the sar mission"));
  // Every drone on a brain of its own (no builtin drone): the mission key does not matter.
  std::string brains_only = text;
  const std::string scout_3 = "  - {name: scout_3, airframe: x500}\n";
  brains_only.erase(brains_only.find(scout_3), scout_3.size());
  auto spec = Load(brains_only);
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->mission.kind, MissionKind::kSar);
  EXPECT_EQ(spec->drones.size(), 2u);
}

TEST(UserSoftwareKeys, BuiltinAndDockerfileAndImageBrains) {
  auto spec = Load(With("{name: scout_3, airframe: x500}", "{name: scout_3, airframe: x500, brain: builtin}"));
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->drones[2].brain.kind, BrainKind::kBuiltin);

  spec = Load(With("{name: scout_3, airframe: x500}", "{name: scout_3, airframe: x500, brain: {dockerfile: docker/Dockerfile}}"));
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->drones[2].brain.kind, BrainKind::kDockerfile);
  EXPECT_EQ(spec->drones[2].brain.host_path, "/home/u/exp/docker/Dockerfile");

  spec = Load(With("{name: scout_3, airframe: x500}", "{name: scout_3, airframe: x500, brain: {image: \"mine/brain:2\", args: [-v]}}"));
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->drones[2].brain.kind, BrainKind::kImage);
  EXPECT_EQ(spec->drones[2].brain.path, "mine/brain:2");
  EXPECT_THAT(spec->drones[2].brain.ArgList(), ::testing::ElementsAre("-v"));
}

TEST(UserSoftwareKeys, ComponentsWithEveryKey) {
  auto spec = Load(kTrial);
  ASSERT_TRUE(spec) << spec.error().ToString();
  ASSERT_EQ(spec->components.size(), 2u);
  const UserComponentSpec& ground = spec->components[0];
  EXPECT_EQ(ground.name, "ground");
  EXPECT_EQ(ground.source, ComponentSource::kProgram);
  EXPECT_EQ(ground.host_path, "/home/u/exp/bin/ground");
  EXPECT_THAT(ground.args, ::testing::ElementsAre("--out", "/tmp/ground.csv"));
  EXPECT_EQ(ground.env.at("LEVEL"), "debug");
  EXPECT_EQ(ground.env.at("N"), "3");
  EXPECT_THAT(ground.networks, ::testing::ElementsAre("sim"));
  EXPECT_EQ(ground.priority, 10);
  EXPECT_EQ(ground.ready, "event=ready");
  EXPECT_THAT(ground.collect, ::testing::ElementsAre("/tmp/ground.csv", "/out/log"));
  const UserComponentSpec& rec = spec->components[1];
  EXPECT_EQ(rec.source, ComponentSource::kImage);
  EXPECT_EQ(rec.ref, "recorder:local");
  EXPECT_TRUE(rec.networks.empty());  // none by default
  EXPECT_EQ(rec.priority, 0);
  EXPECT_EQ(spec->FindComponent("recorder"), &rec);
}

TEST(UserSoftwareKeys, AnEndConditionMayListenToAComponent) {
  auto spec = Load(With("timeout: {sim: 60s}", "end: [{on: \"event=done\", outcome: success, from: ground}]\ntimeout: {sim: 60s}"));
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->end[0].from, "ground");
}

TEST(UserSoftwareKeys, BrainErrorsPointAtTheKey) {
  const std::string lib = "{library: brains/librendezvous.so, name: rendezvous, args: {radius_m: 6, label: ring}}";
  struct Case {
    std::string brain;
    std::string where;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"{library: brains/missing.so, name: r}", "byo.yaml:4:", "brain library 'brains/missing.so' not found (no file /home/u/exp/brains/missing.so"},
      {"{library: bin/c_brain, name: r}", "byo.yaml:4:", "is an ELF executable (/home/u/exp/bin/c_brain), expected an ELF shared object"},
      {"{program: brains/librendezvous.so}", "byo.yaml:4:", "is an ELF shared object (/home/u/exp/brains/librendezvous.so), expected an ELF executable"},
      {"{program: bin/script.sh}", "byo.yaml:4:", "'bin/script.sh' is not an ELF file"},
      {"{dockerfile: docker}", "byo.yaml:4:", "is a directory"},
      {"{library: brains/librendezvous.so, program: bin/c_brain, name: r}", "byo.yaml:4:", "has both 'library' and 'program': give exactly one source"},
      {"{name: r}", "byo.yaml:4:", "needs one of library, program, dockerfile, image"},
      {"{library: brains/librendezvous.so}", "byo.yaml:4:", "a library brain needs 'name'"},
      {"{program: bin/c_brain, name: x}", "byo.yaml:4:", "'name' belongs to library brains"},
      {"{library: brains/librendezvous.so, name: r, args: [a]}", "byo.yaml:4:", "'args' of a library brain must be a mapping"},
      {"{program: bin/c_brain, args: {a: 1}}", "byo.yaml:4:", "'args' of a program brain must be a list of strings"},
      {"{program: bin/c_brain, rate_hz: 60}", "byo.yaml:4:", "'rate_hz' must divide the agent's 250 Hz step"},
      {"{program: bin/c_brain, rate_hz: 0}", "byo.yaml:4:", "'rate_hz' must divide"},
      {"{program: bin/c_brain, offboard: {timeout_ms: 0}}", "byo.yaml:4:", "'timeout_ms' must be > 0"},
      {"{program: bin/c_brain, offboard: {hold_ms: -1}}", "byo.yaml:4:", "'hold_ms' must be >= 0"},
      {"{program: bin/c_brain, offboard: {lost_ms: 1}}", "byo.yaml:4:", "lost_ms"},
      {"{image: \"my brain\"}", "byo.yaml:4:", "'image' must be an image reference"},
      {"{program: bin/c_brain, colour: red}", "byo.yaml:4:", "colour"},
      {"smart", "byo.yaml:4:", "'brain' must be builtin or a mapping"},
  };
  for (const Case& c : cases) {
    const std::string err = ErrorOf(With(lib, c.brain));
    EXPECT_THAT(err, HasSubstr(c.where)) << c.brain;
    EXPECT_THAT(err, HasSubstr(c.message)) << c.brain;
  }
}

TEST(UserSoftwareKeys, ComponentErrorsPointAtTheKey) {
  const std::string rec = "{name: recorder, image: \"recorder:local\"}";
  struct Case {
    std::string component;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"{name: ground, image: \"x:1\"}", "component name 'ground' is used twice"},
      {"{name: scout_1, image: \"x:1\"}", "component name 'scout_1' is taken by the trial"},
      {"{name: scout_2-brain, image: \"x:1\"}", "is taken by the trial"},
      {"{name: physics, image: \"x:1\"}", "is taken by the trial"},
      {"{name: Rec, image: \"x:1\"}", "component name 'Rec' must be 1-32 characters"},
      {"{name: rec}", "component 'rec' needs one of image, program, dockerfile"},
      {"{name: rec, image: \"x:1\", program: bin/ground}", "has both 'image' and 'program'"},
      {"{name: rec, program: bin/missing}", "component program 'bin/missing' not found"},
      {"{name: rec, program: brains/librendezvous.so}", "expected an ELF executable"},
      {"{name: rec, dockerfile: docker}", "is a directory"},
      {"{name: rec, image: \"x:1\", networks: [radio]}", "unknown network 'radio' (expected sim"},
      {"{name: rec, image: \"x:1\", networks: [mesh]}", "network 'mesh' exists with radio.model netem only"},
      {"{name: rec, image: \"x:1\", networks: [sim, sim]}", "network 'sim' is listed twice"},
      {"{name: rec, image: \"x:1\", networks: sim}", "'networks' must be a list"},
      {"{name: rec, image: \"x:1\", ready: \"event=(ready\"}", "'ready' is not a valid regular expression"},
      {"{name: rec, image: \"x:1\", ready: \"\"}", "'ready' must not be empty"},
      {"{name: rec, image: \"x:1\", collect: [out.csv]}", "'collect' paths must be absolute"},
      {"{name: rec, image: \"x:1\", collect: [/a/out.csv, /b/out.csv]}", "two paths named 'out.csv'"},
      {"{name: rec, image: \"x:1\", env: {1X: a}}", "environment variable name '1X'"},
      {"{name: rec, image: \"x:1\", env: {X: [a]}}", "the value of 'X' must be a string"},
      {"{name: rec, image: \"x:1\", priority: 5000}", "'priority' must be in [-1000, 1000] (the drones are 100)"},
      {"{name: rec, image: \"x:1\", args: [[a]]}", "must be a list of strings"},
      {"{name: rec, image: \"x:1\", volume: /data}", "volume"},
  };
  for (const Case& c : cases) {
    const std::string err = ErrorOf(With(rec, c.component));
    EXPECT_THAT(err, HasSubstr("byo.yaml:9:")) << c.component;
    EXPECT_THAT(err, HasSubstr(c.message)) << c.component;
  }
  const std::string trial = kTrial;
  const std::string not_a_list = trial.substr(0, trial.find("components:")) + "components: {a: 1}\ntimeout: {sim: 60s}\n";
  EXPECT_THAT(ErrorOf(not_a_list), HasSubstr("byo.yaml:7:13: 'components' must be a list"));
}

TEST(UserSoftwareKeys, ANetemTrialLetsComponentsJoinTheMesh) {
  auto spec = Load(With("{name: recorder, image: \"recorder:local\"}",
                        "{name: recorder, image: \"recorder:local\", networks: [sim, mesh]}") +
                   "radio: {model: netem}\n");
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_THAT(spec->components[1].networks, ::testing::ElementsAre("sim", "mesh"));
}

TEST(UserSoftwareKeys, FilesAreNotProbedWithoutReferenceChecks) {
  LoadOptions o = Opts();
  o.check_references = false;
  o.file_kind = [](const std::string&) { return FileKind::kMissing; };
  auto spec = LoadTrialText(kTrial, "/home/u/exp/byo.yaml", o);
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->drones[0].brain.host_path, "/home/u/exp/brains/librendezvous.so");
}

TEST(UserSoftwareKeys, ToDocumentWritesTheSameKeysBack) {
  auto spec = Load(kTrial);
  ASSERT_TRUE(spec) << spec.error().ToString();
  const std::string text = yaml::Emit(ToDocument(*spec));
  auto again = LoadTrialText(text, "/home/u/exp/again.yaml", Opts());
  ASSERT_TRUE(again) << again.error().ToString() << "\n" << text;
  for (std::size_t i = 0; i < spec->drones.size(); ++i) {
    const BrainSpec& a = spec->drones[i].brain;
    const BrainSpec& b = again->drones[i].brain;
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.host_path, b.host_path);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.ArgsJson(), b.ArgsJson());
    EXPECT_EQ(a.ArgList(), b.ArgList());
    EXPECT_EQ(a.rate_hz, b.rate_hz);
    EXPECT_EQ(a.offboard.timeout_ms, b.offboard.timeout_ms);
    EXPECT_EQ(a.offboard.hold_ms, b.offboard.hold_ms);
  }
  ASSERT_EQ(again->components.size(), spec->components.size());
  for (std::size_t i = 0; i < spec->components.size(); ++i) {
    const UserComponentSpec& a = spec->components[i];
    const UserComponentSpec& b = again->components[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.source, b.source);
    EXPECT_EQ(a.ref, b.ref);
    EXPECT_EQ(a.args, b.args);
    EXPECT_EQ(a.env, b.env);
    EXPECT_EQ(a.networks, b.networks);
    EXPECT_EQ(a.priority, b.priority);
    EXPECT_EQ(a.ready, b.ready);
    EXPECT_EQ(a.collect, b.collect);
  }
}

TEST(UserSoftwareKeys, TheBuilderMakesTheSameSpec) {
  TrialSpec t = TrialSpec::Named("byo")
                    .World("worlds/open_field.yaml")
                    .Drone("scout_1", "x500", {0, 0, 0})
                    .Drone("scout_2", "x500", {3, 0, 0})
                    .Brain("scout_1", BrainSpec::Library("/abs/librendezvous.so", "rendezvous",
                                                         *yaml::Parse("{radius_m: 6}")))
                    .Brain("scout_2", BrainSpec::Program("/abs/c_brain", {"--radius-m", "6"}))
                    .Component(UserComponentSpec::Image("recorder", "recorder:local"))
                    .Timeout(Duration::Seconds(60));
  EXPECT_EQ(t.drones[0].brain.ArgsJson(), R"({"radius_m":6})");
  EXPECT_THAT(t.drones[1].brain.ArgList(), ::testing::ElementsAre("--radius-m", "6"));
  const yaml::Node doc = ToDocument(t);
  const std::string text = yaml::Emit(doc);
  EXPECT_THAT(text, HasSubstr("library: \"/abs/librendezvous.so\""));
  EXPECT_THAT(text, HasSubstr("name: \"rendezvous\""));
  EXPECT_THAT(text, HasSubstr("program: \"/abs/c_brain\""));
  EXPECT_THAT(text, HasSubstr("image: \"recorder:local\""));
  LoadOptions o = Opts();
  o.file_kind = [](const std::string& p) {
    return p == "/abs/librendezvous.so" ? FileKind::kElfShared : FileKind::kElfExecutable;
  };
  auto back = LoadTrialText(text, "/elsewhere/t.yaml", o);
  ASSERT_TRUE(back) << back.error().ToString();
  EXPECT_EQ(back->drones[0].brain.host_path, "/abs/librendezvous.so");
  EXPECT_EQ(back->drones[1].brain.host_path, "/abs/c_brain");
  EXPECT_EQ(back->components[0].ref, "recorder:local");
}

TEST(FileKinds, ClassifiesTheElfHeader) {
  EXPECT_EQ(ClassifyFileBytes("#!/bin/sh\necho hi\n"), FileKind::kOther);
  EXPECT_EQ(ClassifyFileBytes(""), FileKind::kOther);
  EXPECT_EQ(ClassifyFileBytes(std::string("\x7f" "ELF", 4)), FileKind::kElfOther);
  // ELF64 little endian, one program header at 64: ET_DYN without PT_INTERP is a shared object,
  // with it a PIE program; ET_EXEC a program; ET_REL neither.
  auto elf = [](std::uint16_t type, std::uint32_t first_segment) {
    std::string b(64 + 56, '\0');
    b.replace(0, 4, "\x7f" "ELF");
    b[4] = 2;  // ELFCLASS64
    b[5] = 1;  // little endian
    b[16] = static_cast<char>(type);
    b[32] = 64;  // e_phoff
    b[54] = 56;  // e_phentsize
    b[56] = 1;   // e_phnum
    b[64] = static_cast<char>(first_segment);
    return b;
  };
  EXPECT_EQ(ClassifyFileBytes(elf(3, 1)), FileKind::kElfShared);
  EXPECT_EQ(ClassifyFileBytes(elf(3, 3)), FileKind::kElfExecutable);
  EXPECT_EQ(ClassifyFileBytes(elf(2, 1)), FileKind::kElfExecutable);
  EXPECT_EQ(ClassifyFileBytes(elf(1, 1)), FileKind::kElfOther);
  EXPECT_EQ(ClassifyFileBytes(elf(3, 1).substr(0, 66)), FileKind::kElfOther);  // headers cut off
  // This test binary is a PIE program (ET_DYN with PT_INTERP).
  EXPECT_EQ(ProbeFileKind("/proc/self/exe"), FileKind::kElfExecutable);
  EXPECT_EQ(ProbeFileKind("/no/such/file"), FileKind::kMissing);
  EXPECT_EQ(ProbeFileKind("/tmp"), FileKind::kDirectory);
}

}  // namespace
}  // namespace swarmbox::dsl
