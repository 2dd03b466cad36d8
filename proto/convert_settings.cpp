// proto/convert.h: the settings of the filter, ICP and the error map.
#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"
#include "proto/convert.h"
#include "proto/convert_helpers.h"

namespace surfinspect::wire {

absl::StatusOr<LinkClusteringSettings> FilterSettingsFromProto(const v1::FilterSettings& msg,
                                                               const std::string& field,
                                                               const LinkClusteringSettings& base) {
  LinkClusteringSettings s = base;
  if (msg.has_link_distance_mm()) s.link_distance_mm = msg.link_distance_mm();
  if (msg.has_min_cluster_points()) s.min_cluster_points = msg.min_cluster_points();
  if (msg.has_connectivity()) s.connectivity = static_cast<int>(msg.connectivity());
  if (msg.has_min_fraction_of_largest()) s.min_fraction_of_largest = msg.min_fraction_of_largest();
  if (auto st = ValidateLinkClusteringSettings(s); !st.ok()) return Invalid(field, st.message());
  return s;
}

void FilterSettingsToProto(const LinkClusteringSettings& s, v1::FilterSettings* msg) {
  msg->set_link_distance_mm(s.link_distance_mm);
  msg->set_min_cluster_points(s.min_cluster_points);
  msg->set_connectivity(static_cast<uint32_t>(s.connectivity));
  msg->set_min_fraction_of_largest(s.min_fraction_of_largest);
}

absl::StatusOr<IcpSettings> IcpSettingsFromProto(const v1::IcpSettings& msg,
                                                 const std::string& field) {
  IcpSettings s;
  switch (msg.step()) {
    case v1::IcpSettings::STEP_UNSPECIFIED:
    case v1::IcpSettings::STEP_POINT_TO_POINT:
      s.step = IcpStep::kPointToPoint;
      break;
    case v1::IcpSettings::STEP_POINT_TO_PLANE:
      s.step = IcpStep::kPointToPlane;
      break;
    default:
      return Invalid(field + ".step", "unknown step");
  }
  // Clamped so a huge uint32 cannot wrap into the valid range; the validator refuses it.
  if (msg.has_max_iterations())
    s.max_iterations = static_cast<int>(std::min<uint32_t>(msg.max_iterations(), INT32_MAX));
  if (msg.has_max_correspondence_mm()) s.max_correspondence_mm = msg.max_correspondence_mm();
  if (msg.has_min_correspondence_mm()) s.min_correspondence_mm = msg.min_correspondence_mm();
  if (msg.has_trim_fraction()) s.trim_fraction = msg.trim_fraction();
  if (msg.has_relative_cost_tolerance()) s.relative_cost_tolerance = msg.relative_cost_tolerance();
  if (msg.has_max_points()) s.max_points = msg.max_points();
  if (auto st = ValidateIcpSettings(s); !st.ok()) return Invalid(field, st.message());
  return s;
}

void IcpSettingsToProto(const IcpSettings& s, v1::IcpSettings* msg) {
  msg->set_step(s.step == IcpStep::kPointToPlane ? v1::IcpSettings::STEP_POINT_TO_PLANE
                                                 : v1::IcpSettings::STEP_POINT_TO_POINT);
  msg->set_max_iterations(static_cast<uint32_t>(s.max_iterations));
  msg->set_max_correspondence_mm(s.max_correspondence_mm);
  msg->set_min_correspondence_mm(s.min_correspondence_mm);
  msg->set_trim_fraction(s.trim_fraction);
  msg->set_relative_cost_tolerance(s.relative_cost_tolerance);
  msg->set_max_points(static_cast<uint32_t>(s.max_points));
}

absl::StatusOr<ErrorMapSettings> ErrorMapSettingsFromProto(const v1::ErrorMapSettings& msg,
                                                           const std::string& field) {
  ErrorMapSettings s;
  if (msg.has_tolerance_mm()) s.tolerance_mm = msg.tolerance_mm();
  if (msg.has_max_distance_mm()) s.max_distance_mm = msg.max_distance_mm();
  if (msg.has_allowed_fraction_outside())
    s.allowed_fraction_outside = msg.allowed_fraction_outside();
  if (msg.has_histogram_bins())
    s.histogram_bins = static_cast<int>(std::min<uint32_t>(msg.histogram_bins(), INT32_MAX));
  if (msg.has_histogram_range_mm()) s.histogram_range_mm = msg.histogram_range_mm();
  s.split_components = msg.split_components();
  if (auto st = ValidateErrorMapSettings(s); !st.ok()) return Invalid(field, st.message());
  return s;
}

void ErrorMapSettingsToProto(const ErrorMapSettings& s, v1::ErrorMapSettings* msg) {
  msg->set_tolerance_mm(s.tolerance_mm);
  msg->set_max_distance_mm(s.max_distance_mm);
  msg->set_allowed_fraction_outside(s.allowed_fraction_outside);
  msg->set_histogram_bins(static_cast<uint32_t>(s.histogram_bins));
  msg->set_histogram_range_mm(s.histogram_range_mm);
  msg->set_split_components(s.split_components);
}

}  // namespace surfinspect::wire
