"""A small Python client of surfinspectd for MES integrators.

It reads what a cell already has on disk (cell.json, the part's STL and one
organized PCD per viewpoint), streams a whole part to the service's
bidirectional `Inspect` RPC and returns the `InspectResult` (verdict and the
report JSON). It needs only Debian's python3-grpcio and python3-protobuf plus
the stubs that generate.sh makes from proto/surfinspect/v1/inspection.proto.

Units: millimetres. Transforms are row-major 4x4 ("world_from_sensor" maps
sensor coordinates into the world frame), as in cell.json.
"""
import hashlib
import json
import math
import os
import random
import struct
import time

import grpc

from surfinspect.v1 import inspection_pb2 as pb
from surfinspect.v1 import inspection_pb2_grpc as pb_grpc

CHUNK_BYTES = 1 << 20  # ~1 MB per CloudChunk, like the C++ clients
MAX_POINTS = 50_000_000  # sanity cap on sizes declared by a file header


class ClientError(Exception):
    """Bad input or a failed call, with a message meant for an operator."""


# ---- files ---------------------------------------------------------------

PCD_KEYS = ("VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS",
            "DATA")
MAX_HEADER_BYTES = 64 << 10


def _pcd_header(path, data):
    """({KEY: [words]}, data offset), refusing what the C++ reader refuses:
    an unknown or repeated key, a key out of order, a header over 64 KiB."""
    header, offset, last = {}, 0, -1
    while "DATA" not in header:
        end = data.find(b"\n", offset)
        if end < 0 or end > MAX_HEADER_BYTES:
            raise ClientError(f"{path}: truncated PCD header (no DATA line in the first 64 KiB)")
        line = data[offset:end].decode("ascii", "replace").strip()
        offset = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        key = key.upper()
        if key not in PCD_KEYS:
            raise ClientError(f"{path}: unknown PCD header line {line[:40]!r}")
        if key in header or PCD_KEYS.index(key) < last:
            raise ClientError(f"{path}: PCD header key {key} repeated or out of order")
        last = PCD_KEYS.index(key)
        header[key] = value.split()
    return header, offset


def _positive_int(path, header, key):
    words = header.get(key)
    if not words or len(words) != 1 or not words[0].isdigit() or int(words[0]) <= 0:
        raise ClientError(f"{path}: PCD {key} must be one positive integer, not {words}")
    return int(words[0])


def read_pcd(path):
    """(xyz bytes as little-endian float32, width, height) of a PCD file.

    Reads the ascii and binary encodings with x, y, z float32 fields among any
    others; NaN marks a pixel with no data (organized grids are kept). The
    header is parsed strictly and every declared size is checked against the
    file before anything is allocated from it.
    """
    with open(path, "rb") as f:
        data = f.read()
    header, offset = _pcd_header(path, data)
    fields = header.get("FIELDS", [])
    try:
        sizes = [int(v) for v in header["SIZE"]]
        types = header["TYPE"]
        counts = [int(c) for c in header.get("COUNT", ["1"] * len(fields))]
    except (KeyError, ValueError) as e:
        raise ClientError(f"{path}: malformed PCD header ({e})") from None
    width, height = _positive_int(path, header, "WIDTH"), _positive_int(path, header, "HEIGHT")
    n = width * height
    if not n <= MAX_POINTS or not 0 < len(fields) == len(sizes) == len(types) == len(counts):
        raise ClientError(f"{path}: bad PCD sizes ({width} x {height}, {len(fields)} fields)")
    if "POINTS" in header and _positive_int(path, header, "POINTS") != n:
        raise ClientError(f"{path}: bad PCD sizes (POINTS is not WIDTH x HEIGHT = {n})")
    if len(set(fields)) != len(fields) or any(s not in (1, 2, 4, 8) for s in sizes) or \
            any(t not in ("I", "U", "F") for t in types) or any(not 0 < c <= 1 << 16 for c in counts):
        raise ClientError(f"{path}: bad PCD fields (names, SIZE 1/2/4/8, TYPE I/U/F, COUNT)")
    for axis in "xyz":
        if axis not in fields:
            raise ClientError(f"{path}: no {axis} field")
        i = fields.index(axis)
        if (sizes[i], types[i], counts[i]) != (4, "F", 1):
            raise ClientError(f"{path}: field {axis} is not a float32")
    encoding = header["DATA"][0] if len(header["DATA"]) == 1 else ""
    if encoding == "binary":
        xyz = _pcd_binary_xyz(path, data[offset:], fields, sizes, counts, n)
    elif encoding == "ascii":
        xyz = _pcd_ascii_xyz(path, data[offset:], fields, counts, n)
    else:
        raise ClientError(f"{path}: PCD encoding {header['DATA']} is not supported here (use ascii or binary)")
    if any(math.isinf(v) for v in struct.unpack(f"<{3 * n}f", xyz)):
        raise ClientError(f"{path}: a point has an infinite coordinate (NaN marks no point)")
    return xyz, width, height


