#include "proto/inspect_stream.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"

namespace surfinspect::wire {
namespace {

absl::Status InvalidField(const std::string& field, const std::string& why) {
  return absl::InvalidArgumentError(field + ": " + why);
}

}  // namespace

InspectStreamReader::InspectStreamReader(const Limits& limits, Hooks hooks)
    : limits_(limits), hooks_(std::move(hooks)) {}

absl::Status InspectStreamReader::Consume(v1::InspectRequest* msg) {
  switch (msg->message_case()) {
    case v1::InspectRequest::kPart:
      return ConsumePart(msg->mutable_part());
    case v1::InspectRequest::kView:
      return ConsumeView(msg->view());
    case v1::InspectRequest::kChunk:
      return ConsumeChunk(msg->chunk());
    case v1::InspectRequest::kEnd:
      return ConsumeEnd();
    default:
      return InvalidField("message", "empty InspectRequest");
  }
}

// Validates and parses the header into part_. The mesh moves out of the
// message, which the next read overwrites anyway.
absl::Status InspectStreamReader::ConsumePart(v1::PartHeader* header) {
  if (state_ != State::kExpectPart) return InvalidField("part", "only one part header per stream");
  if (header->part_id().empty() || header->part_id().size() > 256)
    return InvalidField("part.part_id", "must be 1..256 characters");
  if (header->part().source_case() == v1::MeshRef::SOURCE_NOT_SET)
    return InvalidField("part.part", "mesh is missing (set inline or sha256)");
  // A mesh sent by hash is looked up now, so a miss fails before the client
  // streams its views; an inline mesh is the caller's, after the end marker.
  if (header->part().source_case() == v1::MeshRef::kSha256 && hooks_.resolve_mesh)
    RETURN_IF_ERROR(hooks_.resolve_mesh(header->part(), "part.part"));
  ASSIGN_OR_RETURN(auto world_from_part,
                   TransformFromProto(header->world_from_part(), "part.world_from_part"));
  ASSIGN_OR_RETURN(auto error_map,
                   ErrorMapSettingsFromProto(header->error_map(), "part.error_map"));
  ASSIGN_OR_RETURN(auto filter, FilterSettingsFromProto(header->filter(), "part.filter",
                                                        LinkClusteringSettings::ForInspection()));
  // The plan's own values are checked here; against the mesh (triangle ids,
  // groups) by InspectPart once the mesh is indexed.
  if (header->has_plan()) {
    ASSIGN_OR_RETURN(part_.settings.plan, PlanFromProto(header->plan(), error_map, "part.plan"));
  }
  part_.id = header->part_id();
  part_.mesh.Swap(header->mutable_part());
  part_.world_from_part = world_from_part;
  part_.settings.filter = !header->skip_filter();
  part_.settings.filter_settings = filter;
  part_.settings.error_map = error_map;
  part_.return_deviations = header->return_deviations();
  part_.return_png = header->return_png();
  state_ = State::kExpectView;
  return absl::OkStatus();
}

absl::Status InspectStreamReader::ConsumeView(const v1::ViewHeader& view) {
  if (state_ == State::kExpectPart) return InvalidField("view", "the part header must come first");
  if (state_ == State::kInView) return IncompleteView("view", views_.empty() ? "" : "previous");
  if (state_ == State::kEnded) return InvalidField("view", "the stream has ended");
  const std::string field = absl::StrCat("view[", views_.size(), "]");
  RETURN_IF_ERROR(CheckCloudShape(view.width(), view.height(), field, limits_));
  const uint64_t view_points = uint64_t{view.width()} * view.height();
  total_points_ += view_points;
  if (total_points_ > limits_.max_points)
    return absl::ResourceExhaustedError(
        absl::StrCat("part: ", total_points_, " points exceed the limit of ", limits_.max_points));
  ASSIGN_OR_RETURN(auto pose,
                   TransformFromProto(view.world_from_sensor(), field + ".world_from_sensor"));
  ViewScan scan;
  scan.name = view.name().empty() ? absl::StrCat("view", views_.size()) : view.name();
  // Before a byte of the view is buffered: a part that does not fit is
  // refused now, while the client still holds its data to send again.
  if (hooks_.reserve_view) RETURN_IF_ERROR(hooks_.reserve_view(view_points, scan.name));
  scan.world_from_sensor = pose;
  views_.push_back(std::move(scan));
  view_cloud_.Start(view.width(), view.height());
  state_ = State::kInView;
  return absl::OkStatus();
}

absl::Status InspectStreamReader::ConsumeChunk(const v1::CloudChunk& chunk) {
  if (state_ != State::kInView) return InvalidField("chunk", "a chunk must follow a view header");
  const std::string field = absl::StrCat("view '", views_.back().name, "'");
  RETURN_IF_ERROR(view_cloud_.Add(chunk.xyz(), field));
  if (!view_cloud_.complete()) return absl::OkStatus();
  ASSIGN_OR_RETURN(auto cloud, view_cloud_.Take(field));
  views_.back().cloud_in_sensor = std::move(cloud);
  state_ = State::kExpectView;
  if (hooks_.view_received)
    hooks_.view_received(views_.back().name, views_.back().cloud_in_sensor.size());
  return absl::OkStatus();
}

absl::Status InspectStreamReader::ConsumeEnd() {
  if (state_ == State::kInView) return IncompleteView("end", views_.back().name);
  if (state_ != State::kExpectView || views_.empty())
    return InvalidField("end", "a part header and at least one view must come first");
  state_ = State::kEnded;
  return absl::OkStatus();
}

absl::Status InspectStreamReader::IncompleteView(const std::string& field,
                                                 const std::string& name) const {
  return InvalidField(
      field, absl::StrCat("view '", name, "' is incomplete: ", view_cloud_.received_bytes(), " of ",
                          view_cloud_.expected_bytes(), " bytes"));
}

}  // namespace surfinspect::wire
