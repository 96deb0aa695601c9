#!/usr/bin/python3
"""Cost against accuracy of one scene: full resolution, every uniform level, adaptive sweeps.

  experiment.py SPEC.json [--out DIR] [--strata PATH] [--jobs N] [--list] [--only RUN]
                          [--report-only] [--threads N] [--set key.path=value ...]

SPEC.json (paths relative to the spec file):

  {"name": "slab_press_dynamic",                      # folder name under --out
   "scene": "../scenes/slab_press_dynamic_tolerance.json",   # must have a "hierarchy" key
   "tolerances": [0.05, 0.02, 0.01, 0.005],           # adaptive runs, hierarchy.tolerance
   "uniform_levels": "all",                           # or a list of levels below hierarchy.levels
   "set": {"solver.duration": 0.04},                  # overrides applied to every run (optional)
   "quick": {"set": {...}, "tolerances": [...],       # the short version run with --quick
             "variants": [...]},                       # (the variants it keeps; default all)
   "variants": [{"name": "springs",                   # further runs compared with the full one
                 "scene": "../scenes/other.json",     # optional: another scene (same probes
                 "set": {...}}],                      #   and frames), optional overrides
   "precomputed": {"train": [{"name": "left",         # cuts recorded by `strata precompute` from
                              "set": {...}}],         #   the scene under other loads (overrides
                   "windows": [1, 4],                 #   on top of the spec's), played back on
                   "tolerance": 0.005}}               #   the spec's scene: one run per window count

A variant is one more run, `variant-NAME`, charted as a point of its own: another model of the
same scene (e.g. surface springs in place of element plasticity, on a scene without a hierarchy)
measured against the same full-resolution run.

Precomputed runs, `precomputed-wK`: the training scenes (the spec's scene with each `train` entry's
overrides; relative paths in them are made absolute) are run once by `strata precompute --windows K
--tolerance T` (T default: half of 0.01), and the spec's scene runs on the cut in hierarchy mode
"precomputed" — a load the training did not see. The training cost is reported beside the run
(`training_seconds`).

Every run uses the scene's time stepping unchanged. Per run the sweep records wall and CPU time
(of the strata process), element evaluations, Newton and CG iterations, the largest active tets
and DOFs, cut changes, redone steps, the run's own estimated error and the error against full
resolution: the largest probe-displacement difference over every frame and probe, relative to the
largest full-resolution probe displacement (what hierarchy.tolerance bounds), and the difference of
the final energies (elastic, kinetic, external potential; the largest, relative to the largest of
the full run's). It writes
OUT/NAME/results.csv, results.json and the charts error_vs_cost.png and adaptive_over_time.png.

Resuming: each run lives in OUT/NAME/runs/<run>-<hash>/, the hash taken over the scene file's
bytes, the spec's overrides and the run's settings; `run.json` is written there last, after the
run's outputs are complete, and a run with a `run.json` is skipped. A killed sweep therefore
resumes where it stopped, and changing the scene or the overrides starts afresh.

Spreading runs: --jobs N runs N at once (each with cores/N threads); --list prints one command
per run (`experiment.py SPEC --only RUN`) for a scheduler (a Slurm job array, GNU parallel), and
--report-only builds the tables and charts from whatever runs have finished.
"""
import argparse
import concurrent.futures
import csv
import hashlib
import json
import os
import re
import shlex
import subprocess
import sys
import threading
import time
import xml.etree.ElementTree as ElementTree

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "experiments", "hierarchy"))
from compare_to_full import read_probes  # noqa: E402  (probes.csv keyed by (time, probe))
sys.path.insert(0, HERE)
import vtk_xml  # noqa: E402  (strata's .vtu/.vtp frames)


def fail(message):
    sys.exit(f"experiment: {message}")


