#!/usr/bin/env bash
# Benchmark (not a test): strata's static solver against CalculiX (ccx 2.20, Debian calculix-ccx) on
# the same mesh. A 2 m x 0.2 m x 0.2 m StVK cantilever under gravity, the face x = 0 fixed, 10 load
# steps, run back to back by both solvers; writes OUT/results.json and OUT/results.csv and prints a
# table (wall/user/system times, iterations, tip displacements and their relative difference).
#
# Usage: ./experiments/calculix/cantilever_vs_calculix.sh [--cells NX NY NZ] [--repeat K]
#          [--out DIR] [--strata PATH] [--threads N]
#   --cells    box cells (6 tets each), NY and NZ even so a node lies at the tip centre (80 8 8)
#   --repeat   run strata and CalculiX alternately K times (1)
#   --out      output folder (experiments/calculix/out)
#   --strata   strata executable (build/experiments/cli/strata; waited for up to 40 min)
#   --threads  passed to `strata run` as --threads N when that option exists (else ignored)
# Missing Debian packages (calculix-ccx, time, python3-meshio, python3-numpy) are installed with
# apt-get, as root or through sudo. CalculiX runs with OMP_NUM_THREADS=1.
set -euo pipefail

script_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo_root="$(cd "${script_dir}/../.." && pwd)"
python=/usr/bin/python3  # Debian's interpreter: it has meshio and numpy
helper="${script_dir}/calculix_cantilever.py"

cells=(80 8 8)
repeat=1
out_dir="${script_dir}/out"
strata="${repo_root}/build/experiments/cli/strata"
threads=""

usage() {  # the header comment
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
}
die() { echo "cantilever_vs_calculix: $*" >&2; exit 1; }
is_int() { [[ "$1" =~ ^[0-9]+$ ]] && (("$1" >= 1)); }

