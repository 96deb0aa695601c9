#!/usr/bin/python3
"""CTest check of field_error.py against brute-force computations.

  check_field_error.py STRATA WORK_DIR

1. Point location: random points in Freudenthal-split box meshes, one uniform and one graded
   (cells from 1 % to 37 % of the box, so large tets span many grid cells), are located in a tet
   that holds them (barycentric coordinates ≥ −1e-12 that reproduce the point to 1e-12).
2. A small struck block run at full resolution (1 level) and on its roots (uniform level 0),
   frames written: the field error equals the one computed point by point, each full vertex
   located by testing every root tet, to 1e-10 relative; it is positive, and a run against itself
   has error 0.
Exits non-zero with a message on the first failure.
"""
import json
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import field_error  # noqa: E402


def fail(message):
    sys.exit(f"check_field_error: {message}")


def box_mesh(cells, graded=False):
    """Vertices and tets of the unit box split into cells, each cell into 6 tets around a diagonal;
    graded: the cells' widths along each axis double from one cell to the next."""
    nx, ny, nz = cells

    def nodes(n):
        widths = 2.0 ** np.arange(n) if graded else np.ones(n)
        return np.concatenate([[0.0], np.cumsum(widths)]) / widths.sum()

    xs, ys, zs = nodes(nx), nodes(ny), nodes(nz)
    vertices = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    index = lambda i, j, k: (i * (ny + 1) + j) * (nz + 1) + k  # noqa: E731
    paths = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    tets = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                for path in paths:
                    corner = [i, j, k]
                    tet = [index(*corner)]
                    for axis in path:
                        corner[axis] += 1
                        tet.append(index(*corner))
                    tets.append(tet)
    return vertices, np.array(tets)


def check_locate():
    rng = np.random.default_rng(7)
    for graded in (False, True):
        vertices, tets = box_mesh((6, 5, 4), graded)
        points = rng.random((4000, 3))
        points = np.concatenate([points, vertices])  # vertices sit on many tets' corners
        tet, weights, score = field_error.locate(points, vertices, tets)
        if score.min() < -1e-12:
            fail(f"locate (graded {graded}): a point lies outside its tet by {-score.min():.3g}")
        rebuilt = np.einsum("pk,pkc->pc", weights, vertices[tets[tet]])
        error = np.abs(rebuilt - points).max()
        if error > 1e-12:
            fail(f"locate (graded {graded}): barycentric coordinates reproduce the points to "
                 f"{error:.3g} only")


def brute_force_error(full_folder, run_folder):
    worst, scale = 0.0, 0.0
    full_frames, run_frames = field_error.frames(full_folder), field_error.frames(run_folder)
    if len(full_frames) != len(run_frames) or len(full_frames) < 3:
        fail(f"expected the same frames (at least 3), got {len(full_frames)} and {len(run_frames)}")
    for (full_time, full_path), (run_time, run_path) in zip(full_frames, run_frames):
        if full_time != run_time:
            fail(f"frame times differ: {full_time} and {run_time}")
        full_rest, full_u, _ = field_error.read_frame(full_path)
        rest, u, tets = field_error.read_frame(run_path)
        for p, x in enumerate(full_rest):
            best, best_weights = -np.inf, None
            for tet in tets:
                corners = rest[tet]
                matrix = np.vstack([corners.T, np.ones(4)])
                weights = np.linalg.solve(matrix, np.append(x, 1.0))
                if weights.min() > best:
                    best, best_weights, best_tet = weights.min(), weights, tet
            if best < -1e-9:
                fail(f"brute force: full vertex {p} lies in no tet of {run_path}")
            value = best_weights @ u[best_tet]
            worst = max(worst, np.linalg.norm(value - full_u[p]))
            scale = max(scale, np.linalg.norm(full_u[p]))
    return worst / scale


def check_runs(strata, work):
    scene = {
        "mesh": {"box": {"min": [0, 0, 0], "max": [0.4, 0.4, 0.2], "cells": [2, 2, 1]}},
        "material": {"model": "neohookean", "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                     "density": 1000},
        "fixed": [{"plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}}],
        "forces": [{"region": {"box": {"min": [0.1, 0.1, 0.2], "max": [0.3, 0.3, 0.2]}},
                    "total_force": [0, 0, -2000]}],
        "solver": {"mode": "dynamic", "integrator": "implicit_euler", "dt": 0.002,
                   "duration": 0.01},
        "output": {"every": 2, "vtk": True},
        "hierarchy": {"levels": 1},
    }
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    folders = {}
    for name, settings in (("full", ["hierarchy.mode=full"]),
                           ("roots", ["hierarchy.mode=uniform", "hierarchy.level=0"])):
        folders[name] = os.path.join(work, name)
        command = [strata, "run", path, "--out", folders[name], "--quiet"]
        for item in settings:
            command += ["--set", item]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            fail(f"{name} run failed ({result.returncode}): {result.stderr.strip()}")
    measured = field_error.field_error(folders["full"], folders["roots"])["error"]
    expected = brute_force_error(folders["full"], folders["roots"])
    if not expected > 0.0:
        fail("the roots' run has no error against full resolution: the check tests nothing")
    if abs(measured - expected) > 1e-10 * expected:
        fail(f"field error {measured!r} against {expected!r} by brute force")
    itself = field_error.field_error(folders["full"], folders["full"])["error"]
    if itself != 0.0:
        fail(f"a run against itself has field error {itself!r}")
    print(f"check_field_error: roots against full resolution {100 * measured:.3f} % "
          f"(brute force {100 * expected:.3f} %)")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().split("\n\n")[1].strip())
    check_locate()
    check_runs(sys.argv[1], sys.argv[2])


if __name__ == "__main__":
    main()
