// The Cyclone DDS configuration of every SwarmBox process on a domain, as the XML Cyclone reads
// (dds_create_domain, or the CYCLONEDDS_URI environment variable of a program the runner starts).
// Vendor-free and header-only (a string): the Cyclone backend gives it to dds_create_domain, and
// the orchestrator, which links neither DDS nor the bus, gives the same text to external brains
// and components.
//
//   auto xml = CycloneXml({.interface = "eth0"});
//
// Each setting and why (bus/README.md "Cyclone DDS configuration" has the figures):
//   General/Interfaces      the one interface of the domain, multicast forced on (lo says it cannot)
//   General/AllowMulticast  true: SPDP (participant discovery) and SEDP (endpoint discovery) go to
//                           a multicast group, one send for every participant instead of one per
//                           participant (the physics server's ~200 endpoints to 100 agents); data
//                           stays unicast where a writer has one reader (sensor, camera, actuator)
//   General/MaxMessageSize  65000 B, FragmentSize 62000 B: a 230 KB camera frame is 4 fragments in
//                           4 datagrams, not 172 fragments in 16 (Cyclone's 14720 B / 1344 B)
//   Discovery/ParticipantIndex none: unicast ports from the kernel, no limit on participants per
//                           address (auto stops at MaxAutoParticipantIndex, 9)
//   Discovery/LeaseDuration 20 s: a participant silent that long (a starved or paused container)
//                           is dropped; the lockstep's own timeouts decide whether a drone is lost
//   Discovery/SPDPInterval  10 s: each participant's periodic SPDP, which every other participant
//                           processes (N^2 / interval receptions per second for the host)
//   Internal/SocketReceiveBufferSize max 4 MiB: room for a step's burst of 100 answers at the
//                           server and for camera frames at a slow agent (capped by rmem_max)
//   Internal/WriterLingerDuration  only when set (ParticipantConfig::writer_linger_ms)
//   Tracing                 severe only, to stderr
//
// Discovery as a star (the sim domain of a trial; ARCHITECTURE.md, "Two radio models"):
//   participant_index >= 0  Discovery/ParticipantIndex N: the participant's unicast discovery port is
//                           the well-known DDSI one (CycloneDiscoveryPort), so others can name it
//                           as a peer. The physics server: 0, alone in its container.
//   peers non-empty         AllowMulticast false and Discovery/Peers: the participant announces
//                           itself only to these "host:port"s and hears no multicast, so it
//                           discovers them and whoever answers them, not every other participant.
//                           An agent names the physics server (and its own brain): N agents make
//                           N server-agent pairs, not N^2/2 agent-agent pairs whose endpoint
//                           announcements (SEDP, reliable) swamped a 40-drone start on 2 cores.
#pragma once

#include <string>
#include <vector>

namespace swarmbox::bus {

struct CycloneSettings {
  std::string interface;      // network interface name (not validated here)
  int writer_linger_ms = -1;  // Internal/WriterLingerDuration; -1: Cyclone's default (1 s)
  int participant_index = -1;        // Discovery/ParticipantIndex; -1: none (ports from the kernel)
  std::vector<std::string> peers = {};  // "host:port"; non-empty: unicast discovery to these only
};

// The DDSI well-known unicast discovery (metatraffic) port of participant index `index` on
// domain `domain_id`: PB + DG * domain + d1 + PG * index with Cyclone's defaults (7400, 250, 10, 2).
inline int CycloneDiscoveryPort(int domain_id, int index) { return 7400 + 250 * domain_id + 10 + 2 * index; }

// The <CycloneDDS> document for every domain id (Domain Id="any").
inline std::string CycloneXml(const CycloneSettings& s) {
  std::string internal = "<SocketReceiveBufferSize max=\"4MiB\"/>";
  if (s.writer_linger_ms >= 0) {
    internal += "<WriterLingerDuration>" + std::to_string(s.writer_linger_ms) + " ms</WriterLingerDuration>";
  }
  const bool star = !s.peers.empty();
  std::string peers;
  for (const std::string& p : s.peers) peers += "<Peer Address=\"" + p + "\"/>";
  const std::string index = s.participant_index >= 0 ? std::to_string(s.participant_index) : "none";
  return "<CycloneDDS><Domain Id=\"any\">"
         "<General><Interfaces><NetworkInterface name=\"" + s.interface + "\"" +
         (star ? std::string() : std::string(" multicast=\"true\"")) + "/></Interfaces>"
         "<AllowMulticast>" + (star ? "false" : "true") + "</AllowMulticast>"
         "<MaxMessageSize>65000B</MaxMessageSize><FragmentSize>62000B</FragmentSize></General>"
         "<Discovery><ParticipantIndex>" + index + "</ParticipantIndex>" +
         (star ? "<Peers>" + peers + "</Peers>" : std::string()) +
         "<LeaseDuration>20 s</LeaseDuration>"
         "<SPDPInterval>10 s</SPDPInterval></Discovery>"
         "<Internal>" + internal + "</Internal>"
         "<Tracing><Verbosity>severe</Verbosity><OutputFile>stderr</OutputFile></Tracing>"
         "</Domain></CycloneDDS>";
}

}  // namespace swarmbox::bus
