// InspectStreamReader: the reading side of one Inspect stream, as a state
// machine over InspectRequest messages: one part header, then per view a
// header and its chunks, then the end marker. Each message is validated as
// it comes (sizes against limits before any byte is buffered); the server's
// own steps (a mesh looked up by hash, a memory reservation per view, the
// progress event when a view is complete) are hooks, so the server's reactor
// and the fuzz target run the same checks.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/pipeline/inspection.h"
#include "core/registration/registration.h"
#include "proto/convert.h"
#include "surfinspect/v1/inspection.pb.h"

namespace surfinspect::wire {

// The stream's part header, parsed and validated once when it arrives.
struct InspectPart {
  std::string id;
  v1::MeshRef mesh;  // moved out of the request
  Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
  InspectionSettings settings;
  bool return_deviations = false;
  bool return_png = false;
};

class InspectStreamReader {
 public:
  struct Hooks {
    // At the part header, for a mesh sent by hash (field "part.part").
    std::function<absl::Status(const v1::MeshRef& mesh, const std::string& field)> resolve_mesh;
    // At each view header, after its checks and before any of its bytes.
    std::function<absl::Status(uint64_t view_points, const std::string& view_name)> reserve_view;
    // When a view's last chunk has arrived.
    std::function<void(const std::string& view_name, uint64_t points)> view_received;
  };

  // A hook left empty does nothing and returns OK.
  InspectStreamReader(const Limits& limits, Hooks hooks);

  // Takes one message; the part header's mesh is moved out of it. Any error
  // ends the stream (the caller stops reading).
  absl::Status Consume(v1::InspectRequest* msg);
  // True once the end marker was accepted.
  bool ended() const { return state_ == State::kEnded; }
  const InspectPart& part() const { return part_; }
  std::vector<ViewScan>& views() { return views_; }
  // Points declared by every view header so far.
  uint64_t total_points() const { return total_points_; }

 private:
  enum class State { kExpectPart, kExpectView, kInView, kEnded };
  absl::Status ConsumePart(v1::PartHeader* header);
  absl::Status ConsumeView(const v1::ViewHeader& view);
  absl::Status ConsumeChunk(const v1::CloudChunk& chunk);
  absl::Status ConsumeEnd();
  absl::Status IncompleteView(const std::string& field, const std::string& name) const;

  Limits limits_;
  Hooks hooks_;
  State state_ = State::kExpectPart;
  InspectPart part_;
  std::vector<ViewScan> views_;
  CloudAssembler view_cloud_;  // the view whose chunks are arriving
  uint64_t total_points_ = 0;
};

}  // namespace surfinspect::wire
