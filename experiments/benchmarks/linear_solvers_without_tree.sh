#!/usr/bin/env bash
# Linear solvers on meshes without a refinement tree: each scene run through the `strata` CLI with
# `solver.linear_solver` = cholmod, amg and auto, back to back (compare as ratios within one run:
# the machines are shared). Scenes: a 1 m StVK cube (E = 1 MPa, ν = 0.45) clamped at x = 0 under
# gravity, N³ box cells (6 N³ tets), 3 backward-Euler steps of 1 ms or 3 static load steps; and
# the 2 × 0.2 × 0.2 m StVK cantilever of experiments/calculix (E = 40 MPa), 10 static load steps
# or 10 backward-Euler steps. Writes <out>/results.tsv (scene, solver, wall s, user s, sys s,
# peak MB, Newton and CG iterations, multigrid setups and their seconds, the solver auto chose,
# probe u_z) and prints it.
#
# Usage: linear_solvers_without_tree.sh [--quick] [--out DIR] [--strata PATH]
#   --quick: the two smallest scenes only.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
strata="${repo_root}/build/experiments/cli/strata"
out_dir="${repo_root}/experiments/benchmarks/out/linear_solvers"
quick=0
while (($# > 0)); do
  case "$1" in
    --quick) quick=1; shift ;;
    --out) out_dir="$2"; shift 2 ;;
    --strata) strata="$2"; shift 2 ;;
    -h | --help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "linear_solvers_without_tree: unknown argument: $1" >&2; exit 2 ;;
  esac
done
[[ -x "${strata}" ]] || { echo "linear_solvers_without_tree: ${strata} not built" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "linear_solvers_without_tree: needs /usr/bin/time (package time)" >&2; exit 1; }
mkdir -p "${out_dir}/scenes" "${out_dir}/runs"

# box_scene NAME LX LY LZ NX NY NZ E NU SOLVER_BLOCK: a StVK box [0, L] clamped at x = 0 under
# gravity, probed at the centre of its far end.
box_scene() {
  cat >"${out_dir}/scenes/$1.json" <<JSON
{
  "mesh": {"box": {"min": [0, 0, 0], "max": [$2, $3, $4], "cells": [$5, $6, $7]}},
  "material": {"model": "stvk", "youngs_modulus": $8, "poisson_ratio": $9, "density": 1000},
  "gravity": [0, 0, -9.81],
  "fixed": [{"box": {"min": [0, 0, 0], "max": [0, $3, $4]}}],
  "solver": {${10}},
  "output": {"probes": [[$2, $(awk "BEGIN{print $3/2}"), $(awk "BEGIN{print $4/2}")]], "vtk": false}
}
JSON
}
static() { echo "\"mode\": \"static\", \"load_steps\": $1"; }
implicit() { echo "\"mode\": \"dynamic\", \"integrator\": \"implicit_euler\", \"dt\": 0.001, \"duration\": $1"; }
cube() {  # name cells solver_block: 1 m cube, E = 1 MPa, ν = 0.45
  box_scene "$1" 1 1 1 "$2" "$2" "$2" 1e6 0.45 "$3"
}
cantilever() {  # name nx solver_block: 2 × 0.2 × 0.2 m, E = 40 MPa, ν = 0.3
  box_scene "$1" 2 0.2 0.2 "$2" $(($2 / 10)) $(($2 / 10)) 4e7 0.3 "$3"
}

scenes=(cube20_dynamic cube30_dynamic)
cube cube20_dynamic 20 "$(implicit 0.003)"
cube cube30_dynamic 30 "$(implicit 0.003)"
if ((quick == 0)); then
  cube cube40_dynamic 40 "$(implicit 0.003)"
  cube cube30_static 30 "$(static 3)"
  cube cube40_static 40 "$(static 3)"
  cantilever cantilever80_static 80 "$(static 10)"
  cantilever cantilever160_static 160 "$(static 10)"
  cantilever cantilever160_dynamic 160 "$(implicit 0.01)"
  scenes+=(cube40_dynamic cube30_static cube40_static cantilever80_static cantilever160_static
    cantilever160_dynamic)
fi

results="${out_dir}/results.tsv"
printf 'scene\tsolver\twall_s\tuser_s\tsys_s\tpeak_mb\tnewton\tcg\tsetups\tsetup_s\tchosen\tprobe_uz\n' >"${results}.part"
for scene in "${scenes[@]}"; do
  for solver in cholmod amg auto; do
    run="${out_dir}/runs/${scene}_${solver}"
    rm -rf "${run}"
    /usr/bin/time -f '%e %U %S %M' -o "${run}.time" "${strata}" run "${out_dir}/scenes/${scene}.json" \
      --out "${run}" -q --set "solver.linear_solver=${solver}"
    read -r wall user sys peak_kb <"${run}.time"
    python3 - "${run}/stats.json" "${run}/probes.csv" "${scene}" "${solver}" "${wall}" "${user}" \
      "${sys}" "${peak_kb}" >>"${results}.part" <<'PY'
import csv, json, sys
stats_path, probes_path, scene, solver, wall, user, sys_s, peak_kb = sys.argv[1:]
newton = json.load(open(stats_path))["newton"]
rows = list(csv.reader(open(probes_path)))
uz = rows[-1][-1]
iterations = newton["exact_hessian_iterations"] + newton["projected_hessian_iterations"]
print("\t".join([scene, solver, wall, user, sys_s, "%.0f" % (float(peak_kb) / 1024.0),
                 str(iterations), str(newton["linear_iterations"]), str(newton["multigrid_setups"]),
                 "%.2f" % newton["multigrid_setup_seconds"], newton["linear_solver"], uz]))
PY
  done
done
mv "${results}.part" "${results}"
column -t -s $'\t' "${results}"