def load_spec(path, quick=False):
    try:
        with open(path) as f:
            spec = json.load(f)
    except (OSError, json.JSONDecodeError) as error:
        fail(f"{path}: {error}")
    for key in spec:
        if key not in ("name", "scene", "tolerances", "uniform_levels", "set", "quick",
                       "variants", "pictures", "precomputed"):
            fail(f"{path}: unknown key '{key}' (valid: name, scene, tolerances, uniform_levels, "
                 "set, quick, variants, pictures, precomputed)")
    if "scene" not in spec:
        fail(f"{path}: 'scene' is required")
    spec["scene"] = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)),
                                                  spec["scene"]))
    spec.setdefault("name", os.path.splitext(os.path.basename(path))[0])
    spec.setdefault("tolerances", [0.05, 0.02, 0.01, 0.005])
    spec.setdefault("uniform_levels", "all")
    spec.setdefault("set", {})
    if not isinstance(spec["set"], dict):
        fail(f"{path}: 'set' must be an object of key.path: value")
    if quick:
        block = spec.get("quick", {})
        for key in block:
            if key not in ("set", "tolerances", "variants"):
                fail(f"{path}: quick: unknown key '{key}' (valid: set, tolerances, variants)")
        spec["set"] = {**spec["set"], **block.get("set", {})}
        spec["tolerances"] = block.get("tolerances", spec["tolerances"])
        if "variants" in block:  # the variants the short version keeps (default: all)
            keep = block["variants"]
            if not isinstance(keep, list) or not all(isinstance(v, str) for v in keep):
                fail(f"{path}: quick.variants: an array of variant names")
            spec["variants"] = [v for v in spec.get("variants", []) if v.get("name") in keep]
    for i, tolerance in enumerate(spec["tolerances"]):
        if not isinstance(tolerance, (int, float)) or not 0 < tolerance < 1:
            fail(f"{path}: tolerances.{i}: must be a number in (0, 1)")
    try:
        with open(spec["scene"], "rb") as f:
            spec["scene_bytes"] = f.read()
        scene = json.loads(spec["scene_bytes"])
    except (OSError, json.JSONDecodeError) as error:
        fail(f"{path}: scene: {error}")
    if "hierarchy" not in scene:
        fail(f"{path}: scene {spec['scene']} has no 'hierarchy' key")
    levels = spec["set"].get("hierarchy.levels", scene["hierarchy"].get("levels", 2))
    if spec["uniform_levels"] == "all":
        spec["uniform_levels"] = list(range(levels))
    for i, level in enumerate(spec["uniform_levels"]):
        if not isinstance(level, int) or not 0 <= level < levels:
            fail(f"{path}: uniform_levels.{i}: must be an integer in 0..{levels - 1}")
    spec["levels"] = levels
    variants = spec.get("variants", [])
    if not isinstance(variants, list):
        fail(f"{path}: variants: must be an array")
    names = set()
    for i, variant in enumerate(variants):
        where = f"{path}: variants.{i}"
        if not isinstance(variant, dict):
            fail(f"{where}: must be an object")
        for key in variant:
            if key not in ("name", "scene", "set"):
                fail(f"{where}: unknown key '{key}' (valid: name, scene, set)")
        name = variant.get("name")
        if not isinstance(name, str) or not re.fullmatch(r"[a-z0-9_.-]+", name):
            fail(f"{where}.name: required, letters a-z, digits, '_', '-', '.'")
        if name in names:
            fail(f"{where}.name: '{name}' appears twice")
        names.add(name)
        variant.setdefault("set", {})
        if not isinstance(variant["set"], dict):
            fail(f"{where}.set: must be an object of key.path: value")
        if "scene" in variant:
            variant["scene"] = os.path.normpath(
                os.path.join(os.path.dirname(os.path.abspath(path)), variant["scene"]))
            try:
                with open(variant["scene"], "rb") as f:
                    variant["scene_bytes"] = f.read()
                json.loads(variant["scene_bytes"])
            except (OSError, json.JSONDecodeError) as error:
                fail(f"{where}.scene: {error}")
    spec["variants"] = variants
    precomputed = spec.get("precomputed")
    if precomputed is not None:
        where = f"{path}: precomputed"
        if not isinstance(precomputed, dict):
            fail(f"{where}: must be an object")
        for key in precomputed:
            if key not in ("train", "windows", "tolerance"):
                fail(f"{where}: unknown key '{key}' (valid: train, windows, tolerance)")
        train = precomputed.get("train")
        if not isinstance(train, list) or not train:
            fail(f"{where}.train: a non-empty array of {{name, set}}")
        names = set()
        for i, entry in enumerate(train):
            if not isinstance(entry, dict) or set(entry) - {"name", "set"}:
                fail(f"{where}.train.{i}: an object with name and set")
            name = entry.get("name")
            if not isinstance(name, str) or not re.fullmatch(r"[a-z0-9_.-]+", name) \
                    or name in names:
                fail(f"{where}.train.{i}.name: required, unique, letters a-z, digits, '_-.'")
            names.add(name)
            entry.setdefault("set", {})
            if not isinstance(entry["set"], dict):
                fail(f"{where}.train.{i}.set: must be an object of key.path: value")
        windows = precomputed.setdefault("windows", [1])
        if not isinstance(windows, list) or not windows or \
                not all(isinstance(k, int) and k >= 1 for k in windows):
            fail(f"{where}.windows: an array of integers >= 1")
        tolerance = precomputed.setdefault("tolerance", 0.005)
        if not isinstance(tolerance, (int, float)) or not 0 < tolerance < 1:
            fail(f"{where}.tolerance: a number in (0, 1)")
    pictures = spec.get("pictures")
    if pictures is not None:
        where = f"{path}: pictures"
        if not isinstance(pictures, dict):
            fail(f"{where}: must be an object")
        for key in pictures:
            if key not in ("run", "frames", "titles", "fields", "exaggerate", "view", "up",
                           "gif"):
                fail(f"{where}: unknown key '{key}' (valid: run, frames, titles, fields, "
                     "exaggerate, view, up, gif)")
        if pictures.get("run") not in [r[0] for r in planned_runs(spec)]:
            fail(f"{where}.run: must name a run of the sweep (see --list)")
        frames = pictures.setdefault("frames", [1.0])
        if not frames or not all(isinstance(f, (int, float)) and 0 <= f <= 1 for f in frames):
            fail(f"{where}.frames: fractions of the run in [0, 1]")
        titles = pictures.setdefault("titles", [f"{f:g} of the run" for f in frames])
        if len(titles) != len(frames):
            fail(f"{where}.titles: one per frame")
        pictures.setdefault("fields", ["von_mises"])
        pictures.setdefault("exaggerate", 1.0)
        pictures.setdefault("view", [22.0, -60.0])
        if pictures.setdefault("up", "z") not in ("x", "y", "z"):
            fail(f"{where}.up: one of \"x\", \"y\", \"z\"")
        gif = pictures.get("gif")
        if gif is not None and not isinstance(gif, str):
            fail(f"{where}.gif: the field to animate (e.g. \"level\")")
    return spec


