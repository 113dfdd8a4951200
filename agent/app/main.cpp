// swarmbox-agent: one drone's companion computer. Thin: parses the command line, builds the
// AgentNode (agent_node.hpp) and runs it. Exit codes: 0 done, 2 bad usage/config, 3 the bus or
// the physics server is not there.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>

#include "agent_node.hpp"

int main(int argc, char** argv) {
  swarmbox::agent::AgentOptions o;
  CLI::App app{"swarmbox-agent: one drone's flight stack on the SwarmBox bus (lockstep with swarmbox-physics)"};
  std::string start;
  double first_timeout_s = 10.0, stall_timeout_s = 5.0;
  bool no_mesh = false, no_damping = false;
  app.add_option("--name", o.name, "Drone name (as the physics server knows it)")->required();
  app.add_option("--airframe", o.airframe_path, "Airframe file (trials/airframes/*.yaml)")->required()->check(CLI::ExistingFile);
  app.add_option("--middleware", o.middleware, "DDS implementation")->check(CLI::IsMember({"cyclonedds", "fastdds"}))->capture_default_str();
  app.add_option("--sim-interface", o.sim_interface, "Network interface of the sim bus")->capture_default_str();
  app.add_option("--sim-domain", o.sim_domain, "DDS domain id of the sim bus")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_option("--mesh-interface", o.mesh_interface, "Network interface of the mesh (radio) bus")->capture_default_str();
  app.add_option("--mesh-domain", o.mesh_domain, "DDS domain id of the mesh bus")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_flag("--no-mesh", no_mesh, "Do not join the mesh bus");
  app.add_option("--plan", o.plan, "Built-in flight plan: takeoff:H, hover:S, goto:X:Y:Z[:YAW_DEG], velocity:VX:VY:VZ:S, land")->capture_default_str();
  app.add_option("--preflight", o.preflight_s, "Simulated seconds on the ground before take-off")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--start", start, "Take-off spot x,y,z [m, ENU] (the trial's pose); default: first GPS fix");
  app.add_option("--payload-mass", o.payload_mass_kg, "Load carried at start [kg] (initial estimate)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_flag("--no-swing-damping", no_damping, "Disable slung-load swing damping");
  app.add_option("--sample-timeout", first_timeout_s, "Wall seconds to wait for the first sensor sample")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--stall-timeout", stall_timeout_s, "Wall seconds without samples after which the run ends")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--exit-when-done", o.exit_when_done, "Exit as soon as the plan is complete");
  CLI11_PARSE(app, argc, argv);

  o.mesh = !no_mesh;
  o.swing_damping = !no_damping;
  o.first_sample_timeout = std::chrono::milliseconds(static_cast<long>(first_timeout_s * 1000.0));
  o.stall_timeout = std::chrono::milliseconds(static_cast<long>(stall_timeout_s * 1000.0));
  if (!start.empty()) {
    double x = 0, y = 0, z = 0;
    char tail = 0;
    if (std::sscanf(start.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3) {
      std::fprintf(stderr, "swarmbox-agent: --start '%s': expected x,y,z in metres\n", start.c_str());
      return 2;
    }
    o.has_start = true;
    o.start_m = swarmbox::flight::Vec3(x, y, z);
  }
  auto node = swarmbox::agent::AgentNode::Create(o);
  if (!node) {
    std::fprintf(stderr, "swarmbox-agent: %s\n", node.error().ToString().c_str());
    return node.error().code() == swarmbox::ErrorCode::kInvalidArgument ||
                   node.error().code() == swarmbox::ErrorCode::kNotFound
               ? 2
               : 3;
  }
  swarmbox::Status s = (*node)->Run();
  if (!s) {
    std::printf("%s\n", swarmbox::LogEvent(0.0, o.name, "error").Add("reason", s.error().ToString()).str().c_str());
    std::fprintf(stderr, "swarmbox-agent: %s\n", s.error().ToString().c_str());
    return 3;
  }
  return 0;
}
