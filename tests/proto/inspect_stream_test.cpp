#include "proto/inspect_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace surfinspect::wire {
namespace {

v1::InspectRequest Part(const std::string& id, bool by_hash) {
  v1::InspectRequest msg;
  v1::PartHeader* p = msg.mutable_part();
  p->set_part_id(id);
  if (by_hash)
    p->mutable_part()->set_sha256(std::string(64, 'a'));
  else
    p->mutable_part()->mutable_inline_()->set_vertices(std::string(36, '\0'));
  TransformToProto(Eigen::Isometry3d::Identity(), p->mutable_world_from_part());
  return msg;
}

v1::InspectRequest View(const std::string& name, uint32_t w, uint32_t h) {
  v1::InspectRequest msg;
  msg.mutable_view()->set_name(name);
  msg.mutable_view()->set_width(w);
  msg.mutable_view()->set_height(h);
  TransformToProto(Eigen::Isometry3d::Identity(), msg.mutable_view()->mutable_world_from_sensor());
  return msg;
}

v1::InspectRequest Chunk(const std::vector<float>& xyz) {
  v1::InspectRequest msg;
  msg.mutable_chunk()->set_xyz(PackFloats(xyz));
  return msg;
}

v1::InspectRequest End() {
  v1::InspectRequest msg;
  msg.mutable_end();
  return msg;
}

// A whole stream: the part, two views (one sent in two chunks that split a
// point), the end; the views carry the bytes sent and the hooks see each step.
TEST(InspectStreamReader, AcceptsAWholeStreamAndCallsTheHooks) {
  std::vector<std::string> calls;
  InspectStreamReader::Hooks hooks;
  hooks.resolve_mesh = [&](const v1::MeshRef&, const std::string& field) {
    calls.push_back("resolve " + field);
    return absl::OkStatus();
  };
  hooks.reserve_view = [&](uint64_t points, const std::string& view) {
    calls.push_back("reserve " + view + " " + std::to_string(points));
    return absl::OkStatus();
  };
  hooks.view_received = [&](const std::string& view, uint64_t points) {
    calls.push_back("received " + view + " " + std::to_string(points));
  };
  InspectStreamReader reader(Limits{}, hooks);
  std::vector<v1::InspectRequest> msgs = {
      Part("p", true), View("a", 2, 1),  Chunk({1, 2}), Chunk({3, 4, 5, 6}),
      View("", 1, 1),  Chunk({7, 8, 9}), End()};
  for (auto& m : msgs) {
    ASSERT_FALSE(reader.ended());
    ASSERT_TRUE(reader.Consume(&m).ok());
  }
  EXPECT_TRUE(reader.ended());
  EXPECT_EQ(reader.part().id, "p");
  EXPECT_EQ(reader.part().mesh.sha256(), std::string(64, 'a'));
  EXPECT_EQ(reader.total_points(), 3u);
  ASSERT_EQ(reader.views().size(), 2u);
  EXPECT_EQ(reader.views()[1].name, "view1");
  EXPECT_EQ(reader.views()[0].cloud_in_sensor.points[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_EQ(calls, (std::vector<std::string>{"resolve part.part", "reserve a 2", "received a 2",
                                             "reserve view1 1", "received view1 1"}));
}

// The messages the reactor has always sent, byte for byte.
TEST(InspectStreamReader, RefusesMessagesOutOfOrderWithTheFieldNamed) {
  auto first_error = [](std::vector<v1::InspectRequest> msgs, Limits limits = {}) {
    InspectStreamReader reader(limits, {});
    for (auto& m : msgs)
      if (absl::Status st = reader.Consume(&m); !st.ok()) return st;
    return absl::OkStatus();
  };
  EXPECT_EQ(first_error({View("a", 1, 1)}).message(), "view: the part header must come first");
  EXPECT_EQ(first_error({v1::InspectRequest()}).message(), "message: empty InspectRequest");
  EXPECT_EQ(first_error({Part("p", false), Part("p", false)}).message(),
            "part: only one part header per stream");
  EXPECT_EQ(first_error({Part("", false)}).message(), "part.part_id: must be 1..256 characters");
  EXPECT_EQ(first_error({Part("p", false), Chunk({1, 2, 3})}).message(),
            "chunk: a chunk must follow a view header");
  EXPECT_EQ(first_error({Part("p", false), End()}).message(),
            "end: a part header and at least one view must come first");
  EXPECT_EQ(first_error({Part("p", false), View("a", 2, 1), Chunk({1, 2, 3}), End()}).message(),
            "end: view 'a' is incomplete: 12 of 24 bytes");
  EXPECT_EQ(first_error({Part("p", false), View("a", 2, 1), View("b", 1, 1)}).message(),
            "view: view 'previous' is incomplete: 0 of 24 bytes");
  Limits small;
  small.max_points = 5;
  const absl::Status over = first_error(
      {Part("p", false), View("a", 2, 1), Chunk({1, 2, 3, 4, 5, 6}), View("b", 2, 2)}, small);
  EXPECT_EQ(over.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(over.message(), "part: 6 points exceed the limit of 5");
}

// A hook's refusal is returned as it is, and stops the message: no view is
// started when its reservation fails.
TEST(InspectStreamReader, AHookRefusalEndsTheMessage) {
  InspectStreamReader::Hooks hooks;
  hooks.reserve_view = [](uint64_t, const std::string& view) {
    return absl::ResourceExhaustedError("no room for " + view);
  };
  InspectStreamReader reader(Limits{}, hooks);
  auto part = Part("p", false);
  ASSERT_TRUE(reader.Consume(&part).ok());
  auto view = View("a", 1, 1);
  const absl::Status st = reader.Consume(&view);
  EXPECT_EQ(st.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(st.message(), "no room for a");
  EXPECT_TRUE(reader.views().empty());
}

}  // namespace
}  // namespace surfinspect::wire
