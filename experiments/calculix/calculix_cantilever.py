"""Helper of cantilever_vs_calculix.sh: writes the CalculiX deck from strata's mesh, reads both
solvers' results and writes results.json / results.csv.

Run with Debian's /usr/bin/python3 (meshio, numpy):
  calculix_cantilever.py deck --vtu FRAME0.vtu --inp DECK.inp --mesh-json MESH.json \
      --scene SCENE.json
  calculix_cantilever.py summarize --out OUT
"""

import argparse
import csv
import json
import math
import os
import pathlib
import re
import statistics
import sys

import meshio
import numpy as np


def load_scene(path):
    with open(path) as f:
        return json.load(f)


def write_id_lines(out, ids, per_line=8):
    for start in range(0, len(ids), per_line):
        out.write(", ".join(str(i) for i in ids[start:start + per_line]) + "\n")


def cmd_deck(args):
    scene = load_scene(args.scene)
    box = scene["mesh"]["box"]
    lo = np.array(box["min"], dtype=float)
    hi = np.array(box["max"], dtype=float)
    material = scene["material"]
    gravity = np.array(scene["gravity"], dtype=float)
    load_steps = scene["solver"]["load_steps"]
    probe = np.array(scene["output"]["probes"][0], dtype=float)

    mesh = meshio.read(args.vtu)
    points = np.asarray(mesh.points, dtype=float)
    if "displacement" in mesh.point_data:  # the .vtu holds deformed points: frame 0 is the rest
        points = points - np.asarray(mesh.point_data["displacement"], dtype=float)
    tets = np.asarray(mesh.cells_dict["tetra"], dtype=np.int64)
    if tets.min() < 0 or tets.max() >= len(points):
        sys.exit("deck: tet vertex index out of range")

    # strata's tets are positive with det[x1-x0, x2-x0, x3-x0] > 0; CalculiX's C3D4 wants the
    # same (nodes 1-2-3 counter-clockwise seen from node 4). Swap the last two of any negative one.
    x = points[tets]
    det = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0])
    negative = det < 0
    if np.any(det == 0):
        sys.exit("deck: degenerate tets in strata's mesh")
    tets_ccx = tets.copy()
    tets_ccx[negative, 2], tets_ccx[negative, 3] = tets[negative, 3], tets[negative, 2]

    size = float(np.linalg.norm(hi - lo))
    tol = 1e-9 * size
    fixed = np.nonzero(np.abs(points[:, 0] - lo[0]) <= tol)[0]
    tip_distance = np.linalg.norm(points - probe, axis=1)
    tip = int(np.argmin(tip_distance))
    if tip_distance[tip] > tol:
        sys.exit(f"deck: no mesh node at the probe {probe.tolist()} (nearest at "
                 f"{tip_distance[tip]:.3g} m): NY and NZ must be even")

    g_norm = float(np.linalg.norm(gravity))
    direction = gravity / g_norm
    increment = 1.0 / load_steps
    with open(args.inp, "w") as out:
        out.write("** Cantilever under gravity, StVK (linear elastic + NLGEOM), mesh exported from "
                  "strata's box mesh.\n"
                  "** Written by calculix_cantilever.py (cantilever_vs_calculix.sh).\n"
                  "*HEADING\nstrata vs CalculiX cantilever\n")
        out.write("*NODE, NSET=Nall\n")
        for i, p in enumerate(points):
            out.write(f"{i + 1}, {p[0]!r}, {p[1]!r}, {p[2]!r}\n")
        out.write("*ELEMENT, TYPE=C3D4, ELSET=Eall\n")
        for e, t in enumerate(tets_ccx):
            out.write(f"{e + 1}, {t[0] + 1}, {t[1] + 1}, {t[2] + 1}, {t[3] + 1}\n")
        out.write("*NSET, NSET=Nfix\n")
        write_id_lines(out, [int(i) + 1 for i in fixed])
        out.write(f"*NSET, NSET=Ntip\n{tip + 1}\n")
        out.write("*BOUNDARY\nNfix, 1, 3\n")
        out.write("*MATERIAL, NAME=STVK\n*ELASTIC\n"
                  f"{material['youngs_modulus']!r}, {material['poisson_ratio']!r}\n"
                  f"*DENSITY\n{material['density']!r}\n")
        out.write("*SOLID SECTION, ELSET=Eall, MATERIAL=STVK\n")
        # INC: the maximum number of increments; DIRECT: fixed increments of 1/load_steps.
        out.write(f"*STEP, NLGEOM, INC=100\n*STATIC, DIRECT\n{increment!r}, 1.0\n")
        out.write(f"*DLOAD\nEall, GRAV, {g_norm!r}, {direction[0]!r}, {direction[1]!r}, "
                  f"{direction[2]!r}\n")
        out.write("*NODE PRINT, NSET=Ntip\nU\n*END STEP\n")

    volume = float(np.sum(np.abs(det)) / 6.0)
    info = {
        "nodes": int(len(points)),
        "tets": int(len(tets)),
        "fixed_nodes": int(len(fixed)),
        "tip_node": tip + 1,
        "tip_point": points[tip].tolist(),
        "reoriented_for_calculix": int(np.count_nonzero(negative)),
        "volume": volume,
    }
    with open(args.mesh_json, "w") as f:
        json.dump(info, f, indent=2)
    print(f"deck: {info['nodes']} nodes, {info['tets']} C3D4, {info['fixed_nodes']} fixed nodes, "
          f"tip node {tip + 1}, {info['reoriented_for_calculix']} tets reordered, "
          f"volume {volume:.6g} m^3")


