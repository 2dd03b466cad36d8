#include "core/distance/embree_handles.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

// The square [0, 10]^2 in z = 0 as two CCW triangles split along (0,0)-(10,10).
TriangleMesh Square() {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

struct Hit {
  unsigned geometry = RTC_INVALID_GEOMETRY_ID;
  unsigned primitive = RTC_INVALID_GEOMETRY_ID;
  float t = INFINITY;
};

// A ray straight down (-z) from (x, y, 5). Debian's Embree has ray masks
// compiled in, so the mask must be set or nothing is hit.
Hit CastDown(RTCScene scene, float x, float y) {
  RTCRayHit rh{};
  rh.ray.org_x = x;
  rh.ray.org_y = y;
  rh.ray.org_z = 5;
  rh.ray.dir_z = -1;
  rh.ray.tnear = 0;
  rh.ray.tfar = INFINITY;
  rh.ray.mask = 0xFFFFFFFF;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcIntersect1(scene, &context, &rh);
  return {rh.hit.geomID, rh.hit.primID, rh.ray.tfar};
}

TEST(EmbreeHandles, DeviceIsCreatedWithAndWithoutAConfig) {
  for (const std::string config : {"", "threads=1", "threads=2,verbose=0"}) {
    auto device = EmbreeDevice::Create(config);
    ASSERT_TRUE(device.ok()) << config << ": " << device.status();
    EXPECT_NE((*device)->get(), nullptr);
    EXPECT_TRUE((*device)->TakeError().ok()) << "no error after a clean start";
  }
}

TEST(EmbreeHandles, ErrorsReachTheDeviceAsStatusesAndTakeErrorClearsThem) {
  auto device = EmbreeDevice::Create("threads=1");
  ASSERT_TRUE(device.ok());
  EmbreeDevice& d = **device;
  // An invalid geometry type: Embree reports it through the device's error
  // callback and returns no geometry. The status carries Embree's code and
  // message.
  RTCGeometry geom = rtcNewGeometry(d.get(), static_cast<RTCGeometryType>(12345));
  EXPECT_EQ(geom, nullptr);
  const absl::Status first = d.TakeError();
  EXPECT_EQ(first.code(), absl::StatusCode::kInternal);
  EXPECT_NE(first.message().find("embree error "), std::string::npos) << first;
  EXPECT_NE(first.message().find("invalid geometry type"), std::string::npos) << first;
  EXPECT_TRUE(d.TakeError().ok()) << "taken, so cleared";

  // Two errors in a row: the first one is kept.
  rtcNewGeometry(d.get(), static_cast<RTCGeometryType>(12345));
  RTCGeometry tri = rtcNewGeometry(d.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
  ASSERT_NE(tri, nullptr);
  rtcCommitGeometry(tri);  // no vertex buffer: a second, different error
  rtcReleaseGeometry(tri);
  const absl::Status kept = d.TakeError();
  EXPECT_EQ(kept, first);
  EXPECT_TRUE(d.TakeError().ok());
}

TEST(EmbreeHandles, OutOfMemoryIsResourceExhausted) {
  auto device = EmbreeDevice::Create("threads=1");
  ASSERT_TRUE(device.ok());
  // A memory monitor that refuses every allocation: Embree raises
  // RTC_ERROR_OUT_OF_MEMORY, and the scene build returns it as a status.
  rtcSetDeviceMemoryMonitorFunction((*device)->get(),
                                    [](void*, ssize_t bytes, bool) { return bytes <= 0; }, nullptr);
  auto scene = EmbreeTriangleScene::Build(*device, Square());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kResourceExhausted) << scene.status();
  EXPECT_NE(scene.status().message().find(absl::StrCat("embree error ", RTC_ERROR_OUT_OF_MEMORY)),
            std::string::npos)
      << scene.status();
  // Once the monitor allows it again, the same device builds the scene.
  rtcSetDeviceMemoryMonitorFunction((*device)->get(), nullptr, nullptr);
  (*device)->TakeError().IgnoreError();
  EXPECT_TRUE(EmbreeTriangleScene::Build(*device, Square()).ok());
}

TEST(EmbreeHandles, SceneHoldsTheMeshAsGeometryZero) {
  auto device = EmbreeDevice::Create("threads=1");
  ASSERT_TRUE(device.ok());
  TriangleMesh mesh = Square();
  auto scene = EmbreeTriangleScene::Build(*device, mesh);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const RTCScene s = (*scene)->get();
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(&(*scene)->device(), device->get());

  RTCBounds bounds;
  rtcGetSceneBounds(s, &bounds);
  EXPECT_EQ(bounds.lower_x, 0);
  EXPECT_EQ(bounds.upper_x, 10);
  EXPECT_EQ(bounds.upper_y, 10);
  EXPECT_EQ(bounds.lower_z, 0);
  EXPECT_EQ(bounds.upper_z, 0);

  const Hit below_diagonal = CastDown(s, 7, 2);
  EXPECT_EQ(below_diagonal.geometry, 0u);
  EXPECT_EQ(below_diagonal.primitive, 0u);
  EXPECT_FLOAT_EQ(below_diagonal.t, 5);
  const Hit above_diagonal = CastDown(s, 2, 7);
  EXPECT_EQ(above_diagonal.geometry, 0u);
  EXPECT_EQ(above_diagonal.primitive, 1u);
  EXPECT_EQ(CastDown(s, 12, 3).geometry, RTC_INVALID_GEOMETRY_ID) << "outside the square";

  // The vertices were copied: changing or dropping the mesh and the
  // caller's device handle changes nothing.
  mesh.vertices[1].z() = 100;
  mesh = TriangleMesh{};
  device->reset();
  EXPECT_FLOAT_EQ(CastDown(s, 7, 2).t, 5);
  EXPECT_TRUE((*scene)->device().TakeError().ok());
}

TEST(EmbreeHandles, BuildAnswersForEveryTriangleOfALargerMesh) {
  auto device = EmbreeDevice::Create();
  ASSERT_TRUE(device.ok());
  const TriangleMesh field = testing::HeightField(
      0, 40, 0, 30, 41, 31, [](double x, double y) { return 0.05 * x + 0.02 * y; });
  for (RTCBuildQuality q :
       {RTC_BUILD_QUALITY_LOW, RTC_BUILD_QUALITY_MEDIUM, RTC_BUILD_QUALITY_HIGH}) {
    auto scene = EmbreeTriangleScene::Build(*device, field, q);
    ASSERT_TRUE(scene.ok()) << scene.status();
    // A ray down through each triangle's centroid hits that triangle at the
    // height of the plane z = 0.05 x + 0.02 y (below the rays' start at z = 5).
    for (std::size_t t = 0; t < field.num_triangles(); t += 7) {
      Eigen::Vector3f c = Eigen::Vector3f::Zero();
      for (uint32_t v : field.triangles[t]) c += field.vertices[v] / 3;
      const Hit h = CastDown((*scene)->get(), c.x(), c.y());
      ASSERT_EQ(h.primitive, t);
      EXPECT_NEAR(5 - h.t, 0.05 * c.x() + 0.02 * c.y(), 1e-4);
    }
  }
}

TEST(EmbreeHandles, BuildRejectsAnInvalidMeshBeforeEmbreeSeesIt) {
  auto device = EmbreeDevice::Create("threads=1");
  ASSERT_TRUE(device.ok());
  TriangleMesh bad = Square();
  bad.triangles[1][2] = 9;
  auto scene = EmbreeTriangleScene::Build(*device, bad);
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(scene.status().message().find("refers to vertex 9"), std::string::npos)
      << scene.status();
  EXPECT_EQ(EmbreeTriangleScene::Build(*device, TriangleMesh{}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE((*device)->TakeError().ok());
}

}  // namespace
}  // namespace surfinspect

namespace surfinspect {
namespace {

// A device that cannot get the memory for its thread pool is a retryable
// RESOURCE_EXHAUSTED, not INTERNAL. Tried in a child process whose address
// space is capped a little above what it already maps.
TEST(EmbreeDeviceCreate, OutOfAddressSpaceIsResourceExhausted) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's shadow memory does not fit under an address-space cap";
#endif
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::ifstream statm("/proc/self/statm");
    uint64_t pages = 0;
    statm >> pages;
    const rlim_t cap = pages * uint64_t(sysconf(_SC_PAGESIZE)) + (uint64_t{8} << 20);
    rlimit limit{cap, cap};
    setrlimit(RLIMIT_AS, &limit);
    auto device = EmbreeDevice::Create("threads=8");
    _exit(device.ok() ? 100 : static_cast<int>(device.status().code()));
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  if (WEXITSTATUS(status) == 100) GTEST_SKIP() << "the device was created within the cap";
  EXPECT_EQ(WEXITSTATUS(status), static_cast<int>(absl::StatusCode::kResourceExhausted));
}

}  // namespace
}  // namespace surfinspect
