/* The command line of swarmbox_c_brain (the contract of `brain: {program: ...}` in a trial: the
 * orchestrator passes --drone, --domain and --members first, then the trial's brain.args):
 *
 *   swarmbox_c_brain --drone NAME --members a,b,c [--domain N] [--altitude-m A] [--radius-m R]
 *                    [--hold-s S]
 *
 * Each flag as `--flag value` or `--flag=value`; a later one wins. */
#ifndef SWARMBOX_C_BRAIN_OPTIONS_H
#define SWARMBOX_C_BRAIN_OPTIONS_H

#include <stddef.h>
#include <stdint.h>

#include "rendezvous.h"

typedef struct brain_options {
  char drone[RV_NAME_MAX]; /* this drone: the topics are offboard/<drone>/input|output */
  uint32_t domain;         /* the DDS domain of the trial's sim network (default 0) */
  rv_config rendezvous;    /* altitude_m 10, radius_m 6, hold_s 5; members sorted */
  int help;                /* --help was given */
} brain_options;

/* 0 and `out` filled, or -1 with the reason in `error` (one line, no newline). */
int parse_options(int argc, char **argv, brain_options *out, char *error, size_t error_size);

extern const char kUsage[];

#endif /* SWARMBOX_C_BRAIN_OPTIONS_H */
