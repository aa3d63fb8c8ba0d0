#!/usr/bin/env bash
# The README's main job: installs what is missing, builds, and runs the paper's scenario
# (Sec. IV, docs/method.md#the-papers-experiment) for both estimator schemes, printing the metrics and where the figures are.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
make demo
