/* The rendezvous protocol: rendezvous.h. */
#include "rendezvous.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double kPi = 3.14159265358979323846;

void rv_init(rv_state *s, const rv_config *config) {
  memset(s, 0, sizeof *s);
  s->config = *config;
}

/* The member's index, or n_members when `name` (`length` bytes) is none of them. */
static size_t member_index(const rv_config *c, const char *name, size_t length) {
  for (size_t i = 0; i < c->n_members; ++i) {
    if (strlen(c->members[i]) == length && memcmp(c->members[i], name, length) == 0) return i;
  }
  return c->n_members;
}

/* A finite number filling all of `text`. */
static bool parse_double(const char *text, double *out) {
  char *end = NULL;
  errno = 0;
  const double v = strtod(text, &end);
  if (end == text || *end != '\0' || errno != 0 || !isfinite(v)) return false;
  *out = v;
  return true;
}

void rv_apply_entry(rv_state *s, const uint8_t *data, size_t length) {
  char text[RV_ENTRY_MAX];
  if (length == 0 || length >= sizeof text) return;
  memcpy(text, data, length);
  text[length] = '\0';
  if (strlen(text) != length) return; /* holds a NUL: not text */

  /* Words separated by runs of spaces: "pos <member> <x> <y>" or "arrived <member>". */
  char *words[4];
  size_t n = 0;
  for (char *p = text; *p != '\0';) {
    if (*p == ' ') {
      *p++ = '\0';
      continue;
    }
    if (n == 4) return; /* a fifth word: not ours */
    words[n++] = p;
    while (*p != '\0' && *p != ' ') ++p;
  }
  if (n < 2) return;
  const size_t who = member_index(&s->config, words[1], strlen(words[1]));
  if (who == s->config.n_members) return;

  if (n == 4 && strcmp(words[0], "pos") == 0) {
    double x = 0.0;
    double y = 0.0;
    if (!parse_double(words[2], &x) || !parse_double(words[3], &y)) return;
    if (s->have_pos[who]) return; /* the first one counts */
    s->have_pos[who] = true;
    s->pos_x_m[who] = x;
    s->pos_y_m[who] = y;
    ++s->n_pos;
  } else if (n == 2 && strcmp(words[0], "arrived") == 0) {
    if (s->have_arrived[who]) return;
    s->have_arrived[who] = true;
    ++s->n_arrived;
  }
}

static void add_command(rv_output *out, const char *name, double param) {
  out->commands[out->n_commands].name = name;
  out->commands[out->n_commands].param = param;
  ++out->n_commands;
}

static void add_proposal(rv_output *out, const char *text) {
  snprintf(out->proposals[out->n_proposals], sizeof out->proposals[0], "%s", text);
  ++out->n_proposals;
}

static rv_event *add_event(rv_output *out, const char *name) {
  rv_event *e = &out->events[out->n_events++];
  e->name = name;
  e->n_fields = 0;
  return e;
}

static void add_field(rv_event *e, const char *key, const char *value) {
  snprintf(e->fields[e->n_fields].key, sizeof e->fields[0].key, "%s", key);
  snprintf(e->fields[e->n_fields].value, sizeof e->fields[0].value, "%s", value);
  ++e->n_fields;
}

/* Due: never proposed, or proposed at least RV_REPROPOSE_NS ago (simulated). */
static bool due(bool proposed, int64_t proposed_ns, int64_t t_ns) {
  return !proposed || t_ns - proposed_ns >= RV_REPROPOSE_NS;
}

/* P and this drone's slot, once every member's "pos" is committed. */
static void place_slot(rv_state *s, rv_output *out) {
  const rv_config *c = &s->config;
  double sum_x = 0.0;
  double sum_y = 0.0;
  for (size_t i = 0; i < c->n_members; ++i) { /* sorted member order: the same sum everywhere */
    sum_x += s->pos_x_m[i];
    sum_y += s->pos_y_m[i];
  }
  const double n = (double)c->n_members;
  s->point_m[0] = sum_x / n;
  s->point_m[1] = sum_y / n;
  const double a = 2.0 * kPi * (double)c->self / n;
  s->slot_m[0] = s->point_m[0] + c->radius_m * cos(a);
  s->slot_m[1] = s->point_m[1] + c->radius_m * sin(a);
  s->point_known = true;

  char value[32];
  rv_event *e = add_event(out, "rendezvous_point");
  snprintf(value, sizeof value, "%.3f", s->point_m[0]);
  add_field(e, "x", value);
  snprintf(value, sizeof value, "%.3f", s->point_m[1]);
  add_field(e, "y", value);
}

