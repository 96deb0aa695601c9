#!/usr/bin/python3
"""The experiments report: REPORT.md from the sweeps' results (experiment.py).

  report.py [--results DIR] [--out DIR] [--strata PATH] [SPEC.json ...]

Reads DIR/<name>/results.json of every sweep (default out/experiments, or only those of the given
specs), copies each sweep's charts next to the report and writes OUT/REPORT.md (default
experiments/results): the machine, the commands, per scene a table of every run (error against
full resolution, the final-energy difference, the run's estimate and effectivity, wall time,
speed-up, active DOFs), the charts,
and the headline figures — the speed-up over full resolution at the default tolerance (0.01) and
of the cheapest run within 1 % error — with a plain statement wherever a target is missed:
adaptive at least 5× cheaper than full resolution at ≤ 1 % error on the local-load scenes, never
slower than full resolution on the bending-dominated ones, and cheaper at equal error than every
uniform level.
"""
import argparse
import csv
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_TOLERANCE = 0.01


def machine():
    model = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    memory = "?"
    try:
        with open("/proc/meminfo") as f:
            memory = f"{int(f.readline().split()[1]) / 2**20:.0f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    return f"{model}, {cores} cores available, {memory} memory, {platform.system()}"


def version(strata):
    try:
        return subprocess.run([strata, "--version"], capture_output=True, text=True,
                              timeout=10).stdout.strip() or "?"
    except (OSError, subprocess.SubprocessError):
        return "?"


def commit():
    try:
        return subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, timeout=10).stdout.strip() or "?"
    except (OSError, subprocess.SubprocessError):
        return "?"


def percent(value):
    return "–" if value is None else f"{100 * value:.3g} %"


def failed_cuts(runs):
    """Precomputed runs whose error exceeds the tolerance their cut was recorded at."""
    return [r for r in runs if r.get("kind") == "precomputed" and r.get("error") is not None
            and r.get("recorded_tolerance") is not None and r["error"] > r["recorded_tolerance"]]


def headline(runs):
    """(speed-up at the default tolerance, (run, speed-up) of the cheapest run within 1 %)."""
    ok = [r for r in runs if r["status"] == "ok" and r.get("error") is not None]
    default = next((r for r in ok if r["kind"] == "adaptive"
                    and abs(r["tolerance"] - DEFAULT_TOLERANCE) < 1e-12), None)
    within = [r for r in ok if r["kind"] != "full" and r["error"] <= 0.01]
    cheapest = min(within, key=lambda r: r["wall_seconds"]) if within else None
    return default, cheapest


def dominated(runs):
    """Adaptive runs that some uniform level beats: no larger error at lower wall time."""
    ok = [r for r in runs if r["status"] == "ok" and r.get("error") is not None]
    uniform = [r for r in ok if r["kind"] == "uniform"]
    out = []
    for r in (r for r in ok if r["kind"] == "adaptive"):
        for u in uniform:
            if u["error"] <= r["error"] and u["wall_seconds"] < r["wall_seconds"]:
                out.append((r, u))
                break
    return out


def why_missed(runs, run):
    """A sentence from the sweep's own numbers on why `run` is not cheaper: how much of full
    resolution its cut keeps, how much of its time it takes, how cautious its estimate is, how
    much of its time went to cut changes, redone steps and the initial adaptation, and whether
    any coarser uniform level is within 1 %."""
    full = next((r for r in runs if r["run"] == "full"), None)
    if full is None or not full.get("max_dofs") or not full.get("wall_seconds"):
        return ""
    dofs = run.get("max_dofs", 0) / full["max_dofs"]
    time = run["wall_seconds"] / full["wall_seconds"]
    mesh = "largest cut" if run["kind"] == "adaptive" else "mesh"
    parts = [f"its {mesh} keeps {100 * dofs:.0f} % of full resolution's DOFs and the run takes "
             f"{100 * time:.0f} % of its wall time"]
    if run.get("effectivity") is not None and run["effectivity"] > 2:
        parts.append(f"its estimate is {run['effectivity']:.1f}× the true error, so the cut is "
                     "finer than the tolerance needs")
    overhead = sum(run.get(k) or 0.0 for k in ("cut_change_seconds", "redo_seconds",
                                                 "initial_adaptation_seconds"))
    if run.get("full_resolution_step") is not None:
        step = run["full_resolution_step"]
        when = "before the first step" if step == 0 else f"after step {step}"
        parts.append(f"its cut grew past hierarchy.full_resolution_fraction of the finest level "
                     f"{when}, so it went on at full resolution")
    if run["kind"] == "adaptive" and run["wall_seconds"] > 0:
        parts.append(f"cut changes, redone steps and the initial adaptation took "
                     f"{100 * overhead / run['wall_seconds']:.0f} % of its time")
    uniform = [r for r in runs if r["kind"] == "uniform" and r["status"] == "ok"
               and r.get("error") is not None]
    if uniform and min(r["error"] for r in uniform) > 0.01:
        finest = max(uniform, key=lambda r: r.get("level", 0))
        parts.append(f"no coarser uniform level is within 1 % ({finest['run']}: "
                     f"{percent(finest['error'])} off): 1 % needs the finest level wherever the "
                     "field varies")
    return "; ".join(parts) + "."


