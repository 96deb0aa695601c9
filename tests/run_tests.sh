#!/usr/bin/env bash
# Test command: sets up and builds strata (.ci/setup.sh), then runs the whole CTest suite (unit
# tests of every module, the CLI tests, the install + find_package consumer test and a short
# benchmark smoke run; the benchmarks themselves are not run).
#
# Usage: ./tests/run_tests.sh [extra ctest arguments, e.g. -R install]
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${STRATA_BUILD_DIR:-${repo_root}/build}"
jobs="${STRATA_JOBS:-$(nproc 2>/dev/null || echo 2)}"

"${repo_root}/.ci/setup.sh"

start=$(date +%s.%N)
status=0
ctest --test-dir "${build_dir}" --output-on-failure -j "${jobs}" "$@" || status=$?
end=$(date +%s.%N)
awk -v s="${start}" -v e="${end}" 'BEGIN { printf "tests: ctest took %.1f s\n", e - s }'
exit "${status}"