static void fly_to_slot(const rv_state *s, rv_output *out) {
  out->has_setpoint = true;
  out->setpoint_enu_m[0] = s->slot_m[0];
  out->setpoint_enu_m[1] = s->slot_m[1];
  out->setpoint_enu_m[2] = s->config.altitude_m;
}

void rv_step(rv_state *s, const rv_input *in, rv_output *out) {
  const rv_config *c = &s->config;
  const char *self = c->members[c->self];
  memset(out, 0, sizeof *out);

  if (in->hover_event ||
      (strcmp(in->flight_mode, "hold") == 0 && in->position_enu_m[2] > c->altitude_m - 1.0)) {
    s->airborne = true;
  }

  if (s->done) {
    out->status = "rendezvous/done";
    return;
  }
  if (s->land_commanded) {
    if (in->landed || in->landed_event) {
      s->done = true;
      char members[32];
      snprintf(members, sizeof members, "%zu", c->n_members);
      add_field(add_event(out, "rendezvous_complete"), "members", members);
      out->status = "rendezvous/done";
    } else {
      out->status = "rendezvous/landing";
    }
    return;
  }

  /* 1. take off */
  if (!s->airborne) {
    if (in->rejected_event) s->takeoff_asked = false; /* the flight stack refused it: ask again */
    if (!s->takeoff_asked && in->landed && strcmp(in->flight_mode, "init") != 0) {
      add_command(out, "takeoff", c->altitude_m);
      s->takeoff_asked = true;
    }
    out->status = "rendezvous/takeoff";
    return;
  }

  /* 2. vote on the positions */
  if (s->n_pos < c->n_members) {
    if (s->pos_entry[0] == '\0') { /* where it hovers first: the same entry every time */
      snprintf(s->pos_entry, sizeof s->pos_entry, "pos %s %.3f %.3f", self, in->position_enu_m[0],
               in->position_enu_m[1]);
    }
    if (!s->have_pos[c->self] && due(s->pos_proposed, s->pos_proposed_ns, in->t_ns)) {
      add_proposal(out, s->pos_entry);
      s->pos_proposed = true;
      s->pos_proposed_ns = in->t_ns;
    }
    out->status = "rendezvous/voting";
    return;
  }

  /* 3. fly to the slot */
  if (!s->point_known) place_slot(s, out);

  /* 5. everyone arrived: hold hold_s on the slot, then land */
  if (s->n_arrived == c->n_members) {
    if (!s->all_arrived) {
      s->all_arrived = true;
      s->all_arrived_ns = in->t_ns;
    }
    const int64_t hold_ns = (int64_t)llround(c->hold_s * 1e9);
    if (in->t_ns - s->all_arrived_ns >= hold_ns) {
      add_command(out, "land", 0.0);
      s->land_commanded = true;
    } else {
      fly_to_slot(s, out);
    }
    out->status = "rendezvous/landing";
    return;
  }

  /* 4. arrived: tell the others */
  fly_to_slot(s, out);
  if (!s->near_slot && hypot(in->position_enu_m[0] - s->slot_m[0],
                             in->position_enu_m[1] - s->slot_m[1]) <= RV_ARRIVED_RADIUS_M) {
    s->near_slot = true;
  }
  if (!s->near_slot) {
    out->status = "rendezvous/flying";
    return;
  }
  if (!s->have_arrived[c->self] && due(s->arrived_proposed, s->arrived_proposed_ns, in->t_ns)) {
    char entry[RV_ENTRY_MAX];
    snprintf(entry, sizeof entry, "arrived %s", self);
    add_proposal(out, entry);
    s->arrived_proposed = true;
    s->arrived_proposed_ns = in->t_ns;
  }
  out->status = "rendezvous/arrived";
}
