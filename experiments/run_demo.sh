#!/usr/bin/env bash
# Demo: installs what is missing and builds only the strata command-line tool (.ci/setup.sh with
# STRATA_BUILD_TARGETS=strata; no tests or benchmarks), then runs the short version of the
# experiments suite — every scene of experiments/specs at full resolution, at every uniform level
# and adaptively at two tolerances (experiment.py --quick) — and the stability maps on their coarse
# grids (stability_map.py --quick, over stiffness and over compression), and writes the report
# with its charts (report.py) to out/demo/REPORT.md. A few minutes on 2 cores after the build.
#
# Usage: ./experiments/run_demo.sh [--full]   (--full: the whole sweep, four tolerances and the
#                                              scenes' full durations; much longer)
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${STRATA_BUILD_DIR:-${repo_root}/build}"
# The short suite runs two runs at once, one thread each (its timings are ratios of runs that
# shared the machine); the full sweep runs one at a time on every core.
quick=(--quick)
jobs=(--jobs 2)
results="${repo_root}/out/demo/runs"
report="${repo_root}/out/demo"
if [[ "${1:-}" == "--full" ]]; then
  quick=()
  jobs=()
  results="${repo_root}/out/experiments"
  report="${repo_root}/experiments/results"
fi

STRATA_BUILD_TARGETS="${STRATA_BUILD_TARGETS:-strata}" "${repo_root}/.ci/setup.sh"
strata="${build_dir}/experiments/cli/strata"
[[ -x "${strata}" ]] || { echo "demo: ${strata} was not built" >&2; exit 1; }

start=$(date +%s)
specs=("${repo_root}"/experiments/specs/*.json)
for spec in "${specs[@]}"; do
  # Scenes on CGAL's scanned models read them from build/data/models (extracted by configure).
  if grep -q "data/models/" "$(dirname "${spec}")/$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["scene"])' "${spec}")" &&
     [[ ! -d "${repo_root}/build/data/models" ]]; then
    echo "demo: skipping ${spec} (needs the CGAL models in build/data/models)"
    continue
  fi
  /usr/bin/python3 "${repo_root}/experiments/experiment.py" "${spec}" "${quick[@]}" "${jobs[@]}" \
    --out "${results}" --strata "${strata}"
done
for axis in stiffness compression; do
  /usr/bin/python3 "${repo_root}/experiments/stability_map.py" "${quick[@]}" --axis "${axis}" \
    --out "${results}/stability" --strata "${strata}"
done
/usr/bin/python3 "${repo_root}/experiments/report.py" "${specs[@]}" --results "${results}" \
  --out "${report}" --strata "${strata}" --stability "${results}/stability"
echo "demo: the experiments took $(($(date +%s) - start)) s"
echo
echo "demo: report ${report}/REPORT.md (charts beside it); headline:"
sed -n '/^## Headline/,/^Targets/p' "${report}/REPORT.md" | sed -n '3,/^$/p'
