// Recording inspected parts in the results store (core/history), from the
// files a part leaves on disk (part_outputs.h): report.json gives the
// verdict, the characteristics and the defects; errormap.ply (world frame,
// float x y z deviation + rgb) gives the deviation field, whose points are
// matched again to their closest CAD triangle on the part mesh held here
// (the server's Inspect result carries deviations but no triangle ids), so
// that in-process and remote parts get the same per-triangle summary. The
// files are the primary record: a part the store missed (database down,
// agent killed) is recorded later from them, once (key: cell + part id).
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cell/cell_config.h"
#include "core/distance/mesh_index.h"
#include "core/history/results_store.h"

namespace surfinspect::client {

inline constexpr char kSoftwareVersion[] = "0.1.0";

struct RecordContext {
  std::string cell;              // CellConfig::name
  std::string plan_hash;         // PlanHash of the cell's plan ("" without one)
  std::string calibration_json;  // CalibrationStateJson
  Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
  double max_distance_mm = 5;             // the error map's
  std::shared_ptr<const MeshIndex> part;  // null: no triangle summary
};

// Lowercase hex SHA-256 of the plan's JSON text (nlohmann dump, sorted keys).
std::string PlanHash(const nlohmann::json& plan);
// Per viewpoint: its name and whether (and where) it is calibrated.
std::string CalibrationStateJson(const CellConfig& cell);
// The context for a cell's parts; `part` is the cell's part mesh index.
RecordContext RecordContextOf(const CellConfig& cell, std::shared_ptr<const MeshIndex> part);

// A part's record from its report.json text and its deviation field
// (`points_in_world`, one deviation each). `triangle_id` per point when the
// caller has it (an in-process error map); empty = matched here on
// context.part (no summary without one). Time and files are left to the caller.
absl::StatusOr<PartRecord> MakePartRecord(const RecordContext& context, const std::string& part_id,
                                          const std::string& report_json, const std::string& where,
                                          const PointCloud& points_in_world,
                                          const std::vector<float>& deviation_mm,
                                          const std::vector<uint32_t>& triangle_id = {});

// The record of the part whose files are in `dir`; its time is report.json's
// modification time (when the result was made, however late it is recorded).
absl::StatusOr<PartRecord> PartRecordFromFiles(const RecordContext& context,
                                               const std::string& part_id, const std::string& dir);
// The same, recorded: true when written, false when it was there already.
absl::StatusOr<bool> RecordPartFromFiles(ResultsStore& store, const RecordContext& context,
                                         const std::string& part_id, const std::string& dir);
// Records every RESULTS/<id>/report.json the store lacks. Returns how many
// were written; a part whose files cannot be read is skipped and named in
// `skipped`; a store error ends the catch-up.
absl::StatusOr<int> CatchUpFromFiles(ResultsStore& store, const RecordContext& context,
                                     const std::string& results_root,
                                     std::vector<std::string>* skipped = nullptr);

// errormap.ply as written by WriteErrorMapPly: points (their frame) and
// deviations. DataLoss naming the file for anything else.
absl::Status ReadErrorMapPly(const std::string& path, PointCloud* points,
                             std::vector<float>* deviation_mm);

}  // namespace surfinspect::client
