// swarmbox_faults: fault injection for SwarmBox trials (ARCHITECTURE.md "Faults", "Two networks
// per trial"). This header includes the whole API and says how the runner wires it; each piece is
// pure except the edges named "I/O". Two libraries: swarmbox_faults_model (swarmbox::faults_model,
// the pure pieces: common alone, what the DSL links) and swarmbox_faults (swarmbox::faults: the
// model and the I/O edges PosixCommandRunner, DockerExecCommandRunner and ExecuteDockerActions,
// on the Docker client).
//
// 1. Parse and validate (at `swarmbox validate` / `run` time; errors are file:line:col):
//      auto mesh   = ParseMeshBlock(*trial.Find("network")->Find("mesh"));   // netem_spec.hpp
//      auto faults = ParseFaults(*trial.Find("faults"));                     // fault_spec.hpp
//      ValidateFaults(*faults, drone_names); ValidateRadioPeers(mesh->rules, drone_names);
//
// 2. One fault sidecar per agent (created by the runner at Build): image with tc, iptables
//    (xtables-nft-multi and its /usr/lib/x86_64-linux-gnu/xtables/*.so plugins), tc's distribution
//    tables (/usr/lib/x86_64-linux-gnu/tc/*.dist, for `distribution` under kernel netem),
//    swarmbox-netemd and a /run directory;
//      spec.network_mode = "container:" + agent_id;  spec.cap_add = {"NET_ADMIN"};
//      spec.cmd = {"/usr/bin/swarmbox-netemd", "sleep"};       // pid 1: reaps, stops on SIGTERM
//    The agent itself stays unprivileged. Commands run in it through
//      DockerExecCommandRunner sidecar(api, sidecar_id);       // docker_exec_runner.hpp (I/O)
//
// 3. Mechanism, once per host, then refuse what it cannot do before anything starts:
//      auto mech = cache.Get(host, [&] { return DetectMechanism(sidecar); });   // mechanism.hpp
//      CheckMechanismSupports(rules, *mech) for the mesh rules and every radio fault.
//
// 4. Run: the mesh block on every agent,
//      RadioLayers layers(mesh->rules, drones);                                  // radio_layers.hpp
//      auto plan = PlanRadio(layers.Effective(d), link_of(d), *mech, {.seed = trial_seed});
//      RunCommands(sidecar_of(d), plan->apply);                                  // command_runner.hpp
//    then the schedule:
//      FaultTimeline timeline(*faults);  LeaderTracker leaders;                  // fault_timeline.hpp
//      every log line:  leaders.Feed(line); Carry(timeline.OnLogLine(line, wall_s));
//      every ~50 ms:    Carry(timeline.Advance(sim_s, wall_s));
//      shutdown:        Carry(timeline.RemoveAll());   the mesh plans need no undo when the
//                       sidecars are removed next: their rules and daemons go with the sidecars'
//                       network namespaces (the runner's FaultInjector records them removed so);
//                       a fault window ending mid-trial is undone with its plan's undo.
//    Carrying one action, by kind (targets from ResolveTarget(target, drones, leaders, rng) with
//    rng seeded from the trial's seed: target_resolver.hpp):
//      radio      apply: changed = layers.Push(id, targets, rules); remove: changed = layers.Pop(id);
//                 for each changed node: PlanRadioChange(before, after, ...) -> RunCommands in its
//                 sidecar (radio_plan.hpp). Mechanism: MechanismName(*mech).
//      partition  PlanPartition(fault, mesh_nodes, fault_index): apply/undo per node in its sidecar
//                 (partition_plan.hpp). Mechanism "iptables".
//      kill/stop/pause/restart
//                 PlanProcessFault(fault, containers, has_duration) -> ExecuteDockerActions(api,
//                 plan.apply / plan.undo) (process_plan.hpp). Mechanism "docker".
//      gps_dropout/gps_degrade/imu_bias/wind_gust
//                 PlanPhysicsFault(fault, targets) -> world commands for the physics server,
//                 each sent by `swarmbox-physics --send-command` exec'd in the physics container
//                 (physics_plan.hpp). Mechanism "physics-command".
//    Each application, removal or failure is one events.jsonl line: FaultEventJson(fault, record)
//    (fault_event.hpp), with the resolved targets and the mechanism used; the mesh block on each
//    agent is recorded with MeshEventJson(node, rules, record).
//
// The userspace delayer, swarmbox-netemd (netemd_args.hpp for its command line), is started and
// stopped by the radio plans themselves; its scheduling core is DelayScheduler
// (delay_scheduler.hpp), with netem's random numbers in netem_random.hpp.
#pragma once

#include "swarmbox/faults/channel_support.hpp"
#include "swarmbox/faults/command_runner.hpp"
#include "swarmbox/faults/delay_scheduler.hpp"
#include "swarmbox/faults/docker_actions.hpp"
#include "swarmbox/faults/docker_exec_runner.hpp"
#include "swarmbox/faults/duration_ms.hpp"
#include "swarmbox/faults/fault_event.hpp"
#include "swarmbox/faults/fault_spec.hpp"
#include "swarmbox/faults/fault_timeline.hpp"
#include "swarmbox/faults/leader_tracker.hpp"
#include "swarmbox/faults/mechanism.hpp"
#include "swarmbox/faults/netem_random.hpp"
#include "swarmbox/faults/netem_spec.hpp"
#include "swarmbox/faults/netemd_args.hpp"
#include "swarmbox/faults/partition_plan.hpp"
#include "swarmbox/faults/physics_plan.hpp"
#include "swarmbox/faults/posix_command_runner.hpp"
#include "swarmbox/faults/process_plan.hpp"
#include "swarmbox/faults/radio_layers.hpp"
#include "swarmbox/faults/radio_plan.hpp"
#include "swarmbox/faults/target_resolver.hpp"
