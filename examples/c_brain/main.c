/* swarmbox_c_brain: the rendezvous brain (rendezvous.h) for one SwarmBox drone, in plain C11 over
 * the offboard topics (offboard.h), in its own process: README.md here.
 *
 * Exit codes: 0 on SIGTERM or SIGINT, 1 on a DDS failure, 2 on a bad command line. */
#define _POSIX_C_SOURCE 200809L /* sigaction */

#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "offboard.h"
#include "options.h"
#include "rendezvous.h"

static volatile sig_atomic_t g_stop = 0;

static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

int main(int argc, char **argv) {
  static brain_options options; /* static: rv_config holds 64 names */
  static rv_state brain;
  char error[256];
  if (parse_options(argc, argv, &options, error, sizeof error) != 0) {
    fprintf(stderr, "swarmbox_c_brain: %s\n%s", error, kUsage);
    return 2;
  }
  if (options.help) {
    fputs(kUsage, stdout);
    return 0;
  }

  struct sigaction action;
  memset(&action, 0, sizeof action);
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGTERM, &action, NULL);
  sigaction(SIGINT, &action, NULL);

  rv_init(&brain, &options.rendezvous);
  offboard o;
  if (offboard_open(&o, options.domain, options.drone, error, sizeof error) != 0) {
    fprintf(stderr, "swarmbox_c_brain: %s\n", error);
    offboard_close(&o);
    return 1;
  }
  printf("swarmbox_c_brain: drone=%s members=%zu domain=%u: answering offboard/%s/input\n",
         options.drone, options.rendezvous.n_members, (unsigned)options.domain, options.drone);
  fflush(stdout);

  const int rc = offboard_run(&o, &brain, &g_stop, error, sizeof error);
  if (rc != 0) fprintf(stderr, "swarmbox_c_brain: %s\n", error);
  printf("swarmbox_c_brain: stopped after %llu inputs\n", (unsigned long long)o.answered);
  offboard_close(&o);
  return rc == 0 ? 0 : 1;
}
