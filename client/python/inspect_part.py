#!/usr/bin/env python3
"""Inspect one part on surfinspectd and print the verdict: the example an MES
integrator starts from.

  client/python/generate.sh /tmp/gen
  PYTHONPATH=/tmp/gen:client/python /usr/bin/python3 client/python/inspect_part.py \
      --cell cell/cell.json --scans inbox/part-001 --server 127.0.0.1:50051

Prints "<part-id> pass|fail  min <mm> max <mm>" and exits 0 (pass), 1 (fail)
or 2 (the part could not be inspected: bad input, or the call failed).
"""
import argparse
import os
import sys
import tempfile

import grpc

import surfinspect_client as sc


def write_atomically(path, text):
    """Temporary file in the same folder, then rename: never a half report."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".tmp-")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cell", required=True, help="calibrated cell.json")
    ap.add_argument("--scans", required=True, help="folder with <viewpoint>.pcd of one part")
    ap.add_argument("--server", required=True, help="gRPC target: host:port, dns:///name:port, ipv4:a:p,b:p")
    ap.add_argument("--part-id", help="default: the scans folder's name")
    ap.add_argument("--report", help="write the report JSON here")
    ap.add_argument("--token-file", help="file with the bearer token")
    ap.add_argument("--tls-ca", help="PEM CA of the server certificate (enables TLS)")
    ap.add_argument("--tls-cert", help="client certificate (mTLS)")
    ap.add_argument("--tls-key", help="client key (mTLS)")
    ap.add_argument("--timeout", type=float, default=300, help="seconds for the whole part")
    ap.add_argument("--mesh", choices=("auto", "hash", "inline"), default="auto",
                    help="send the part mesh inline, by its SHA-256, or inline when small (auto)")
    a = ap.parse_args()
    part_id = a.part_id or os.path.basename(os.path.normpath(a.scans))
    try:
        token = None
        if a.token_file:
            with open(a.token_file) as f:
                token = f.read().strip()
        cell = sc.read_cell(a.cell)
        with sc.connect(a.server, a.tls_ca, a.tls_cert, a.tls_key) as channel:
            result = sc.inspect_part(channel, cell, a.scans, part_id, token=token, timeout_s=a.timeout,
                                     mesh=a.mesh)
    except (sc.ClientError, OSError) as e:
        print(f"{part_id}: error: {e}", file=sys.stderr)
        return 2
    except grpc.RpcError as e:
        print(f"{part_id}: error: {e.code().name}: {e.details()}", file=sys.stderr)
        return 2
    if a.report:
        write_atomically(a.report, result.report_json)
    # The typed results: the part verdict, statistics, characteristics, defects.
    verdict = "pass" if result.part_verdict == sc.pb.VERDICT_PASS else "fail"
    print(f"{part_id} {verdict}  min {result.statistics.min_mm:+.3f} mm"
          f"  max {result.statistics.max_mm:+.3f} mm")
    for c in result.characteristics:
        if c.verdict == sc.pb.VERDICT_NOT_MEASURED:
            print(f"  not measured {c.name}: {c.reason}")
        elif c.verdict != sc.pb.VERDICT_PASS:
            print(f"  failed {c.name}: {c.reason}")
    for d in result.defects:
        kind = "dent" if d.kind == sc.pb.DEFECT_DENT else "bump"
        x, y, z = d.centroid_mm
        print(f"  defect {d.id} {kind} at ({x:.1f}, {y:.1f}, {z:.1f}) mm: peak {d.peak_mm:+.3f} mm,"
              f" {d.area_mm2:.1f} mm2")
    return 0 if verdict == "pass" else 1


if __name__ == "__main__":
    sys.exit(main())
