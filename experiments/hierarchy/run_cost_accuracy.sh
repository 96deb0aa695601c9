#!/usr/bin/env bash
# Runs the cost-against-accuracy experiment (cost_accuracy.py) on a scene; builds nothing.
# The strata executable is $STRATA, else build/experiments/cli/strata of the repository.
# Writes out/experiments/cost_accuracy.csv and cost_accuracy.png.
#
# Usage: ./experiments/hierarchy/run_cost_accuracy.sh [scene.json] [extra cost_accuracy.py args]
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
strata="${STRATA:-${repo_root}/build/experiments/cli/strata}"
[[ -x "${strata}" ]] || { echo "run_cost_accuracy: ${strata} is not built (set STRATA)" >&2; exit 1; }
scene="${1:-${repo_root}/experiments/scenes/slab_press.json}"
shift || true
exec /usr/bin/python3 "${repo_root}/experiments/hierarchy/cost_accuracy.py" --strata "${strata}" \
  --scene "${scene}" --out "${repo_root}/out/experiments" "$@"
