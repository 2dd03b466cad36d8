// Small pieces the conversions of proto/convert.h share: the InvalidArgument
// every FromProto returns (the field's path, then why: "plan.regions[0].select:
// no selector"), and the vectors and tolerance bands of plans and results.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "proto/convert.h"

namespace surfinspect::wire {

inline absl::Status Invalid(const std::string& field, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat(field, ": ", why));
}

inline absl::StatusOr<Eigen::Vector3d> Vector3FromProto(
    const google::protobuf::RepeatedField<double>& v, const std::string& field) {
  if (v.size() != 3) return Invalid(field, "must be 3 numbers");
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

inline void Vector3ToProto(const Eigen::Vector3d& v, google::protobuf::RepeatedField<double>* out) {
  out->Clear();
  for (int a = 0; a < 3; ++a) out->Add(v[a]);
}

inline ToleranceBand BandFromProto(const v1::ToleranceBand& b) {
  return {b.lower_mm(), b.upper_mm()};
}

inline void BandToProto(const ToleranceBand& b, v1::ToleranceBand* msg) {
  msg->set_lower_mm(b.lower_mm);
  msg->set_upper_mm(b.upper_mm);
}

}  // namespace surfinspect::wire