def has_fine_surface(spec):
    """Whether the spec's scene simulates a fine surface (mesh.surface): its runs then write the
    surface frames (output.vtk "surface") for the fine-surface error."""
    return "surface" in json.loads(spec["scene_bytes"]).get("mesh", {})


def planned_runs(spec):
    """(name, kind, settings) of every run of the sweep, the reference first."""
    runs = planned_runs_of(spec)
    if has_fine_surface(spec):
        for _, _, settings in runs:
            settings["output.vtk"] = "surface"
    return runs


def planned_runs_of(spec):
    runs = [("full", "full", {"hierarchy.mode": "full"})]
    for level in spec["uniform_levels"]:
        runs.append((f"uniform-{level}", "uniform",
                     {"hierarchy.mode": "uniform", "hierarchy.level": level}))
    for tolerance in spec["tolerances"]:
        runs.append((f"adaptive-{tolerance:g}", "adaptive",
                     {"hierarchy.mode": "adaptive", "hierarchy.tolerance": tolerance}))
    for variant in spec["variants"]:
        settings = dict(variant["set"])
        if "scene" in variant:
            settings[SCENE_KEY] = variant["scene"]
        runs.append((f"variant-{variant['name']}", "variant", settings))
    precomputed = spec.get("precomputed")
    for windows in (precomputed or {}).get("windows", []):
        runs.append((f"precomputed-w{windows}", "precomputed",
                     {"hierarchy.mode": "precomputed", WINDOWS_KEY: windows,
                      TRAIN_KEY: {"train": precomputed["train"],
                                  "tolerance": precomputed["tolerance"]}}))
    return runs


# A run's own scene file (variants), carried among its settings.
SCENE_KEY = "@scene"
# Precomputed runs: the window count and the training set, carried among the settings (so that
# the run folder's hash covers them); the cut file is made from them before the run.
WINDOWS_KEY = "@windows"
TRAIN_KEY = "@train"
# Scene keys holding file paths, relative to the scene's folder.
PATH_KEYS = (("mesh", "file"), ("mesh", "surface"), ("mesh", "level_set"))


def set_path(tree, path, value):
    """Sets a dotted key path in a JSON tree (numeric parts index arrays), as strata's --set."""
    parts = path.split(".")
    node = tree
    for i, part in enumerate(parts):
        last = i + 1 == len(parts)
        if isinstance(node, list):
            index = int(part)
            if index == len(node):
                node.append(value if last else {})
            elif last:
                node[index] = value
            node = node[index]
        else:
            if last:
                node[part] = value
            else:
                node = node.setdefault(part, {})


def cut_folder(args, spec, settings):
    """Where the cut of a precomputed run and its training runs live."""
    digest = hashlib.sha256()
    digest.update(spec["scene_bytes"])
    digest.update(json.dumps([spec["set"], settings[TRAIN_KEY], settings[WINDOWS_KEY]],
                             sort_keys=True).encode())
    return os.path.join(args.out, spec["name"], "cuts",
                        f"w{settings[WINDOWS_KEY]}-{digest.hexdigest()[:12]}")


def cut_for(args, spec, settings, threads):
    """The cut file of a precomputed run, made by `strata precompute` unless it exists."""
    training = settings[TRAIN_KEY]
    windows = settings[WINDOWS_KEY]
    folder = cut_folder(args, spec, settings)
    cut = os.path.join(folder, "cut.json")
    if os.path.exists(cut) and os.path.exists(os.path.join(folder, "precompute.json")):
        return cut
    os.makedirs(folder, exist_ok=True)
    base = json.loads(spec["scene_bytes"])
    scene_folder = os.path.dirname(spec["scene"])
    for keys in PATH_KEYS:
        node = base
        for key in keys[:-1]:
            node = node.get(key, {})
        if isinstance(node.get(keys[-1]), str) and not os.path.isabs(node[keys[-1]]):
            node[keys[-1]] = os.path.join(scene_folder, node[keys[-1]])
    scenes = []
    for entry in training["train"]:
        scene = json.loads(json.dumps(base))
        for key, value in list(spec["set"].items()) + list(entry["set"].items()):
            set_path(scene, key, value)
        scene_path = os.path.join(folder, f"{entry['name']}.json")
        with open(scene_path, "w") as f:
            json.dump(scene, f, indent=1)
        scenes.append(scene_path)
    command = [args.strata, "precompute", *scenes, "--out", cut, "--windows", str(windows),
               "--tolerance", repr(training["tolerance"]), "--quiet"]
    if threads > 0:
        command += ["--threads", str(threads)]
    start = time.monotonic()
    result = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    if result.returncode != 0:
        raise RuntimeError(f"strata precompute failed: {result.stderr.decode(errors='replace')}")
    with open(os.path.join(folder, "precompute.json"), "w") as f:
        json.dump({"command": command, "wall_seconds": time.monotonic() - start}, f, indent=1)
    return cut


# strata rewrites this file in a run's folder with "<fraction done> <seconds elapsed>".
PROGRESS_FILE = "progress.txt"


