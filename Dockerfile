# surfinspect container image: surfinspectd (the default command), the
# surfinspect CLI, cell-agent and surfinspect-cad-worker (STEP/IGES parts,
# run by the CLI and the agent as a limited child; docs/cad.md). Two stages:
#   build    debian:bookworm       the README's own `./run deps` + `./run build`
#   runtime  debian:bookworm-slim  only the shared libraries the binaries link
#                                  (tests/deploy/deploy_files_test.py checks
#                                  the list against the built binaries), and
#                                  the font report.pdf embeds (DejaVu Sans)
#   docker build -t surfinspect:0.1.0 .        (or: deploy/build-image.sh)
#   docker run --rm -p 50051:50051 -p 9464:9464 surfinspect:0.1.0
FROM debian:bookworm AS build
WORKDIR /src
# Dependencies first: this layer stays cached while only sources change.
COPY run ./run
RUN ./run deps && rm -rf /var/lib/apt/lists/*
COPY . .
# Tests are not shipped; `./run build` passes extra arguments on to CMake.
RUN ./run build -DBUILD_TESTING=OFF \
 && strip build/bin/surfinspectd build/bin/surfinspect build/bin/cell-agent \
          build/bin/surfinspect-cad-worker

FROM debian:bookworm-slim AS runtime
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
      libabsl20220623 libassimp5 libembree3-3 libfmt9 libgrpc++1.51 libgrpc29 \
      libmosquitto1 libpng16-16 libprometheus-cpp-core1.0 \
      libprometheus-cpp-pull1.0 libprotobuf32 libpugixml1v5 libspdlog1.10 libssl3 libstdc++6 \
      libtbb12 libcairo2 libglib2.0-0 libpango-1.0-0 libpangocairo-1.0-0 fonts-dejavu-core \
      libsqlite3-0 libpqxx-6.4 libpq5 zlib1g \
      libocct-foundation-7.6 libocct-modeling-data-7.6 libocct-modeling-algorithms-7.6 \
      libocct-data-exchange-7.6 libocct-ocaf-7.6 \
 && rm -rf /var/lib/apt/lists/*
RUN useradd --system --uid 10001 --user-group --home-dir /var/lib/surfinspect --create-home \
      --shell /usr/sbin/nologin surfinspect
COPY --from=build /src/build/bin/surfinspectd /src/build/bin/surfinspect /src/build/bin/cell-agent \
     /src/build/bin/surfinspect-cad-worker /usr/local/bin/
COPY --from=build /src/proto /usr/local/share/surfinspect/proto
# Numeric, so Kubernetes' runAsNonRoot can verify it.
USER 10001:10001
WORKDIR /var/lib/surfinspect
ENV SURFINSPECT_LISTEN=0.0.0.0:50051 \
    SURFINSPECT_METRICS_LISTEN=0.0.0.0:9464
# gRPC (inspection, grpc.health.v1, reflection) and Prometheus /metrics.
EXPOSE 50051 9464
# Plaintext health check on the gRPC port; with TLS on, Kubernetes uses the
# tls/ overlay's exec probe instead (see deploy/k8s/tls).
HEALTHCHECK --interval=10s --timeout=5s --start-period=5s --retries=3 \
  CMD ["surfinspect", "health", "--server", "127.0.0.1:50051"]
# SIGTERM drains: health NOT_SERVING, new calls refused, SURFINSPECT_DRAIN_SECONDS
# (default 20) for calls in flight. Give `docker stop -t` more than that.
STOPSIGNAL SIGTERM
ENTRYPOINT ["surfinspectd"]
