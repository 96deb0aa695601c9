"""Reads the VTK XML frames strata writes (.vtu and .vtp), binary or ASCII, with the standard
library only.

  frame = read("run/scene_000004.vtu")
  frame.points                   # [[x, y, z], ...]
  frame.point_data["velocity"]   # [[vx, vy, vz], ...] (one list per point; scalars as [v])
  frame.cell_data["level"]       # per cell
  frame.cells["Cells/connectivity"], frame.cells["Polys/offsets"]   # flat lists

Accepts what strata writes and what ParaView writes by default: one Piece, DataArrays in ASCII,
inline base64 or appended raw data, uncompressed or zlib-compressed, UInt32 or UInt64 headers,
little endian. Raises ValueError naming the file for anything else or a damaged file.
"""
import base64
import re
import struct
import zlib

_FORMATS = {"Float64": "d", "Float32": "f", "Int64": "q", "UInt64": "Q", "Int32": "i",
            "UInt32": "I", "Int16": "h", "UInt16": "H", "Int8": "b", "UInt8": "B"}
_TAG = re.compile(rb"<(/?)(\w+)((?:\s+[\w:.-]+\s*=\s*(?:\"[^\"]*\"|'[^']*'))*)\s*(/?)>")
_ATTRIBUTE = re.compile(rb"([\w:.-]+)\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")
_CELL_SECTIONS = ("Cells", "Polys", "Lines", "Verts", "Strips")


class Frame:
    """The arrays of one frame: see the module's docstring."""

    def __init__(self):
        self.type = ""
        self.points = []
        self.point_data = {}
        self.cell_data = {}
        self.cells = {}


def _attributes(text):
    return {k.decode(): (a if a is not None else b).decode()
            for k, a, b in _ATTRIBUTE.findall(text)}


def read(path):
    """The Frame of a single-piece .vtu or .vtp."""
    with open(path, "rb") as f:
        data = f.read()

    def fail(message):
        raise ValueError(f"{path}: {message}")

    appended_at = data.find(b"<AppendedData")
    markup = data if appended_at < 0 else data[:appended_at]
    raw = b""
    if appended_at >= 0:
        end = data.find(b">", appended_at)
        head = _attributes(data[appended_at:end])
        if head.get("encoding", "raw") != "raw":
            fail("appended data must be raw")
        underscore = data.find(b"_", end)
        if end < 0 or underscore < 0:
            fail("truncated <AppendedData>")
        raw = data[underscore + 1:]

    frame = Frame()
    header, compressed, section = "<I", False, None
    num_points = num_cells = 0
    arrays = []  # (section, name, components, values)
    for match in _TAG.finditer(markup):
        closing, name, attributes, self_closing = match.groups()
        name = name.decode()
        if closing:
            if name == section:
                section = None
            continue
        attrs = _attributes(attributes)
        if name == "VTKFile":
            frame.type = attrs.get("type", "")
            if frame.type not in ("UnstructuredGrid", "PolyData"):
                fail(f"not a .vtu or .vtp (type '{frame.type}')")
            if attrs.get("byte_order", "LittleEndian") != "LittleEndian":
                fail("big-endian data is not supported")
            if attrs.get("header_type", "UInt32") == "UInt64":
                header = "<Q"
            compressor = attrs.get("compressor")
            if compressor not in (None, "vtkZLibDataCompressor"):
                fail(f"compressor '{compressor}' is not supported")
            compressed = compressor is not None
        elif name == "Piece":
            num_points = int(attrs.get("NumberOfPoints", 0))
            num_cells = (int(attrs.get("NumberOfCells", 0)) if frame.type == "UnstructuredGrid"
                         else sum(int(attrs.get("NumberOf" + k, 0))
                                  for k in ("Verts", "Lines", "Strips", "Polys")))
        elif name == "DataArray" and section not in (None, "FieldData"):
            kind = _FORMATS.get(attrs.get("type", ""))
            if kind is None:
                fail(f"DataArray '{attrs.get('Name', '')}' has unknown type")
            encoding = attrs.get("format", "ascii")
            content = b"" if self_closing else markup[match.end():markup.find(b"<", match.end())]
            if encoding == "ascii":
                values = [float(v) for v in content.split()]
            elif encoding == "binary":
                values = _decode(base64.b64decode(b"".join(content.split())), 0, kind, header,
                                 compressed, fail)
            elif encoding == "appended":
                values = _decode(raw, int(attrs["offset"]), kind, header, compressed, fail)
            else:
                fail(f"unknown DataArray format '{encoding}'")
            arrays.append((section, attrs.get("Name", ""),
                           int(attrs.get("NumberOfComponents", 1)), values))
        elif not self_closing and name in ("Points", "PointData", "CellData", "FieldData",
                                           *_CELL_SECTIONS):
            section = name
    if not frame.type:
        fail("not a VTK XML file")

    def tuples(values, components, rows, what):
        if len(values) != rows * components:
            fail(f"{what} holds {len(values)} values, expected {rows} × {components}")
        return [values[i:i + components] for i in range(0, len(values), components)]

    for section, name, components, values in arrays:
        if section == "Points" and not frame.points:
            frame.points = tuples(values, components, num_points, "Points")
        elif section == "PointData":
            frame.point_data[name] = tuples(values, components, num_points, name)
        elif section == "CellData":
            frame.cell_data[name] = tuples(values, components, num_cells, name)
        elif section in _CELL_SECTIONS:
            frame.cells[f"{section}/{name}"] = values
    return frame


def _decode(data, offset, kind, header, compressed, fail):
    """The values of one binary array starting at `offset` of `data`."""
    word = struct.calcsize(header)
    try:
        if not compressed:
            (size,) = struct.unpack_from(header, data, offset)
            payload = data[offset + word:offset + word + size]
            if len(payload) != size:
                fail("binary array is truncated")
        else:
            blocks, _, _ = struct.unpack_from("<3" + header[1], data, offset)
            sizes = struct.unpack_from("<%d%s" % (blocks, header[1]), data, offset + 3 * word)
            at = offset + (3 + blocks) * word
            parts = []
            for size in sizes:
                parts.append(zlib.decompress(data[at:at + size]))
                at += size
            payload = b"".join(parts)
    except (struct.error, zlib.error) as error:
        fail(f"damaged binary array ({error})")
    item = struct.calcsize("<" + kind)
    if len(payload) % item:
        fail("binary array is not a whole number of values")
    return [float(v) for v in struct.unpack("<%d%s" % (len(payload) // item, kind), payload)]
