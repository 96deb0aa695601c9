#!/usr/bin/python3
"""CTest smoke run of the whole experiments suite and its report, as the demo runs it:

  check_report_smoke.py STRATA OUT [--expect-failed NAME/RUN ...] [SPEC.json ...]
                                    (default: every spec in experiments/specs)

Runs every spec's short version (experiment.py --quick --jobs 2), both stability maps on their
coarse grids (stability_map.py --quick, over stiffness and over compression), then report.py on
those results, and checks the report: a headline row and a section per spec, a table row per
planned run, every chart and picture it links present and non-empty, each spec's
error_vs_cost.png (and pictures.png when the spec asks for pictures, surface.png when its scene
has a fine surface) among them, and the stability section with both maps. OUT is emptied first,
so that no earlier run is reused. Every run must finish with status ok, but for those named by --expect-failed,
which must not (e.g. block_compress/variant-stvk: StVK cannot hold the block compressed to a
fifth of its height). Specs whose scene reads CGAL's models are skipped when the models are missing.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def fail(message):
    sys.exit(f"check_report_smoke: {message}")


def run(command):
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        fail(f"{' '.join(command[1:3])} failed: {result.stderr.strip()[-1500:]}")
    return result.stdout


def needs_models(spec):
    with open(spec) as f:
        scene = os.path.join(os.path.dirname(spec), json.load(f)["scene"])
    with open(scene) as f:
        return "data/models/" in f.read()


def main():
    strata, out = sys.argv[1:3]
    rest, expected_failures = sys.argv[3:], set()
    while "--expect-failed" in rest:
        i = rest.index("--expect-failed")
        expected_failures.add(rest[i + 1])
        del rest[i:i + 2]
    specs = rest or sorted(glob.glob(os.path.join(REPO, "experiments", "specs", "*.json")))
    models = os.path.isdir(os.path.join(REPO, "build", "data", "models"))
    specs = [s for s in specs if models or not needs_models(s)]
    shutil.rmtree(out, ignore_errors=True)
    results = os.path.join(out, "runs")
    planned, wanted = {}, []
    for spec in specs:
        base = [sys.executable, os.path.join(HERE, "experiment.py"), spec, "--quick",
                "--out", results, "--strata", strata, "--jobs", "2", "--threads", "1"]
        run(base)
        with open(spec) as f:
            spec_json = json.load(f)
        name = spec_json.get("name", os.path.splitext(os.path.basename(spec))[0])
        wanted.append(f"{name}/error_vs_cost.png")
        if "pictures" in spec_json:
            wanted.append(f"{name}/pictures.png")
            with open(os.path.join(os.path.dirname(spec), spec_json["scene"])) as f:
                if "surface" in json.load(f).get("mesh", {}):
                    wanted.append(f"{name}/surface.png")
        planned[name] = [line for line in run(base + ["--list"]).splitlines() if line.strip()]
        with open(os.path.join(results, name, "results.json")) as f:
            for row in json.load(f)["runs"]:
                key = f"{name}/{row['run']}"
                if key in expected_failures and row["status"] == "ok":
                    fail(f"{key} finished, but it should fail")
                if key not in expected_failures and row["status"] != "ok":
                    fail(f"{key}: status {row['status']} {row.get('message', '')}")
                expected_failures.discard(key)
    if expected_failures:
        fail(f"--expect-failed names runs that were not run: {sorted(expected_failures)}")
    stability = os.path.join(results, "stability")
    for axis in ("stiffness", "compression"):
        run([sys.executable, os.path.join(HERE, "stability_map.py"), "--quick", "--axis", axis,
             "--out", stability, "--strata", strata, "--jobs", "2"])
    report = os.path.join(out, "report")
    run([sys.executable, os.path.join(HERE, "report.py"), *specs, "--results", results,
         "--out", report, "--strata", strata, "--stability", stability])
    with open(os.path.join(report, "REPORT.md")) as f:
        text = f.read()
    headline = text.split("## Headline", 1)[1].split("\n## ", 1)[0]
    for name, commands in planned.items():
        if not re.search(rf"^\| {re.escape(name)} \|", headline, re.M):
            fail(f"no headline row for {name}")
        match = re.search(rf"^## {re.escape(name)}\n(.*?)(?=^## |\Z)", text, re.M | re.S)
        if not match:
            fail(f"no section for {name}")
        rows = [line for line in match.group(1).splitlines()
                if re.match(r"\| (full|uniform-|adaptive-|variant-|precomputed-)", line)]
        if len(rows) != len(commands):
            fail(f"{name}: {len(rows)} table rows for {len(commands)} planned runs")
    links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    for link in links:
        path = os.path.join(report, link)
        if not os.path.exists(path) or os.path.getsize(path) < 1000:
            fail(f"the report links {link}, which is missing or empty")
    for chart in wanted + ["stability_map.png", "stability_compression.png"]:
        if chart not in links:
            fail(f"the report does not show {chart}")
    print(f"check_report_smoke: {len(planned)} scenes, {len(links)} charts and pictures, "
          "report complete")


if __name__ == "__main__":
    main()
