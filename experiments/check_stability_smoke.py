#!/usr/bin/python3
"""CTest smoke run of stability_map.py --quick, with the physics the map must show:

  check_stability_smoke.py STRATA OUT [--axis stiffness|compression]

Over stiffness (the cantilever): backward Euler is stable at every point of the grid; an
explicit run whose dt is at most the stable-step estimate (a guaranteed bound of the system's
highest frequency) is stable; an explicit run whose dt is at least 3x the estimate is not (it
blows up or inverts an element).

Over compression (the clamped cube, ν = 0.45): backward Euler with stable neo-Hookean is stable
at every compression down to a fifth of the height (its uniaxial response has no limit point
above a stretch of about 0.15 at this ν); StVK fails (inverts or blows up) under every
integrator and step once the cube is compressed to 0.4 of its height or less (StVK's resistance
to compression peaks at a stretch of 1/√3 ≈ 0.58 and falls to zero beyond); StVK with backward
Euler holds the mild compression to 0.8; explicit runs at or below the estimate are stable at
mild compression (0.6 and above) with neo-Hookean, and no explicit run at 3x the estimate is.
"""
import csv
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def stiffness_problems(rows):
    problems = []
    for r in rows:
        label = f"{r['integrator']} {r['material']} E={r['youngs_modulus']} dt={r['dt']}"
        if r["outcome"] == "failed":  # strata wrote no stats.json
            problems.append(f"{label}: no result ({r['message']})")
            continue
        dt, estimate = float(r["dt"]), float(r["stable_dt_estimate"])
        if r["integrator"] == "implicit_euler" and r["outcome"] != "stable":
            problems.append(f"{label}: backward Euler {r['outcome']}")
        if r["integrator"] != "implicit_euler":
            if dt <= estimate and r["outcome"] != "stable":
                problems.append(f"{label}: {r['outcome']} below the estimate {estimate:.3g}")
            if dt >= 3 * estimate and r["outcome"] == "stable":
                problems.append(f"{label}: stable at 3x the estimate {estimate:.3g}")
    return problems


def compression_problems(rows):
    problems = []
    for r in rows:
        if r["outcome"] == "failed":  # strata wrote no stats.json
            problems.append(f"{r['integrator']} {r['material']} ratio={r['compression_ratio']} "
                            f"dt={r['dt']}: no result ({r['message']})")
            continue
        dt, estimate = float(r["dt"]), float(r["stable_dt_estimate"])
        ratio = float(r["compression_ratio"])
        label = f"{r['integrator']} {r['material']} ratio={r['compression_ratio']} dt={r['dt']}"
        implicit = r["integrator"] == "implicit_euler"
        if implicit and r["material"] == "neohookean" and r["outcome"] != "stable":
            problems.append(f"{label}: backward Euler neo-Hookean {r['outcome']}")
        if r["material"] == "stvk" and ratio <= 0.4 and r["outcome"] not in ("inverted",
                                                                             "diverged"):
            problems.append(f"{label}: StVK {r['outcome']} under strong compression")
        if implicit and r["material"] == "stvk" and ratio >= 0.8 and r["outcome"] != "stable":
            problems.append(f"{label}: backward Euler StVK {r['outcome']} at mild compression")
        if not implicit:
            if (r["material"] == "neohookean" and ratio >= 0.6 and dt <= estimate
                    and r["outcome"] != "stable"):
                problems.append(f"{label}: {r['outcome']} below the estimate {estimate:.3g}")
            if dt >= 3 * estimate and r["outcome"] == "stable":
                problems.append(f"{label}: stable at 3x the estimate {estimate:.3g}")
    return problems


def main():
    strata, out = sys.argv[1:3]
    axis = "stiffness"
    if sys.argv[3:5] and sys.argv[3] == "--axis":
        axis = sys.argv[4]
    shutil.rmtree(out, ignore_errors=True)  # no run of an earlier build is reused
    result = subprocess.run([sys.executable, os.path.join(HERE, "stability_map.py"), "--quick",
                             "--axis", axis, "--out", out, "--strata", strata, "--jobs", "2"],
                            capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"check_stability_smoke: stability_map failed: {result.stderr.strip()}")
    stem = "stability_compression" if axis == "compression" else "stability"
    chart = "stability_compression.png" if axis == "compression" else "stability_map.png"
    with open(os.path.join(out, f"{stem}.csv")) as f:
        rows = list(csv.DictReader(f))
    if len(rows) != 96 or not os.path.getsize(os.path.join(out, chart)) > 1000:
        sys.exit(f"check_stability_smoke: {len(rows)} rows (expected 96) or no chart")
    problems = compression_problems(rows) if axis == "compression" else stiffness_problems(rows)
    if problems:
        sys.exit("check_stability_smoke: " + "; ".join(problems))
    print(f"check_stability_smoke: {len(rows)} runs over {axis} as expected")


if __name__ == "__main__":
    main()
