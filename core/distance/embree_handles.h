// Small owning wrappers for Embree 3's C handles. The device registers an
// error callback that records the first error, so callers can turn Embree's
// failures into an absl::Status instead of printing or aborting.
#pragma once

#include <embree3/rtcore.h>

#include <memory>
#include <mutex>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

class EmbreeDevice {
 public:
  // `config` is Embree's device config string, e.g. "threads=1".
  static absl::StatusOr<std::shared_ptr<EmbreeDevice>> Create(const std::string& config = "");
  ~EmbreeDevice();
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;

  RTCDevice get() const { return device_; }
  // Returns (and clears) the first error recorded since the last call.
  absl::Status TakeError();

 private:
  EmbreeDevice() = default;
  static void OnError(void* self, RTCError code, const char* message);
  RTCDevice device_ = nullptr;
  std::mutex mu_;
  absl::Status error_;
};

// A committed scene holding one triangle geometry (geometry id 0) built from
// a mesh, vertices copied into Embree-owned buffers (Embree needs 16 bytes
// readable past the last vertex, which std::vector does not promise).
class EmbreeTriangleScene {
 public:
  static absl::StatusOr<std::unique_ptr<EmbreeTriangleScene>> Build(
      std::shared_ptr<EmbreeDevice> device, const TriangleMesh& mesh,
      RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH);
  ~EmbreeTriangleScene();
  EmbreeTriangleScene(const EmbreeTriangleScene&) = delete;
  EmbreeTriangleScene& operator=(const EmbreeTriangleScene&) = delete;

  RTCScene get() const { return scene_; }
  EmbreeDevice& device() const { return *device_; }

 private:
  EmbreeTriangleScene() = default;
  std::shared_ptr<EmbreeDevice> device_;
  RTCScene scene_ = nullptr;
};

}  // namespace surfinspect