def run_eta(folder):
    """(fraction done, seconds left) of a running run from its progress file, or None."""
    try:
        with open(os.path.join(folder, PROGRESS_FILE)) as f:
            fraction, elapsed = (float(v) for v in f.read().split())
    except (OSError, ValueError):
        return None
    if fraction <= 0.0:
        return None
    return fraction, elapsed * (1.0 - fraction) / fraction


def scene_of(spec, settings):
    return settings.get(SCENE_KEY, spec["scene"])


def run_folder(args, spec, name, settings):
    digest = hashlib.sha256()
    digest.update(spec["scene_bytes"])
    digest.update(json.dumps(spec["set"], sort_keys=True).encode())
    digest.update(json.dumps(settings, sort_keys=True).encode())
    if SCENE_KEY in settings:
        with open(settings[SCENE_KEY], "rb") as f:
            digest.update(f.read())
    return os.path.join(args.out, spec["name"], "runs", f"{name}-{digest.hexdigest()[:12]}")


def command_for(args, spec, folder, settings, threads):
    command = [args.strata, "run", scene_of(spec, settings), "--out", folder, "--quiet",
               "--progress-file", os.path.join(folder, PROGRESS_FILE), "--set", "output.vtk=false"]
    if threads > 0:
        command += ["--threads", str(threads)]
    for key, value in list(spec["set"].items()) + list(settings.items()):
        if key in (SCENE_KEY, WINDOWS_KEY, TRAIN_KEY):
            continue
        command += ["--set", f"{key}={json.dumps(value)}"]
    if WINDOWS_KEY in settings:
        command += ["--set", f"hierarchy.cut={json.dumps(os.path.abspath(cut_for(args, spec, settings, threads)))}"]
    return command


def execute(args, spec, name, settings, threads):
    """Runs one configuration unless it has finished before; returns its run.json record."""
    folder = run_folder(args, spec, name, settings)
    marker = os.path.join(folder, "run.json")
    if os.path.exists(marker):
        with open(marker) as f:
            return json.load(f)
    os.makedirs(folder, exist_ok=True)
    try:
        command = command_for(args, spec, folder, settings, threads)
    except RuntimeError as error:
        return {"name": name, "settings": settings, "returncode": -1, "wall_seconds": 0.0,
                "cpu_seconds": 0.0, "stderr": str(error)[-2000:]}
    try:  # a killed earlier attempt's progress would show as this run's
        os.remove(os.path.join(folder, PROGRESS_FILE))
    except FileNotFoundError:
        pass
    start = time.monotonic()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    stderr_text = []
    reader = threading.Thread(target=lambda: stderr_text.append(process.stderr.read()))
    reader.start()
    _, status, usage = os.wait4(process.pid, 0)
    reader.join()
    process.returncode = os.waitstatus_to_exitcode(status)
    record = {"name": name, "settings": settings, "command": command,
              "returncode": process.returncode, "wall_seconds": time.monotonic() - start,
              "cpu_seconds": usage.ru_utime + usage.ru_stime,
              "system_seconds": usage.ru_stime,
              "stderr": stderr_text[0].decode(errors="replace")[-2000:] if stderr_text else ""}
    if process.returncode == 0 and not os.path.exists(os.path.join(folder, "stats.json")):
        record["returncode"] = -1
        record["stderr"] += "\nno stats.json written"
    # run.json last and atomically: its presence means the outputs are complete.
    temporary = marker + ".part"
    with open(temporary, "w") as f:
        json.dump(record, f, indent=1)
    os.replace(temporary, marker)
    return record


def draw_pictures(args, spec):
    """Re-runs the spec's picture run with .vtu frames (once; kept like a run) and renders them
    into OUT/NAME/pictures.png."""
    pictures = spec.get("pictures")
    if not pictures:
        return
    name = pictures["run"]
    settings = next(r[2] for r in planned_runs(spec) if r[0] == name)
    folder = run_folder(args, spec, name, settings).replace(
        os.path.join(spec["name"], "runs"), os.path.join(spec["name"], "pictures"))
    marker = os.path.join(folder, "run.json")
    if not os.path.exists(marker):
        os.makedirs(folder, exist_ok=True)
        command = command_for(args, spec, folder, settings, args.threads) + [
            "--set", "output.vtk=true"]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            print(f"experiment: the picture run failed: {result.stderr.strip()[-300:]}",
                  file=sys.stderr)
            return
        with open(marker + ".part", "w") as f:
            json.dump({"command": command}, f)
        os.replace(marker + ".part", marker)
    frames = sorted(f for f in os.listdir(folder) if re.fullmatch(r".*_\d{6}\.vtu", f))
    if not frames:
        print("experiment: the picture run wrote no .vtu frames", file=sys.stderr)
        return
    chosen = [os.path.join(folder, frames[round(f * (len(frames) - 1))])
              for f in pictures["frames"]]
    command = [sys.executable, os.path.join(HERE, "render.py"), *chosen,
               "--out", os.path.join(args.out, spec["name"], "pictures.png"),
               "--fields", ",".join(pictures["fields"]),
               "--exaggerate", str(pictures["exaggerate"]),
               "--view", *[str(v) for v in pictures["view"]], "--up", pictures["up"],
               "--titles", *pictures["titles"]]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        print(f"experiment: rendering failed: {result.stderr.strip()[-300:]}", file=sys.stderr)
    # The bound fine surface at the same frames, coloured by its displacement.
    surfaces = sorted(f for f in os.listdir(folder) if re.fullmatch(r".*_surface_\d{6}\.vtp", f))
    if len(surfaces) == len(frames):
        chosen = [os.path.join(folder, surfaces[round(f * (len(surfaces) - 1))])
                  for f in pictures["frames"]]
        command = [sys.executable, os.path.join(HERE, "render.py"), *chosen,
                   "--out", os.path.join(args.out, spec["name"], "surface.png"),
                   "--fields", "displacement", "--exaggerate", str(pictures["exaggerate"]),
                   "--view", *[str(v) for v in pictures["view"]], "--up", pictures["up"],
                   "--titles", *[f"{t}, fine surface" for t in pictures["titles"]]]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            print(f"experiment: rendering the fine surface failed: "
                  f"{result.stderr.strip()[-300:]}", file=sys.stderr)
    if pictures.get("gif"):
        series = [f for f in os.listdir(folder) if f.endswith(".pvd")]
        if not series:
            print("experiment: the picture run wrote no .pvd series", file=sys.stderr)
            return
        command = [sys.executable, os.path.join(HERE, "render.py"),
                   os.path.join(folder, series[0]),
                   "--gif", os.path.join(args.out, spec["name"], "animation.gif"),
                   "--fields", pictures["gif"], "--exaggerate", str(pictures["exaggerate"]),
                   "--view", *[str(v) for v in pictures["view"]], "--up", pictures["up"]]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            print(f"experiment: the animation failed: {result.stderr.strip()[-300:]}",
                  file=sys.stderr)


