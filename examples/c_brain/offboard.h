/* The offboard topics over Cyclone DDS's C API: what any program that flies a SwarmBox drone must
 * do (README.md here has the same as prose).
 *
 *   participant  domain --domain; the network interface from CYCLONEDDS_URI
 *   reader       offboard/<drone>/input   swarmbox::msg::BrainInput    (agent -> brain)
 *   writer       offboard/<drone>/output  swarmbox::msg::BrainOutput   (brain -> agent)
 *   QoS (both)   reliable, volatile, keep-last 16: the bus's kLockstep preset; the writer
 *                writes plain CDR (XCDR1), which every SwarmBox agent reads
 *   rule         every BrainInput is answered by exactly one BrainOutput with its sim_time_ns;
 *                an input repeating the previous one's sim_time_ns (the agent resends its first
 *                input until it hears an answer) gets the same answer again, the brain is not
 *                stepped twice
 */
#ifndef SWARMBOX_C_BRAIN_OFFBOARD_H
#define SWARMBOX_C_BRAIN_OFFBOARD_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <dds/dds.h>

#include "rendezvous.h"

typedef struct offboard {
  char drone[RV_NAME_MAX];
  dds_entity_t participant; /* owns the topics, the reader, the writer and the waitset */
  dds_entity_t reader;
  dds_entity_t writer;
  dds_entity_t waitset;
  uint64_t answered; /* BrainInputs answered */
  bool has_last;     /* last: the previous answer, for a repeated input */
  int64_t last_t_ns;
  rv_output last;
} offboard;

/* 0, or -1 with what failed (and Cyclone's reason) in `error`; offboard_close either way. */
int offboard_open(offboard *o, uint32_t domain, const char *drone, char *error, size_t error_size);

/* Answers every BrainInput until *stop becomes non-zero (checked at least every 100 ms of wall
 * time: a liveness bound, never an input to the brain): 0, or -1 with the reason in `error`. */
int offboard_run(offboard *o, rv_state *brain, volatile sig_atomic_t *stop, char *error,
                 size_t error_size);

void offboard_close(offboard *o);

#endif /* SWARMBOX_C_BRAIN_OFFBOARD_H */
