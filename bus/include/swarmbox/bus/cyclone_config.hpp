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
#pragma once

#include <string>

namespace swarmbox::bus {

struct CycloneSettings {
  std::string interface;      // network interface name (not validated here)
  int writer_linger_ms = -1;  // Internal/WriterLingerDuration; -1: Cyclone's default (1 s)
};

// The <CycloneDDS> document for every domain id (Domain Id="any").
inline std::string CycloneXml(const CycloneSettings& s) {
  std::string internal = "<SocketReceiveBufferSize max=\"4MiB\"/>";
  if (s.writer_linger_ms >= 0) {
    internal += "<WriterLingerDuration>" + std::to_string(s.writer_linger_ms) + " ms</WriterLingerDuration>";
  }
  return "<CycloneDDS><Domain Id=\"any\">"
         "<General><Interfaces><NetworkInterface name=\"" + s.interface + "\" multicast=\"true\"/></Interfaces>"
         "<AllowMulticast>true</AllowMulticast>"
         "<MaxMessageSize>65000B</MaxMessageSize><FragmentSize>62000B</FragmentSize></General>"
         "<Discovery><ParticipantIndex>none</ParticipantIndex><LeaseDuration>20 s</LeaseDuration>"
         "<SPDPInterval>10 s</SPDPInterval></Discovery>"
         "<Internal>" + internal + "</Internal>"
         "<Tracing><Verbosity>severe</Verbosity><OutputFile>stderr</OutputFile></Tracing>"
         "</Domain></CycloneDDS>";
}

}  // namespace swarmbox::bus
