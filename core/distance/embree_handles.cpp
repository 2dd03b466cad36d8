#include "core/distance/embree_handles.h"

#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"

namespace surfinspect {

absl::StatusOr<std::shared_ptr<EmbreeDevice>> EmbreeDevice::Create(const std::string& config) {
  std::shared_ptr<EmbreeDevice> d(new EmbreeDevice());
  d->device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
  if (!d->device_) {
    // Only a bad configuration string is our mistake. Otherwise the device
    // failed for want of memory or threads (it starts its own thread pool),
    // which a caller retries later: RESOURCE_EXHAUSTED, not INTERNAL.
    const RTCError code = rtcGetDeviceError(nullptr);
    const std::string text = absl::StrCat("embree: cannot create device (error ", int(code), ")");
    return code == RTC_ERROR_INVALID_ARGUMENT || code == RTC_ERROR_INVALID_OPERATION
               ? absl::InternalError(text)
               : absl::ResourceExhaustedError(text);
  }
  rtcSetDeviceErrorFunction(d->device_, &EmbreeDevice::OnError, d.get());
  return d;
}

EmbreeDevice::~EmbreeDevice() {
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeDevice::OnError(void* self, RTCError code, const char* message) {
  auto* d = static_cast<EmbreeDevice*>(self);
  std::lock_guard<std::mutex> lock(d->mu_);
  if (!d->error_.ok()) return;  // keep the first: later ones are usually fallout
  const std::string text =
      absl::StrCat("embree error ", static_cast<int>(code), ": ", message ? message : "");
  d->error_ = code == RTC_ERROR_OUT_OF_MEMORY ? absl::ResourceExhaustedError(text)
                                              : absl::InternalError(text);
}

absl::Status EmbreeDevice::TakeError() {
  std::lock_guard<std::mutex> lock(mu_);
  absl::Status e = error_;
  error_ = absl::OkStatus();
  return e;
}

absl::StatusOr<std::unique_ptr<EmbreeTriangleScene>> EmbreeTriangleScene::Build(
    std::shared_ptr<EmbreeDevice> device, const TriangleMesh& mesh, RTCBuildQuality quality) {
  RETURN_IF_ERROR(mesh.Validate());
  std::unique_ptr<EmbreeTriangleScene> s(new EmbreeTriangleScene());
  s->device_ = std::move(device);
  RTCDevice dev = s->device_->get();
  s->scene_ = rtcNewScene(dev);
  rtcSetSceneBuildQuality(s->scene_, quality);
  RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                            RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                                            mesh.triangles.size()));
  if (!vb || !ib) {
    rtcReleaseGeometry(geom);
    auto e = s->device_->TakeError();
    return e.ok() ? absl::ResourceExhaustedError("embree: cannot allocate mesh buffers") : e;
  }
  std::memcpy(vb, mesh.vertices.data(), mesh.vertices.size() * 3 * sizeof(float));
  std::memcpy(ib, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(uint32_t));
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(s->scene_, geom, 0);
  rtcReleaseGeometry(geom);
  rtcCommitScene(s->scene_);
  RETURN_IF_ERROR(s->device_->TakeError());
  return s;
}

EmbreeTriangleScene::~EmbreeTriangleScene() {
  if (scene_) rtcReleaseScene(scene_);
}

}  // namespace surfinspect
