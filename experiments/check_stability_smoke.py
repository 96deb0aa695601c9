#!/usr/bin/python3
"""CTest smoke run of stability_map.py --quick, with the physics the map must show:

  check_stability_smoke.py STRATA OUT

backward Euler is stable at every point of the grid; an explicit run whose dt is at most the
stable-step estimate (a guaranteed bound of the system's highest frequency) is stable; an explicit
run whose dt is at least 3x the estimate is not (it blows up or inverts an element).
"""
import csv
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    strata, out = sys.argv[1:3]
    result = subprocess.run([sys.executable, os.path.join(HERE, "stability_map.py"), "--quick",
                             "--out", out, "--strata", strata, "--jobs", "2"],
                            capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"check_stability_smoke: stability_map failed: {result.stderr.strip()}")
    with open(os.path.join(out, "stability.csv")) as f:
        rows = list(csv.DictReader(f))
    if len(rows) != 96 or not os.path.getsize(os.path.join(out, "stability_map.png")) > 1000:
        sys.exit(f"check_stability_smoke: {len(rows)} rows (expected 96) or no chart")
    problems = []
    for r in rows:
        dt, estimate = float(r["dt"]), float(r["stable_dt_estimate"])
        label = f"{r['integrator']} {r['material']} E={r['youngs_modulus']} dt={r['dt']}"
        if r["integrator"] == "implicit_euler" and r["outcome"] != "stable":
            problems.append(f"{label}: backward Euler {r['outcome']}")
        if r["integrator"] != "implicit_euler":
            if dt <= estimate and r["outcome"] != "stable":
                problems.append(f"{label}: {r['outcome']} below the estimate {estimate:.3g}")
            if dt >= 3 * estimate and r["outcome"] == "stable":
                problems.append(f"{label}: stable at 3x the estimate {estimate:.3g}")
    if problems:
        sys.exit("check_stability_smoke: " + "; ".join(problems))
    print(f"check_stability_smoke: {len(rows)} runs as expected")


if __name__ == "__main__":
    main()
