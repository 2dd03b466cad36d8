#!/usr/bin/env bash
# Builds the surfinspect image from the top-level Dockerfile without a Docker
# daemon (podman/buildah with vfs storage and chroot isolation), optionally
# from local base images, then smoke-tests it.
#
#   deploy/build-image.sh [--local-base] [--smoke] [--no-build] [TAG]
#                                                  (default TAG surfinspect:0.1.0)
#
#   --local-base  no registry needed: make debian:bookworm and
#                 debian:bookworm-slim from `debootstrap --variant=minbase`
#                 (a Debian mirror is still needed for apt) and import them
#   --smoke       run the image's binaries (as uid 10001): health, then the
#                 demo cell calibrated and one part inspected
#   --no-build    only the smoke test, of an image built before
#
# Needs root and Debian's podman (apt-get install podman buildah, plus
# debootstrap for --local-base). The build installs the build dependencies
# and compiles the project (6-9 minutes on 2 shared cores, measured); it runs
# under `nice -n 19`. The image was about 840 MB while its runtime stage
# installed PCL's I/O (which pulls in VTK); it has not been measured since.
set -euo pipefail
cd "$(dirname "$0")/.."
LOCAL_BASE=0
SMOKE=0
BUILD=1
TAG=surfinspect:0.1.0
for a in "$@"; do
  case "$a" in
    --local-base) LOCAL_BASE=1 ;;
    --smoke) SMOKE=1 ;;
    --no-build) BUILD=0 ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) TAG=$a ;;
  esac
done
say() { printf '\033[1m[build-image]\033[0m %s\n' "$*" >&2; }
die() { printf '\033[31m[build-image] error:\033[0m %s\n' "$*" >&2; exit 1; }
command -v podman >/dev/null || die "podman not found (apt-get install podman buildah)"
# vfs storage and chroot isolation work without overlayfs, user namespaces
# or an OCI runtime.
PODMAN=(podman --storage-driver vfs)

if [ "$LOCAL_BASE" = 1 ]; then
  command -v debootstrap >/dev/null || die "debootstrap not found (apt-get install debootstrap)"
  MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
  ROOTFS=$(mktemp -d /tmp/surfinspect-rootfs.XXXXXX)
  trap 'rm -rf "$ROOTFS"' EXIT
  say "debootstrap --variant=minbase bookworm ($MIRROR)"
  nice -n 19 debootstrap --variant=minbase bookworm "$ROOTFS" "$MIRROR" >/dev/null
  rm -rf "$ROOTFS"/var/lib/apt/lists/* "$ROOTFS"/var/cache/apt/archives/*.deb
  # The same apt sources as the official image (updates and security too).
  rm -f "$ROOTFS"/etc/apt/sources.list
  cat > "$ROOTFS"/etc/apt/sources.list.d/debian.sources <<SOURCES
Types: deb
URIs: $MIRROR
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: ${DEBIAN_SECURITY_MIRROR:-http://deb.debian.org/debian-security}
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SOURCES
  for base in debian:bookworm debian:bookworm-slim; do
    say "importing $base"
    tar -C "$ROOTFS" --numeric-owner -c . |
      "${PODMAN[@]}" import --change 'ENV=PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
        --change 'CMD=["bash"]' - "$base" >/dev/null
  done
fi

# Host networking for RUN steps: apt-get needs the mirror, and no bridge
# network is required. Docker format: OCI images drop HEALTHCHECK.
if [ "$BUILD" = 1 ]; then
  say "podman build -t $TAG (whole project; nice -n 19)"
  nice -n 19 "${PODMAN[@]}" build --isolation chroot --network host --pull=never --format docker \
    -t "$TAG" -f Dockerfile .
fi
"${PODMAN[@]}" image ls "$TAG"

if [ "$SMOKE" = 1 ]; then
  # Runs the image's own binaries in a chroot of a container's root file
  # system, as the image's uid 10001: no OCI runtime needed (in some
  # sandboxes runc cannot set the container's rlimits). The image's
  # surfinspectd, surfinspect and cell-agent then do the demo end to end.
  PORT=${SMOKE_PORT:-55051}
  CID=$("${PODMAN[@]}" create --no-healthcheck "$TAG")
  SERVER_PID=""
  cleanup() {
    if [ -n "$SERVER_PID" ]; then kill -TERM "$SERVER_PID" 2>/dev/null || true; wait "$SERVER_PID" || true; fi
    "${PODMAN[@]}" umount "$CID" >/dev/null 2>&1 || true
    "${PODMAN[@]}" rm -f "$CID" >/dev/null 2>&1 || true
    rm -rf "${ROOTFS:-}"
  }
  trap 'rc=$?; set +e; cleanup; exit $rc' EXIT
  ROOT=$("${PODMAN[@]}" mount "$CID")
  chmod 0755 "$ROOT"  # vfs creates the container's root directory 0700
  as_image_user() { chroot --userspec=10001:10001 "$ROOT" /usr/bin/env -i PATH=/usr/local/bin:/usr/bin:/bin "$@"; }
  say "smoke test: the image's surfinspectd on 127.0.0.1:$PORT as uid 10001"
  # exec: $! is then surfinspectd itself (chroot and env exec too).
  (exec chroot --userspec=10001:10001 "$ROOT" /usr/bin/env -i SURFINSPECT_LISTEN=127.0.0.1:$PORT \
     /usr/local/bin/surfinspectd >/dev/null 2>&1) &
  SERVER_PID=$!
  for _ in $(seq 50); do
    as_image_user surfinspect health --server 127.0.0.1:$PORT >/dev/null 2>&1 && break
    sleep 0.2
  done
  as_image_user surfinspect health --server 127.0.0.1:$PORT
  as_image_user /bin/sh -ec "cd /tmp && surfinspect demo-cell --out cell --parts 1 >/dev/null &&
    cell-agent calibrate --cell cell/cell.json --server 127.0.0.1:$PORT | tail -1 &&
    surfinspect inspect --cell cell/cell.json --scans cell/scans/part-001 --out out \
      --server 127.0.0.1:$PORT 2>/dev/null && test -s out/report.json"
  say "ok: $TAG serves and inspects the demo part, as uid 10001"
fi
