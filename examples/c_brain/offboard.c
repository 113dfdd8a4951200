/* The offboard topics over Cyclone DDS's C API: offboard.h. */
#include "offboard.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "swarmbox.h" /* idlc -l c of swarmbox.idl */

/* Inputs taken per dds_take (loaned: Cyclone owns the samples until dds_return_loan). */
#define TAKE_BATCH 16

static int dds_fail(char *error, size_t size, const char *doing, dds_return_t rc) {
  snprintf(error, size, "%s: %s", doing, dds_strretcode(rc));
  return -1;
}

/* kLockstep of bus/include/swarmbox/bus/topics.hpp; the caller deletes it. */
static dds_qos_t *lockstep_qos(bool writer) {
  dds_qos_t *q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 16);
  if (writer) {
    const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
    dds_qset_data_representation(q, 1, &xcdr1);
  }
  return q;
}

int offboard_open(offboard *o, uint32_t domain, const char *drone, char *error, size_t error_size) {
  memset(o, 0, sizeof *o);
  snprintf(o->drone, sizeof o->drone, "%s", drone);
  char name[RV_NAME_MAX + 32];

  o->participant = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (o->participant < 0) {
    const dds_return_t rc = o->participant;
    o->participant = 0;
    snprintf(name, sizeof name, "creating a participant on domain %u", (unsigned)domain);
    return dds_fail(error, error_size, name, rc);
  }

  snprintf(name, sizeof name, "offboard/%s/input", drone);
  const dds_entity_t in_topic =
      dds_create_topic(o->participant, &swarmbox_msg_BrainInput_desc, name, NULL, NULL);
  if (in_topic < 0) return dds_fail(error, error_size, "creating topic offboard/<drone>/input", in_topic);
  dds_qos_t *q = lockstep_qos(false);
  o->reader = dds_create_reader(o->participant, in_topic, q, NULL);
  dds_delete_qos(q);
  if (o->reader < 0) return dds_fail(error, error_size, "creating the BrainInput reader", o->reader);

  snprintf(name, sizeof name, "offboard/%s/output", drone);
  const dds_entity_t out_topic =
      dds_create_topic(o->participant, &swarmbox_msg_BrainOutput_desc, name, NULL, NULL);
  if (out_topic < 0) return dds_fail(error, error_size, "creating topic offboard/<drone>/output", out_topic);
  q = lockstep_qos(true);
  o->writer = dds_create_writer(o->participant, out_topic, q, NULL);
  dds_delete_qos(q);
  if (o->writer < 0) return dds_fail(error, error_size, "creating the BrainOutput writer", o->writer);

  o->waitset = dds_create_waitset(o->participant);
  if (o->waitset < 0) return dds_fail(error, error_size, "creating a waitset", o->waitset);
  const dds_entity_t ready = dds_create_readcondition(o->reader, DDS_ANY_STATE);
  if (ready < 0) return dds_fail(error, error_size, "creating a read condition", ready);
  const dds_return_t rc = dds_waitset_attach(o->waitset, ready, 0);
  if (rc < 0) return dds_fail(error, error_size, "attaching the read condition", rc);
  return 0;
}

void offboard_close(offboard *o) {
  if (o->participant > 0) dds_delete(o->participant); /* and everything it created */
  o->participant = 0;
}

/* rv_input from a BrainInput; the committed entries go to the brain first, in index order. */
static void read_input(rv_state *brain, const swarmbox_msg_BrainInput *in, rv_input *out) {
  for (uint32_t i = 0; i < in->committed._length; ++i) {
    const dds_sequence_octet *data = &in->committed._buffer[i].data;
    rv_apply_entry(brain, data->_buffer, data->_length);
  }
  memset(out, 0, sizeof *out);
  out->t_ns = in->sim_time_ns;
  memcpy(out->position_enu_m, in->vehicle.position_enu_m, sizeof out->position_enu_m);
  out->flight_mode = in->vehicle.flight_mode != NULL ? in->vehicle.flight_mode : "";
  out->landed = in->vehicle.landed;
  for (uint32_t i = 0; i < in->flight_events._length; ++i) {
    const char *event = in->flight_events._buffer[i].name;
    if (event == NULL) continue;
    if (strcmp(event, "hover") == 0) out->hover_event = true;
    if (strcmp(event, "setpoint_rejected") == 0) out->rejected_event = true;
    if (strcmp(event, "landed") == 0) out->landed_event = true;
  }
}

/* Sends `r` as the BrainOutput answering `t_ns`. Every sequence points into `r` or the locals
 * here (_release false): nothing is allocated, nothing to free. */
