#!/usr/bin/env bash
# netns_host.sh: a second "Docker host" on this machine, for the two-host experiment test.
#
#   scripts/netns_host.sh up   NAME STATE_DIR [ADDR_PREFIX]   # prints KEY=VALUE lines on stdout
#   scripts/netns_host.sh down NAME STATE_DIR
#
# `up` makes a network namespace NAME with a veth pair to the root namespace (the root side gets
# <prefix>.1/30, the namespace <prefix>.2/30; default prefix 10.250.0), and starts inside it
#   - sshd on <prefix>.2:22, key-only, with a host key and an authorized client key generated here
#     (STATE_DIR/client_key), and STATE_DIR/known_hosts for the client;
#   - dockerd with its own data root, exec root, pidfile, socket (STATE_DIR/docker.sock), no default
#     bridge, no iptables rules, its own cgroup parent.
# It waits until both answer, then prints ADDR=, SSH_USER=, SSH_KEY=, KNOWN_HOSTS=, DOCKER_SOCK=,
# DOCKERD_PID=, SSHD_PID=. Everything it made is undone by `down` (also after a half-failed `up`),
# which first removes every container and network left in that engine.
#
# dockerd is entered with `nsenter --net=` rather than `ip netns exec`, which remounts /sys and
# hides the cgroup mounts ("Devices cgroup isn't mounted").
set -euo pipefail

cmd=${1:?usage: netns_host.sh up|down NAME STATE_DIR [ADDR_PREFIX]}
name=${2:?NAME}
dir=${3:?STATE_DIR}
prefix=${4:-10.250.0}
veth_root="${name:0:10}a"
veth_ns="${name:0:10}b"
nspath="/run/netns/$name"

die() { echo "netns_host.sh: $*" >&2; exit 1; }

down() {
  if [[ -S "$dir/docker.sock" ]] && [[ -f "$dir/docker.pid" ]] && kill -0 "$(cat "$dir/docker.pid")" 2>/dev/null; then
    # Leave nothing behind in the engine's data root (containers hold mounts under it).
    local ids
    ids=$(curl -s --max-time 10 --unix-socket "$dir/docker.sock" 'http://d/containers/json?all=1' |
      grep -o '"Id":"[0-9a-f]*"' | cut -d'"' -f4 || true)
    for id in $ids; do
      curl -s --max-time 20 -X DELETE --unix-socket "$dir/docker.sock" \
        "http://d/containers/$id?force=1&v=1" >/dev/null || true
    done
  fi
  for pidfile in "$dir/docker.pid" "$dir/sshd.pid"; do
    if [[ -f "$pidfile" ]]; then
      local pid
      pid=$(cat "$pidfile")
      if kill -0 "$pid" 2>/dev/null; then
        kill -TERM "$pid" 2>/dev/null || true
        for _ in $(seq 1 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -KILL "$pid" 2>/dev/null || true
      fi
    fi
  done
  # containerd-shims of a killed dockerd live on; they run under the exec root.
  if [[ -d "$dir/exec" ]]; then
    for p in $(pgrep -f -- "$dir/exec" || true); do kill -KILL "$p" 2>/dev/null || true; done
  fi
  if [[ -d "$dir/data" ]]; then
    { grep -o " $dir/[^ ]*" /proc/mounts || true; } | sort -r | while read -r m; do umount -l "$m" 2>/dev/null || true; done
  fi
  ip link del "$veth_root" 2>/dev/null || true
  if [[ -e "$nspath" ]]; then ip netns del "$name" 2>/dev/null || true; fi
  rm -rf "$dir"
}

up() {
  [[ $(id -u) -eq 0 ]] || die "needs root (ip netns, dockerd)"
  for tool in ip nsenter sshd ssh-keygen dockerd curl; do
    command -v "$tool" >/dev/null || die "missing $tool"
  done
  [[ ! -e "$nspath" ]] || die "namespace $name exists already (run: $0 down $name $dir)"
  mkdir -p "$dir" "$dir/data" "$dir/exec"
  chmod 700 "$dir"
  trap 'echo "netns_host.sh: up failed, undoing" >&2; down' ERR

  ip netns add "$name"
  ip link add "$veth_root" type veth peer name "$veth_ns"
  ip link set "$veth_ns" netns "$name"
  ip addr add "$prefix.1/30" dev "$veth_root"
  ip link set "$veth_root" up
  nsenter --net="$nspath" ip addr add "$prefix.2/30" dev "$veth_ns"
  nsenter --net="$nspath" ip link set "$veth_ns" up
  nsenter --net="$nspath" ip link set lo up

  ssh-keygen -q -t ed25519 -N '' -C "$name-host" -f "$dir/host_key"
  ssh-keygen -q -t ed25519 -N '' -C "$name-client" -f "$dir/client_key"
  cp "$dir/client_key.pub" "$dir/authorized_keys"
  chmod 600 "$dir/authorized_keys"
  echo "$prefix.2 $(cut -d' ' -f1,2 "$dir/host_key.pub")" >"$dir/known_hosts"
  mkdir -p /run/sshd
  cat >"$dir/sshd_config" <<EOF
ListenAddress $prefix.2
Port 22
HostKey $dir/host_key
PidFile $dir/sshd.pid
AuthorizedKeysFile $dir/authorized_keys
PermitRootLogin prohibit-password
PubkeyAuthentication yes
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
AllowStreamLocalForwarding yes
AllowTcpForwarding yes
StrictModes no
EOF
  nsenter --net="$nspath" /usr/sbin/sshd -f "$dir/sshd_config" -E "$dir/sshd.log"

  echo '{}' >"$dir/daemon.json"
  nsenter --net="$nspath" setsid dockerd --config-file "$dir/daemon.json" \
    --data-root "$dir/data" --exec-root "$dir/exec" --pidfile "$dir/docker.pid" \
    -H "unix://$dir/docker.sock" --bridge=none --iptables=false --ip-masq=false \
    --cgroup-parent "/$name" --containerd-namespace "$name" --containerd-plugins-namespace "$name-plugins" \
    >"$dir/dockerd.log" 2>&1 </dev/null &
  for _ in $(seq 1 300); do
    if curl -s --max-time 2 --unix-socket "$dir/docker.sock" http://d/_ping 2>/dev/null | grep -q OK; then
      break
    fi
    sleep 0.1
  done
  curl -s --max-time 2 --unix-socket "$dir/docker.sock" http://d/_ping 2>/dev/null | grep -q OK ||
    { tail -n 20 "$dir/dockerd.log" >&2; die "dockerd in $name did not answer within 30 s (log above)"; }
  for _ in $(seq 1 50); do [[ -f "$dir/sshd.pid" ]] && break; sleep 0.1; done
  [[ -f "$dir/sshd.pid" ]] || { cat "$dir/sshd.log" >&2; die "sshd in $name did not start"; }
  trap - ERR
  echo "ADDR=$prefix.2"
  echo "SSH_USER=$(id -un)"
  echo "SSH_KEY=$dir/client_key"
  echo "KNOWN_HOSTS=$dir/known_hosts"
  echo "DOCKER_SOCK=$dir/docker.sock"
  echo "DOCKERD_PID=$(cat "$dir/docker.pid")"
  echo "SSHD_PID=$(cat "$dir/sshd.pid")"
}

case "$cmd" in
  up) up ;;
  down) down ;;
  *) die "unknown command $cmd (up|down)" ;;
esac