def _pcd_binary_xyz(path, body, fields, sizes, counts, n):
    stride = sum(s * c for s, c in zip(sizes, counts))
    if len(body) < n * stride:
        raise ClientError(f"{path}: truncated: {len(body)} data bytes, header declares {n * stride}")
    offsets = {f: sum(s * c for s, c in zip(sizes[:i], counts[:i])) for i, f in enumerate(fields)}
    if stride == 12 and (offsets["x"], offsets["y"], offsets["z"]) == (0, 4, 8):
        return bytes(body[:n * 12])  # already the wire layout (PCD binary is little-endian)
    out = bytearray(n * 12)  # other fields interleaved: pick x, y, z per point
    for p in range(n):
        base = p * stride
        for k, axis in enumerate("xyz"):
            o = base + offsets[axis]
            out[p * 12 + 4 * k:p * 12 + 4 * k + 4] = body[o:o + 4]
    return bytes(out)


def _pcd_ascii_xyz(path, body, fields, counts, n):
    columns = {f: sum(counts[:i]) for i, f in enumerate(fields)}
    words = sum(counts)
    if len(body) < 2 * words * n - 1:  # each value takes a digit and a separator at least
        raise ClientError(f"{path}: truncated: {len(body)} data bytes cannot hold {n} points")
    rows = [l for l in body.decode("ascii", "replace").split("\n") if l.strip()]
    if len(rows) < n:
        raise ClientError(f"{path}: truncated: {len(rows)} points, header declares {n}")
    out = bytearray()
    pack = struct.Struct("<3f").pack
    for row in rows[:n]:
        v = row.split()
        try:
            if len(v) != words:
                raise ValueError
            out += pack(*(float(v[columns[a]]) for a in "xyz"))
        except (ValueError, OverflowError):
            raise ClientError(f"{path}: bad point line {row[:80]!r} (expected {words} numbers)") from None
    return bytes(out)


def _stl_ascii_corners(path, data):
    """Corners of an ASCII STL, three per facet; a facet with another number
    of vertices is refused (this reader does not triangulate)."""
    corners, in_loop = [], None
    for number, line in enumerate(data.decode("ascii", "replace").splitlines(), 1):
        w = line.split()
        if not w:
            continue
        if w[0] == "outer":
            in_loop = 0
        elif w[0] == "vertex":
            if in_loop is None or len(w) != 4:
                raise ClientError(f"{path}: line {number}: a vertex outside a facet's loop, or not x y z")
            try:
                c = struct.unpack("<3f", struct.pack("<3f", *map(float, w[1:])))
            except (ValueError, OverflowError):
                raise ClientError(f"{path}: line {number}: bad vertex {line.strip()[:60]!r}") from None
            corners.append(c)  # rounded through float32, as the wire and the C++ reader are
            in_loop += 1
        elif w[0] == "endloop":
            if in_loop != 3:
                raise ClientError(f"{path}: line {number}: a facet with {in_loop} vertices (STL facets are triangles)")
            in_loop = None
    return corners