# ---------------------------------------------------------------------------------------------
# Results


def read_time_file(path):
    """/usr/bin/time -f '%e %U %S %M' output (its last line; earlier lines may be warnings)."""
    lines = [line for line in pathlib.Path(path).read_text().splitlines() if line.strip()]
    fields = lines[-1].split()
    return {"time_wall_s": float(fields[0]), "user_s": float(fields[1]),
            "sys_s": float(fields[2]), "max_rss_kb": int(fields[3])}


def strata_result(run_dir):
    stats = json.loads((run_dir / "stats.json").read_text())
    rows = list(csv.DictReader(open(run_dir / "probes.csv")))
    rows = [r for r in rows if int(r["probe"]) == 0]
    last_time = max(float(r["time"]) for r in rows)
    last = [r for r in rows if float(r["time"]) == last_time][-1]
    return {
        "status": stats.get("status"),
        "iterations": stats["newton_iterations"],
        "steps": stats.get("steps"),
        "factorizations": stats.get("factorizations"),
        "internal_wall_s": stats.get("wall_seconds"),
        "final_load_factor": stats.get("final_load_factor"),
        "tets": stats.get("tets"),
        "tip": [float(last["ux"]), float(last["uy"]), float(last["uz"])],
        "binary_sha256": (run_dir / "strata.sha256").read_text().strip(),
    }


DAT_BLOCK = re.compile(r"displacements \(vx,vy,vz\) for set (\S+) and time\s+(\S+)")


def ccx_result(run_dir, job, tip_node):
    dat = (run_dir / f"{job}.dat").read_text().splitlines()
    blocks = []  # (time, {node: u})
    for i, line in enumerate(dat):
        m = DAT_BLOCK.search(line)
        if not m:
            continue
        values = {}
        for row in dat[i + 1:]:
            if DAT_BLOCK.search(row) or (row.strip() and not row.split()[0].isdigit()):
                break
            fields = row.split()
            if len(fields) == 4:
                values[int(fields[0])] = [float(v) for v in fields[1:]]
        blocks.append((float(m.group(2)), values))
    if not blocks:
        raise RuntimeError(f"{run_dir}/{job}.dat: no displacement block")
    time, values = blocks[-1]
    # .sta: one line per converged increment, "STEP INC ATT ITRS TOT-TIME STEP-TIME INC-TIME".
    increments = []
    for line in (run_dir / f"{job}.sta").read_text().splitlines():
        fields = line.split()
        if len(fields) >= 7 and all(f.isdigit() for f in fields[:4]):
            increments.append({"step": int(fields[0]), "increment": int(fields[1]),
                               "attempt": int(fields[2]), "iterations": int(fields[3]),
                               "total_time": float(fields[4])})
    stdout = (run_dir / "stdout.log").read_text()
    stdout_iterations = len(re.findall(r"^\s*iteration\s+\d+", stdout, re.MULTILINE))
    return {
        "status": "ok" if abs(time - 1.0) < 1e-9 else "incomplete",
        "iterations": sum(inc["iterations"] for inc in increments),
        "stdout_iteration_lines": stdout_iterations,
        "increments": len(increments),
        "iterations_per_increment": [inc["iterations"] for inc in increments],
        "final_time": time,
        "tip": values[tip_node],
    }