while (($# > 0)); do
  case "$1" in
    --cells)
      (($# >= 4)) || die "--cells needs NX NY NZ"
      cells=("$2" "$3" "$4")
      shift 4
      ;;
    --repeat) (($# >= 2)) || die "--repeat needs K"; repeat="$2"; shift 2 ;;
    --out) (($# >= 2)) || die "--out needs DIR"; out_dir="$2"; shift 2 ;;
    --strata) (($# >= 2)) || die "--strata needs PATH"; strata="$2"; shift 2 ;;
    --threads) (($# >= 2)) || die "--threads needs N"; threads="$2"; shift 2 ;;
    -h | --help) usage; exit 0 ;;
    *) usage >&2; die "unknown argument: $1" ;;
  esac
done
for c in "${cells[@]}" "${repeat}" ${threads:+"${threads}"}; do
  is_int "${c}" || die "expected a positive integer, got '${c}'"
done
((cells[1] % 2 == 0 && cells[2] % 2 == 0)) ||
  die "NY and NZ must be even (a node at the tip centre)"

# --- packages -------------------------------------------------------------------------------------
missing=()
command -v ccx >/dev/null 2>&1 || missing+=(calculix-ccx)
[[ -x /usr/bin/time ]] || missing+=(time)
"${python}" -c 'import numpy' 2>/dev/null || missing+=(python3-numpy)
"${python}" -c 'import meshio' 2>/dev/null || missing+=(python3-meshio)
if ((${#missing[@]} > 0)); then
  echo "cantilever_vs_calculix: installing missing Debian packages: ${missing[*]}"
  if [[ "$(id -u)" -eq 0 ]]; then
    as_root=()
  elif command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    die "missing packages (${missing[*]}) and neither root nor sudo available"
  fi
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
    "${missing[@]}"
fi
ccx_bin="$(command -v ccx)"

# --- strata executable (the build may still be running) -------------------------------------------
waited=0
until [[ -x "${strata}" && -f "${strata}" ]]; do
  ((waited < 40)) || die "${strata} did not appear within 40 minutes"
  echo "cantilever_vs_calculix: waiting for ${strata} (${waited} min so far)"
  sleep 60
  waited=$((waited + 1))
done
strata="$(cd "$(dirname "${strata}")" && pwd)/$(basename "${strata}")"
strata_threads=()
if [[ -n "${threads}" ]]; then
  if "${strata}" run --help 2>/dev/null | grep -q -- '--threads'; then
    strata_threads=(--threads "${threads}")
  else
    echo "cantilever_vs_calculix: strata run has no --threads option: running without it"
  fi
fi

# --- scene, mesh export, CalculiX deck ----------------------------------------------------------
mkdir -p "${out_dir}"
out_dir="$(cd "${out_dir}" && pwd)"
rm -rf "${out_dir}/runs" "${out_dir}/mesh_export" "${out_dir}/results.json" \
  "${out_dir}/results.csv" "${out_dir}/runs.tsv"
mkdir -p "${out_dir}/runs"

length=2 width=0.2 height=0.2
probe_y=0.1 probe_z=0.1  # the tip centre (L, W/2, H/2)
youngs=4e7 poisson=0.3 density=1000 load_steps=10
scene="${out_dir}/cantilever.json"
cat >"${scene}" <<EOF
{
  "mesh": {"box": {"min": [0, 0, 0], "max": [${length}, ${width}, ${height}],
                   "cells": [${cells[0]}, ${cells[1]}, ${cells[2]}]}},
  "material": {"model": "stvk", "youngs_modulus": ${youngs}, "poisson_ratio": ${poisson},
               "density": ${density}},
  "gravity": [0, 0, -9.81],
  "fixed": [{"box": {"min": [0, 0, 0], "max": [0, ${width}, ${height}]}}],
  "solver": {"mode": "static", "load_steps": ${load_steps}},
  "output": {"probes": [[${length}, ${probe_y}, ${probe_z}]], "vtk": false}
}
EOF

# The timed runs write no VTK frames (CalculiX writes only its small .dat, .sta and .frd); the mesh
# export does: strata's own box mesh is frame 0 of a run without load (rest positions).
echo "cantilever_vs_calculix: exporting strata's mesh (cells ${cells[*]})"
"${strata}" run "${scene}" --out "${out_dir}/mesh_export" -q --set solver.load_steps=1 \
  --set 'gravity=[0,0,0]' --set output.vtk=true
ccx_job=cantilever
"${python}" "${helper}" deck --vtu "${out_dir}/mesh_export/cantilever_000000.vtu" \
  --inp "${out_dir}/${ccx_job}.inp" --mesh-json "${out_dir}/mesh.json" --scene "${scene}"

# --- runs ---------------------------------------------------------------------------------------
now() { date +%s.%N; }
# Busy CPU time of the whole machine so far, in clock ticks (user+nice+system+irq+softirq+steal):
# around a run, it minus the run's own user+sys is what other processes used meanwhile.
busy_ticks() {
  local _cpu user nice system idle iowait irq softirq steal _rest
  read -r _cpu user nice system idle iowait irq softirq steal _rest </proc/stat
  echo $((user + nice + system + irq + softirq + steal))
}
elapsed() { awk -v s="$1" -v e="$2" 'BEGIN { printf "%.6f", e - s }'; }

run_strata() {  # run index
  local dir="${out_dir}/runs/strata_$1" start end busy_before
  mkdir -p "${dir}"
  busy_before="$(busy_ticks)"
  start="$(now)"
  /usr/bin/time -f '%e %U %S %M' -o "${dir}/time.txt" \
    "${strata}" run "${scene}" --out "${dir}" -q "${strata_threads[@]+"${strata_threads[@]}"}" \
    >"${dir}/stdout.log" 2>"${dir}/stderr.log" || die "strata failed (see ${dir}/stderr.log)"
  end="$(now)"
  echo "${busy_before} $(busy_ticks)" >"${dir}/busy_ticks.txt"
  printf 'strata\t%s\t%s\t%s\n' "$1" "runs/strata_$1" "$(elapsed "${start}" "${end}")" \
    >>"${out_dir}/runs.tsv"
  sha256sum "${strata}" | cut -d' ' -f1 >"${dir}/strata.sha256"
}

run_calculix() {  # run index
  local dir="${out_dir}/runs/calculix_$1" start end busy_before
  mkdir -p "${dir}"
  cp "${out_dir}/${ccx_job}.inp" "${dir}/"
  busy_before="$(busy_ticks)"
  start="$(now)"
  (cd "${dir}" && OMP_NUM_THREADS=1 /usr/bin/time -f '%e %U %S %M' -o time.txt \
    "${ccx_bin}" -i "${ccx_job}" >stdout.log 2>stderr.log) ||
    die "ccx failed (see ${dir}/stdout.log)"
  end="$(now)"
  echo "${busy_before} $(busy_ticks)" >"${dir}/busy_ticks.txt"
  if grep -q '\*ERROR' "${dir}/stdout.log" "${dir}/stderr.log"; then
    grep '\*ERROR' "${dir}/stdout.log" "${dir}/stderr.log" >&2
    die "ccx reported errors (see ${dir}/stdout.log)"
  fi
  printf 'calculix\t%s\t%s\t%s\n' "$1" "runs/calculix_$1" "$(elapsed "${start}" "${end}")" \
    >>"${out_dir}/runs.tsv"
}

# Timings are only meaningful on an otherwise idle machine: warn when something else is running
# (the CPU the machine used over 3 s; each run's share of other processes is checked at the end).
read -r load_start _ </proc/loadavg
busy_before="$(busy_ticks)"
sleep 3
idle_busy_percent=$(( ($(busy_ticks) - busy_before) * 100 / (3 * $(getconf CLK_TCK)) ))
if ((idle_busy_percent > 10)); then
  echo "cantilever_vs_calculix: warning: other processes use ${idle_busy_percent} % of a core:" \
    "the timings may be disturbed" >&2
fi

# Warm-up: the mesh export has loaded strata; load ccx and its libraries once too (a first run from
# a cold page cache, e.g. right after installing, takes ~1 s longer in wall time).
"${ccx_bin}" -v >/dev/null 2>&1 || true

for ((k = 1; k <= repeat; ++k)); do
  echo "cantilever_vs_calculix: run ${k}/${repeat}: strata"
  run_strata "${k}"
  echo "cantilever_vs_calculix: run ${k}/${repeat}: CalculiX"
  run_calculix "${k}"
done

# --- results ------------------------------------------------------------------------------------
strata_version="$("${strata}" --version 2>/dev/null | head -n1 || true)"
ccx_version="$("${ccx_bin}" -v 2>/dev/null | grep -o 'Version [0-9.]*' | head -n1 || true)"
commit="$(git -C "${repo_root}" rev-parse --short HEAD 2>/dev/null || echo unknown)"
# "+dirty": tracked sources changed since that commit (this folder aside).
[[ -z "$(git -C "${repo_root}" status --porcelain --untracked-files=no -- . \
  ':!experiments/calculix' 2>/dev/null)" ]] || commit="${commit}+dirty"
cpu="$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//' || true)"
STRATA_VERSION="${strata_version}" CCX_VERSION="${ccx_version}" COMMIT="${commit}" CPU="${cpu}" \
  "${python}" - "${out_dir}" <<EOF
import json, os, sys
meta = {
    "cells": [${cells[0]}, ${cells[1]}, ${cells[2]}],
    "size": [${length}, ${width}, ${height}],
    "material": {"model": "stvk", "youngs_modulus": ${youngs}, "poisson_ratio": ${poisson},
                 "density": ${density}},
    "gravity": [0, 0, -9.81],
    "load_steps": ${load_steps},
    "repeat": ${repeat},
    "strata_threads": "${strata_threads[1]:-default}",
    "threads_requested": "${threads}",
    "loadavg_start": ${load_start},
    "busy_percent_before_runs": ${idle_busy_percent},
    "loadavg_end": float(open("/proc/loadavg").read().split()[0]),
    "calculix_threads": 1,
    "strata_version": os.environ["STRATA_VERSION"],
    "calculix_version": os.environ["CCX_VERSION"],
    "commit": os.environ["COMMIT"],
    "cpu": os.environ["CPU"],
    "cores": os.cpu_count(),
    "ccx_job": "${ccx_job}",
}
with open(os.path.join(sys.argv[1], "meta.json"), "w") as f:
    json.dump(meta, f, indent=2)
EOF
"${python}" "${helper}" summarize --out "${out_dir}"