def read_stl(path):
    """(vertex bytes, triangle bytes) of an STL mesh in the wire layout.

    Identical vertices are merged in order of first appearance, as the C++
    readers do (Assimp's JoinIdenticalVertices), so the mesh, its pseudo-
    normals and its content hash are the same as the C++ clients'.
    """
    with open(path, "rb") as f:
        data = f.read()
    corners = []
    if len(data) >= 84 and 84 + 50 * struct.unpack_from("<I", data, 80)[0] == len(data):
        count = struct.unpack_from("<I", data, 80)[0]
        for t in range(count):
            v = struct.unpack_from("<9f", data, 84 + 50 * t + 12)
            corners += [v[0:3], v[3:6], v[6:9]]
    elif data.lstrip().startswith(b"solid"):
        corners = _stl_ascii_corners(path, data)
    else:
        raise ClientError(f"{path}: not an STL file (binary size mismatch, no 'solid')")
    if not corners:
        raise ClientError(f"{path}: no triangles")
    if not all(math.isfinite(x) for c in corners for x in c):
        raise ClientError(f"{path}: a vertex is not finite")
    index, vertices, triangles = {}, bytearray(), bytearray()
    for c in corners:
        key = struct.pack("<3f", *c)
        i = index.get(key)
        if i is None:
            i = index[key] = len(index)
            vertices += key
        triangles += struct.pack("<I", i)
    return bytes(vertices), bytes(triangles)


