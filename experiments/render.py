#!/usr/bin/python3
"""Pictures of strata frames: the deformed body's surface coloured by a per-cell field.

  render.py FRAME.vtu [FRAME.vtu ...] --out PICTURE.png [--fields level,von_mises,...]
            [--view ELEVATION AZIMUTH] [--up x|y|z] [--titles "peak load" "unloaded" ...]
            [--exaggerate K]
  render.py SERIES.pvd --gif ANIMATION.gif [--fields level] [--fps 8] [--up x|y|z]

One panel per frame and field (rows: frames, columns: fields). A frame is a .vtu that `strata
run` writes (positions already deformed); its boundary triangles (the tet faces that belong to
one tet) are drawn with the colour of their tet's value, lit by a light above the viewer
(Lambert shading with ambient light) and painter-sorted by depth, with a colour bar per field
shared by the frames. The surface .vtp frames of a bound fine surface are drawn
the same way (point fields are averaged per triangle). Fields: any cell field of the frame —
`level` (active tree level, integer colours), `von_mises` [Pa], `plastic_strain`, `stress` or
`green_strain` (the first Voigt component) — or a point field (`displacement` magnitude).
Continuous fields are coloured up to their 99th percentile over the frames (the rest in the top
colour). `--up` names the model's vertical axis (default z; y for models such as the armadillo scan).
Needs /usr/bin/python3 (matplotlib, numpy; Pillow for --gif); frames are read by vtk_xml.py.
"""
import argparse
import os
import sys
import xml.etree.ElementTree as ElementTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vtk_xml  # noqa: E402  (strata's .vtu/.vtp frames, binary or ASCII)

import numpy as np


def fail(message):
    sys.exit(f"render: {message}")


class Cells:
    """One block of cells of a frame: `type` "tetra" or "triangle", `data` #cells × nodes."""

    def __init__(self, kind, data):
        self.type, self.data = kind, data


class Mesh:
    """A frame read by vtk_xml, with numpy arrays: points, cells, point_data, cell_data (one
    array per block)."""

    def __init__(self, frame):
        self.points = np.asarray(frame.points, dtype=float).reshape(-1, 3)
        self.cells = []
        if frame.type == "UnstructuredGrid":
            connectivity = np.asarray(frame.cells.get("Cells/connectivity", []), dtype=int)
            types = np.asarray(frame.cells.get("Cells/types", []), dtype=int)
            if len(types) and (types == 10).all() and len(connectivity) == 4 * len(types):
                self.cells.append(Cells("tetra", connectivity.reshape(-1, 4)))
        else:
            connectivity = np.asarray(frame.cells.get("Polys/connectivity", []), dtype=int)
            if len(connectivity) % 3 == 0 and len(connectivity):
                self.cells.append(Cells("triangle", connectivity.reshape(-1, 3)))
        self.point_data = {k: np.asarray(v, dtype=float) for k, v in frame.point_data.items()}
        self.cell_data = {k: [np.asarray(v, dtype=float)] for k, v in frame.cell_data.items()}


def load(path):
    try:
        return Mesh(vtk_xml.read(path))
    except (OSError, ValueError) as error:
        fail(f"{path}: cannot read ({error})")


def boundary(mesh):
    """(triangles #F × 3, owning cell #F) of the mesh's surface."""
    tets = [c.data for c in mesh.cells if c.type == "tetra"]
    triangles = [c.data for c in mesh.cells if c.type == "triangle"]
    if triangles:
        faces = np.vstack(triangles)
        return faces, np.arange(len(faces))
    if not tets:
        fail("the frame has neither tets nor triangles")
    tets = np.vstack(tets)
    local = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
    faces = tets[:, local].reshape(-1, 3)
    owner = np.repeat(np.arange(len(tets)), 4)
    keys = np.sort(faces, axis=1)
    _, index, counts = np.unique(keys, axis=0, return_index=True, return_counts=True)
    once = index[counts == 1]
    return faces[once], owner[once]


