#!/usr/bin/python3
"""Stability map: where each integrator and material holds or fails, over time step × stiffness
or time step × compression.

  stability_map.py [--axis stiffness|compression] [--scene SCENE.json] [--out DIR]
                   [--strata PATH] [--jobs N] [--quick]

--axis stiffness (default) runs the scene (default: a 1 m cantilever of 20 × 2 × 2 cells under
gravity, undamped, released from rest, 0.3 s) over Young's modulus E × time step dt; --axis
compression runs a 0.1 m cube of 3 × 3 × 3 cells (E = 1 MPa, ν = 0.45, undamped) on a fixed
base whose clamped top face is pushed down to a fraction of its height (the compression ratio:
final height / rest height) over 0.2 s and held for 0.1 s, over compression ratio × dt. Every
point runs for every integrator (symplectic_euler, rk4, implicit_euler) and material (stvk,
neohookean) and is classified from its stats.json: stable (status ok), inverted (diverged with
an inverted element, which StVK and corotated cannot handle) or diverged (blow-up, non-finite
state or Newton failure). Writes OUT/stability.csv and OUT/stability_map.png (--axis compression:
OUT/stability_compression.csv and OUT/stability_compression.png): one panel per integrator and
material, coloured by outcome, with the run's stable-step estimate (stats.json
stable_dt_estimate, the element bound of the explicit integrators at rest) drawn as a line.
Finished runs (their stats.json) are kept and skipped when the map is drawn again.
"""
import argparse
import concurrent.futures
import csv
import json
import os
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
INTEGRATORS = ["symplectic_euler", "rk4", "implicit_euler"]
MATERIALS = ["stvk", "neohookean"]
DEFAULT_SCENE = {
    "mesh": {"box": {"min": [0, 0, 0], "max": [1, 0.1, 0.1], "cells": [20, 2, 2]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.4,
                 "density": 1000},
    "gravity": [0, 0, -9.81],
    "fixed": [{"plane": {"point": [0, 0, 0], "normal": [1, 0, 0]}}],
    "solver": {"mode": "dynamic", "integrator": "implicit_euler", "dt": 0.001, "duration": 0.3},
    "output": {"every": 1000000, "vtk": False},
}
# The compression axis: the top face moves down by (1 - ratio) × 0.1 m over 0.2 s, then holds.
COMPRESSION_SCENE = {
    "mesh": {"box": {"min": [0, 0, 0], "max": [0.1, 0.1, 0.1], "cells": [3, 3, 3]}},
    "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.45,
                 "density": 1000},
    "fixed": [{"plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}}],
    "prescribed": [{"region": {"plane": {"point": [0, 0, 0.1], "normal": [0, 0, 1]}},
                    "displacement": [0, 0, -0.05], "amplitude": [[0, 0], [0.2, 1]]}],
    "solver": {"mode": "dynamic", "integrator": "implicit_euler", "dt": 0.001, "duration": 0.3},
    "output": {"every": 1000000, "vtk": False},
}
HEIGHT = 0.1


def classify(stats):
    if stats.get("status") == "ok":
        return "stable"
    message = stats.get("message", "")
    return "inverted" if "inverted" in message else "diverged"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--axis", choices=["stiffness", "compression"], default="stiffness",
                        help="the second axis: Young's modulus or the compression ratio")
    parser.add_argument("--scene", help="scene file (default: the built-in cantilever, or with "
                        "--axis compression the built-in cube)")
    parser.add_argument("--out", default=os.path.join(REPO, "out", "stability"))
    parser.add_argument("--strata", default=os.environ.get("STRATA") or os.path.join(
        REPO, "build", "experiments", "cli", "strata"))
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="a coarser grid (4 × 4 per panel)")
    args = parser.parse_args()
    if not os.access(args.strata, os.X_OK):
        sys.exit(f"stability_map: {args.strata} is not an executable (build strata or --strata)")
    os.makedirs(args.out, exist_ok=True)
    compression = args.axis == "compression"
    scene_path = args.scene
    if scene_path is None:
        scene_path = os.path.join(args.out, "cube.json" if compression else "cantilever.json")
        with open(scene_path, "w") as f:
            json.dump(COMPRESSION_SCENE if compression else DEFAULT_SCENE, f, indent=1)
    if compression:
        # Final height / rest height; the x axis runs from mild to strong compression.
        values = [0.8, 0.6, 0.4, 0.2] if args.quick else [0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2]
    else:
        values = [1e4, 1e5, 1e6, 1e7] if args.quick else [1e4, 3e4, 1e5, 3e5, 1e6, 3e6, 1e7]
    if compression:  # around the explicit integrators' stable step of this cube (~2e-4 s)
        steps = [3e-5, 1e-4, 3e-4, 1e-3] if args.quick else [3e-5, 1e-4, 2e-4, 3e-4, 1e-3,
                                                              3e-3, 1e-2]
    else:
        steps = [1e-4, 1e-3, 3e-3, 1e-2] if args.quick else [3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2]

    jobs = []
    for integrator in INTEGRATORS:
        for material in MATERIALS:
            for value in values:
                for dt in steps:
                    tag = f"c{value:g}" if compression else f"E{value:g}"
                    jobs.append((f"{integrator}-{material}-{tag}-dt{dt:g}", integrator, material,
                                 value, dt))

    def run(job):
        name, integrator, material, value, dt = job
        folder = os.path.join(args.out, "runs_compression" if compression else "runs", name)
        stats_path = os.path.join(folder, "stats.json")
        if not os.path.exists(stats_path):
            command = [args.strata, "run", scene_path, "--out", folder, "--quiet", "--threads", "1",
                       "--set", f"solver.integrator={integrator}",
                       "--set", f"material.model={material}", "--set", f"solver.dt={dt}"]
            if compression:
                command += ["--set",
                            f"prescribed.0.displacement=[0, 0, {-(1 - value) * HEIGHT!r}]"]
            else:
                command += ["--set", f"material.youngs_modulus={value}"]
            subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if not os.path.exists(stats_path):
            return job, {"status": "failed", "message": "no stats.json"}
        with open(stats_path) as f:
            return job, json.load(f)

    rows = []
    key = "compression_ratio" if compression else "youngs_modulus"
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for k, (job, stats) in enumerate(pool.map(run, jobs)):
            name, integrator, material, value, dt = job
            rows.append({"integrator": integrator, "material": material, key: value,
                         "dt": dt, "outcome": classify(stats),
                         "stable_dt_estimate": stats.get("stable_dt_estimate"),
                         "steps": stats.get("steps"), "message": stats.get("message", "")})
            print(f"\rstability_map: {k + 1}/{len(jobs)} runs", end="", file=sys.stderr,
                  flush=True)
    print(file=sys.stderr)
    stem = "stability_compression" if compression else "stability"
    with open(os.path.join(args.out, f"{stem}.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    colours = {"stable": "#2ca02c", "inverted": "#ff7f0e", "diverged": "#d62728",
               "failed": "#7f7f7f"}
    figure, axes = plt.subplots(len(MATERIALS), len(INTEGRATORS), figsize=(13, 7.5),
                                sharex=True, sharey=True)
    for i, material in enumerate(MATERIALS):
        for j, integrator in enumerate(INTEGRATORS):
            axis = axes[i][j]
            panel = [r for r in rows if r["material"] == material and r["integrator"] == integrator]
            for outcome, colour in colours.items():
                points = [r for r in panel if r["outcome"] == outcome]
                if points:
                    axis.scatter([r[key] for r in points], [r["dt"] for r in points],
                                 s=120, marker="s", color=colour, label=outcome)
            estimate = sorted((r[key], r["stable_dt_estimate"]) for r in panel
                              if r["stable_dt_estimate"])
            estimate = sorted(dict(estimate).items())
            if estimate and integrator != "implicit_euler":
                axis.plot([e for e, _ in estimate], [d for _, d in estimate], "k--",
                          label="stable-step estimate (at rest)")
            if compression:
                axis.set_xlim(1.0, 0.1)  # mild compression left, strong right
            else:
                axis.set_xscale("log")
            axis.set_yscale("log")
            axis.set_title(f"{integrator}, {material}", fontsize=10)
            axis.grid(True, which="both", alpha=0.3)
            if i == len(MATERIALS) - 1:
                axis.set_xlabel("compression ratio (final height / rest height)" if compression
                                else "Young's modulus E [Pa]")
            if j == 0:
                axis.set_ylabel("time step dt [s]")
    handles = {}
    for axis in axes.flat:
        for handle, label in zip(*axis.get_legend_handles_labels()):
            handles.setdefault(label, handle)
    figure.legend(handles.values(), handles.keys(), loc="lower center", ncol=len(handles))
    if args.scene is not None:
        title = f"Stability map: {os.path.basename(args.scene)}"
    elif compression:
        title = ("Stability map: a cube compressed on its base (0.2 s, held 0.1 s; E = 1 MPa, "
                 "ν = 0.45)")
    else:
        title = "Stability map: cantilever under gravity, released from rest (0.3 s)"
    figure.suptitle(title)
    figure.tight_layout(rect=(0, 0.06, 1, 0.96))
    chart = os.path.join(args.out, "stability_compression.png" if compression
                         else "stability_map.png")
    figure.savefig(chart, dpi=110)
    plt.close(figure)
    counts = {}
    for r in rows:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    print(f"stability_map: {len(rows)} runs {counts}; wrote {chart}")


if __name__ == "__main__":
    main()
