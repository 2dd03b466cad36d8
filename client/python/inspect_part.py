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
import json
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
    report = json.loads(result.report_json)
    stats = report.get("statistics", {})
    if a.report:
        write_atomically(a.report, result.report_json)
    print(f"{part_id} {result.verdict}  min {stats.get('min_mm', float('nan')):+.3f} mm"
          f"  max {stats.get('max_mm', float('nan')):+.3f} mm")
    return 0 if result.verdict == "pass" else 1


if __name__ == "__main__":
    sys.exit(main())
