#!/usr/bin/env bash
# Builds the surfinspect image from the top-level Dockerfile without a Docker
# daemon (podman/buildah with vfs storage and chroot isolation), optionally
# from local base images, then smoke-tests it.
#
#   deploy/build-image.sh [--local-base] [--smoke] [TAG]     (default TAG surfinspect:0.1.0)
#
#   --local-base  no registry needed: make debian:bookworm and
#                 debian:bookworm-slim from `debootstrap --variant=minbase`
#                 (a Debian mirror is still needed for apt) and import them
#   --smoke       run the image: the server must answer `surfinspect health`
#
# Needs root and Debian's podman (apt-get install podman buildah runc, plus
# debootstrap for --local-base). The build compiles the whole project: about
# 10+ minutes on 2 cores; it runs under `nice -n 19`.
set -euo pipefail
cd "$(dirname "$0")/.."
LOCAL_BASE=0
SMOKE=0
TAG=surfinspect:0.1.0
for a in "$@"; do
  case "$a" in
    --local-base) LOCAL_BASE=1 ;;
    --smoke) SMOKE=1 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) TAG=$a ;;
  esac
done
say() { printf '\033[1m[build-image]\033[0m %s\n' "$*" >&2; }
die() { printf '\033[31m[build-image] error:\033[0m %s\n' "$*" >&2; exit 1; }
command -v podman >/dev/null || die "podman not found (apt-get install podman buildah runc)"
# vfs + chroot isolation work without overlayfs or user namespaces; runc
# with cgroupfs runs containers where crun fails (hybrid cgroups).
PODMAN=(podman --storage-driver vfs --runtime runc --cgroup-manager cgroupfs)

if [ "$LOCAL_BASE" = 1 ]; then
  command -v debootstrap >/dev/null || die "debootstrap not found (apt-get install debootstrap)"
  MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
  ROOTFS=$(mktemp -d /tmp/surfinspect-rootfs.XXXXXX)
  trap 'rm -rf "$ROOTFS"' EXIT
  say "debootstrap --variant=minbase bookworm ($MIRROR)"
  nice -n 19 debootstrap --variant=minbase bookworm "$ROOTFS" "$MIRROR" >/dev/null
  rm -rf "$ROOTFS"/var/lib/apt/lists/* "$ROOTFS"/var/cache/apt/archives/*.deb
  for base in debian:bookworm debian:bookworm-slim; do
    say "importing $base"
    tar -C "$ROOTFS" --numeric-owner -c . |
      "${PODMAN[@]}" import --change 'ENV=PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
        --change 'CMD=["bash"]' - "$base" >/dev/null
  done
fi

say "podman build -t $TAG (whole project; nice -n 19)"
nice -n 19 "${PODMAN[@]}" build --isolation chroot --pull=never -t "$TAG" -f Dockerfile .
"${PODMAN[@]}" image ls "$TAG"

if [ "$SMOKE" = 1 ]; then
  PORT=${SMOKE_PORT:-55051}
  say "smoke test: surfinspectd in the image on 127.0.0.1:$PORT"
  CID=$("${PODMAN[@]}" run -d --rm --network host -e SURFINSPECT_LISTEN=127.0.0.1:$PORT \
          -e SURFINSPECT_METRICS_LISTEN= "$TAG")
  trap '"${PODMAN[@]}" stop -t 30 "$CID" >/dev/null 2>&1 || true; rm -rf "${ROOTFS:-}"' EXIT
  for _ in $(seq 50); do
    "${PODMAN[@]}" exec "$CID" surfinspect health --server 127.0.0.1:$PORT >/dev/null 2>&1 && break
    sleep 0.2
  done
  "${PODMAN[@]}" exec "$CID" surfinspect health --server 127.0.0.1:$PORT
  "${PODMAN[@]}" exec "$CID" id -u | grep -qx 10001 || die "the image does not run as uid 10001"
  say "ok: $TAG serves, as uid 10001"
fi
