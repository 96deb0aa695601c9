#!/usr/bin/python3
"""Cost against accuracy of the hierarchy's modes on one scene.

Runs the strata CLI on a scene with a "hierarchy" key in mode full (the reference), uniform at
every level 0..L-1, and adaptive with several refine thresholds for both indicators (force and
stress_jump), all through `--set hierarchy.…` overrides. From each run's probes.csv (last frame)
and stats.json it takes the probe displacement, the active tets, the DOFs and the wall time, and
writes

  <out>/cost_accuracy.csv   one row per run
  <out>/cost_accuracy.png   probe error against full resolution vs active tets and vs wall seconds

The error of a run is |u_z − u_z,full| / |u_z,full| at the probe chosen with --probe (default 0),
at the last frame. Usage:

  cost_accuracy.py [--strata PATH] [--scene SCENE.json] [--out DIR] [--probe I]
                   [--force-thresholds 1.1,1.5,3,6] [--stress-jump-thresholds 0.1,0.15,0.3,0.5]

Needs python3 with matplotlib only.
"""
import argparse
import csv
import json
import os
import resource
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--strata", default=os.environ.get("STRATA") or os.path.join(
        REPO, "build", "experiments", "cli", "strata"), help="the strata executable")
    parser.add_argument("--scene", default=os.path.join(REPO, "experiments", "scenes",
                                                        "slab_press.json"))
    parser.add_argument("--out", default=os.path.join(REPO, "out", "experiments"))
    parser.add_argument("--probe", type=int, default=0, help="probe index compared")
    parser.add_argument("--force-thresholds", default="1.1,1.5,3,6")
    parser.add_argument("--stress-jump-thresholds", default="0.1,0.15,0.3,0.5")
    return parser.parse_args()


def thresholds(text):
    return [float(t) for t in text.split(",") if t.strip()]


def run_strata(args, name, settings):
    """Runs one configuration; returns the row of the table (without the error)."""
    folder = os.path.join(args.out, "cost_accuracy_runs", name)
    command = [args.strata, "run", args.scene, "--out", folder, "--quiet",
               "--set", "output.vtk=false"]
    for key, value in settings.items():
        command += ["--set", f"hierarchy.{key}={value}"]
    start = time.monotonic()
    usage_before = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = subprocess.run(command, capture_output=True, text=True)
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    elapsed = time.monotonic() - start
    cpu = (usage.ru_utime - usage_before.ru_utime) + (usage.ru_stime - usage_before.ru_stime)
    if result.returncode != 0:
        sys.exit(f"cost_accuracy: {' '.join(command)} failed ({result.returncode}):\n"
                 f"{result.stderr}")
    with open(os.path.join(folder, "stats.json")) as file:
        stats = json.load(file)
    with open(os.path.join(folder, "probes.csv")) as file:
        rows = [r for r in csv.DictReader(file) if int(r["probe"]) == args.probe]
    last = max(rows, key=lambda r: float(r["time"]))
    hierarchy = stats["hierarchy"]
    row = {
        "run": name,
        "mode": hierarchy["mode"],
        "indicator": hierarchy["indicator"] if hierarchy["mode"] == "adaptive" else "",
        "threshold": hierarchy["refine_threshold"] if hierarchy["mode"] == "adaptive" else "",
        "level": hierarchy["level"] if hierarchy["mode"] == "uniform" else "",
        "active_tets": stats["tets"],
        "max_active_tets": max(hierarchy["history"]["tets"]),
        "free_dofs": stats["free_dofs"],
        "cut_changes": len(hierarchy["changes"]),
        "newton_iterations": stats["newton_iterations"],
        "wall_seconds": stats["wall_seconds"],
        "process_seconds": round(elapsed, 3),
        "cpu_seconds": round(cpu, 3),
        "bookkeeping_seconds": hierarchy["bookkeeping_seconds"],
        "stepping_seconds": hierarchy["stepping_seconds"],
        "probe_uz": float(last["uz"]),
    }
    print(f"  {name:24s} {row['active_tets']:>8} tets  u_z = {row['probe_uz']:.4e}  "
          f"{row['wall_seconds']:.2f} s wall, {cpu:.2f} s CPU", flush=True)
    return row


