// An inspected part's results, the same whether it was computed in-process
// or by surfinspectd, and its files in a results folder: the catalogue's
// (client/cell/part_files.h) that the cell asks for, the PLY in the world
// frame, the pictures in the part frame, written as one whole set with
// report.json last.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cell/part_files.h"
#include "core/pipeline/inspection.h"
#include "core/pipeline/inspection_report.h"
#include "core/report/html_sections.h"
#include "core/types/point_cloud.h"
#include "surfinspect/v1/inspection.pb.h"

namespace surfinspect::client {

struct PartOutputs {
  std::string part_id;
  std::string verdict;  // "pass" / "fail"
  std::string report_json;
  std::string png;                  // PNG bytes
  PointCloud merged_in_world;       // merged, valid points
  std::vector<float> deviation_mm;  // per merged point
  double tolerance_mm = 0, color_range_mm = 0;
  // For people: from the report.
  double min_mm = 0, max_mm = 0;
  std::vector<std::string> failed;     // "name: reason" per failing characteristic
  std::vector<std::string> defects;    // one line per defect found
  std::vector<std::string> alignment;  // AlignmentLines (core/report/report_content.h)
  // Context for the reports written beside report.json: the cell's name, the
  // part's pose, and its CAD mesh in the part frame (null when not at hand).
  std::string cell;
  Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
  std::shared_ptr<const TriangleMesh> mesh_in_part;
  std::vector<ViewpointCalibration> viewpoints;  // calibration status; empty: not known
  // The part's tessellation when it came from STEP/IGES: written into
  // report.json as "cad" (the server never sees the STEP file).
  std::optional<ReportCad> cad;
  // The units the scans and the part were read in (report.json "input_units").
  std::optional<ReportInputUnits> input_units;
};

// The lines of PartOutputs::failed and ::defects.
std::vector<std::string> FailedLines(const CharacteristicsResult& characteristics);
std::vector<std::string> DefectLines(const DefectsResult& defects);

absl::StatusOr<PartOutputs> OutputsFromLocal(const std::string& part_id, const InspectionResult& r,
                                             const InspectionSettings& settings,
                                             const Eigen::Isometry3d& world_from_part,
                                             const TriangleMesh& part);
absl::StatusOr<PartOutputs> OutputsFromRemote(const ::surfinspect::v1::InspectResult& r);

// The Inspect stream's header for a part, asking for everything the part
// outputs need (deviations, merged cloud and PNG).
::surfinspect::v1::PartHeader MakePartHeader(const std::string& part_id,
                                             const Eigen::Isometry3d& world_from_part,
                                             const InspectionSettings& settings);

// The part's files as one whole set (WritePartFiles); `bytes` as there.
absl::Status WritePartOutputs(const std::string& dir, const PartOutputs& outputs,
                              const PartFileSet& files = PartFileSet::Defaults(),
                              uint64_t* bytes = nullptr);

}  // namespace surfinspect::client
