#!/usr/bin/env bash
# Prepares a Debian 12 machine and builds strata: installs the Debian packages that are missing
# (apt-get, as root or through sudo), configures a Release build in build/ once, then builds
# everything (or the targets in STRATA_BUILD_TARGETS). Idempotent: with all packages present and
# the build up to date it takes seconds.
#
# Environment: STRATA_BUILD_DIR (default <repo>/build), STRATA_JOBS (default: number of cores).
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${STRATA_BUILD_DIR:-${repo_root}/build}"
jobs="${STRATA_JOBS:-$(nproc 2>/dev/null || echo 2)}"

packages=(
  build-essential cmake g++ make
  libeigen3-dev libtbb-dev nlohmann-json3-dev libcli11-dev libsuitesparse-dev
  libopenblas0-pthread libgtest-dev libgmock-dev googletest libbenchmark-dev
  libcgal-dev libcgal-demo libopenvdb-dev libboost-iostreams-dev zlib1g-dev libdeflate-dev libhypre-dev
  python3-matplotlib python3-meshio clang-format
)

missing=()
for package in "${packages[@]}"; do
  status="$(dpkg-query -W -f='${db:Status-Status}' "${package}" 2>/dev/null || true)"
  if [[ "${status}" != "installed" ]]; then
    missing+=("${package}")
  fi
done

if ((${#missing[@]} > 0)); then
  echo "setup: installing missing Debian packages: ${missing[*]}"
  if [[ "$(id -u)" -eq 0 ]]; then
    as_root=()
  elif command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    echo "setup: missing packages (${missing[*]}) and neither root nor sudo available" >&2
    exit 1
  fi
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
    "${missing[@]}"
else
  echo "setup: all ${#packages[@]} Debian packages present"
fi

start=$(date +%s.%N)
# Configuring also extracts the CGAL test models (libcgal-demo) into <build>/data/models/: run it
# again when they are missing (e.g. the package was installed after the first configure).
if [[ ! -f "${build_dir}/CMakeCache.txt" ]]; then
  cmake -S "${repo_root}" -B "${build_dir}" -DCMAKE_BUILD_TYPE=Release
elif [[ ! -f "${build_dir}/data/models/armadillo.off" ]]; then
  cmake -S "${repo_root}" -B "${build_dir}"
fi
# STRATA_BUILD_TARGETS (space-separated): build only these targets (the demo builds `strata`).
targets=()
for target in ${STRATA_BUILD_TARGETS:-}; do
  targets+=(--target "${target}")
done
cmake --build "${build_dir}" -j "${jobs}" "${targets[@]}"
end=$(date +%s.%N)
awk -v s="${start}" -v e="${end}" -v d="${build_dir}" -v j="${jobs}" \
  'BEGIN { printf "setup: build of %s took %.1f s (%d jobs)\n", d, e - s, j }'
