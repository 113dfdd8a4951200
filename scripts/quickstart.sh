#!/usr/bin/env bash
# SwarmBox quick start: set up the machine, build, build the registry-free images and run the
# main trial in containers. The README's first command.
#   bash scripts/quickstart.sh                 # trials/sar_search.yaml at real time, outputs in runs/
#   bash scripts/quickstart.sh TRIAL.yaml      # another trial
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/setup.sh

BUILD_DIR=${BUILD_DIR:-build}
TRIAL=${1:-trials/sar_search.yaml}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)" --target swarmbox swarmbox-physics swarmbox-agent swarmbox-netemd

swarmbox="$BUILD_DIR/orchestrator/cli/swarmbox"
"$swarmbox" images
exec "$swarmbox" run "$TRIAL" --out runs