def mesh_sha256(vertices, triangles):
    """The service's mesh cache key (see MeshRef in inspection.proto)."""
    h = hashlib.sha256(b"surfinspect.mesh.v1\0")
    h.update(struct.pack("<QQ", len(vertices) // 12, len(triangles) // 12))
    h.update(vertices)
    h.update(triangles)
    return h.hexdigest()


def _transform(m, what):
    try:
        rows = m["matrix"]
        values = [float(rows[r][c]) for r in range(4) for c in range(4)]
    except (KeyError, TypeError, IndexError, ValueError):
        raise ClientError(f"{what}: expected {{\"matrix\": [[4 numbers] x 4]}}") from None
    return pb.Transform(row_major=values)


def read_cell(path):
    """The parts of cell.json that an inspection needs (paths resolved)."""
    try:
        with open(path) as f:
            j = json.load(f)
    except (OSError, ValueError) as e:
        raise ClientError(f"{path}: {e}") from None
    base = os.path.dirname(os.path.abspath(path))
    try:
        cell = {
            "part_mesh": os.path.join(base, j["part"]["mesh"]),
            "world_from_part": _transform(j["part"]["world_from_part"], "part.world_from_part"),
            "viewpoints": [(v["name"], v.get("world_from_sensor")) for v in j["viewpoints"]],
            "tolerance_mm": j.get("tolerance_mm"),
            "error_map": j.get("error_map", {}),
            "filter": j.get("filter", {}),
            "plan": _read_plan(base, j.get("plan")),
        }
    except (KeyError, TypeError) as e:
        raise ClientError(f"{path}: missing {e}") from None
    for key in ("error_map", "filter"):
        if not isinstance(cell[key], dict):
            raise ClientError(f"{path}: {key} must be an object")
    if not cell["viewpoints"] or not all(isinstance(n, str) and n and "/" not in n
                                         for n, _ in cell["viewpoints"]):
        raise ClientError(f"{path}: viewpoints need non-empty names without '/'")
    return cell


# ---- the inspection plan (docs/inspection-plan.md) ------------------------

_PLAN_KEYS = {
    "plan": {"schema", "tolerance_mm", "allowed_fraction_outside", "min_coverage",
             "coverage_distance_mm", "allow_not_measured", "regions", "points", "sections",
             "holes", "slots", "edge_points", "defects", "alignment"},
    "region": {"name", "select", "tolerance_mm", "allowed_fraction_outside", "min_coverage"},
    "select": {"box_mm", "triangles", "group"},
    "point": {"name", "position_mm", "normal", "direction", "radius_mm", "tolerance_mm",
              "min_coverage"},
    "section": {"name", "point_mm", "normal", "width_mm", "region", "tolerance_mm",
                "allowed_fraction_outside"},
    "hole": {"name", "position_mm", "axis", "diameter_mm", "position_tolerance_mm",
             "diameter_tolerance_mm", "min_arc_deg"},
    "slot": {"name", "position_mm", "axis", "direction", "width_mm", "length_mm",
             "position_tolerance_mm", "width_tolerance_mm", "length_tolerance_mm", "min_arc_deg"},
    "edge_point": {"name", "position_mm", "radius_mm", "tolerance_mm"},
    "defects": {"threshold_mm", "min_area_mm2", "max_count"},
    "alignment": {"mode", "references", "regions", "locked", "max_correction_mm",
                  "max_correction_deg"},
    "reference": {"name", "hole", "position_mm", "radius_mm"},
    "band": {"lower", "upper"},
}


def _read_plan(base, plan):
    """cell.json's "plan": a file name (relative to cell.json), an inline
    object, or absent (None)."""
    if plan is None or isinstance(plan, dict):
        return plan
    if not isinstance(plan, str):
        raise ClientError("cell.json: plan must be a file name or an object")
    path = os.path.join(base, plan)
    try:
        with open(path) as f:
            plan = json.load(f)
    except (OSError, ValueError) as e:
        raise ClientError(f"{path}: {e}") from None
    if not isinstance(plan, dict):
        raise ClientError(f"{path}: plan: not a JSON object")
    return plan


def _keys(obj, kind, where):
    if not isinstance(obj, dict):
        raise ClientError(f"{where}: must be an object")
    for key in obj:
        if key not in _PLAN_KEYS[kind]:
            raise ClientError(f"{where}.{key}: unknown key")


def _band(obj, msg, where):
    _keys(obj, "band", where)
    msg.lower_mm = _number(obj, "lower", where)
    msg.upper_mm = _number(obj, "upper", where)


def _vector3(values, where):
    if not isinstance(values, list) or len(values) != 3:
        raise ClientError(f"{where}: must be an array of 3 numbers")
    return [_number({"v": v}, "v", where) for v in values]


def _optional_numbers(entry, m, where, keys):
    """Each of `keys` the plan entry gives, into the message field of that name."""
    for key in keys:
        if key in entry:
            setattr(m, key, _number(entry, key, where))


def _optional_band(entry, key, band_msg, where):
    """The band `key` of the plan entry, when given, into `band_msg`."""
    if key in entry:
        _band(entry[key], band_msg, f"{where}.{key}")


def _regions(plan, msg):
    for i, r in enumerate(plan.get("regions", [])):
        where = f"plan.regions[{i}]"
        _keys(r, "region", where)
        m = msg.regions.add(name=str(r.get("name", "")))
        s = r.get("select", {})
        _keys(s, "select", where + ".select")
        if "box_mm" in s:
            box = s["box_mm"]
            if not isinstance(box, list) or len(box) != 2:
                raise ClientError(f"{where}.select.box_mm: must be [[x, y, z], [x, y, z]]")
            m.select.box_mm.min_mm.extend(_vector3(box[0], where + ".select.box_mm[0]"))
            m.select.box_mm.max_mm.extend(_vector3(box[1], where + ".select.box_mm[1]"))
        elif "triangles" in s:
            m.select.triangles.SetInParent()
            for k, t in enumerate(s["triangles"]):
                m.select.triangles.ids.append(
                    _number({"t": t}, "t", f"{where}.select.triangles[{k}]", True, 0, 2**32 - 1))
        elif "group" in s:
            m.select.group = str(s["group"])
        _optional_band(r, "tolerance_mm", m.tolerance_mm, where)
        _optional_numbers(r, m, where, ("allowed_fraction_outside", "min_coverage"))


def _points(plan, msg):
    for i, p in enumerate(plan.get("points", [])):
        where = f"plan.points[{i}]"
        _keys(p, "point", where)
        m = msg.points.add(name=str(p.get("name", "")))
        m.position_mm.extend(_vector3(p.get("position_mm"), where + ".position_mm"))
        for key in ("normal", "direction"):
            if key in p:
                getattr(m, key).extend(_vector3(p[key], f"{where}.{key}"))
        _optional_numbers(p, m, where, ("radius_mm", "min_coverage"))
        _optional_band(p, "tolerance_mm", m.tolerance_mm, where)


def _sections(plan, msg):
    for i, c in enumerate(plan.get("sections", [])):
        where = f"plan.sections[{i}]"
        _keys(c, "section", where)
        m = msg.sections.add(name=str(c.get("name", "")), region=str(c.get("region", "")))
        m.point_mm.extend(_vector3(c.get("point_mm"), where + ".point_mm"))
        m.normal.extend(_vector3(c.get("normal"), where + ".normal"))
        _optional_numbers(c, m, where, ("width_mm", "allowed_fraction_outside"))
        _optional_band(c, "tolerance_mm", m.tolerance_mm, where)


def _holes(plan, msg):
    """Holes, then slots, as the C++ parser orders them (PlanHole.slot)."""
    for kind, size in (("hole", "diameter"), ("slot", "width")):
        for i, h in enumerate(plan.get(kind + "s", [])):
            where = f"plan.{kind}s[{i}]"
            _keys(h, kind, where)
            required = ["position_mm", "axis", size + "_mm"]
            required += ["length_mm", "direction"] if kind == "slot" else []
            for key in required:
                if key not in h:
                    raise ClientError(f"{where}.{key}: missing")
            m = msg.holes.add(name=str(h.get("name", "")), slot=kind == "slot")
            m.position_mm.extend(_vector3(h.get("position_mm"), where + ".position_mm"))
            m.axis.extend(_vector3(h.get("axis"), where + ".axis"))
            m.diameter_mm = _number(h, size + "_mm", where)
            _optional_numbers(h, m, where, ("position_tolerance_mm", "min_arc_deg"))
            _optional_band(h, size + "_tolerance_mm", m.diameter_tolerance_mm, where)
            if kind == "slot":
                m.length_mm = _number(h, "length_mm", where)
                m.direction.extend(_vector3(h.get("direction"), where + ".direction"))
                _optional_band(h, "length_tolerance_mm", m.length_tolerance_mm, where)


def _edge_points(plan, msg):
    for i, e in enumerate(plan.get("edge_points", [])):
        where = f"plan.edge_points[{i}]"
        _keys(e, "edge_point", where)
        m = msg.edge_points.add(name=str(e.get("name", "")))
        m.position_mm.extend(_vector3(e.get("position_mm"), where + ".position_mm"))
        _optional_numbers(e, m, where, ("radius_mm",))
        _optional_band(e, "tolerance_mm", m.tolerance_mm, where)


_ALIGNMENT_MODES = {"calibrated": pb.ALIGNMENT_MODE_CALIBRATED, "rps": pb.ALIGNMENT_MODE_RPS,
                    "best_fit": pb.ALIGNMENT_MODE_BEST_FIT}


def _strings(values, where):
    if not isinstance(values, list) or not all(isinstance(v, str) for v in values):
        raise ClientError(f"{where}: must be an array of strings")
    return values


def _alignment(plan, msg):
    """docs/alignment.md; the server checks the references against the plan."""
    if "alignment" not in plan:
        return
    a, where = plan["alignment"], "plan.alignment"
    _keys(a, "alignment", where)
    if a.get("mode") not in _ALIGNMENT_MODES:
        raise ClientError(f"{where}.mode: must be calibrated, rps or best_fit")
    m = msg.alignment
    m.mode = _ALIGNMENT_MODES[a["mode"]]
    for i, r in enumerate(a.get("references", [])):
        w = f"{where}.references[{i}]"
        _keys(r, "reference", w)
        ref = m.references.add(name=str(r.get("name", "")), hole=str(r.get("hole", "")))
        if "position_mm" in r:
            ref.position_mm.extend(_vector3(r["position_mm"], w + ".position_mm"))
        _optional_numbers(r, ref, w, ("radius_mm",))
    m.regions.extend(_strings(a.get("regions", []), where + ".regions"))
    m.locked.extend(_strings(a.get("locked", []), where + ".locked"))
    _optional_numbers(a, m, where, ("max_correction_mm", "max_correction_deg"))


def plan_proto(plan):
    """The JSON plan as the typed InspectionPlan message. Keys and shapes are
    checked here, naming the field; the server checks the values against the
    part mesh (INVALID_ARGUMENT "part.plan...")."""
    msg = pb.InspectionPlan()
    _keys(plan, "plan", "plan")
    if "tolerance_mm" in plan:
        _band(plan["tolerance_mm"], msg.tolerance_mm, "plan.tolerance_mm")
    for key in ("allowed_fraction_outside", "min_coverage", "coverage_distance_mm"):
        if key in plan:
            setattr(msg, key, _number(plan, key, "plan"))
    if "allow_not_measured" in plan:
        if not isinstance(plan["allow_not_measured"], bool):
            raise ClientError("plan.allow_not_measured: must be true or false")
        msg.allow_not_measured = plan["allow_not_measured"]
    _regions(plan, msg)
    _points(plan, msg)
    _sections(plan, msg)
    _holes(plan, msg)
    _edge_points(plan, msg)
    _alignment(plan, msg)
    if "defects" in plan:
        d = plan["defects"]
        _keys(d, "defects", "plan.defects")
        msg.defects.SetInParent()
        for key in ("threshold_mm", "min_area_mm2"):
            if key in d:
                setattr(msg.defects, key, _number(d, key, "plan.defects"))
        if "max_count" in d:
            msg.defects.max_count = _number(d, "max_count", "plan.defects", True, 0, 2**31 - 1)
    return msg


# ---- the call ------------------------------------------------------------

def connect(target, tls_ca=None, tls_cert=None, tls_key=None):
    """A channel that spreads calls over every address the target resolves
    to (round_robin): a headless Service (dns:///...) or ipv4:a:p,b:p."""
    options = [("grpc.lb_policy_name", "round_robin"),
               ("grpc.max_receive_message_length", 1 << 30),
               ("grpc.max_send_message_length", 1 << 30)]
    if not tls_ca:
        return grpc.insecure_channel(target, options=options)

    def read(p):
        with open(p, "rb") as f:
            return f.read()
    creds = grpc.ssl_channel_credentials(read(tls_ca), tls_key and read(tls_key), tls_cert and read(tls_cert))
    return grpc.secure_channel(target, creds, options=options)


def _number(settings, key, what, integer=False, lo=None, hi=None):
    """settings[key] as a float or an int within [lo, hi], or a ClientError
    naming the field (cell.json values go into fixed-width proto fields)."""
    value = settings[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ClientError(f"cell.json: {what}.{key} must be a finite number, not {value!r}")
    if integer and value != int(value):
        raise ClientError(f"cell.json: {what}.{key} must be a whole number, not {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ClientError(f"cell.json: {what}.{key} = {value!r} is outside [{lo}, {hi}]")
    return int(value) if integer else float(value)


def _header(cell, part_id, mesh_ref):
    h = pb.PartHeader(part_id=part_id, idempotency_key=part_id, part=mesh_ref,
                      world_from_part=cell["world_from_part"], return_deviations=False, return_png=False)
    e = cell["error_map"]
    if cell["tolerance_mm"] is not None:
        h.error_map.tolerance_mm = _number(cell, "tolerance_mm", "cell", lo=0)
    for key in ("max_distance_mm", "allowed_fraction_outside"):
        if key in e:
            setattr(h.error_map, key, _number(e, key, "error_map", lo=0))
    if "histogram_bins" in e:
        h.error_map.histogram_bins = _number(e, "histogram_bins", "error_map", True, 0, 2**31 - 1)
    f = cell["filter"]
    h.skip_filter = not f.get("enabled", True)
    if "link_distance_mm" in f:
        h.filter.link_distance_mm = _number(f, "link_distance_mm", "filter", lo=0)
    for key in ("min_cluster_points", "connectivity"):
        if key in f:
            setattr(h.filter, key, _number(f, key, "filter", True, 0, 2**32 - 1))
    if cell.get("plan") is not None:
        h.plan.CopyFrom(plan_proto(cell["plan"]))
    return h


def _requests(header, views):
    yield pb.InspectRequest(part=header)
    for name, world_from_sensor, (xyz, width, height) in views:
        yield pb.InspectRequest(view=pb.ViewHeader(name=name, world_from_sensor=world_from_sensor,
                                                   width=width, height=height))
        for off in range(0, len(xyz), CHUNK_BYTES):
            yield pb.InspectRequest(chunk=pb.CloudChunk(xyz=xyz[off:off + CHUNK_BYTES]))
    yield pb.InspectRequest(end=pb.EndOfPart())


def load_views(cell, scans_dir):
    """(name, world_from_sensor, (xyz, width, height)) per viewpoint scan."""
    views = []
    for name, world_from_sensor in cell["viewpoints"]:
        path = os.path.join(scans_dir, name + ".pcd")
        if not os.path.exists(path):
            continue
        if world_from_sensor is None:
            raise ClientError(f"viewpoint {name} is not calibrated (run cell-agent calibrate)")
        views.append((name, _transform(world_from_sensor, f"{name}.world_from_sensor"), read_pcd(path)))
    if not views:
        raise ClientError(f"{scans_dir}: no <viewpoint>.pcd scans of this cell's viewpoints")
    return views


# Codes a later call may not get: the server (or every replica) was busy,
# out of memory budget, unreachable or too slow. The C++ clients retry the
# same set (client/remote/remote_client.cpp IsRetryable).
RETRYABLE = (grpc.StatusCode.RESOURCE_EXHAUSTED, grpc.StatusCode.UNAVAILABLE,
             grpc.StatusCode.DEADLINE_EXCEEDED, grpc.StatusCode.ABORTED)


def backoff_wait(retry, initial_s=0.5, max_s=15.0, rng=random):
    """The wait before retry `retry` (0 = the first), s: exponential backoff
    with full jitter (Brooker, "Exponential Backoff And Jitter", 2015),
    uniform in [0, min(max_s, initial_s * 2**retry)], as the cell-agent does."""
    return rng.uniform(0.0, min(max_s, initial_s * 2.0 ** min(retry, 60)))


def _stream_part(stub, header, views, timeout_s, metadata, on_progress):
    result = None
    for resp in stub.Inspect(_requests(header, views), timeout=timeout_s, metadata=metadata,
                             wait_for_ready=True):
        if resp.HasField("progress") and on_progress:
            on_progress(resp.progress)
        if resp.HasField("result"):
            result = resp.result
    if result is None:
        raise ClientError("Inspect stream ended without a result")
    return result


def inspect_part(channel, cell, scans_dir, part_id, token=None, timeout_s=300, on_progress=None,
                 mesh="auto", max_attempts=8, backoff_initial_s=0.5, backoff_max_s=15.0,
                 on_retry=None, sleep=time.sleep):
    """Streams one part to Inspect and returns the InspectResult.

    mesh: "inline", "hash", or "auto" (inline when the mesh is at most 1/8
    of the clouds' bytes, as the C++ clients do). By hash, a replica that has
    not cached the mesh answers FAILED_PRECONDITION "MESH_NOT_CACHED" and the
    part is sent again with the mesh inline; under round_robin that retry
    lands on another replica, which is why small meshes go inline at once.

    A call that fails with a RETRYABLE code (a server out of memory budget
    answers RESOURCE_EXHAUSTED before the clouds are buffered) is made again
    after backoff_wait(), up to max_attempts calls in all (0 = no limit);
    on_retry(error, calls_so_far, wait_s) is told before each wait.
    timeout_s bounds each call. Raises grpc.RpcError for failed calls.
    """
    vertices, triangles = read_stl(cell["part_mesh"])
    views = load_views(cell, scans_dir)
    stub = pb_grpc.InspectionServiceStub(channel)
    metadata = [("x-request-id", part_id)]
    if token:
        metadata.append(("authorization", "Bearer " + token))
    by_hash = pb.MeshRef(sha256=mesh_sha256(vertices, triangles))
    inline = pb.MeshRef(inline=pb.InlineMesh(vertices=vertices, triangles=triangles))
    if mesh == "auto":
        cloud_bytes = sum(len(xyz) for _, _, (xyz, _, _) in views)
        mesh = "inline" if len(vertices) + len(triangles) <= cloud_bytes // 8 else "hash"
    if mesh not in ("hash", "inline"):
        raise ClientError(f"mesh must be auto, hash or inline, not {mesh!r}")
    mesh_ref = by_hash if mesh == "hash" else inline
    calls = 0
    while True:
        calls += 1
        try:
            return _stream_part(stub, _header(cell, part_id, mesh_ref), views, timeout_s, metadata,
                                on_progress)
        except grpc.RpcError as e:
            if mesh_ref is by_hash and e.code() == grpc.StatusCode.FAILED_PRECONDITION and \
                    (e.details() or "").startswith("MESH_NOT_CACHED"):
                mesh_ref, calls = inline, calls - 1  # not a failure: send the mesh along
                continue
            if e.code() not in RETRYABLE or (max_attempts and calls >= max_attempts):
                raise
            wait = backoff_wait(calls - 1, backoff_initial_s, backoff_max_s)
            if on_retry:
                on_retry(e, calls, wait)
            sleep(wait)
