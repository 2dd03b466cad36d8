#!/usr/bin/env python3
"""Writes the seed corpora of the request targets (fuzz/targets/requests_fuzz.cpp):
valid requests and a few invalid ones, each in protobuf text form encoded by
`protoc --encode`, into fuzz/corpus/<target>/seed-<name>. inspect_stream seeds
are sequences of InspectRequest messages, each a 2-byte little-endian length
and its bytes. Run from the repository root: python3 fuzz/make_request_seeds.py"""
import math
import pathlib
import struct
import subprocess

ROOT = pathlib.Path(__file__).resolve().parent.parent
PROTO = "surfinspect/v1/inspection.proto"


def encode(message, text):
    return subprocess.run(["protoc", f"--encode=surfinspect.v1.{message}",
                           f"--proto_path={ROOT / 'proto'}", PROTO],
                          input=text.encode(), capture_output=True, check=True).stdout


def esc(raw):
    return '"' + "".join(f"\\{b:03o}" for b in raw) + '"'


def floats(values):
    return struct.pack(f"<{len(values)}f", *values)


def cloud_bytes(w, h, hole=True):
    pts = []
    for i in range(w * h):
        pts += [math.nan] * 3 if hole and i == 1 else [float(i), 0.5 * i, 100.0 + i]
    return floats(pts)


