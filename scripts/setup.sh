#!/usr/bin/env bash
# SwarmBox set-up: from a fresh Debian 12 machine to one that builds, tests and runs trials.
#
# - installs every Debian package the project needs (build, test, run), only when one is missing;
# - starts a Docker engine when none answers on /var/run/docker.sock (systemd when it runs the
#   machine, else dockerd in the background with its log in /var/log/swarmbox-dockerd.log).
# Idempotent, and quiet when everything is already there. Needs root (or sudo).
# No registry is needed: SwarmBox builds its images FROM scratch (ARCHITECTURE.md).
set -euo pipefail

PACKAGES=(
  # toolchain (binutils: objcopy strips the images' binaries; ccache: CMake uses it when present)
  build-essential binutils cmake ninja-build pkg-config git ca-certificates curl ccache
  # messaging: Cyclone DDS (C API + idlc) and Fast DDS (+ fastddsgen)
  cyclonedds-dev cyclonedds-tools libfastrtps-dev libfastcdr-dev fastddsgen
  # physics, maths, vision, formats, HTTP, archives
  libode-dev libeigen3-dev libopencv-dev libyaml-dev libcurl4-openssl-dev libssl-dev libarchive-dev zlib1g-dev
  # recordings: MCAP chunk compression (record/)
  libzstd-dev liblz4-dev
  # the live view's WebSocket server (record::LiveServer)
  libwebsockets-dev
  # command line, netfilter queue (userspace netem fallback)
  libcli11-dev libnetfilter-queue-dev
  # tests and micro-benchmarks (swarmbox-microbench); universal-ctags: the function-length check
  # (scripts/long_functions.sh, ctest HouseFunctionLength)
  libgtest-dev libgmock-dev libbenchmark-dev universal-ctags
  # the page of the live view in a real browser (tests/js/page_check.mjs, headless)
  chromium
  # containers, networks, hosts (procps: pgrep in netns_host.sh)
  docker.io docker-compose iptables iproute2 openssh-server openssh-client procps
  # a Linux kernel with sch_netem run as a process (user-mode Linux): the kernel netem path's guest test
  user-mode-linux
)

log() { printf 'setup: %s\n' "$*"; }
die() { printf 'setup: error: %s\n' "$*" >&2; exit 1; }

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null 2>&1 || die "run as root (or install sudo): packages and dockerd need it"
  SUDO=(sudo)
fi

[ -r /etc/debian_version ] || die "this script targets Debian 12 (bookworm); /etc/debian_version not found"

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ "${#missing[@]}" -gt 0 ]; then
  log "installing ${#missing[@]} package(s): ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${SUDO[@]}" apt-get update -qq >/dev/null || die "apt-get update failed"
  if ! "${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/tmp/swarmbox-apt.log 2>&1; then
    tail -n 30 /tmp/swarmbox-apt.log >&2
    die "apt-get install failed (full log: /tmp/swarmbox-apt.log)"
  fi
fi

docker_answers() {
  curl -fsS --max-time 3 --unix-socket /var/run/docker.sock http://localhost/_ping >/dev/null 2>&1
}

wait_for() {  # wait_for SECONDS CONDITION...: polls every 0.5 s
  local tries=$(( $1 * 2 )); shift
  for _ in $(seq 1 "$tries"); do "$@" && return 0; sleep 0.5; done
  "$@"
}
pidfile_alive() { [ -f /var/run/docker.pid ] && kill -0 "$(cat /var/run/docker.pid)" 2>/dev/null; }
answers_or_gone() { docker_answers || ! pidfile_alive; }

if ! docker_answers; then
  if [ -d /run/systemd/system ] && command -v systemctl >/dev/null 2>&1; then
    log "starting the Docker engine (systemctl start docker)"
    "${SUDO[@]}" systemctl start docker || die "systemctl start docker failed"
  else
    # A dockerd that is still starting (or still shutting down) owns the pid file: let it finish.
    if pidfile_alive; then
      log "waiting for the running dockerd (pid $(cat /var/run/docker.pid))"
      wait_for 60 answers_or_gone ||
        die "dockerd (pid $(cat /var/run/docker.pid)) neither answers nor exits; stop it and retry"
    fi
    if ! docker_answers; then
      log "starting the Docker engine (dockerd; log: /var/log/swarmbox-dockerd.log)"
      # A pid file left by a dockerd that died with its machine session.
      "${SUDO[@]}" rm -f /var/run/docker.pid
      "${SUDO[@]}" setsid dockerd >>/var/log/swarmbox-dockerd.log 2>&1 < /dev/null &
    fi
  fi
  wait_for 30 docker_answers || { tail -n 20 /var/log/swarmbox-dockerd.log >&2 || true; die "the Docker engine did not answer on /var/run/docker.sock within 30 s"; }
  log "Docker engine is up ($(docker version --format '{{.Server.Version}}' 2>/dev/null || echo unknown version))"
fi

# The JS test packages (tests/js: @mcap/core and the other independent readers and clients the
# tests check recordings and the live view with), pinned by tests/js/package-lock.json. Debian's
# nodejs/npm only when no node is there (a newer node from elsewhere is kept). `npm ci` runs as the
# calling user, and again only when the lock file changed since the last install (a stamp in
# node_modules).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  log "installing nodejs and npm"
  export DEBIAN_FRONTEND=noninteractive
  "${SUDO[@]}" apt-get update -qq >/dev/null || die "apt-get update failed"
  if ! "${SUDO[@]}" apt-get install -y -qq --no-install-recommends nodejs npm >/tmp/swarmbox-apt.log 2>&1; then
    tail -n 30 /tmp/swarmbox-apt.log >&2
    die "apt-get install nodejs npm failed (full log: /tmp/swarmbox-apt.log)"
  fi
fi
js_dir="$(cd "$(dirname "$0")/.." && pwd)/tests/js"
js_stamp="$js_dir/node_modules/.swarmbox-lock-sha256"
js_lock_sum="$(sha256sum "$js_dir/package-lock.json" | cut -d' ' -f1)"
if [ "$(cat "$js_stamp" 2>/dev/null)" != "$js_lock_sum" ]; then
  log "installing the JS test packages (npm ci in tests/js)"
  if ! (cd "$js_dir" && npm ci --no-audit --no-fund >/tmp/swarmbox-npm.log 2>&1); then
    tail -n 30 /tmp/swarmbox-npm.log >&2
    die "npm ci in tests/js failed (full log: /tmp/swarmbox-npm.log)"
  fi
  echo "$js_lock_sum" > "$js_stamp"
fi

# sshd (multi-host experiments) needs its privilege-separation directory.
[ -d /run/sshd ] || "${SUDO[@]}" mkdir -p /run/sshd
exit 0
