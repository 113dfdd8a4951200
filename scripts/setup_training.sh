#!/usr/bin/env bash
# SwarmBox: what retraining the victim detector's CNN second stage needs, beyond scripts/setup.sh.
#
#   scripts/setup_training.sh
#
# Installs Debian 12's PyTorch (python3-torch 1.13, with python3-numpy) for Debian's own
# /usr/bin/python3, which `swarmbox-train-detector --cnn tools/train_detector/train_cnn.py` runs
# (tools/train_detector/README.md). Only whoever retrains needs it: CI and the agent never train
# (the model is committed and compiled in). Idempotent; needs root (or sudo).
set -euo pipefail

PACKAGES=(python3 python3-numpy python3-torch)

log() { printf 'setup_training: %s\n' "$*"; }
die() { printf 'setup_training: error: %s\n' "$*" >&2; exit 1; }

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null 2>&1 || die "run as root (or install sudo): apt-get needs it"
  SUDO=(sudo)
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  log "installing ${missing[*]}"
  "${SUDO[@]}" apt-get update
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi
/usr/bin/python3 -c 'import numpy, torch; print("setup_training: torch", torch.__version__, "numpy", numpy.__version__)'