def transform(tx=0.0):
    m = [1, 0, 0, tx, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    return "{ " + " ".join(f"row_major: {v}" for v in m) + " }"


def cloud(w, h, raw=None):
    raw = cloud_bytes(w, h) if raw is None else raw
    return f"{{ xyz: {esc(raw)} width: {w} height: {h} }}"


def packed_cloud(w, h):
    """cloud_bytes' grid without its no-data point (index 1), by valid_bits."""
    raw = cloud_bytes(w, h)
    bits = bytearray((w * h + 7) // 8)
    kept = b""
    for i in range(w * h):
        if i != 1:
            bits[i // 8] |= 1 << (i % 8)
            kept += raw[12 * i:12 * i + 12]
    return f"{{ xyz: {esc(kept)} width: {w} height: {h} valid_bits: {esc(bytes(bits))} }}"


MESH = ("{ inline { vertices: " + esc(floats([0, 0, 0, 100, 0, 0, 0, 100, 0])) +
        " triangles: " + esc(struct.pack("<3I", 0, 1, 2)) + " } }")
FILTER = "{ link_distance_mm: 0.5 min_cluster_points: 4 connectivity: 8 min_fraction_of_largest: 0.1 }"
ERRMAP = ("{ tolerance_mm: 0.1 max_distance_mm: 5 allowed_fraction_outside: 0.01 "
          "histogram_bins: 41 histogram_range_mm: 1.5 split_components: true }")
ICP = "{ max_iterations: 50 max_correspondence_mm: 20 min_correspondence_mm: 2 trim_fraction: 0.1 }"

SEEDS = {
    "filter_request": {
        "valid": ("FilterRequest", f"cloud: {cloud(3, 2)} settings: {FILTER}"),
        "defaults": ("FilterRequest", f"cloud: {cloud(4, 1)}"),
        "short-bytes": ("FilterRequest", f"cloud: {{ xyz: {esc(b'abc')} width: 2 height: 2 }}"),
        "packed": ("FilterRequest", f"cloud: {packed_cloud(5, 3)} settings: {FILTER}"),
        "bad-settings": ("FilterRequest", f"cloud: {cloud(2, 1)} settings: {{ connectivity: 5 }}"),
    },
    "calibrate_request": {
        "valid": ("CalibrateRequest", f"gauge: {MESH} world_from_gauge: {transform(10)} "
                  f"scan: {cloud(3, 3)} initial_world_from_sensor: {transform()} icp: {ICP} "
                  f"filter: {FILTER}"),
        "by-hash": ("CalibrateRequest", f"gauge {{ sha256: \"{'0' * 64}\" }} "
                    f"world_from_gauge: {transform()} scan: {cloud(2, 2)} "
                    f"initial_world_from_sensor: {transform()} skip_filter: true"),
        "short-transform": ("CalibrateRequest", "world_from_gauge { row_major: 1 row_major: 2 }"),
    },
    "register_request": {
        "valid": ("RegisterRequest", f"views {{ name: \"v1\" world_from_sensor: {transform()} "
                  f"cloud: {cloud(3, 2)} }} views {{ name: \"v2\" world_from_sensor: "
                  f"{transform(5)} cloud: {cloud(2, 2)} }} filter: true "
                  f"filter_settings: {FILTER}"),
        "best-fit": ("RegisterRequest", f"views {{ world_from_sensor: {transform()} "
                     f"cloud: {cloud(2, 2)} }} best_fit: true part: {MESH} "
                     f"world_from_part: {transform()}"),
        "no-views": ("RegisterRequest", "filter: true"),
        "huge-view": ("RegisterRequest", f"views {{ world_from_sensor: {transform()} "
                      "cloud { width: 100000 height: 100000 } }"),
    },
    "errormap_request": {
        "valid": ("ErrorMapRequest", f"cloud: {cloud(3, 2)} part: {MESH} "
                  f"world_from_part: {transform()} settings: {ERRMAP} return_deviations: true"),
        "defaults": ("ErrorMapRequest", f"cloud: {cloud(2, 2)} part {{ sha256: \"abc\" }} "
                     f"world_from_part: {transform()}"),
        "packed": ("ErrorMapRequest", f"cloud: {packed_cloud(3, 3)} part: {MESH} "
                   f"world_from_part: {transform()} return_deviations: true"),
        "even-bins": ("ErrorMapRequest", f"cloud: {cloud(1, 1)} part: {MESH} "
                      f"world_from_part: {transform()} settings {{ histogram_bins: 40 }}"),
    },
}


def frame(messages):
    out = b""
    for text in messages:
        raw = encode("InspectRequest", text)
        out += struct.pack("<H", len(raw)) + raw
    return out


PART = (f"part {{ part_id: \"p1\" part: {MESH} world_from_part: {transform()} "
        f"error_map: {ERRMAP} filter: {FILTER} return_deviations: true }}")
V1 = cloud_bytes(3, 2)
STREAMS = {
    "valid": [PART, f"view {{ name: \"v1\" world_from_sensor: {transform()} width: 3 height: 2 }}",
              f"chunk {{ xyz: {esc(V1[:30])} }}", f"chunk {{ xyz: {esc(V1[30:])} }}",
              f"view {{ world_from_sensor: {transform(1)} width: 1 height: 1 }}",
              f"chunk {{ xyz: {esc(floats([1, 2, 3]))} }}", "end { }"],
    "by-hash": [f"part {{ part_id: \"p2\" part {{ sha256: \"{'0' * 64}\" }} "
                f"world_from_part: {transform()} skip_filter: true }}",
                f"view {{ world_from_sensor: {transform()} width: 2 height: 1 }}",
                f"chunk {{ xyz: {esc(floats([1, 2, 3, 4, 5, 6]))} }}", "end { }"],
    "view-first": [f"view {{ world_from_sensor: {transform()} width: 1 height: 1 }}"],
    "incomplete-view": [PART, f"view {{ world_from_sensor: {transform()} width: 2 height: 2 }}",
                        f"chunk {{ xyz: {esc(floats([1, 2, 3]))} }}", "end { }"],
    "too-many-points": [PART, f"view {{ world_from_sensor: {transform()} width: 1000 height: 1000 }}",
                        f"view {{ world_from_sensor: {transform()} width: 1000 height: 1000 }}"],
}

for target, seeds in SEEDS.items():
    folder = ROOT / "fuzz" / "corpus" / target
    folder.mkdir(parents=True, exist_ok=True)
    for name, (message, text) in seeds.items():
        (folder / f"seed-{name}").write_bytes(encode(message, text))
folder = ROOT / "fuzz" / "corpus" / "inspect_stream"
folder.mkdir(parents=True, exist_ok=True)
for name, messages in STREAMS.items():
    (folder / f"seed-{name}").write_bytes(frame(messages))
