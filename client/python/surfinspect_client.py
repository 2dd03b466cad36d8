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
import os
import struct

import grpc

from surfinspect.v1 import inspection_pb2 as pb
from surfinspect.v1 import inspection_pb2_grpc as pb_grpc

CHUNK_BYTES = 1 << 20  # ~1 MB per CloudChunk, like the C++ clients
MAX_POINTS = 50_000_000  # sanity cap on sizes declared by a file header


class ClientError(Exception):
    """Bad input or a failed call, with a message meant for an operator."""


# ---- files ---------------------------------------------------------------

def read_pcd(path):
    """(xyz bytes as little-endian float32, width, height) of a PCD file.

    Reads the ascii and binary encodings with x, y, z float32 fields among any
    others; NaN marks a pixel with no data (organized grids are kept).
    """
    with open(path, "rb") as f:
        data = f.read()
    header, offset = {}, 0
    while True:
        end = data.find(b"\n", offset)
        if end < 0:
            raise ClientError(f"{path}: truncated PCD header")
        line = data[offset:end].decode("ascii", "replace").strip()
        offset = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        header[key.upper()] = value.split()
        if key.upper() == "DATA":
            break
    try:
        fields = header["FIELDS"]
        sizes = [int(s) for s in header["SIZE"]]
        types = header["TYPE"]
        counts = [int(c) for c in header.get("COUNT", ["1"] * len(fields))]
        width, height = int(header["WIDTH"][0]), int(header["HEIGHT"][0])
        encoding = header["DATA"][0]
    except (KeyError, ValueError, IndexError) as e:
        raise ClientError(f"{path}: malformed PCD header ({e})") from None
    n = width * height
    if not 0 < n <= MAX_POINTS or not len(fields) == len(sizes) == len(types) == len(counts):
        raise ClientError(f"{path}: bad PCD sizes ({width} x {height}, {len(fields)} fields)")
    for axis in "xyz":
        if axis not in fields:
            raise ClientError(f"{path}: no {axis} field")
        i = fields.index(axis)
        if (sizes[i], types[i], counts[i]) != (4, "F", 1):
            raise ClientError(f"{path}: field {axis} is not a float32")
    if encoding == "binary":
        return _pcd_binary_xyz(path, data[offset:], fields, sizes, counts, n), width, height
    if encoding == "ascii":
        return _pcd_ascii_xyz(path, data[offset:], fields, counts, n), width, height
    raise ClientError(f"{path}: PCD encoding {encoding!r} is not supported here (use ascii or binary)")


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
    lines = body.decode("ascii", "replace").split("\n")
    rows = [l for l in lines if l.strip()]
    if len(rows) < n:
        raise ClientError(f"{path}: truncated: {len(rows)} points, header declares {n}")
    out = bytearray()
    pack = struct.Struct("<3f").pack
    for row in rows[:n]:
        v = row.split()
        try:
            out += pack(*(float(v[columns[a]]) for a in "xyz"))
        except (ValueError, IndexError):
            raise ClientError(f"{path}: bad point line {row!r}") from None
    return bytes(out)


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
        for line in data.decode("ascii", "replace").splitlines():
            w = line.split()
            if len(w) == 4 and w[0] == "vertex":
                # Round through float32: the wire and the C++ reader use it.
                corners.append(struct.unpack("<3f", struct.pack("<3f", *map(float, w[1:]))))
        if len(corners) % 3:
            raise ClientError(f"{path}: ascii STL with a facet that is not a triangle")
    else:
        raise ClientError(f"{path}: not an STL file (binary size mismatch, no 'solid')")
    if not corners:
        raise ClientError(f"{path}: no triangles")
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
        }
    except (KeyError, TypeError) as e:
        raise ClientError(f"{path}: missing {e}") from None
    return cell


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


def _header(cell, part_id, mesh_ref):
    h = pb.PartHeader(part_id=part_id, idempotency_key=part_id, part=mesh_ref,
                      world_from_part=cell["world_from_part"], return_deviations=False, return_png=False)
    e = cell["error_map"]
    if cell["tolerance_mm"] is not None:
        h.error_map.tolerance_mm = float(cell["tolerance_mm"])
    for key in ("max_distance_mm", "allowed_fraction_outside"):
        if key in e:
            setattr(h.error_map, key, float(e[key]))
    if "histogram_bins" in e:
        h.error_map.histogram_bins = int(e["histogram_bins"])
    f = cell["filter"]
    h.skip_filter = not f.get("enabled", True)
    if "link_distance_mm" in f:
        h.filter.link_distance_mm = float(f["link_distance_mm"])
    for key in ("min_cluster_points", "connectivity"):
        if key in f:
            setattr(h.filter, key, int(f[key]))
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


def inspect_part(channel, cell, scans_dir, part_id, token=None, timeout_s=300, on_progress=None,
                 mesh="auto"):
    """Streams one part to Inspect and returns the InspectResult.

    mesh: "inline", "hash", or "auto" (inline when the mesh is at most 1/8
    of the clouds' bytes, as the C++ clients do). By hash, a replica that has
    not cached the mesh answers FAILED_PRECONDITION "MESH_NOT_CACHED" and the
    part is sent again with the mesh inline; under round_robin that retry
    lands on another replica, which is why small meshes go inline at once.
    Raises grpc.RpcError for failed calls.
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
    for mesh_ref in ((by_hash, inline) if mesh == "hash" else (inline,)):
        result = None
        try:
            for resp in stub.Inspect(_requests(_header(cell, part_id, mesh_ref), views), timeout=timeout_s,
                                     metadata=metadata, wait_for_ready=True):
                if resp.HasField("progress") and on_progress:
                    on_progress(resp.progress)
                if resp.HasField("result"):
                    result = resp.result
        except grpc.RpcError as e:
            if mesh_ref is by_hash and e.code() == grpc.StatusCode.FAILED_PRECONDITION and \
                    (e.details() or "").startswith("MESH_NOT_CACHED"):
                continue
            raise
        if result is None:
            raise ClientError("Inspect stream ended without a result")
        return result
    raise AssertionError("unreachable")
