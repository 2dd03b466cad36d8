// The server's request decoders on untrusted bytes: each unary request
// (Filter, Calibrate, Register, ErrorMap) parsed as its v1 message and put
// through the proto/convert validation its handler runs
// (server/inspection_service.cpp) in the same order, and an Inspect stream
// as a sequence of messages through wire::InspectStreamReader, the reactor's
// own reading side. Only the decoding runs: no filter, registration or
// error map, no mesh index.
#include <algorithm>
#include <cstring>
#include <string>

#include "fuzz/fuzz_target.h"
#include "proto/convert.h"
#include "proto/inspect_stream.h"

namespace {

namespace v1 = ::surfinspect::v1;
namespace wire = ::surfinspect::wire;

// The fuzzer's memory limit (2 GB RSS), not the server's: a cloud of 1 M
// points is 12 MB, a mesh of 200 k triangles about 5 MB.
wire::Limits FuzzLimits() {
  wire::Limits limits;
  limits.max_points = 1'000'000;
  limits.max_triangles = 200'000;
  return limits;
}

// What ResolveMesh converts: an inline mesh through MeshFromProto; a hash
// is only looked up.
void ConvertMesh(const v1::MeshRef& ref, const std::string& field) {
  if (!ref.has_inline_()) return;
  (void)wire::MeshFromProto(ref.inline_(), field + ".inline", FuzzLimits());
}

template <typename Message>
bool Parse(std::string_view bytes, Message* msg) {
  return msg->ParseFromArray(bytes.data(), static_cast<int>(bytes.size()));
}

}  // namespace

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_filter_request)
SURFINSPECT_FUZZ_TARGET(filter_request) {
  v1::FilterRequest req;
  if (!Parse(bytes, &req)) return;
  if (!wire::CloudFromProto(req.cloud(), "cloud", FuzzLimits()).ok()) return;
  (void)wire::FilterSettingsFromProto(req.settings(), "settings");
}
#endif

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_calibrate_request)
SURFINSPECT_FUZZ_TARGET(calibrate_request) {
  v1::CalibrateRequest req;
  if (!Parse(bytes, &req)) return;
  if (!wire::TransformFromProto(req.world_from_gauge(), "world_from_gauge").ok()) return;
  if (!wire::TransformFromProto(req.initial_world_from_sensor(), "initial_world_from_sensor").ok())
    return;
  if (!wire::CloudFromProto(req.scan(), "scan", FuzzLimits()).ok()) return;
  if (!wire::FilterSettingsFromProto(req.filter(), "filter").ok()) return;
  if (!wire::IcpSettingsFromProto(req.icp(), "icp").ok()) return;
  ConvertMesh(req.gauge(), "gauge");
}
#endif

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_register_request)
SURFINSPECT_FUZZ_TARGET(register_request) {
  v1::RegisterRequest req;
  if (!Parse(bytes, &req)) return;
  const wire::Limits limits = FuzzLimits();
  uint64_t points = 0;
  for (const auto& v : req.views()) points += uint64_t{v.cloud().width()} * v.cloud().height();
  if (req.views().empty() || points > limits.max_points) return;
  if (!wire::FilterSettingsFromProto(req.filter_settings(), "filter_settings").ok()) return;
  for (int i = 0; i < req.views_size(); ++i) {
    const std::string field = "views[" + std::to_string(i) + "]";
    const v1::ViewScan& v = req.views(i);
    if (!wire::TransformFromProto(v.world_from_sensor(), field + ".world_from_sensor").ok()) return;
    if (!wire::CloudFromProto(v.cloud(), field + ".cloud", limits).ok()) return;
  }
  if (!req.best_fit()) return;
  if (!wire::TransformFromProto(req.world_from_part(), "world_from_part").ok()) return;
  ConvertMesh(req.part(), "part");
}
#endif

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_errormap_request)
SURFINSPECT_FUZZ_TARGET(errormap_request) {
  v1::ErrorMapRequest req;
  if (!Parse(bytes, &req)) return;
  if (!wire::CloudFromProto(req.cloud(), "cloud", FuzzLimits()).ok()) return;
  if (!wire::TransformFromProto(req.world_from_part(), "world_from_part").ok()) return;
  if (!wire::ErrorMapSettingsFromProto(req.settings(), "settings").ok()) return;
  ConvertMesh(req.part(), "part");
}
#endif

#if !defined(SURFINSPECT_LIBFUZZER) || defined(FUZZ_inspect_stream)
// The input is a sequence of InspectRequest messages, each a 2-byte
// little-endian length and that many bytes (the last one may be short). As
// in the reactor, the first refused message ends the stream, and so does
// the end marker; then the pool job's inline mesh conversion runs.
SURFINSPECT_FUZZ_TARGET(inspect_stream) {
  const std::string cached(64, '0');  // the one mesh hash "in the cache"
  uint64_t reserved_points = 0;
  wire::InspectStreamReader::Hooks hooks;
  hooks.resolve_mesh = [&](const v1::MeshRef& mesh, const std::string& field) {
    return mesh.sha256() == cached ? absl::OkStatus()
                                   : absl::FailedPreconditionError(field + ".sha256 not cached");
  };
  hooks.reserve_view = [&](uint64_t view_points, const std::string& view) {
    reserved_points += view_points;
    return reserved_points <= 600'000 ? absl::OkStatus()
                                      : absl::ResourceExhaustedError("no room for " + view);
  };
  wire::InspectStreamReader reader(FuzzLimits(), hooks);
  while (!bytes.empty() && !reader.ended()) {
    std::size_t n = static_cast<unsigned char>(bytes[0]);
    if (bytes.size() >= 2) n |= std::size_t{static_cast<unsigned char>(bytes[1])} << 8;
    bytes.remove_prefix(std::min<std::size_t>(2, bytes.size()));
    n = std::min(n, bytes.size());
    v1::InspectRequest msg;
    if (!Parse(bytes.substr(0, n), &msg)) return;  // gRPC refuses what does not parse
    bytes.remove_prefix(n);
    if (!reader.Consume(&msg).ok()) return;
  }
  if (reader.ended()) ConvertMesh(reader.part().mesh, "part.part");
}
#endif