def draw_variant_pictures(args, spec):
    """The full run's fine surface beside each variant's surface at the last frame, coloured by
    the displacement on one scale, into OUT/NAME/variants.png (skipped when the runs wrote no
    surface frames)."""
    chosen, titles = [], []
    for name, _kind, settings in planned_runs(spec):
        if name != "full" and not name.startswith("variant-"):
            continue
        frames = surface_frames(run_folder(args, spec, name, settings))
        if frames:
            chosen.append(frames[-1])
            titles.append("tet model, full resolution" if name == "full"
                          else name[len("variant-"):])
    picture = os.path.join(args.out, spec["name"], "variants.png")
    if os.path.exists(picture):
        os.remove(picture)
    if len(chosen) < 2 or titles[0] != "tet model, full resolution":
        return
    pictures = spec.get("pictures", {})
    command = [sys.executable, os.path.join(HERE, "render.py"), *chosen,
               "--out", picture,
               "--fields", "displacement", "--exaggerate", str(pictures.get("exaggerate", 1.0)),
               "--view", *[str(v) for v in pictures.get("view", [22.0, -60.0])],
               "--up", pictures.get("up", "z"), "--titles", *[f"{t}, end" for t in titles]]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        print(f"experiment: rendering the variants failed: {result.stderr.strip()[-300:]}",
              file=sys.stderr)


def error_against(reference, frames):
    """(largest |Δu| over frames and probes / largest |u_ref|, per-time errors) or None."""
    scale = max((sum(c * c for c in u) ** 0.5 for u in reference.values()), default=0.0)
    if scale == 0.0 or not frames:
        return None, {}
    worst, per_time = 0.0, {}
    for key, u_ref in reference.items():
        if key not in frames:
            return None, {}
        d = sum((a - b) ** 2 for a, b in zip(frames[key], u_ref)) ** 0.5 / scale
        worst = max(worst, d)
        per_time[key[0]] = max(per_time.get(key[0], 0.0), d)
    return worst, per_time


