#!/usr/bin/env bash
# Demo: sets up and builds strata (.ci/setup.sh), runs the cantilever scene and reports where the
# ParaView series and the probe table are and how far the beam tip deflected.
#
# Usage: ./experiments/run_demo.sh [extra arguments for `strata run`]
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${STRATA_BUILD_DIR:-${repo_root}/build}"
scene="${repo_root}/experiments/scenes/cantilever.json"
out_dir="${repo_root}/out/cantilever"

"${repo_root}/.ci/setup.sh"

strata="${build_dir}/experiments/cli/strata"
if [[ ! -x "${strata}" ]]; then
  echo "demo: ${strata} was not built" >&2
  exit 1
fi

echo "demo: ${strata} run ${scene} --out ${out_dir}"
start=$(date +%s.%N)
"${strata}" run "${scene}" --out "${out_dir}" "$@"
end=$(date +%s.%N)
awk -v s="${start}" -v e="${end}" 'BEGIN { printf "demo: simulation took %.1f s\n", e - s }'

echo
echo "demo: outputs in ${out_dir}"
pvd="$(find "${out_dir}" -maxdepth 1 -name '*.pvd' | head -n 1)"
if [[ -n "${pvd}" ]]; then
  echo "  ParaView series: ${pvd}  (open it in ParaView: paraview ${pvd})"
else
  echo "  ParaView series: none written (the scene sets output.vtk = false)"
fi
probes="${out_dir}/probes.csv"
if [[ -f "${probes}" ]]; then
  echo "  probe table:     ${probes}  (time,probe,x,y,z,ux,uy,uz)"
  # Every probe at the last recorded time; the tip deflection is the probe that moved most.
  awk -F, 'NR > 1 { rows[NR] = $0; last = $1 }
    END {
      best = -1
      for (i = 2; i in rows; ++i) {
        split(rows[i], c, ",")
        if (c[1] != last) continue
        m = sqrt(c[6] * c[6] + c[7] * c[7] + c[8] * c[8])
        printf "  probe %s at (%s, %s, %s), time or load factor %s: u = (%.6g, %.6g, %.6g) m, |u| = %.6g m\n",
               c[2], c[3], c[4], c[5], c[1], c[6], c[7], c[8], m
        if (m > best) { best = m; tip = c[2]; uz = c[8] }
      }
      if (best < 0) { print "  tip deflection:  no probe rows"; exit }
      printf "  tip deflection:  %.6g m (probe %s; vertical u_z = %.6g m)\n", best, tip, uz
    }' "${probes}"
else
  echo "  probe table:     none written (the scene lists no output.probes)"
fi
if [[ -f "${out_dir}/reactions.csv" ]]; then
  echo "  reactions:       ${out_dir}/reactions.csv"
fi