def values(mesh, field, faces, owner):
    """One value per face for `field` (cell data, or point data averaged over the corners)."""
    if field in mesh.cell_data:
        data = np.concatenate([np.asarray(d) for d in mesh.cell_data[field]])
        data = data.reshape(len(data), -1)
        column = np.linalg.norm(data, axis=1) if data.shape[1] == 3 else data[:, 0]
        return column[owner]
    if field in mesh.point_data:
        data = np.asarray(mesh.point_data[field]).reshape(len(mesh.points), -1)
        column = np.linalg.norm(data, axis=1) if data.shape[1] > 1 else data[:, 0]
        return column[faces].mean(axis=1)
    fields = sorted(set(mesh.cell_data) | set(mesh.point_data))
    fail(f"no field '{field}' in the frame (it has {', '.join(fields)})")


# In the scene's units (SI unless the scene chose others, e.g. mm for the armadillo scan).
LABELS = {"level": "active level", "von_mises": "von Mises stress",
          "plastic_strain": "equivalent plastic strain", "displacement": "displacement",
          "stress": "σ_xx", "green_strain": "E_xx"}
# Continuous fields: light at the low end, so that the shading shows the shape everywhere.
CONTINUOUS = "YlOrRd"


def positions(mesh, exaggerate):
    """The frame's deformed positions, the displacement scaled by `exaggerate`."""
    points = np.asarray(mesh.points, dtype=float)
    if exaggerate != 1.0 and "displacement" in mesh.point_data:
        u = np.asarray(mesh.point_data["displacement"], dtype=float).reshape(len(points), 3)
        points = points + (exaggerate - 1.0) * u
    return points


def colour_range(per_frame, integer):
    """(lo, hi) of a field over the frames: the whole range for integer fields (levels), else up
    to the 99th percentile, so that a few peak values (a contact, a corner) do not darken the
    rest; values above are drawn in the top colour."""
    values = np.concatenate(per_frame)
    lo = float(values.min())
    hi = float(values.max()) if integer else float(np.percentile(values, 99))
    return lo, max(hi, lo)


# Column order that puts the model's up axis on the plot's vertical axis (a cyclic permutation:
# the picture is not mirrored).
UP = {"x": [1, 2, 0], "y": [2, 0, 1], "z": [0, 1, 2]}