def summarise(args, spec):
    """Rows of every finished run, with errors against the full run when it has finished."""
    rows = []
    reference = None
    for name, kind, settings in planned_runs(spec):
        folder = run_folder(args, spec, name, settings)
        marker = os.path.join(folder, "run.json")
        if not os.path.exists(marker):
            continue
        with open(marker) as f:
            record = json.load(f)
        row = {"run": name, "kind": kind, "status": "failed" if record["returncode"] else "ok",
               "wall_seconds": record["wall_seconds"], "cpu_seconds": record["cpu_seconds"],
               "folder": os.path.relpath(folder, os.path.join(args.out, spec["name"]))}
        if kind == "uniform":
            row["level"] = settings["hierarchy.level"]
        if kind == "adaptive":
            row["tolerance"] = settings["hierarchy.tolerance"]
        if kind == "variant":
            row["variant"] = name[len("variant-"):]
        if kind == "precomputed":
            row["windows"] = settings[WINDOWS_KEY]
            record = os.path.join(cut_folder(args, spec, settings), "precompute.json")
            if os.path.exists(record):
                with open(record) as f:
                    row["training_seconds"] = json.load(f)["wall_seconds"]
        stats_path = os.path.join(folder, "stats.json")
        if os.path.exists(stats_path):
            with open(stats_path) as f:
                stats = json.load(f)
            hierarchy = stats.get("hierarchy", {})
            history = hierarchy.get("history", {})
            row.update({
                "status": stats.get("status", row["status"]),
                "message": stats.get("message", ""),
                "strata_wall_seconds": stats.get("wall_seconds"),
                "element_evaluations": stats.get("element_evaluations"),
                "newton_iterations": stats.get("newton_iterations"),
                "linear_iterations": stats.get("newton", {}).get("linear_iterations"),
                "linear_solver": stats.get("newton", {}).get("linear_solver"),
                "max_active_tets": max(history.get("tets") or [stats.get("tets", 0)]),
                "max_dofs": max(history.get("dofs") or [stats.get("dofs", 0)]),
                "cut_changes": len(hierarchy.get("changes", [])),
                "redone_steps": hierarchy.get("redone_steps", 0),
                # time the hierarchy spent beside the steps on the cut: cut changes, redone
                # steps, the initial adaptation
                "cut_change_seconds": sum(c.get("seconds", 0.0)
                                          for c in hierarchy.get("changes", [])),
                "redo_seconds": hierarchy.get("redo_seconds", 0.0),
                "initial_adaptation_seconds": hierarchy.get("initial_adaptation_seconds", 0.0),
                # the step after which an adaptive run went on at full resolution, or None
                "full_resolution_step": hierarchy.get("full_resolution_step"),
                "estimated_error": hierarchy.get("estimated_error"),
                "tolerance_met": hierarchy.get("tolerance_met"),
                "recorded_tolerance": hierarchy.get("precomputed", {}).get("recorded_tolerance"),
                "final_energies": stats.get("energies"),
                "history": {**{k: history.get(k, []) for k in ("time", "tets", "dofs",
                                                                "estimated_error")},
                            # cut changes: time, DOFs after, refined and coarsened nodes
                            "changes": [[c.get("time"), c.get("dofs_after"), c.get("refined", 0),
                                         c.get("coarsened", 0)]
                                        for c in hierarchy.get("changes", [])]},
            })
        has_probes = os.path.exists(os.path.join(folder, "probes.csv"))
        row["probes"] = read_probes(folder) if has_probes else {}
        row["surface_frames"] = surface_frames(folder)
        if name == "full" and row["status"] == "ok":
            reference = row["probes"]
        rows.append(row)
    for row in rows:
        error, per_time = (None, {}) if reference is None else error_against(reference,
                                                                             row["probes"])
        row["error"] = error
        row["error_over_time"] = sorted(per_time.items())
        del row["probes"]
    full = next((r for r in rows if r["run"] == "full"), None)
    if full is not None and full["surface_frames"]:
        for row in rows:
            row["surface_error"] = surface_error(full["surface_frames"], row["surface_frames"])
    for row in rows:
        del row["surface_frames"]
    for row in rows:
        # Final elastic, kinetic and external-potential energies against the full run's, relative
        # to the full run's largest of the three.
        if (full is not None and full.get("final_energies") and row.get("final_energies")
                and row["status"] == "ok"):
            reference = full["final_energies"]
            scale = max(abs(v) for v in reference.values())
            if scale > 0.0:
                row["energy_difference"] = max(abs(row["final_energies"].get(k, 0.0) - v)
                                               for k, v in reference.items()) / scale
        if full is not None and row.get("wall_seconds") and row["status"] == "ok":
            row["speedup"] = full["wall_seconds"] / row["wall_seconds"]
        if row.get("error") and row.get("estimated_error") is not None and row["kind"] == "adaptive":
            row["effectivity"] = row["estimated_error"] / row["error"]
    return rows


def surface_frames(folder):
    """The fine surface's .vtp frames of a run in frame order: `*_surface_NNNNNN.vtp` of a tet
    run, else part 0 of a skeleton-spring body's .pvd (the surface as given; part 1 is its
    skeleton, part 2 its simplified springs' surface)."""
    if not os.path.isdir(folder):
        return []
    names = sorted(os.listdir(folder))
    frames = [f for f in names if re.fullmatch(r".*_surface_\d{6}\.vtp", f)]
    if not frames:
        for pvd in (f for f in names if f.endswith(".pvd")):
            try:
                root = ElementTree.parse(os.path.join(folder, pvd)).getroot()
            except ElementTree.ParseError:
                continue
            frames += [d.get("file") for d in root.iter("DataSet")
                       if d.get("part", "0") == "0" and d.get("file", "").endswith(".vtp")]
    return [os.path.join(folder, f) for f in frames]


def vtp_points(path):
    """The points (n × 3) of a .vtp frame written by strata (binary or ASCII)."""
    return vtk_xml.read(path).points


