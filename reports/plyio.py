#!/usr/bin/python3
"""A small PLY reader (ASCII and binary, either endianness) returning numpy arrays, so reports
need no plyfile package. Only what frames need: vertex x, y, z and triangle/polygon faces."""

import numpy as np

_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
          "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
          "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def _parse_header(f):
    """(format, elements) where elements = [(name, count, [(prop, type) | (prop, ('list', ct, it))])]."""
    if f.readline().strip() != b"ply":
        raise ValueError("not a PLY file")
    fmt, elements = None, []
    while True:
        line = f.readline()
        if not line:
            raise ValueError("PLY header has no end_header")
        words = line.decode("ascii", "replace").split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            if words[1] == "list":
                elements[-1][2].append((words[4], ("list", _TYPES[words[2]], _TYPES[words[3]])))
            else:
                elements[-1][2].append((words[2], _TYPES[words[1]]))
        elif words[0] == "end_header":
            return fmt, elements


def _faces_to_triangles(polys):
    """Fan-triangulate polygons given as a list of index arrays."""
    tris = []
    for p in polys:
        for k in range(1, len(p) - 1):
            tris.append((p[0], p[k], p[k + 1]))
    return np.asarray(tris, dtype=np.int64).reshape(-1, 3)


def _read_ascii(f, elements):
    tokens = f.read().split()
    pos = 0
    out = {}
    for name, count, props in elements:
        rows = []
        for _ in range(count):
            row = {}
            for pname, ptype in props:
                if isinstance(ptype, tuple):
                    n = int(tokens[pos]); pos += 1
                    row[pname] = [int(t) for t in tokens[pos:pos + n]]; pos += n
                else:
                    row[pname] = float(tokens[pos]); pos += 1
            rows.append(row)
        out[name] = rows
    verts = np.array([[r["x"], r["y"], r["z"]] for r in out.get("vertex", [])], dtype=float).reshape(-1, 3)
    key = _face_key(elements)
    polys = [r[key] for r in out.get("face", [])] if key else []
    return verts, _faces_to_triangles(polys)


def _face_key(elements):
    for name, _, props in elements:
        if name == "face":
            for pname, ptype in props:
                if isinstance(ptype, tuple):
                    return pname
    return None


def _read_binary(f, elements, endian):
    data = f.read()
    pos = 0
    verts, tris = np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    for name, count, props in elements:
        if all(not isinstance(t, tuple) for _, t in props):
            # Fixed-size records: one structured read.
            dt = np.dtype([(p, endian + t) for p, t in props])
            arr = np.frombuffer(data, dtype=dt, count=count, offset=pos)
            pos += dt.itemsize * count
            if name == "vertex":
                verts = np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(float)
            continue
        # Lists: try the common case (all triangles, list first or only) as a structured read,
        # fall back to a record-by-record walk.
        fields = []
        for p, t in props:
            if isinstance(t, tuple):
                fields += [(p + "_n", endian + t[1]), (p, endian + t[2], (3,))]
            else:
                fields.append((p, endian + t))
        dt = np.dtype(fields)
        key = next(p for p, t in props if isinstance(t, tuple))
        if pos + dt.itemsize * count <= len(data):
            arr = np.frombuffer(data, dtype=dt, count=count, offset=pos)
            if count == 0 or np.all(arr[key + "_n"] == 3):
                pos += dt.itemsize * count
                if name == "face":
                    tris = arr[key].astype(np.int64)
                continue
        polys = []
        for _ in range(count):
            for p, t in props:
                if isinstance(t, tuple):
                    ct, it = np.dtype(endian + t[1]), np.dtype(endian + t[2])
                    n = int(np.frombuffer(data, ct, 1, pos)[0]); pos += ct.itemsize
                    idx = np.frombuffer(data, it, n, pos); pos += it.itemsize * n
                    if p == key:
                        polys.append(idx)
                else:
                    pos += np.dtype(t).itemsize
        if name == "face":
            tris = _faces_to_triangles(polys)
    return verts, tris


def read_ply(path):
    """(vertices n×3 float array, triangles m×3 int array) of a PLY file."""
    with open(path, "rb") as f:
        fmt, elements = _parse_header(f)
        if fmt == "ascii":
            return _read_ascii(f, elements)
        if fmt in ("binary_little_endian", "binary_big_endian"):
            return _read_binary(f, elements, "<" if fmt == "binary_little_endian" else ">")
        raise ValueError("unknown PLY format %r" % fmt)


def write_ply(path, vertices, triangles, binary=True):
    """Write a triangle mesh as PLY (used by the tests' fake results)."""
    vertices = np.asarray(vertices, dtype="<f4")
    triangles = np.asarray(triangles, dtype="<i4")
    header = ("ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
              "element face %d\nproperty list uchar int vertex_indices\nend_header\n"
              % ("binary_little_endian" if binary else "ascii", len(vertices), len(triangles)))
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        if binary:
            rec = np.zeros(len(triangles), dtype=[("n", "u1"), ("i", "<i4", (3,))])
            rec["n"] = 3
            rec["i"] = triangles
            f.write(vertices.tobytes())
            f.write(rec.tobytes())
        else:
            for v in vertices:
                f.write(("%g %g %g\n" % tuple(v)).encode())
            for t in triangles:
                f.write(("3 %d %d %d\n" % tuple(t)).encode())