def outcome_table(path):
    """Rows of a stability_map.py table counted per (integrator, material) panel."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    panels = {}
    for r in rows:
        key = (r["integrator"], r["material"])
        panels.setdefault(key, {"stable": 0, "inverted": 0, "diverged": 0, "failed": 0})
        panels[key][r["outcome"]] += 1
    lines = ["| integrator | material | stable | inverted | diverged |", "|---|---|---|---|---|"]
    for (integrator, material), c in sorted(panels.items()):
        lines.append(f"| {integrator} | {material} | {c['stable']} | {c['inverted']} | "
                     f"{c['diverged']} |")
    return lines


def stability_section(folder, out):
    """The stability maps (stability_map.py: over stiffness, and over compression when that map
    was drawn too) with a count of outcomes per panel."""
    source = os.path.join(folder, "stability_map.png")
    table = os.path.join(folder, "stability.csv")
    if not os.path.exists(source) or not os.path.exists(table):
        sys.exit(f"report: {folder} has no stability_map.png / stability.csv")
    shutil.copyfile(source, os.path.join(out, "stability_map.png"))
    lines = ["## Stability map", "",
             "Command: `/usr/bin/python3 experiments/stability_map.py` (`--quick` for the coarse "
             "grid). A cantilever under gravity released from rest, every integrator and material "
             "over Young's modulus × time step; the dashed line is the run's stable-step estimate "
             "(the explicit integrators' element bound).", ""]
    lines += outcome_table(table)
    lines += ["", "![stability map](stability_map.png)", ""]
    source = os.path.join(folder, "stability_compression.png")
    table = os.path.join(folder, "stability_compression.csv")
    if os.path.exists(source) and os.path.exists(table):
        shutil.copyfile(source, os.path.join(out, "stability_compression.png"))
        lines += ["### Over compression", "",
                  "Command: `/usr/bin/python3 experiments/stability_map.py --axis compression` "
                  "(`--quick` for the coarse grid). A 0.1 m cube (E = 1 MPa, ν = 0.45) on a fixed "
                  "base, its clamped top face pushed down to the compression ratio (final height / "
                  "rest height) over 0.2 s and held for 0.1 s, every integrator and material over "
                  "compression ratio × time step. StVK's resistance to compression peaks at a "
                  "stretch of 1/√3 and falls to zero beyond, so strong compression inverts its "
                  "elements whatever the step; stable neo-Hookean's peaks at a stretch that "
                  "falls with ν (0.38 at ν = 0.3, 0.15 at ν = 0.45), so at ν = 0.45 it holds "
                  "the cube at a fifth of its height.", ""]
        lines += outcome_table(table)
        lines += ["", "![stability over compression](stability_compression.png)", ""]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("specs", nargs="*")
    parser.add_argument("--results", default=os.path.join(REPO, "out", "experiments"))
    parser.add_argument("--out", default=os.path.join(REPO, "experiments", "results"))
    parser.add_argument("--strata", default=os.environ.get("STRATA") or os.path.join(
        REPO, "build", "experiments", "cli", "strata"))
    parser.add_argument("--local-load", default="block_poke,slab_press_tolerance,"
                        "slab_press_dynamic_tolerance",
                        help="comma-separated sweep names held to the 5x target")
    parser.add_argument("--stability", help="folder of a stability_map.py run to include")
    parser.add_argument("--bending", default="bar_twist,bracket_plastic,cantilever_gravity,"
                        "cantilever_tip_poke,thin_slab_poke",
                        help="comma-separated sweep names held to 'never slower than full'")
    args = parser.parse_args()
    if args.specs:
        names = []
        for spec in args.specs:
            with open(spec) as f:
                names.append(json.load(f).get("name", os.path.splitext(os.path.basename(spec))[0]))
    else:
        names = sorted(d for d in os.listdir(args.results)
                       if os.path.exists(os.path.join(args.results, d, "results.json"))) \
            if os.path.isdir(args.results) else []
    if not names:
        sys.exit(f"report: no results.json under {args.results} (run experiment.py first)")
    local_load = set(args.local_load.split(","))
    bending = set(args.bending.split(","))
    os.makedirs(args.out, exist_ok=True)
    lines = ["# strata experiments: cost against accuracy", "",
             f"Generated {datetime.date.today().isoformat()} by `experiments/report.py` from the "
             f"sweeps of `experiments/experiment.py` (strata {version(args.strata)}; report "
             f"built at commit {commit()}).", "", f"Machine: {machine()}. Times are wall times of one run each "
             "on a shared machine: compare them as ratios within one sweep.", "",
             "Error = the largest probe-displacement difference to the full-resolution run over "
             "every frame and probe, relative to the largest full-resolution probe displacement "
             "(what `hierarchy.tolerance` bounds). Estimated = the run's own estimate "
             "(`hierarchy.estimated_error`); effectivity = estimated / true. Surface RMS (scenes "
             "with a fine surface) = the largest over the frames of the RMS distance between the "
             "run's fine surface and the full run's, relative to the surface's bounding-box "
             "diagonal.", "",
             "## Headline", "",
             "| scene | speed-up at τ = 0.01 (error) | cheapest run within 1 % error | target |",
             "|---|---|---|---|"]
    sections = []
    for name in names:
        path = os.path.join(args.results, name, "results.json")
        if not os.path.exists(path):
            sys.exit(f"report: {path} missing (run experiment.py on that spec)")
        with open(path) as f:
            data = json.load(f)
        runs = data["runs"]
        default, cheapest = headline(runs)
        notes = []
        reasons = []
        if name in local_load:
            if cheapest is None or cheapest.get("speedup", 0) < 5:
                notes.append("**missed**: no run within 1 % error is 5× cheaper than full "
                             "resolution")
                if cheapest is not None:
                    reasons.append(f"Why the 5× target is missed: the cheapest run within 1 % "
                                   f"({cheapest['run']}, {cheapest.get('speedup', 0):.2f}×): "
                                   + why_missed(runs, cheapest))
            else:
                notes.append("met (≥ 5× within 1 %)")
        if name in bending:
            if default is not None and default.get("speedup", 0) < 1:
                notes.append(f"**missed**: slower than full resolution at τ = "
                             f"{DEFAULT_TOLERANCE:g} ({default['speedup']:.2f}×)")
                reasons.append(f"Why {default['run']} is slower than full resolution: "
                               + why_missed(runs, default))
            elif default is not None:
                notes.append("met (not slower than full resolution)")
        for r in failed_cuts(runs):
            notes.append(f"**the precomputed cut fails on this load** ({r['run']}: "
                         f"{percent(r['error'])} error)")
        for r, u in dominated(runs):
            notes.append(f"**{r['run']} is beaten by {u['run']}** (error {percent(u['error'])} "
                         f"in {u['wall_seconds']:.1f} s)")
        lines.append(f"| {name} | " +
                     (f"{default.get('speedup', 0):.2f}× ({percent(default['error'])})"
                      if default else "–") + " | " +
                     (f"{cheapest['run']}: {cheapest.get('speedup', 0):.2f}× "
                      f"({percent(cheapest['error'])})" if cheapest else "none") + " | " +
                     ("; ".join(notes) or "–") + " |")
        target = os.path.join(args.out, name)
        os.makedirs(target, exist_ok=True)
        charts = []
        for chart in ("error_vs_cost.png", "adaptive_over_time.png", "pictures.png",
                      "surface.png", "variants.png", "animation.gif"):
            source = os.path.join(args.results, name, chart)
            if os.path.exists(source):
                shutil.copyfile(source, os.path.join(target, chart))
                charts.append(f"![{chart}]({name}/{chart})")
        overrides = " ".join(f"--set {k}={json.dumps(v)}" for k, v in data.get("set", {}).items())
        section = [f"## {name}", "", f"Scene: `{os.path.relpath(data['scene'], REPO)}`, "
                   f"{data['levels']} levels. Command: `/usr/bin/python3 experiments/experiment.py "
                   f"experiments/specs/{name}.json {overrides}`".rstrip() + "", "",
                   "| run | status | error | surface RMS | energy diff. | estimated | effectivity | "
                   "wall s | speed-up | largest DOFs | Newton its | CG its | cut changes | "
                   "redone steps |",
                   "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in runs:
            effectivity = f"{r['effectivity']:.2f}" if r.get("effectivity") is not None else "–"
            section.append(f"| {r['run']} | {r['status']} | {percent(r.get('error'))} | "
                           f"{percent(r.get('surface_error'))} | "
                           f"{percent(r.get('energy_difference'))} | "
                           f"{percent(r.get('estimated_error'))} | {effectivity} | ")
            speedup = f"{r['speedup']:.2f}×" if r.get("speedup") is not None else "–"
            section[-1] += (f"{r['wall_seconds']:.2f} | {speedup} | "
                            f"{r.get('max_dofs', '–')} | {r.get('newton_iterations', '–')} | "
                            f"{r.get('linear_iterations', '–')} | {r.get('cut_changes', '–')} | "
                            f"{r.get('redone_steps', '–')} |")
        for r in runs:
            if r.get("kind") == "precomputed" and r.get("training_seconds") is not None:
                section.append(f"\n{r['run']}: the cut of `strata precompute --windows "
                               f"{r['windows']}` over the spec's training loads (none of them the "
                               f"load above), recorded in {r['training_seconds']:.1f} s once.")
        for r in runs:
            if r["status"] != "ok":
                message = (r.get("message") or "").strip()
                section.append(f"\n**{r['run']} did not finish** ({r['status']})" +
                               (f": {message}" if message else "") + ". It has no error "
                               "against full resolution and no speed-up (its frames stop at the "
                               "failure), and is left out of the charts.")
        for r in failed_cuts(runs):
            flagged = ("its own estimate flagged it (`tolerance_met: false`, a warning)"
                       if r.get("tolerance_met") is False else
                       "its own estimate did not flag it")
            section.append(f"\n**{r['run']} fails on this load**: {percent(r['error'])} error "
                           f"against the {percent(r['recorded_tolerance'])} the cut was recorded "
                           f"at; {flagged}. The training loads did not refine where this load "
                           "acts, so the cut is coarse there: precompute with loads like this "
                           "one, or run adaptively.")
        for reason in reasons:
            section.append(f"\n{reason}")
        section += [""] + charts + [""]
        sections.append("\n".join(section))
    lines += ["", "Targets: adaptive at least 5× cheaper than full resolution at ≤ 1 % error on the "
              f"local-load scenes ({', '.join(sorted(local_load))}); never slower than full "
              f"resolution on the bending-dominated ones ({', '.join(sorted(bending))}); no uniform "
              "level cheaper at equal or smaller error than an adaptive run. A miss is stated in "
              "the table.", ""]
    if args.stability:
        sections.append(stability_section(args.stability, args.out))
    report = "\n".join(lines) + "\n" + "\n".join(sections)
    temporary = os.path.join(args.out, "REPORT.md.part")
    with open(temporary, "w") as f:
        f.write(report)
    os.replace(temporary, os.path.join(args.out, "REPORT.md"))
    print(f"report: wrote {os.path.join(args.out, 'REPORT.md')} ({len(names)} scenes)")


if __name__ == "__main__":
    main()
