// cell.json: everything a robot cell needs to inspect parts. Paths inside
// are relative to the file's directory. Written by `surfinspect demo-cell`
// (or by hand), completed by `cell-agent calibrate`, read by `cell-agent run`
// and `surfinspect inspect`:
//   name                                    optional; default: the folder's name.
//                                           Letters, digits, '.', '_', '-': it
//                                           names the cell in results, events
//                                           and the results store
//   part.mesh, part.world_from_part         CAD of the part (a mesh, or a STEP/
//                                           IGES file: client/cell/cell_part.h)
//                                           and its pose
//   cad{chord_tolerance_mm, angular_tolerance_deg, body, cache, timeout_s,
//       memory_mb}                          optional: how a STEP/IGES part is
//                                           tessellated (docs/cad.md)
//   gauge.mesh                              CAD of the calibration gauge
//   viewpoints[]: name, nominal_world_from_sensor, world_from_gauge,
//                 gauge_scan, world_from_sensor (after calibration),
//                 calibration (quality figures)
//   tolerance_mm, error_map{...}, filter{...}   optional settings
//   plan                                    optional inspection plan: a path
//                                           ("plan.json") or an inline object
//                                           (docs/inspection-plan.md)
//   outputs                                 optional list of the files each part
//                                           gets, by catalogue name ("ply", "csv",
//                                           "png", "pdf", "html", "qif";
//                                           client/cell/part_files.h); default
//                                           all but "csv". report.json always.
//   server{target, tls_ca, tls_cert, tls_key, token_file}   optional
//   mqtt{url, topic_prefix, ...}            optional plant events, read by
//                                           client/agent/mqtt_events.h
// Transforms are {"matrix": [[...]...]} (row-major, mm).
#pragma once

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/cell/part_files.h"
#include "core/cad/cad_report.h"
#include "core/cad/cad_settings.h"
#include "core/errormap/error_map.h"
#include "core/filter/link_clustering.h"
#include "core/io/length_units.h"
#include "core/pipeline/inspection.h"

namespace surfinspect::client {

struct CellViewpoint {
  std::string name;
  Eigen::Isometry3d nominal_world_from_sensor = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d world_from_gauge = Eigen::Isometry3d::Identity();
  std::string gauge_scan;                              // resolved path, may be empty
  std::optional<Eigen::Isometry3d> world_from_sensor;  // calibrated
};

struct CellServer {
  std::string target, tls_ca, tls_cert, tls_key, token_file;  // paths resolved
};

struct CellConfig {
  std::string path;                   // of cell.json
  std::string name;                   // the cell's name (see above)
  std::string part_mesh, gauge_mesh;  // resolved paths
  // A STEP/IGES part: its tessellation settings and cache folder (default
  // <cell folder>/.cad-cache). LoadCellPart points part_mesh at the cached
  // mesh and keeps the file in part_source and the report in part_cad.
  CadSettings cad;
  std::string cad_cache;
  std::string part_source;
  std::optional<CadReport> part_cad;
  // The units of the scans and of the part mesh: "units" for both, or
  // "sensor.units" / "part.units" (docs/units.md). Absent = millimetres
  // assumed, and checked by core/io/unit_doubt.h. A STEP/IGES part declares
  // its own unit. Transforms are millimetres.
  InputUnit sensor_units, part_units;
  Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
  std::vector<CellViewpoint> viewpoints;
  ErrorMapSettings error_map;
  bool filter = true;
  LinkClusteringSettings filter_settings = LinkClusteringSettings::ForInspection();
  CellServer server;
  // The inspection plan's JSON (read from its file when cell.json names
  // one); parsed against the part mesh by PlanOf. Unset: no plan.
  std::optional<nlohmann::json> plan;
  std::string plan_source;  // the file it came from, for messages
  // The files each part gets ("outputs": catalogue names, report.json always).
  PartFileSet outputs = PartFileSet::Defaults();
  nlohmann::json raw;  // the whole file, kept for rewriting
};

absl::StatusOr<CellConfig> ReadCellConfig(const std::string& path);

// The cell's filter and error-map settings as one InspectionSettings.
InspectionSettings InspectionSettingsOf(const CellConfig& cell);

// An inspection plan file (JSON object, at most 16 MB); the plan is parsed
// against a mesh by ParsePlanWithDefaults.
absl::StatusOr<nlohmann::json> ReadPlanJson(const std::string& path);

// The cell's plan parsed against `part` (in millimetres: ReadCellPartMesh,
// client/cell/cell_part.h) with `settings` as its defaults
// (core/plan/plan_evaluation.h), or unset when the cell has none.
// InvalidArgument "<file>: plan.<field>: ..." for a bad plan.
absl::StatusOr<std::optional<InspectionPlan>> PlanOf(const CellConfig& cell,
                                                     const TriangleMesh& part,
                                                     const ErrorMapSettings& settings);

// Stores each calibrated viewpoint's world_from_sensor and quality (JSON)
// into the file: the previous file is kept as cell.json.bak, the new one is
// written to a temporary file and renamed over cell.json.
absl::Status WriteCellCalibrations(
    const CellConfig& cell, const std::vector<std::pair<std::string, nlohmann::json>>& quality);

}  // namespace surfinspect::client
