// report.json ("schema": "surfinspect.report/2") as a type with one JSON
// codec. Every program writes the report through EncodeReport, so the CLI,
// the server and the cell-agent write the same bytes; every reader (the PDF
// and HTML reports, QIF, the results store, the CLI's summary, MQTT events)
// decodes it with DecodeReport and reads the struct, never a JSON key.
// docs/reports.md lists the fields.
//
// Millimetres, part frame. A number that does not exist (a statistic over
// no points, a comparison point with no point near it) is NaN here and null
// in the JSON; a decoded report that lacks a section has that section's
// defaults (NaN, 0, empty).
#pragma once

#include <Eigen/Core>
#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/cad/cad_report.h"
#include "core/errormap/error_map.h"
#include "core/pipeline/report_alignment.h"
#include "core/pipeline/report_coverage.h"
#include "core/pipeline/report_section.h"
#include "core/plan/characteristics.h"
#include "core/plan/defects.h"
#include "core/plan/plan_evaluation.h"
#include "core/types/json_fields.h"

namespace surfinspect {

inline constexpr char kReportSchema[] = "surfinspect.report/2";

// The error-map settings the report was made with.
struct ReportSettings {
  double tolerance_mm = 0;
  double max_distance_mm = NAN;  // NaN (null): unlimited
  double allowed_fraction_outside = 0;
  int histogram_bins = 0;
  bool split_components = false;
};

// The +-band verdict over all matched points.
struct ReportTolerance {
  double band_mm = 0;
  std::size_t within = 0, above = 0, below = 0;
  double fraction_within = NAN, fraction_outside = NAN;  // of matched points
  std::string verdict;                                   // "pass" | "fail"; "" when not said
  std::string reason;                                    // one line, for people
};

// One characteristic of the plan, as judged.
struct ReportCharacteristic {
  std::string name;
  std::string type;     // "surface" | "region" | "point" | "section" | "hole" | "slot"
  std::string verdict;  // "pass" | "fail" | "not_measured"
  std::string reason;   // one line, for people
  ToleranceBand tolerance{NAN, NAN};  // NaN when not said
  // The covered fraction of its CAD area and the least it needed
  // (core/plan/coverage.h); NaN in a report from before coverage.
  double coverage = NAN, min_coverage = NAN;
  std::size_t points = 0;  // matched points judged
  double min_mm = NAN, max_mm = NAN, mean_mm = NAN, stddev_mm = NAN, rms_mm = NAN;
  double fraction_within = NAN;
  double value_mm = NAN;                  // points and edge points only
  double allowed_fraction_outside = NAN;  // surface and regions only
  // Holes and slots (core/plan/holes.h): the measured centre in the plan
  // plane, its deviation from the nominal, the true position and its zone;
  // the diameter (a slot's width) and a slot's length with their
  // deviations; the form, the edge's arc seen and the pixel pitch there.
  // `points` are the edge points kept, `tolerance_mm` the diameter's band.
  Eigen::Vector3d measured_position_mm = Eigen::Vector3d::Constant(NAN);
  Eigen::Vector3d position_deviation_mm = Eigen::Vector3d::Constant(NAN);
  double true_position_mm = NAN, position_tolerance_mm = NAN;
  double measured_diameter_mm = NAN, diameter_deviation_mm = NAN;
  double measured_length_mm = NAN, length_deviation_mm = NAN;
  ToleranceBand length_tolerance{NAN, NAN};
  double form_mm = NAN, arc_coverage_deg = NAN, pixel_pitch_mm = NAN;
  bool is_point() const { return type == "point"; }
  bool has_value() const { return type == "point" || type == "edge_point"; }  // value_mm
  bool is_hole() const { return type == "hole" || type == "slot"; }
  bool passed() const { return verdict == "pass"; }
  bool measured() const { return verdict != "not_measured"; }
  bool operator==(const ReportCharacteristic& o) const;
};

// One defect found by the plan's defect rules.
struct ReportDefect {
  int id = 0;
  std::string kind;  // "dent" | "bump"
  Eigen::Vector3d centroid_mm = Eigen::Vector3d::Zero();
  double area_mm2 = 0, extent_mm = 0, peak_mm = 0;
  // "fit" (the Gaussian's c + A) or "median" (the deepest local median: the
  // fit failed or left the measured extremes), with the evidence the fit was
  // checked against (core/plan/defects.h). "" in a report from before them.
  std::string peak_source;
  double measured_extreme_mm = NAN, noise_mm = NAN;
  std::size_t points = 0;
  std::string region;  // "" outside every region
  bool operator==(const ReportDefect& o) const;
};

// Timing of the distances, and of the whole command where the program that
// wrote the report timed it (the CLI's errormap).
struct ReportTiming {
  double query_seconds = 0, order_seconds = 0, statistics_seconds = 0;
  std::size_t certified_points = 0, hint_alone_points = 0;
  std::optional<double> read_seconds, build_seconds, plan_seconds, png_seconds, write_seconds,
      total_seconds;
};

// The CAD mesh's summary, where the program that wrote the report made one.
struct ReportMesh {
  std::size_t triangles = 0, boundary_edges = 0, nonmanifold_edges = 0, degenerate_triangles = 0;
};

// The input files, where the program that wrote the report read files.
struct ReportInputs {
  std::string cloud, mesh, world_from_part;
};

// The CAD the deviations were measured against, when surfinspect tessellated
// it from a STEP or IGES file: the measured tessellation error bounds how
// much of each deviation is the mesh's own (docs/cad.md).
struct ReportCad {
  std::string source, format, declared_unit;
  double chord_tolerance_mm = 0, tessellation_error_mm = 0;
  bool tolerance_held = false;
};
ReportCad ReportCadOf(const CadReport& report);

// The units the inputs were read in (everything after is millimetres), and
// whether the user stated them; `doubts` holds what the plausibility rule
// said of units that were assumed (core/io/unit_doubt.h): a result with a
// doubt may be 1000 times off.
struct ReportInputUnits {
  std::string cloud = "mm", mesh = "mm";
  bool cloud_stated = false, mesh_stated = false;
  std::vector<std::string> doubts;
};

struct InspectionReport {
  std::string schema;   // kReportSchema with a plan; "" for an error-map report alone
  std::string verdict;  // the part verdict; "" without a plan
  ReportSettings settings;
  ErrorMapStats stats;  // point counts and the statistics of all matched points
  ReportTolerance tolerance;
  Histogram histogram;
  double color_range_mm = 0;
  std::optional<std::array<ComponentStats, 4>> components;  // x, y, z, normal; part frame
  ReportTiming timing;
  std::vector<ReportCharacteristic> characteristics;
  std::vector<ReportDefect> defects;
  std::vector<ReportSection> sections;       // the plan's sections, in plan order; "sections"
  std::optional<ReportCoverage> coverage;    // where the scan saw the CAD; "coverage"
  std::optional<ReportAlignment> alignment;  // how the scan was aligned; "alignment"
  // Written by the CLI's errormap only.
  std::optional<ReportInputs> inputs;
  std::optional<ReportMesh> mesh;
  std::optional<ReportCad> cad;                 // set by the client that tessellated the part
  std::optional<ReportInputUnits> input_units;  // set by the client that read the files
  std::string output_frame;                     // "" when not said
  bool pass() const { return verdict == "pass"; }
};

// The report of an error map alone (no schema, no plan), and with its plan.
InspectionReport ErrorMapReport(const ErrorMapResult& error_map, const ErrorMapSettings& settings);
InspectionReport MakeInspectionReport(const ErrorMapResult& error_map,
                                      const ErrorMapSettings& settings, const PlanOutcome& outcome);

// The codec. Encode then decode gives the same struct; decode then encode
// gives the same JSON for every report this codec wrote. DecodeReport
// refuses (DataLoss, naming the field) a value of the wrong type; a missing
// field keeps its default.
nlohmann::json EncodeReport(const InspectionReport& report);
absl::StatusOr<InspectionReport> DecodeReport(const nlohmann::json& json);
// The text of report.json (two-space indent, a final newline), and its parse.
std::string ReportText(const InspectionReport& report);
absl::StatusOr<InspectionReport> ParseReport(const std::string& text);

// One figure of the report with its report.json key, for readers that show
// a section whole (the HTML report's tables keep the key beside each value).
using ReportField = JsonField;
std::vector<ReportField> PointCountFields(const InspectionReport& report);  // count valid matched
std::vector<ReportField> StatisticsFields(const InspectionReport& report);  // min_mm .. p99_mm
// within, above, below, fraction_within of the +-band verdict.
std::vector<ReportField> ToleranceCountFields(const InspectionReport& report);
// The settings, then the inputs, the CAD ("cad.*") and the input units
// ("input_units.*") when there are some, each group by key.
std::vector<ReportField> SettingsFields(const InspectionReport& report);

// The sections alone, as report.json holds them.
nlohmann::json EncodeDefects(const std::vector<ReportDefect>& defects);
nlohmann::json ErrorMapReportJson(const ErrorMapResult& result, const ErrorMapSettings& settings);
nlohmann::json CharacteristicsJson(const CharacteristicsResult& result);
nlohmann::json DefectsJson(const DefectsResult& result);

// ReportText(MakeInspectionReport(...)): the bytes every caller writes.
std::string ErrorMapReportText(const ErrorMapResult& result, const ErrorMapSettings& settings,
                               const PlanOutcome& outcome);

}  // namespace surfinspect
