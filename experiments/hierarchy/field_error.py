#!/usr/bin/python3
"""Displacement error of a hierarchy run against full resolution over the whole body.

The probe error (compare_to_full.py) samples the displacement at a few points; this one compares
it at every vertex of the full-resolution mesh, frame by frame. Each full-mesh vertex is located
in the run's active cut of the same frame (rest positions; the cut's tets are nested in the
tree, so every finest-level vertex lies in one of them up to rounding) and the run's displacement
there is its linear interpolant, which is the field the run computed. The error of a frame is the
largest vertex-displacement difference; the error of the run is the largest over the frames,
relative to the largest full-resolution vertex displacement of the run.

  field_error.py FULL_FOLDER RUN_FOLDER     # folders of `strata run` with output.vtk on

Prints the error and the frame where it is largest. Needs numpy (Debian python3-numpy).
"""
import functools
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import vtk_xml  # noqa: E402

_DATASET = re.compile(r'<DataSet\s[^>]*timestep="([^"]*)"[^>]*part="0"[^>]*file="([^"]*)"')


def frames(folder):
    """(time, .vtu path) of the volume frames listed in the folder's .pvd, in order."""
    pvds = [name for name in sorted(os.listdir(folder)) if name.endswith(".pvd")]
    if len(pvds) != 1:
        raise ValueError(f"{folder}: expected one .pvd, found {len(pvds)}")
    with open(os.path.join(folder, pvds[0])) as f:
        text = f.read()
    listed = [(float(t), os.path.join(folder, name)) for t, name in _DATASET.findall(text)
              if name.endswith(".vtu")]
    if not listed:
        raise ValueError(f"{folder}/{pvds[0]}: no .vtu frames (was output.vtk on?)")
    return listed


@functools.lru_cache(maxsize=64)  # the full run's frames, read once for all the runs compared
def read_frame(path):
    """Rest positions, displacements and tets of one .vtu frame (its points are deformed)."""
    frame = vtk_xml.read(path)
    displacement = np.asarray(frame.point_data["displacement"], dtype=float)
    rest = np.asarray(frame.points, dtype=float) - displacement
    tets = np.asarray(frame.cells["Cells/connectivity"], dtype=np.int64).reshape(-1, 4)
    return rest, displacement, tets


def locate(points, vertices, tets):
    """For each point, a tet that holds it and its barycentric coordinates.

    Tets are bucketed on a grid of cells as large as the median tet's longest edge, each into
    every cell its bounding box (padded by 1e-9 of the mesh's extent, for points on its faces)
    touches; a point is tested against the tets of its cell, and the one where its smallest
    barycentric coordinate is largest is kept (inside up to rounding for points in the mesh)."""
    corners = vertices[tets]                                   # m × 4 × 3
    pad = 1e-9 * np.ptp(vertices, axis=0).max()
    low, high = corners.min(axis=1) - pad, corners.max(axis=1) + pad
    size = max(float(np.median((high - low).max(axis=1))), 1e-12)
    origin = np.minimum(vertices.min(axis=0), points.min(axis=0)) - 1e-9
    shape = np.floor((np.maximum(vertices.max(axis=0), points.max(axis=0)) - origin) / size)
    shape = shape.astype(np.int64) + 1
    first = np.floor((low - origin) / size).astype(np.int64)
    last = np.floor((high - origin) / size).astype(np.int64)
    span = last - first + 1
    cell_tets, cell_keys = [], []
    for dx in range(span[:, 0].max()):
        for dy in range(span[:, 1].max()):
            for dz in range(span[:, 2].max()):
                offset = np.array([dx, dy, dz])
                inside = np.all(offset < span, axis=1)
                cell = first[inside] + offset
                cell_tets.append(np.nonzero(inside)[0])
                cell_keys.append(cell[:, 0] + shape[0] * (cell[:, 1] + shape[1] * cell[:, 2]))
    cell_tets, cell_keys = np.concatenate(cell_tets), np.concatenate(cell_keys)
    order = np.argsort(cell_keys, kind="stable")
    cell_tets, cell_keys = cell_tets[order], cell_keys[order]

    point_cell = np.floor((points - origin) / size).astype(np.int64)
    point_keys = point_cell[:, 0] + shape[0] * (point_cell[:, 1] + shape[1] * point_cell[:, 2])
    begin = np.searchsorted(cell_keys, point_keys, side="left")
    end = np.searchsorted(cell_keys, point_keys, side="right")
    counts = end - begin
    if np.any(counts == 0):
        raise ValueError(f"{np.count_nonzero(counts == 0)} points lie in no tet's cell")
    pair_point = np.repeat(np.arange(len(points)), counts)
    pair_slot = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    pair_tet = cell_tets[np.repeat(begin, counts) + pair_slot]

    edges = corners[:, 1:, :] - corners[:, :1, :]             # m × 3 × 3, rows are edges
    inverse = np.linalg.inv(np.transpose(edges, (0, 2, 1)))    # maps x − x0 to (λ1, λ2, λ3)
    local = np.einsum("pij,pj->pi", inverse[pair_tet], points[pair_point] - corners[pair_tet, 0])
    weights = np.concatenate([1.0 - local.sum(axis=1, keepdims=True), local], axis=1)
    score = weights.min(axis=1)
    # The best pair of each point: sort by (point, score) and take each point's last.
    best = np.lexsort((score, pair_point))
    last_of_point = np.r_[np.nonzero(np.diff(pair_point[best]))[0], len(best) - 1]
    chosen = best[last_of_point]
    return pair_tet[chosen], weights[chosen], score[chosen]


def field_error(full_folder, run_folder):
    """{"error", "worst_time", "worst_outside", "scale", "frames"} of the run against the full
    one; "frames" lists (time, error) per frame, relative to the same scale."""
    reference, run = frames(full_folder), frames(run_folder)
    if [t for t, _ in reference] != [t for t, _ in run]:
        raise ValueError(f"{run_folder}: its frame times differ from {full_folder}'s")
    worst, worst_time, scale, outside, per_frame = 0.0, None, 0.0, 0.0, []
    for (time, full_path), (_, run_path) in zip(reference, run):
        full_rest, full_u, _ = read_frame(full_path)
        rest, u, tets = read_frame(run_path)
        tet, weights, score = locate(full_rest, rest, tets)
        outside = max(outside, -score.min())
        interpolated = np.einsum("pk,pkc->pc", weights, u[tets[tet]])
        difference = np.linalg.norm(interpolated - full_u, axis=1).max()
        scale = max(scale, np.linalg.norm(full_u, axis=1).max())
        per_frame.append((time, difference))
        if difference > worst:
            worst, worst_time = difference, time
    relative = (lambda d: d / scale) if scale > 0 else (lambda d: 0.0)
    return {"error": relative(worst), "worst_time": worst_time, "scale": scale,
            "worst_outside": outside, "frames": [(t, relative(d)) for t, d in per_frame]}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().split("\n\n")[1].strip())
    result = field_error(sys.argv[1], sys.argv[2])
    print(f"field error {100 * result['error']:.3f} % (largest at t = {result['worst_time']}; "
          f"largest full-resolution displacement {result['scale']:.4g} m; points outside the "
          f"cut's tets by up to {result['worst_outside']:.2g} in barycentric coordinates)")


if __name__ == "__main__":
    main()
