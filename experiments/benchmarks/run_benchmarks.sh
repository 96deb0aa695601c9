#!/usr/bin/env bash
# Runs strata_benchmarks (built by .ci/setup.sh) and writes Google Benchmark JSON to
# out/benchmarks/<group>.json, one file per group: forces, energy, stiffness, implicit_euler_step.
#
# Usage: ./experiments/benchmarks/run_benchmarks.sh [group ...] [-- extra benchmark arguments]
#   groups default to all four; STRATA_SKIP_SETUP=1 skips the setup/build step.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build_dir="${STRATA_BUILD_DIR:-${repo_root}/build}"
out_dir="${repo_root}/out/benchmarks"

groups=()
extra=()
while (($# > 0)); do
  if [[ "$1" == "--" ]]; then
    shift
    extra=("$@")
    break
  fi
  groups+=("$1")
  shift
done
((${#groups[@]} > 0)) || groups=(forces energy stiffness implicit_euler_step)

if [[ "${STRATA_SKIP_SETUP:-0}" != "1" ]]; then
  "${repo_root}/.ci/setup.sh"
fi
bench="${build_dir}/experiments/benchmarks/strata_benchmarks"
[[ -x "${bench}" ]] || { echo "benchmarks: ${bench} was not built" >&2; exit 1; }

mkdir -p "${out_dir}"
for group in "${groups[@]}"; do
  json="${out_dir}/${group}.json"
  echo "benchmarks: ${group} -> ${json}"
  "${bench}" --benchmark_filter="^${group}/" --benchmark_out="${json}" \
    --benchmark_out_format=json --benchmark_counters_tabular=true "${extra[@]+"${extra[@]}"}"
done
echo "benchmarks: results in ${out_dir}"