static dds_return_t write_output(offboard *o, int64_t t_ns, rv_output *r) {
  swarmbox_msg_BrainOutput msg;
  memset(&msg, 0, sizeof msg);
  msg.drone = o->drone;
  msg.sim_time_ns = t_ns;

  swarmbox_msg_TrajectorySetpoint setpoint;
  if (r->has_setpoint) {
    for (int axis = 0; axis < 3; ++axis) {
      setpoint.position_enu_m[axis] = r->setpoint_enu_m[axis];
      setpoint.velocity_enu_m_s[axis] = NAN; /* NaN: unset (PX4 TrajectorySetpoint) */
      setpoint.acceleration_enu_m_s2[axis] = NAN;
    }
    setpoint.yaw_rad = NAN;
    setpoint.yawspeed_rad_s = NAN;
    msg.setpoint._buffer = &setpoint;
    msg.setpoint._length = msg.setpoint._maximum = 1;
  }

  char command_names[2][16];
  swarmbox_msg_VehicleCommand commands[2];
  for (size_t i = 0; i < r->n_commands; ++i) {
    snprintf(command_names[i], sizeof command_names[i], "%s", r->commands[i].name);
    commands[i].command = command_names[i];
    commands[i].param = r->commands[i].param;
  }
  msg.commands._buffer = commands;
  msg.commands._length = msg.commands._maximum = (uint32_t)r->n_commands;

  swarmbox_msg_Proposal proposals[2];
  for (size_t i = 0; i < r->n_proposals; ++i) {
    proposals[i].data._buffer = (uint8_t *)r->proposals[i]; /* the text, without its NUL */
    proposals[i].data._length = proposals[i].data._maximum = (uint32_t)strlen(r->proposals[i]);
    proposals[i].data._release = false;
  }
  msg.proposals._buffer = proposals;
  msg.proposals._length = msg.proposals._maximum = (uint32_t)r->n_proposals;

  char status[64];
  snprintf(status, sizeof status, "%s", r->status != NULL ? r->status : "");
  msg.status = status;

  char event_names[2][32];
  swarmbox_msg_KeyValue fields[2][2];
  swarmbox_msg_Event events[2];
  for (size_t i = 0; i < r->n_events; ++i) {
    snprintf(event_names[i], sizeof event_names[i], "%s", r->events[i].name);
    events[i].node = o->drone;
    events[i].sim_time_ns = t_ns;
    events[i].name = event_names[i];
    for (size_t k = 0; k < r->events[i].n_fields; ++k) {
      fields[i][k].key = r->events[i].fields[k].key;
      fields[i][k].value = r->events[i].fields[k].value;
    }
    events[i].fields._buffer = fields[i];
    events[i].fields._length = events[i].fields._maximum = (uint32_t)r->events[i].n_fields;
    events[i].fields._release = false;
  }
  msg.events._buffer = events;
  msg.events._length = msg.events._maximum = (uint32_t)r->n_events;

  return dds_write(o->writer, &msg);
}

/* A line on stdout when the status changes (the agent logs the brain's events itself). */
static void log_status(const offboard *o, int64_t t_ns, const char *status, char *last,
                       size_t last_size) {
  if (status == NULL || strcmp(status, last) == 0) return;
  snprintf(last, last_size, "%s", status);
  printf("t=%.3f node=%s status=%s\n", (double)t_ns / 1e9, o->drone, status);
  fflush(stdout);
}

int offboard_run(offboard *o, rv_state *brain, volatile sig_atomic_t *stop, char *error,
                 size_t error_size) {
  char last_status[64] = "";
  while (!*stop) {
    /* Returns early on data; the timeout only bounds how late a signal is noticed. */
    const dds_return_t woken = dds_waitset_wait(o->waitset, NULL, 0, DDS_MSECS(100));
    if (woken < 0) return dds_fail(error, error_size, "waiting for BrainInput", woken);
    while (!*stop) {
      void *samples[TAKE_BATCH] = {NULL}; /* NULL: Cyclone lends its own buffers */
      dds_sample_info_t infos[TAKE_BATCH];
      const dds_return_t n = dds_take(o->reader, samples, infos, TAKE_BATCH, TAKE_BATCH);
      if (n < 0) return dds_fail(error, error_size, "taking BrainInput", n);
      if (n == 0) break;
      dds_return_t written = 0;
      for (int i = 0; i < n && written >= 0; ++i) {
        if (!infos[i].valid_data) continue; /* a writer went away: no data to answer */
        const swarmbox_msg_BrainInput *in = samples[i];
        if (!o->has_last || in->sim_time_ns != o->last_t_ns) {
          rv_input input;
          read_input(brain, in, &input);
          rv_step(brain, &input, &o->last);
          o->has_last = true;
          o->last_t_ns = in->sim_time_ns;
        }
        written = write_output(o, in->sim_time_ns, &o->last);
        if (written >= 0) {
          ++o->answered;
          log_status(o, in->sim_time_ns, o->last.status, last_status, sizeof last_status);
        }
      }
      dds_return_loan(o->reader, samples, n);
      if (written < 0) return dds_fail(error, error_size, "writing BrainOutput", written);
    }
  }
  return 0;
}
