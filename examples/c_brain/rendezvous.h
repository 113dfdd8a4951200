/* The rendezvous protocol (design of issue #24; the C++ example brain examples/brains/rendezvous
 * implements the same): every member takes off, agrees through the swarm's consensus log on where
 * each one is, flies to its slot on a ring around the mean, waits until all have arrived, holds,
 * and lands.
 *
 *   rv_state s;
 *   rv_init(&s, &config);                       // config from the command line (options.h)
 *   for each BrainInput:
 *     for each committed entry: rv_apply_entry(&s, data, length);   // in index order
 *     rv_step(&s, &input, &output);            // then send output as the BrainOutput
 *
 * Pure: no DDS, no clock, no allocation. The only time is rv_input.t_ns (the BrainInput's
 * sim_time_ns), so the same inputs always give the same outputs.
 *
 * Entries (ASCII text, in Proposal.data / CommittedEntry.data, no terminating NUL; words separated
 * by spaces):
 *   "pos <member> <x> <y>"   its estimated position [m, world ENU] when it started hovering, %.3f
 *   "arrived <member>"       it is within 1 m of its slot
 * The first entry of each kind per member counts; entries of unknown members or of another shape
 * are ignored (the log may hold other brains' entries).
 *
 * Phases (status):
 *   rendezvous/takeoff  landed, flight stack ready (mode not "init"): command takeoff(altitude_m)
 *                       once (again after a setpoint_rejected flight event before hovering)
 *   rendezvous/voting   hovering (flight event "hover", or mode "hold" above altitude_m - 1 m):
 *                       propose "pos" (where it is at that first step); the same entry again
 *                       every 2 s until its own "pos" is committed
 *   rendezvous/flying   a "pos" of every member committed: P = their mean (summed in sorted member
 *                       order); slot i (index in sorted members) = P + radius_m (cos a, sin a),
 *                       a = 2 pi i / N; a position setpoint (slot, altitude_m) every step, yaw unset;
 *                       event rendezvous_point x=.. y=.. once
 *   rendezvous/arrived  within 1.0 m of the slot horizontally: propose "arrived"; again every 2 s
 *                       until committed; the setpoint stays
 *   rendezvous/landing  "arrived" of every member committed: hold_s more on the slot, then the
 *                       land command (once), no setpoint after it
 *   rendezvous/done     landed (vehicle.landed or a flight event "landed") after the land command:
 *                       event rendezvous_complete members=N once
 */
#ifndef SWARMBOX_C_BRAIN_RENDEZVOUS_H
#define SWARMBOX_C_BRAIN_RENDEZVOUS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RV_MAX_MEMBERS 64
#define RV_NAME_MAX 64   /* a drone name's bytes + NUL ([A-Za-z0-9_]+) */
#define RV_ENTRY_MAX 160 /* an entry's text + NUL */
#define RV_REPROPOSE_NS INT64_C(2000000000)
#define RV_ARRIVED_RADIUS_M 1.0

typedef struct rv_config {
  double altitude_m; /* [m] above the start, also the ring's height */
  double radius_m;   /* [m] the ring's radius */
  double hold_s;     /* [s] simulated, on the slot after everyone arrived */
  size_t n_members;
  char members[RV_MAX_MEMBERS][RV_NAME_MAX]; /* sorted by strcmp, unique */
  size_t self;                               /* this drone's index in members */
} rv_config;

/* What rv_step needs of one BrainInput. */
typedef struct rv_input {
  int64_t t_ns;               /* BrainInput.sim_time_ns: the only clock */
  double position_enu_m[3];   /* vehicle.position_enu_m (estimated) */
  const char *flight_mode;    /* vehicle.flight_mode */
  bool landed;                /* vehicle.landed */
  bool hover_event;           /* a flight event "hover" in this input */
  bool rejected_event;        /* a flight event "setpoint_rejected" in this input */
  bool landed_event;          /* a flight event "landed" in this input */
} rv_input;

typedef struct rv_command {
  const char *name; /* "takeoff" or "land" (VehicleCommand.command) */
  double param;     /* takeoff: height above the start [m] */
} rv_command;

typedef struct rv_field {
  char key[16];
  char value[32];
} rv_field;

typedef struct rv_event {
  const char *name; /* "rendezvous_point", "rendezvous_complete" */
  size_t n_fields;
  rv_field fields[2];
} rv_event;

/* One BrainOutput's worth; rv_step clears it first. */
typedef struct rv_output {
  bool has_setpoint;
  double setpoint_enu_m[3]; /* a position setpoint; velocity, acceleration, yaw unset */
  size_t n_commands;
  rv_command commands[2];
  size_t n_proposals;
  char proposals[2][RV_ENTRY_MAX]; /* entries to propose, as text */
  const char *status;              /* "rendezvous/<phase>" */
  size_t n_events;
  rv_event events[2];
} rv_output;

typedef struct rv_state {
  rv_config config;
  bool takeoff_asked;
  bool airborne;
  char pos_entry[RV_ENTRY_MAX]; /* "pos <self> <x> <y>" where it first hovered */
  bool pos_proposed;
  int64_t pos_proposed_ns;
  size_t n_pos;
  bool have_pos[RV_MAX_MEMBERS];
  double pos_x_m[RV_MAX_MEMBERS];
  double pos_y_m[RV_MAX_MEMBERS];
  bool point_known;
  double point_m[2]; /* P */
  double slot_m[2];  /* this drone's slot */
  bool near_slot;
  bool arrived_proposed;
  int64_t arrived_proposed_ns;
  size_t n_arrived;
  bool have_arrived[RV_MAX_MEMBERS];
  bool all_arrived;
  int64_t all_arrived_ns;
  bool land_commanded;
  bool done;
} rv_state;

void rv_init(rv_state *s, const rv_config *config);

/* Applies one committed entry (any bytes; what is not a rendezvous entry is ignored). */
void rv_apply_entry(rv_state *s, const uint8_t *data, size_t length);

/* One brain period: the answer to `in` in `out`. */
void rv_step(rv_state *s, const rv_input *in, rv_output *out);

#ifdef __cplusplus
}
#endif

#endif /* SWARMBOX_C_BRAIN_RENDEZVOUS_H */