def cmd_summarize(args):
    out = pathlib.Path(args.out)
    meta = json.loads((out / "meta.json").read_text())
    mesh = json.loads((out / "mesh.json").read_text())
    runs = []
    for line in (out / "runs.tsv").read_text().splitlines():
        solver, run, run_dir, wall = line.split("\t")
        record = {"solver": solver, "run": int(run), "dir": run_dir}
        run_dir = out / run_dir
        record.update(read_time_file(run_dir / "time.txt"))
        record["wall_s"] = float(wall)
        # CPU time the rest of the machine used during the run: > 0 means disturbed timings.
        before, after = (int(v) for v in (run_dir / "busy_ticks.txt").read_text().split())
        busy = (after - before) / os.sysconf("SC_CLK_TCK")
        record["other_cpu_s"] = max(0.0, busy - record["user_s"] - record["sys_s"])
        if solver == "strata":
            record.update(strata_result(run_dir))
        else:
            record.update(ccx_result(run_dir, meta["ccx_job"], mesh["tip_node"]))
        runs.append(record)

    cells = "x".join(str(c) for c in meta["cells"])
    with open(out / "results.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["solver", "cells", "tets", "run", "wall_s", "user_s", "sys_s",
                         "iterations", "tip_ux", "tip_uy", "tip_uz"])
        for r in runs:
            writer.writerow([r["solver"], cells, mesh["tets"], r["run"], f"{r['wall_s']:.4f}",
                             f"{r['user_s']:.2f}", f"{r['sys_s']:.2f}", r["iterations"],
                             *(f"{u:.9e}" for u in r["tip"])])

    def solver_summary(name):
        rs = [r for r in runs if r["solver"] == name]
        median = lambda key: statistics.median(r[key] for r in rs)
        return {"runs": len(rs), "wall_s_median": median("wall_s"),
                "wall_s_min": min(r["wall_s"] for r in rs), "user_s_median": median("user_s"),
                "sys_s_median": median("sys_s"), "iterations": rs[0]["iterations"],
                "tip": rs[0]["tip"], "max_rss_kb": max(r["max_rss_kb"] for r in rs)}

    s, c = solver_summary("strata"), solver_summary("calculix")
    u_s, u_c = np.array(s["tip"]), np.array(c["tip"])
    rel = float(np.linalg.norm(u_s - u_c) / np.linalg.norm(u_c))
    # CalculiX's .dat has 7 significant digits (E13.6): half a unit in the last place of each
    # component, relative to |u_ccx|, is the smallest difference that can be resolved.
    half_ulp = [0.5 * 10.0 ** (math.floor(math.log10(abs(v))) - 6) if v != 0 else 0.0 for v in u_c]
    resolution = float(np.linalg.norm(half_ulp) / np.linalg.norm(u_c))
    ratio = lambda a, b: a / b if b > 0 else math.nan
    comparison = {
        "speedup_wall": ratio(c["wall_s_median"], s["wall_s_median"]),
        "speedup_user": ratio(c["user_s_median"], s["user_s_median"]),
        "tip_relative_difference": rel,
        "tip_uz_relative_difference": float(abs(u_s[2] - u_c[2]) / abs(u_c[2])),
        "tip_relative_resolution": resolution,
        "strata_sys_over_user": ratio(s["sys_s_median"], s["user_s_median"]),
        "calculix_sys_over_user": ratio(c["sys_s_median"], c["user_s_median"]),
    }
    results = {"meta": meta, "mesh": mesh, "runs": runs,
               "summary": {"strata": s, "calculix": c, "comparison": comparison}}
    (out / "results.json").write_text(json.dumps(results, indent=2) + "\n")

    def fmt_tip(u):
        return "(" + ", ".join(f"{v:+.6e}" for v in u) + ")"

    print(f"\ncantilever {meta['size']} m, cells {cells}, {mesh['nodes']} nodes, "
          f"{mesh['tets']} tets, {meta['load_steps']} load steps, repeat {meta['repeat']}, "
          f"strata threads {meta['strata_threads']}, CalculiX threads 1, "
          f"machine busy {meta['busy_percent_before_runs']} % of a core before the runs")
    print(f"{'solver':<9} {'wall s':>9} {'user s':>8} {'sys s':>7} {'sys/user':>8} "
          f"{'iters':>6}  tip displacement (m)")
    for name, summ in (("strata", s), ("calculix", c)):
        print(f"{name:<9} {summ['wall_s_median']:9.3f} {summ['user_s_median']:8.2f} "
              f"{summ['sys_s_median']:7.2f} "
              f"{ratio(summ['sys_s_median'], summ['user_s_median']):8.3f} "
              f"{summ['iterations']:6d}  {fmt_tip(summ['tip'])}")
    print(f"CalculiX/strata wall time (strata speed-up): {comparison['speedup_wall']:.2f}x "
          f"(user time: {comparison['speedup_user']:.2f}x)")
    print(f"tip |du|/|u_ccx| = {rel:.3e}  (u_z alone: "
          f"{comparison['tip_uz_relative_difference']:.3e}; CalculiX's 7-digit .dat "
          f"resolves {resolution:.1e})")
    disturbed = [r for r in runs if r["other_cpu_s"] > 0.05 * r["wall_s"] + 0.05]
    for r in disturbed:
        print(f"warning: {r['solver']} run {r['run']}: other processes used "
              f"{r['other_cpu_s']:.2f} s of CPU during its {r['wall_s']:.2f} s: timings disturbed")
    print(f"wrote {out / 'results.json'} and {out / 'results.csv'}")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    deck = sub.add_parser("deck")
    deck.add_argument("--vtu", required=True)
    deck.add_argument("--inp", required=True)
    deck.add_argument("--mesh-json", required=True)
    deck.add_argument("--scene", required=True)
    summarize = sub.add_parser("summarize")
    summarize.add_argument("--out", required=True)
    args = parser.parse_args()
    {"deck": cmd_deck, "summarize": cmd_summarize}[args.command](args)


if __name__ == "__main__":
    main()
