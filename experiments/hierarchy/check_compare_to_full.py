#!/usr/bin/python3
"""CTest check of compare_to_full.py against an independent computation on a small scene.

  check_compare_to_full.py STRATA WORK_DIR

A 96-root block at one level under a patch load, 10 backward-Euler steps:
1. a run at full resolution compared with the full reference has error 0;
2. the roots (uniform level 0) have the error computed here from the two probes.csv files (the
   largest probe-displacement difference over every frame and probe, relative to the largest
   full-resolution probe displacement), to 1e-12, and it is positive; uniform runs carry no
   tolerance verdict;
3. adaptive runs carry their tolerance, the run's tolerance_met and within_tolerance, which is
   error <= tolerance; one held on the roots (max_level 0) is over its 5 % tolerance;
4. a second call reuses the full reference (its stats.json is not written again).
Exits non-zero with a message on the first failure.
"""
import csv
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

SCENE = {
    "mesh": {"box": {"min": [0, 0, 0], "max": [0.2, 0.1, 0.1], "cells": [4, 2, 2]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e5, "poisson_ratio": 0.3,
                 "density": 1000, "damping": {"mass": 5.0}},
    "fixed": [{"plane": {"point": [0, 0, 0], "normal": [1, 0, 0]}}],
    "forces": [{"region": {"box": {"min": [0.15, 0.0, 0.1], "max": [0.2, 0.05, 0.1]}},
                "total_force": [0, 0, -5]}],
    "solver": {"mode": "dynamic", "integrator": "implicit_euler", "dt": 0.002, "duration": 0.02},
    "output": {"every": 2, "probes": [[0.2, 0.025, 0.1], [0.1, 0.05, 0.05], [0.05, 0.1, 0.1]]},
    "hierarchy": {"levels": 1},
}


def fail(message):
    sys.exit(f"check_compare_to_full: {message}")


def probes(folder):
    with open(os.path.join(folder, "probes.csv")) as f:
        return {(row["time"], row["probe"]): [float(row[k]) for k in ("ux", "uy", "uz")]
                for row in csv.DictReader(f)}


def compare(strata, scene, out, *runs):
    command = ["/usr/bin/python3", os.path.join(HERE, "compare_to_full.py"), scene, "--out", out,
               "--strata", strata]
    for run in runs:
        command += ["--run", run]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        fail(f"compare_to_full.py failed: {result.stderr.strip()}")
    with open(os.path.join(out, "compare.json")) as f:
        return {entry["name"]: entry for entry in json.load(f)["runs"]}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    strata, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scene = os.path.join(work, "block.json")
    with open(scene, "w") as f:
        json.dump(SCENE, f)
    out = os.path.join(work, "out")
    runs = compare(strata, scene, out, "same:mode=full", "roots:mode=uniform,level=0",
                   "adaptive:tolerance=0.01", "loose:tolerance=0.5",
                   "held:tolerance=0.05,max_level=0")

    if runs["same"]["error"] != 0.0:
        fail(f"a full run against the full reference has error {runs['same']['error']}")
    full = probes(os.path.join(out, "full"))
    roots = probes(os.path.join(out, "roots"))
    if set(full) != set(roots):
        fail("the roots' probes.csv has other frames or probes than the full run's")
    scale = max(sum(c * c for c in u) ** 0.5 for u in full.values())
    error = max(sum((a - b) ** 2 for a, b in zip(roots[k], full[k])) ** 0.5 for k in full) / scale
    if not error > 0.0:
        fail("the roots do not differ from full resolution: the check measures nothing")
    if abs(runs["roots"]["error"] - error) > 1e-12 * error:
        fail(f"roots: compare_to_full error {runs['roots']['error']} against {error} computed here")
    if "within_tolerance" in runs["roots"]:
        fail("a uniform run got a tolerance verdict")

    for name, tolerance in (("adaptive", 0.01), ("loose", 0.5), ("held", 0.05)):
        entry = runs[name]
        if entry.get("tolerance") != tolerance:
            fail(f"{name}: tolerance {entry.get('tolerance')}, expected {tolerance}")
        if not isinstance(entry.get("tolerance_met"), bool):
            fail(f"{name}: tolerance_met {entry.get('tolerance_met')!r} is not the run's boolean")
        if entry.get("within_tolerance") != (entry["error"] <= tolerance):
            fail(f"{name}: within_tolerance {entry.get('within_tolerance')} for error "
                 f"{entry['error']} at tolerance {tolerance}")
        if not isinstance(entry.get("warnings"), list):
            fail(f"{name}: no warnings list")

    if runs["held"]["within_tolerance"] or runs["held"]["error"] <= 0.05:
        fail(f"held on the roots: error {runs['held']['error']} within its 5 % tolerance")

    stats = os.path.join(out, "full", "stats.json")
    written = os.stat(stats).st_mtime_ns
    again = compare(strata, scene, out, "roots:mode=uniform,level=0")
    if os.stat(stats).st_mtime_ns != written:
        fail("the second call ran the full reference again")
    if again["roots"]["error"] != runs["roots"]["error"]:
        fail("the second call measured another error for the same roots run")
    print(f"check_compare_to_full: ok (roots {100 * error:.3f} % off, adaptive "
          f"{100 * runs['adaptive']['error']:.3f} %)")


if __name__ == "__main__":
    main()
