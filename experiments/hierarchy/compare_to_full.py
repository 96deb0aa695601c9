#!/usr/bin/python3
"""Error of hierarchy runs against full resolution, over the whole run.

Runs a scene (which has a "hierarchy" key) once with hierarchy.mode=full — the reference, reused
when its outputs are present from the same command, scene file and strata binary — and once per
configuration given with --run NAME:key=value,... The error of a run is the largest
probe-displacement difference to the full run over every frame and probe, relative to the largest
full-resolution probe displacement (the measure hierarchy.tolerance bounds). An adaptive run's
error is set against its tolerance: `within_tolerance`, beside the run's own `tolerance_met`,
flags a run over its tolerance that reported it met. Prints one line per run (and the run's
warnings) and writes <out>/compare.json:

  compare_to_full.py SCENE.json [--out DIR] [--strata PATH] [--field]
                     [--run adaptive:] [--run tight:tolerance=0.005] [--set key=value ...]

`--set` applies to every run (full included), e.g. --set solver.duration=0.1.
`--field` also measures the field error (field_error.py: the displacement difference at every
vertex of the full mesh in every frame, relative to the largest full-resolution displacement) and
the effectivity against it; each run is repeated with its .vtu frames written, untimed, so that
writing them does not enter the speed-ups.
"""
import argparse
import csv
import hashlib
import json
import os
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def read_probes(folder):
    frames = {}
    with open(os.path.join(folder, "probes.csv")) as f:
        for row in csv.DictReader(f):
            key = (round(float(row["time"]), 12), int(row["probe"]))
            frames[key] = (float(row["ux"]), float(row["uy"]), float(row["uz"]))
    return frames


def fingerprint(args, command):
    """What a run's outputs depend on: the command, the scene file's bytes, the binary."""
    with open(args.scene, "rb") as f:
        scene = hashlib.sha256(f.read()).hexdigest()
    binary = os.stat(args.strata)
    return {"command": command, "scene_sha256": scene,
            "strata": [binary.st_size, binary.st_mtime_ns]}


def run(args, name, settings, frames=False):
    folder = os.path.join(args.out, name + ("-frames" if frames else ""))
    stats_path = os.path.join(folder, "stats.json")
    command = [args.strata, "run", args.scene, "--out", folder, "--quiet",
               "--set", f"output.vtk={'true' if frames else 'false'}"]
    for item in args.set:
        command += ["--set", item]
    for key, value in settings.items():
        command += ["--set", f"hierarchy.{key}={value}"]
    if frames:
        command += ["--set", "output.vtk_encoding=binary"]
    key = fingerprint(args, command)
    key_path = os.path.join(folder, "compare_run.json")
    if name == "full" and os.path.exists(stats_path) and not args.rerun_full:
        if os.path.exists(key_path) and json.load(open(key_path)) == key:
            return json.load(open(stats_path)), folder
    if os.path.exists(key_path):
        os.remove(key_path)
    start = time.monotonic()
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"compare_to_full: {name} failed ({result.returncode}): {result.stderr.strip()}")
    stats = json.load(open(stats_path))
    stats["measured_seconds"] = time.monotonic() - start
    stats["warnings"] = [line.strip() for line in result.stderr.splitlines() if "warning" in line]
    with open(key_path, "w") as f:
        json.dump(key, f)
    return stats, folder


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--out", default=os.path.join(REPO, "out", "compare"))
    parser.add_argument("--strata", default=os.path.join(REPO, "build", "experiments", "cli",
                                                         "strata"))
    parser.add_argument("--run", action="append", default=[])
    parser.add_argument("--set", action="append", default=[])
    parser.add_argument("--rerun-full", action="store_true")
    parser.add_argument("--field", action="store_true")
    args = parser.parse_args()
    runs = args.run or ["adaptive:"]
    full_stats, full_folder = run(args, "full", {"mode": "full"})
    if args.field:
        import field_error  # needs numpy: only with --field
        full_frames = run(args, "full", {"mode": "full"}, frames=True)[1]
    reference = read_probes(full_folder)
    scale = max(sum(c * c for c in u) ** 0.5 for u in reference.values())
    if scale == 0.0:
        sys.exit("compare_to_full: the full run's probes do not move (no error to measure)")
    report = {"scene": args.scene, "full": {"wall_seconds": full_stats["wall_seconds"],
                                            "tets": full_stats["tets"]}, "runs": []}
    print(f"full: {full_stats['tets']} tets, {full_stats['wall_seconds']:.2f} s, "
          f"largest probe displacement {scale:.4g} m")
    for spec in runs:
        name, _, text = spec.partition(":")
        settings = dict(item.split("=", 1) for item in text.split(",") if item)
        stats, folder = run(args, name, settings)
        probes = read_probes(folder)
        worst, worst_key = 0.0, None
        for key, u in reference.items():
            if key not in probes:
                sys.exit(f"compare_to_full: {name} lacks frame/probe {key}")
            d = sum((a - b) ** 2 for a, b in zip(probes[key], u)) ** 0.5
            if d > worst:
                worst, worst_key = d, key
        last_time = max(k[0] for k in reference)
        last = max(sum((a - b) ** 2 for a, b in zip(probes[k], reference[k])) ** 0.5
                   for k in reference if k[0] == last_time)
        h = stats.get("hierarchy", {})
        history = h.get("history", {}).get("tets", [])
        entry = {"name": name, "settings": settings, "error": worst / scale,
                 "error_last_frame": last / scale, "worst_frame_probe": worst_key,
                 "wall_seconds": stats["wall_seconds"],
                 "speedup": full_stats["wall_seconds"] / stats["wall_seconds"],
                 "final_tets": stats["tets"], "max_tets": max(history) if history else None,
                 "estimated_error": h.get("estimated_error"),
                 "redone_steps": h.get("redone_steps"),
                 "warnings": stats.get("warnings", [])}
        if h.get("mode") in ("adaptive", "precomputed") and h.get("tolerance") is not None:
            entry["tolerance"] = h["tolerance"]
            entry["tolerance_met"] = h.get("tolerance_met")
            entry["within_tolerance"] = entry["error"] <= h["tolerance"]
        if args.field:
            field = field_error.field_error(full_frames, run(args, name, settings, True)[1])
            entry["field_error"] = field["error"]
            entry["field_worst_time"] = field["worst_time"]
            estimated = entry["estimated_error"]
            entry["field_effectivity"] = (estimated / field["error"]
                                          if estimated is not None and field["error"] > 0 else None)
            print(f"{name}: field error {100 * field['error']:.3f} % (t = {field['worst_time']}), "
                  f"effectivity {entry['field_effectivity']}")
        report["runs"].append(entry)
        print(f"{name}: error {100 * entry['error']:.2f} % (last frame "
              f"{100 * entry['error_last_frame']:.2f} %), {entry['wall_seconds']:.2f} s "
              f"({entry['speedup']:.2f}x faster than full), tets final {entry['final_tets']} "
              f"max {entry['max_tets']}, estimated {entry['estimated_error']}, "
              f"redone steps {entry['redone_steps']}")
        if "tolerance" in entry:
            verdict = "within" if entry["within_tolerance"] else "OVER"
            reported = "met" if entry["tolerance_met"] else "not met"
            print(f"{name}: {verdict} its tolerance {100 * entry['tolerance']:.2f} % "
                  f"(the run reported it {reported})")
        for line in entry["warnings"]:
            print(f"{name}: {line}")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "compare.json"), "w") as f:
        json.dump(report, f, indent=2)


if __name__ == "__main__":
    main()