def configurations(args, levels):
    runs = [("full", {"mode": "full"})]
    runs += [(f"uniform_{k}", {"mode": "uniform", "level": k}) for k in range(levels)]
    for indicator, values in (("force", thresholds(args.force_thresholds)),
                              ("stress_jump", thresholds(args.stress_jump_thresholds))):
        runs += [(f"adaptive_{indicator}_{t:g}",
                  {"mode": "adaptive", "indicator": indicator, "refine_threshold": t})
                 for t in values]
    return runs


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    full = next(r for r in rows if r["mode"] == "full")
    series = [("uniform level k", lambda r: r["mode"] == "uniform", "s-", "tab:gray"),
              ("adaptive, force", lambda r: r["indicator"] == "force", "o-", "tab:blue"),
              ("adaptive, stress_jump", lambda r: r["indicator"] == "stress_jump", "^-",
               "tab:orange")]
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for axis, key, label in ((axes[0], "active_tets", "active tets (end of run)"),
                             (axes[1], "wall_seconds", "wall time [s]")):
        for name, select, style, color in series:
            chosen = sorted((r for r in rows if select(r)), key=lambda r: r[key])
            if not chosen:
                continue
            axis.plot([r[key] for r in chosen], [max(r["error"], 1e-6) * 100 for r in chosen],
                      style, color=color, label=name)
            if name.startswith("uniform"):
                for r in chosen:
                    axis.annotate(f"k={r['level']}", (r[key], r["error"] * 100),
                                  textcoords="offset points", xytext=(5, 4), fontsize=8)
            else:
                for r in chosen:
                    axis.annotate(f"{r['threshold']:g}", (r[key], max(r["error"], 1e-6) * 100),
                                  textcoords="offset points", xytext=(5, -10), fontsize=8,
                                  color=color)
        axis.axvline(full[key], color="black", linestyle="--", linewidth=1,
                     label=f"full resolution ({full[key]:,.0f})" if key == "active_tets"
                     else f"full resolution ({full[key]:.1f} s)")
        axis.axhline(1.0, color="tab:red", linestyle=":", linewidth=1, label="1 % error")
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel(label)
        axis.set_ylabel("probe u_z error vs full [%]")
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(fontsize=8)
    figure.suptitle("Cost against accuracy (threshold next to each adaptive point)")
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def main():
    args = parse_args()
    if not os.access(args.strata, os.X_OK):
        sys.exit(f"cost_accuracy: {args.strata} is not an executable (set STRATA or --strata)")
    with open(args.scene) as file:
        levels = json.load(file)["hierarchy"]["levels"]
    os.makedirs(args.out, exist_ok=True)
    print(f"cost_accuracy: {args.scene}, {levels} levels, probe {args.probe}")
    rows = [run_strata(args, name, settings) for name, settings in configurations(args, levels)]
    reference = rows[0]["probe_uz"]
    for r in rows:
        r["error"] = abs(r["probe_uz"] - reference) / abs(reference)

    table = os.path.join(args.out, "cost_accuracy.csv")
    with open(table, "w", newline="") as file:
        writer = csv.DictWriter(file, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    chart = os.path.join(args.out, "cost_accuracy.png")
    plot(rows, chart)

    print("\n| run | active tets | free DOFs | probe u_z [m] | error | wall [s] | CPU [s] | "
          "bookkeeping [s] |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['run']} | {r['active_tets']:,} | {r['free_dofs']:,} | {r['probe_uz']:.4e} | "
              f"{100 * r['error']:.2f} % | {r['wall_seconds']:.2f} | {r['cpu_seconds']:.2f} | "
              f"{r['bookkeeping_seconds']:.2f} |")
    good = [r for r in rows if r["mode"] == "adaptive" and r["error"] < 0.01]
    full = rows[0]
    if good:
        best = min(good, key=lambda r: r["active_tets"])
        print(f"\nadaptive within 1 %: {best['run']} at {best['active_tets']:,} tets, "
              f"{full['active_tets'] / best['active_tets']:.1f}x fewer than full "
              f"({full['active_tets']:,}); error {100 * best['error']:.2f} %; wall "
              f"{best['wall_seconds']:.2f} s vs {full['wall_seconds']:.2f} s (CPU {best['cpu_seconds']:.2f} s "
              f"vs {full['cpu_seconds']:.2f} s)")
    else:
        print("\nno adaptive run is within 1 % of full resolution")
    print(f"cost_accuracy: wrote {table} and {chart}")


if __name__ == "__main__":
    main()