def surface_error(reference, frames):
    """The largest RMS distance between the run's fine surface and the full run's over the
    frames, relative to the bounding-box diagonal of the full run's first frame; None when the
    frames do not match."""
    if len(frames) != len(reference) or not frames:
        return None
    worst, diagonal = 0.0, None
    for mine, theirs in zip(frames, reference):
        a, b = vtp_points(mine), vtp_points(theirs)
        if len(a) != len(b) or not a:
            return None
        if diagonal is None:
            lo = [min(p[k] for p in b) for k in range(3)]
            hi = [max(p[k] for p in b) for k in range(3)]
            diagonal = sum((h - l) ** 2 for h, l in zip(hi, lo)) ** 0.5
        squares = sum((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2
                      for p, q in zip(a, b))
        worst = max(worst, (squares / len(a)) ** 0.5)
    return worst / diagonal if diagonal else None


COLUMNS = ["run", "kind", "level", "tolerance", "variant", "windows", "training_seconds", "status",
           "message", "error", "surface_error", "energy_difference",
           "estimated_error",
           "effectivity", "tolerance_met", "wall_seconds", "cpu_seconds", "speedup",
           "max_active_tets", "max_dofs", "element_evaluations", "newton_iterations",
           "linear_iterations", "linear_solver", "cut_changes", "redone_steps", "folder"]


def write_results(args, spec, rows):
    folder = os.path.join(args.out, spec["name"])
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "results.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: row.get(k, "") for k in COLUMNS})
    with open(os.path.join(folder, "results.json"), "w") as f:
        json.dump({"scene": spec["scene"], "set": spec["set"], "levels": spec["levels"],
                   "runs": rows}, f, indent=1)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("experiment: matplotlib not found (run with /usr/bin/python3): no charts",
              file=sys.stderr)
        return
    ok = [r for r in rows if r["status"] == "ok" and r.get("error") is not None]
    # Panels (cost, error measure): the probe error against wall time and against DOFs, and on
    # scenes with a fine surface its RMS error against wall time.
    panels = [("wall_seconds", "wall time [s]", "error", "error vs full resolution"),
              ("max_dofs", "largest active DOFs", "error", "error vs full resolution")]
    if any(r.get("surface_error") is not None and r["run"] != "full" for r in ok):
        panels.append(("wall_seconds", "wall time [s]", "surface_error",
                       "fine-surface RMS vs full resolution"))
    figure, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4.2))
    for axis, (cost, label, measure, measure_label) in zip(axes, panels):
        with_measure = [r for r in ok if r.get(measure) is not None]
        for kind, style in (("uniform", "s-"), ("adaptive", "o-")):
            points = sorted(((r[cost], max(r[measure], 1e-6), r) for r in with_measure
                             if r["kind"] == kind), key=lambda p: (p[0], p[1]))
            if points:
                axis.plot([p[0] for p in points], [p[1] for p in points], style, label=kind)
                for x, y, r in points:
                    axis.annotate(f"L{r['level']}" if kind == "uniform" else f"τ={r['tolerance']:g}",
                                  (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        for r in (r for r in with_measure if r["kind"] == "variant" and r.get(cost)):
            axis.plot([r[cost]], [max(r[measure], 1e-6)], "D", label=r["variant"])
        for r in (r for r in with_measure if r["kind"] == "precomputed" and r.get(cost)):
            axis.plot([r[cost]], [max(r[measure], 1e-6)], "^", markersize=8,
                      label=f"precomputed, {r['windows']} window{'s' if r['windows'] > 1 else ''}")
        full = next((r for r in rows if r["run"] == "full"), None)
        if full is not None and full.get(cost):
            axis.axvline(full[cost], color="k", linestyle=":", label="full resolution")
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel(label)
        axis.set_ylabel(f"{measure_label} (below 1e-6: at 1e-6)")
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(fontsize=8)
    figure.suptitle(f"{spec['name']}: error against cost")
    figure.tight_layout()
    figure.savefig(os.path.join(folder, "error_vs_cost.png"), dpi=120)
    plt.close(figure)

    adaptive = [r for r in ok if r["kind"] == "adaptive" and r.get("history")]
    if adaptive:
        figure, panels = plt.subplots(1, 3, figsize=(15, 4.2))
        tets_axis, axes = panels[0], panels[1:]
        for r in adaptive:
            h = r["history"]
            tets_axis.plot(h["time"], h["tets"], label=f"τ={r['tolerance']:g}")
            line, = axes[0].plot(h["time"], h["dofs"], label=f"τ={r['tolerance']:g}")
            # The refinement events: ▲ where a cut change refined, ▼ where it only coarsened.
            for marker, events in (("^", [c for c in h.get("changes", []) if c[2] > 0]),
                                   ("v", [c for c in h.get("changes", []) if c[2] == 0])):
                if events:
                    axes[0].plot([c[0] for c in events], [c[1] for c in events], marker,
                                 color=line.get_color(), markersize=5, linestyle="none")
            times = [t for t, _ in r["error_over_time"]]
            axes[1].plot(times, [max(e, 1e-6) for _, e in r["error_over_time"]], "-",
                         color=line.get_color(), label=f"true, τ={r['tolerance']:g}")
            axes[1].plot(h["time"], [max(e, 1e-6) for e in h["estimated_error"]], "--",
                         color=line.get_color(), label=f"estimated, τ={r['tolerance']:g}")
        tets_axis.set_xlabel("time [s] (static: load factor)")
        tets_axis.set_ylabel("active tets")
        axes[0].set_xlabel("time [s] (static: load factor)")
        axes[0].set_ylabel("active DOFs (▲ refined, ▼ coarsened)")
        axes[1].set_xlabel("time [s] (static: load factor)")
        axes[1].set_ylabel("error")
        axes[1].set_yscale("log")
        for axis in panels:
            axis.grid(True, alpha=0.3)
            axis.legend(fontsize=7)
        figure.suptitle(f"{spec['name']}: adaptive runs over time")
        figure.tight_layout()
        figure.savefig(os.path.join(folder, "adaptive_over_time.png"), dpi=120)
        plt.close(figure)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("spec")
    parser.add_argument("--out", default=os.path.join(REPO, "out", "experiments"))
    parser.add_argument("--strata", default=os.environ.get("STRATA") or os.path.join(
        REPO, "build", "experiments", "cli", "strata"))
    parser.add_argument("--jobs", type=int, default=1, help="runs at once")
    parser.add_argument("--threads", type=int, default=0,
                        help="threads per run (default: cores / jobs)")
    parser.add_argument("--list", action="store_true", help="print one command per run")
    parser.add_argument("--only", help="run just this run (see --list)")
    parser.add_argument("--report-only", action="store_true",
                        help="tables and charts from the finished runs; run nothing")
    parser.add_argument("--quick", action="store_true",
                        help="the spec's short version: its 'quick' overrides and tolerances")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="an override for every run, added to the spec's (value as JSON)")
    args = parser.parse_args()
    spec = load_spec(args.spec, args.quick)
    for item in args.set:
        key, sep, value = item.partition("=")
        if not sep or not key:
            fail(f"--set {item}: expected key.path=value")
        try:
            spec["set"][key] = json.loads(value)
        except json.JSONDecodeError:
            spec["set"][key] = value
    runs = planned_runs(spec)
    if args.list:
        for name, _, _ in runs:
            command = [sys.executable, os.path.abspath(__file__), os.path.abspath(args.spec),
                       "--out", os.path.abspath(args.out), "--strata", args.strata, "--only", name]
            if args.quick:
                command.append("--quick")
            for item in args.set:
                command += ["--set", item]
            print(" ".join(shlex.quote(a) for a in command))
        return
    if args.only:
        runs = [r for r in runs if r[0] == args.only]
        if not runs:
            fail(f"--only {args.only}: no such run (see --list)")
    if args.jobs < 1:
        fail("--jobs must be >= 1")
    if not args.report_only:
        if not os.access(args.strata, os.X_OK):
            fail(f"{args.strata} is not an executable (build strata or pass --strata)")
        threads = args.threads or max(1, (os.cpu_count() or 1) // args.jobs)
        pending = [r for r in runs
                   if not os.path.exists(os.path.join(run_folder(args, spec, r[0], r[2]),
                                                      "run.json"))]
        done, durations, start = len(runs) - len(pending), [], time.monotonic()
        running = set()
        lock = threading.Lock()

        folders = {r[0]: run_folder(args, spec, r[0], r[2]) for r in runs}

        def progress():
            # Each running run: its share done and ETA from strata's progress file; the sweep's
            # ETA: the running runs' ETAs plus the mean duration of a finished run for each run
            # not started, spread over the jobs.
            # A run without an ETA yet (or no finished run to take a mean from) makes it "?";
            # it is never below the longest running run's ETA.
            shown, etas = [], []
            for name in sorted(running):
                eta = run_eta(folders[name])
                if eta is None:
                    shown.append(name)
                else:
                    shown.append(f"{name} {100 * eta[0]:.0f} % ETA {eta[1]:.0f} s")
                    etas.append(eta[1])
            mean = sum(durations) / len(durations) if durations else None
            waiting = len(runs) - done - len(running)
            if len(etas) == len(running) and (mean is not None or waiting == 0):
                left = (sum(etas) + (mean or 0.0) * waiting) / args.jobs
                eta = f"{max([left] + etas):.0f} s"
            else:
                eta = "?"
            print(f"\rexperiment {spec['name']}: {done}/{len(runs)} done, running "
                  f"{', '.join(shown) or '-'}; elapsed {time.monotonic() - start:.0f} s, "
                  f"sweep ETA {eta}\033[K", end="", file=sys.stderr, flush=True)

        def one(run):
            nonlocal done
            with lock:
                running.add(run[0])
                progress()
            record = execute(args, spec, run[0], run[2], threads)
            with lock:
                running.discard(run[0])
                done += 1
                durations.append(record["wall_seconds"])
                if record["returncode"] != 0:
                    print(f"\nexperiment: {run[0]} failed ({record['returncode']}): "
                          f"{record['stderr'].strip().splitlines()[-1:]}", file=sys.stderr)
                progress()

        finished = threading.Event()

        def ticker():  # redraws the line while runs go on, so that their ETAs move
            while not finished.wait(2.0):
                with lock:
                    if running:
                        progress()

        # On a terminal only: in a log every redraw would be a line of its own.
        watcher = threading.Thread(target=ticker, daemon=True) if sys.stderr.isatty() else None
        if watcher is not None:
            watcher.start()
        try:
            with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
                list(pool.map(one, pending))
        finally:
            finished.set()
            if watcher is not None:
                watcher.join()
        print(file=sys.stderr)
    if args.only:
        # One run of a spread sweep: the report is built once, with --report-only.
        print(f"experiment: {args.only} done; build the report with --report-only")
        return
    rows = summarise(args, spec)
    write_results(args, spec, rows)
    if not args.report_only:
        draw_pictures(args, spec)
        draw_variant_pictures(args, spec)
    for row in rows:
        error = "-" if row.get("error") is None else f"{100 * row['error']:.3g} %"
        estimate = row.get("estimated_error")
        estimate = "-" if estimate is None else f"{100 * estimate:.3g} %"
        print(f"{row['run']:>16}  {row['status']:>8}  error {error:>9}  estimated {estimate:>9}  "
              f"wall {row['wall_seconds']:7.2f} s  speed-up {row.get('speedup', 0):5.2f}x  "
              f"DOFs {row.get('max_dofs', '-')}")
    print(f"experiment: results in {os.path.join(args.out, spec['name'])}")


if __name__ == "__main__":
    main()
