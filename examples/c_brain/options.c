/* The command line: options.h. */
#include "options.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char kUsage[] =
    "usage: swarmbox_c_brain --drone NAME --members a,b,c [--domain N] [--altitude-m A]\n"
    "                        [--radius-m R] [--hold-s S]\n"
    "  --drone NAME      this drone ([A-Za-z0-9_]+): topics offboard/NAME/input and output\n"
    "  --members a,b,c   every drone of the rendezvous (this one included)\n"
    "  --domain N        the DDS domain id of the trial's sim network (default 0)\n"
    "  --altitude-m A    take-off height and the ring's height [m] (default 10)\n"
    "  --radius-m R      the ring's radius [m] (default 6)\n"
    "  --hold-s S        simulated seconds on the ring after everyone arrived (default 5)\n"
    "The network interface comes from CYCLONEDDS_URI in the environment.\n";

static bool valid_name(const char *name, size_t length) {
  if (length == 0 || length >= RV_NAME_MAX) return false;
  for (size_t i = 0; i < length; ++i) {
    const char ch = name[i];
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '_';
    if (!ok) return false;
  }
  return true;
}

static int compare_names(const void *a, const void *b) {
  return strcmp((const char *)a, (const char *)b);
}

static int fail(char *error, size_t size, const char *flag, const char *value, const char *why) {
  snprintf(error, size, "%s '%s': %s", flag, value, why);
  return -1;
}

static int parse_number(const char *flag, const char *value, double min, double *out, char *error,
                        size_t size) {
  char *end = NULL;
  errno = 0;
  const double v = strtod(value, &end);
  if (end == value || *end != '\0' || errno != 0 || !isfinite(v)) {
    return fail(error, size, flag, value, "not a number");
  }
  if (v < min) {
    char why[64];
    snprintf(why, sizeof why, "must be at least %g", min);
    return fail(error, size, flag, value, why);
  }
  *out = v;
  return 0;
}

static int parse_members(const char *value, rv_config *c, char *error, size_t size) {
  c->n_members = 0;
  const char *p = value;
  while (true) {
    const char *comma = strchr(p, ',');
    const size_t length = comma != NULL ? (size_t)(comma - p) : strlen(p);
    if (!valid_name(p, length)) {
      return fail(error, size, "--members", value, "names are [A-Za-z0-9_]+, separated by commas");
    }
    if (c->n_members == RV_MAX_MEMBERS) {
      return fail(error, size, "--members", value, "more than 64 members");
    }
    memcpy(c->members[c->n_members], p, length);
    c->members[c->n_members][length] = '\0';
    ++c->n_members;
    if (comma == NULL) break;
    p = comma + 1;
  }
  qsort(c->members, c->n_members, sizeof c->members[0], compare_names);
  for (size_t i = 1; i < c->n_members; ++i) {
    if (strcmp(c->members[i - 1], c->members[i]) == 0) {
      return fail(error, size, "--members", value, "a member is named twice");
    }
  }
  return 0;
}

int parse_options(int argc, char **argv, brain_options *out, char *error, size_t error_size) {
  memset(out, 0, sizeof *out);
  out->rendezvous.altitude_m = 10.0;
  out->rendezvous.radius_m = 6.0;
  out->rendezvous.hold_s = 5.0;
  const char *members = NULL;

  for (int i = 1; i < argc; ++i) {
    const char *arg = argv[i];
    if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
      out->help = 1;
      return 0;
    }
    if (strncmp(arg, "--", 2) != 0) return fail(error, error_size, "argument", arg, "not a flag");
    char flag[32];
    const char *value = NULL;
    const char *eq = strchr(arg, '=');
    const size_t flag_length = eq != NULL ? (size_t)(eq - arg) : strlen(arg);
    if (flag_length >= sizeof flag) return fail(error, error_size, "flag", arg, "unknown flag");
    memcpy(flag, arg, flag_length);
    flag[flag_length] = '\0';
    if (eq != NULL) {
      value = eq + 1;
    } else if (i + 1 < argc) {
      value = argv[++i];
    } else {
      snprintf(error, error_size, "%s wants a value", flag);
      return -1;
    }

    int rc = 0;
    if (strcmp(flag, "--drone") == 0) {
      if (!valid_name(value, strlen(value))) {
        return fail(error, error_size, flag, value, "a drone name is [A-Za-z0-9_]+");
      }
      snprintf(out->drone, sizeof out->drone, "%s", value);
    } else if (strcmp(flag, "--members") == 0) {
      members = value;
    } else if (strcmp(flag, "--domain") == 0) {
      double d = 0.0;
      rc = parse_number(flag, value, 0.0, &d, error, error_size);
      if (rc == 0 && (d != floor(d) || d > 232.0)) {
        return fail(error, error_size, flag, value, "a DDS domain id is an integer 0 to 232");
      }
      out->domain = (uint32_t)d;
    } else if (strcmp(flag, "--altitude-m") == 0) {
      rc = parse_number(flag, value, 1.0, &out->rendezvous.altitude_m, error, error_size);
    } else if (strcmp(flag, "--radius-m") == 0) {
      rc = parse_number(flag, value, 0.0, &out->rendezvous.radius_m, error, error_size);
    } else if (strcmp(flag, "--hold-s") == 0) {
      rc = parse_number(flag, value, 0.0, &out->rendezvous.hold_s, error, error_size);
    } else {
      return fail(error, error_size, "flag", flag, "unknown flag");
    }
    if (rc != 0) return rc;
  }

  if (out->drone[0] == '\0') {
    snprintf(error, error_size, "--drone is required");
    return -1;
  }
  if (members == NULL) {
    snprintf(error, error_size, "--members is required");
    return -1;
  }
  if (parse_members(members, &out->rendezvous, error, error_size) != 0) return -1;
  for (size_t i = 0; i < out->rendezvous.n_members; ++i) {
    if (strcmp(out->rendezvous.members[i], out->drone) == 0) {
      out->rendezvous.self = i;
      return 0;
    }
  }
  return fail(error, error_size, "--members", members, "does not name --drone");
}
