#!/usr/bin/python3
"""CTest smoke run of experiment.py: a short sweep of a spec, then checks of its outputs.

  check_experiment_smoke.py STRATA SPEC OUT [--set key=value ...]

Runs the sweep with --jobs 2, checks that every planned run finished with status ok and an error
against full resolution (0 for the full run itself), that the coarsest uniform level is farther
from full resolution than the tightest adaptive run (and an `elastic` variant, which ignores
plasticity, more than 10× farther; precomputed runs closer than the coarsest uniform level, with
their training cost), that the charts (and the spec's pictures) exist, and that a
second invocation resumes: it starts no run (every run.json unchanged) and rebuilds the same table.
"""
import csv
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def fail(message):
    sys.exit(f"check_experiment_smoke: {message}")


def main():
    strata, spec, out = sys.argv[1:4]
    extra = sys.argv[4:]
    name = os.path.splitext(os.path.basename(spec))[0]
    command = [sys.executable, os.path.join(HERE, "experiment.py"), spec, "--out", out,
               "--strata", strata, "--jobs", "2", "--threads", "1"] + extra
    first = subprocess.run(command, capture_output=True, text=True)
    if first.returncode != 0:
        fail(f"sweep failed: {first.stderr.strip()}")
    folder = os.path.join(out, name)
    with open(os.path.join(folder, "results.csv")) as f:
        rows = list(csv.DictReader(f))
    listed = subprocess.run(command + ["--list"], capture_output=True, text=True).stdout.split("\n")
    planned = [line for line in listed if line.strip()]
    if len(rows) != len(planned) or len(rows) < 4:
        fail(f"{len(rows)} rows in results.csv for {len(planned)} planned runs")
    for row in rows:
        if row["status"] != "ok" or row["error"] == "":
            fail(f"run {row['run']}: status {row['status']}, error '{row['error']}'")
    by_run = {row["run"]: row for row in rows}
    if float(by_run["full"]["error"]) != 0.0:
        fail(f"the full run's error against itself is {by_run['full']['error']}")
    if float(by_run["full"]["energy_difference"]) != 0.0 or by_run["uniform-0"]["energy_difference"] == "":
        fail("energy differences missing or the full run's is not 0")
    adaptive = [row for row in rows if row["kind"] == "adaptive"]
    tightest = min(adaptive, key=lambda row: float(row["tolerance"]))
    if not float(by_run["uniform-0"]["error"]) > float(tightest["error"]):
        fail("uniform level 0 is not farther from full resolution than the tightest adaptive run")
    variants = [row for row in rows if row["kind"] == "variant"]
    if "variant-elastic" in by_run and not float(by_run["variant-elastic"]["error"]) > 10 * float(
            tightest["error"]):
        fail("ignoring plasticity (variant-elastic) is not clearly farther from full resolution "
             "than the tightest adaptive run")
    precomputed = [row for row in rows if row["kind"] == "precomputed"]
    for row in precomputed:
        if not float(row["error"]) < float(by_run["uniform-0"]["error"]):
            fail(f"{row['run']} is not closer to full resolution than uniform level 0")
        if row["training_seconds"] == "" or not float(row["training_seconds"]) > 0.0:
            fail(f"{row['run']}: no training cost recorded")
    for chart in ("error_vs_cost.png", "adaptive_over_time.png"):
        if os.path.getsize(os.path.join(folder, chart)) < 1000:
            fail(f"{chart} missing or empty")
    with open(spec) as f:
        wants_pictures = "pictures" in json.load(f)
    if wants_pictures and os.path.getsize(os.path.join(folder, "pictures.png")) < 10000:
        fail("pictures.png missing or empty")
    markers = {}
    for run in os.listdir(os.path.join(folder, "runs")):
        markers[run] = os.path.getmtime(os.path.join(folder, "runs", run, "run.json"))
    second = subprocess.run(command, capture_output=True, text=True)
    if second.returncode != 0:
        fail(f"resumed sweep failed: {second.stderr.strip()}")
    for run, mtime in markers.items():
        if os.path.getmtime(os.path.join(folder, "runs", run, "run.json")) != mtime:
            fail(f"resumed sweep ran {run} again")
    with open(os.path.join(folder, "results.csv")) as f:
        again = list(csv.DictReader(f))
    if [r["error"] for r in again] != [r["error"] for r in rows]:
        fail("resumed sweep's table differs from the first")
    print(f"check_experiment_smoke: {len(rows)} runs ok ({len(variants)} variants, "
          f"{len(precomputed)} precomputed), resume ran none again")


if __name__ == "__main__":
    main()
