#!/usr/bin/env bash
# Generates the Python stubs of the surfinspect contract into OUT_DIR
# (default: ./gen), from Debian's tools: `python3 -m grpc_tools.protoc` when
# grpcio-tools is installed, else protoc (protobuf-compiler) with
# grpc_python_plugin (protobuf-compiler-grpc). Nothing generated is committed.
#   client/python/generate.sh /tmp/gen && PYTHONPATH=/tmp/gen:client/python \
#     /usr/bin/python3 client/python/inspect_part.py --help
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
PROTO_DIR=$(cd "$HERE/../../proto" && pwd)
OUT=${1:-$HERE/gen}
PYTHON=${PYTHON:-/usr/bin/python3}
mkdir -p "$OUT"
if "$PYTHON" -c "import grpc_tools.protoc" 2>/dev/null; then
  "$PYTHON" -m grpc_tools.protoc -I "$PROTO_DIR" --python_out="$OUT" --grpc_python_out="$OUT" \
    "$PROTO_DIR/surfinspect/v1/inspection.proto"
else
  PROTOC=${PROTOC:-$(command -v protoc || true)}
  PLUGIN=${GRPC_PYTHON_PLUGIN:-$(command -v grpc_python_plugin || true)}
  [ -x "$PROTOC" ] || { echo "generate.sh: protoc not found (apt-get install protobuf-compiler)" >&2; exit 1; }
  [ -x "$PLUGIN" ] || { echo "generate.sh: grpc_python_plugin not found (apt-get install protobuf-compiler-grpc)" >&2; exit 1; }
  "$PROTOC" -I "$PROTO_DIR" --python_out="$OUT" --grpc_python_out="$OUT" \
    --plugin=protoc-gen-grpc_python="$PLUGIN" "$PROTO_DIR/surfinspect/v1/inspection.proto"
fi
echo "$OUT/surfinspect/v1/inspection_pb2.py, inspection_pb2_grpc.py"