def shade(colours, polygons, elevation, azimuth):
    """The colours lit by a light above the viewer (Lambert, two-sided, with ambient light), so
    that the shape reads in depth; the hue still carries the field."""
    e, a = np.radians(elevation), np.radians(azimuth)
    eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    light = eye + np.array([0.0, 0.0, 0.6])
    light /= np.linalg.norm(light)
    normals = np.cross(polygons[:, 1] - polygons[:, 0], polygons[:, 2] - polygons[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    lengths[lengths == 0.0] = 1.0
    lit = 0.45 + 0.55 * np.abs(normals @ light) / lengths
    out = np.array(colours, dtype=float)
    out[:, :3] *= lit[:, None]
    return out


def draw(axis, points, faces, colours, elevation, azimuth, up="z"):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    points = points[:, UP[up]]
    polygons = points[faces]
    colours = shade(colours, polygons, elevation, azimuth)
    axis.add_collection3d(Poly3DCollection(polygons, facecolors=colours, edgecolors=(0, 0, 0, 0.15),
                                           linewidths=0.2))
    lo, hi = points.min(axis=0), points.max(axis=0)
    extent = np.maximum(hi - lo, 1e-3 * (hi - lo).max())
    for setter, a, b in zip((axis.set_xlim, axis.set_ylim, axis.set_zlim), lo, lo + extent):
        setter(a, b)
    axis.set_box_aspect(tuple(extent), zoom=1.0)
    axis.view_init(elev=elevation, azim=azimuth)
    axis.set_axis_off()


def render(frames, fields, out, titles, view, exaggerate, up="z"):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    meshes = [load(f) for f in frames]
    surfaces = [boundary(m) for m in meshes]
    figure = plt.figure(figsize=(4.2 * len(fields), 3.4 * len(frames)))
    for column, field in enumerate(fields):
        per_frame = [values(m, field, f, o) for m, (f, o) in zip(meshes, surfaces)]
        integer = field == "level"
        lo, hi = colour_range(per_frame, integer)
        if integer:
            cmap = plt.get_cmap("viridis", int(hi - lo) + 1)
            norm = matplotlib.colors.Normalize(lo - 0.5, hi + 0.5)
        else:
            cmap = plt.get_cmap(CONTINUOUS)
            norm = matplotlib.colors.Normalize(lo, hi if hi > lo else lo + 1e-30)
        for row, (mesh, (faces, _), v) in enumerate(zip(meshes, surfaces, per_frame)):
            axis = figure.add_subplot(len(frames), len(fields), row * len(fields) + column + 1,
                                      projection="3d")
            draw(axis, positions(mesh, exaggerate), faces, cmap(norm(v)), *view, up)
            title = LABELS.get(field, field)
            if titles:
                title = f"{titles[row]}: {title}"
            axis.set_title(title, fontsize=9)
            mappable = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
            bar = figure.colorbar(mappable, ax=axis, shrink=0.6, pad=0.02)
            bar.ax.tick_params(labelsize=7)
            if integer:
                bar.set_ticks(range(int(lo), int(hi) + 1))
    if exaggerate != 1.0:
        figure.suptitle(f"displacements ×{exaggerate:g}", fontsize=9)
    figure.tight_layout()
    temporary = out + ".part.png"
    figure.savefig(temporary, dpi=110)
    plt.close(figure)
    os.replace(temporary, out)


def series(pvd):
    """The .vtu frames of a .pvd in time order (part 0: the tet mesh)."""
    try:
        root = ElementTree.parse(pvd).getroot()
    except (OSError, ElementTree.ParseError) as error:
        fail(f"{pvd}: {error}")
    entries = [(float(d.get("timestep", 0)), d.get("file")) for d in root.iter("DataSet")
               if d.get("part", "0") == "0"]
    folder = os.path.dirname(pvd)
    return [(t, os.path.join(folder, f)) for t, f in sorted(entries)]


def animate(pvd, field, out, fps, view, exaggerate, up="z"):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter
    frames = series(pvd)
    if not frames:
        fail(f"{pvd}: no frames")
    meshes = [load(f) for _, f in frames]
    surfaces = [boundary(m) for m in meshes]
    per_frame = [values(m, field, f, o) for m, (f, o) in zip(meshes, surfaces)]
    lo, hi = colour_range(per_frame, field == "level")
    cmap = plt.get_cmap("viridis" if field == "level" else CONTINUOUS)
    norm = matplotlib.colors.Normalize(lo, hi if hi > lo else lo + 1e-30)
    figure = plt.figure(figsize=(5, 4))
    axis = figure.add_subplot(projection="3d")

    def frame(i):
        axis.clear()
        draw(axis, positions(meshes[i], exaggerate), surfaces[i][0], cmap(norm(per_frame[i])),
             *view, up)
        axis.set_title(f"{LABELS.get(field, field)}, t = {frames[i][0]:.4g}", fontsize=9)

    animation = FuncAnimation(figure, frame, frames=len(frames))
    temporary = out + ".part.gif"
    animation.save(temporary, writer=PillowWriter(fps=fps))
    plt.close(figure)
    os.replace(temporary, out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("inputs", nargs="+", help=".vtu/.vtp frames, or one .pvd with --gif")
    parser.add_argument("--out", help="PNG of the panels")
    parser.add_argument("--gif", help="animated GIF of a .pvd series")
    parser.add_argument("--fields", default="von_mises")
    parser.add_argument("--titles", nargs="*")
    parser.add_argument("--view", nargs=2, type=float, default=(22.0, -60.0),
                        metavar=("ELEVATION", "AZIMUTH"))
    parser.add_argument("--fps", type=int, default=8)
    parser.add_argument("--up", choices=sorted(UP), default="z",
                        help="the model's vertical axis (default z)")
    parser.add_argument("--exaggerate", type=float, default=1.0,
                        help="scale the displacement by this factor (1: as simulated)")
    args = parser.parse_args()
    fields = [f for f in args.fields.split(",") if f]
    for path in args.inputs:
        if not os.path.exists(path):
            fail(f"{path}: no such file")
    if args.gif:
        if len(args.inputs) != 1 or not args.inputs[0].endswith(".pvd"):
            fail("--gif takes one .pvd series")
        animate(args.inputs[0], fields[0], args.gif, args.fps, args.view, args.exaggerate,
                args.up)
        print(f"render: wrote {args.gif}")
        return
    if not args.out:
        fail("--out PICTURE.png (or --gif) is required")
    if args.titles and len(args.titles) != len(args.inputs):
        fail(f"--titles: {len(args.titles)} titles for {len(args.inputs)} frames")
    render(args.inputs, fields, args.out, args.titles, args.view, args.exaggerate, args.up)
    print(f"render: wrote {args.out}")


if __name__ == "__main__":
    main()
