// surfinspect filter: link-clustering outlier removal (paper §III). Writes
// the filtered cloud (same grid, removed points NaN), and optionally a JSON
// report and a PNG that shows what was removed.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>

#include "client/cli/commands.h"
#include "client/cli/remote_args.h"
#include "client/cli/unit_args.h"
#include "core/filter/link_clustering.h"
#include "core/io/atomic_file.h"
#include "core/io/io_point_cloud.h"
#include "core/io/png_image.h"
#include "core/io/unit_doubt.h"
#include "proto/convert.h"
#include "proto/packed_cloud.h"

namespace surfinspect::cli {
namespace {

struct FilterArgs {
  std::string in, out, report, png;
  LinkClusteringSettings settings;
  RemoteArgs remote;
  UnitArgs units;
  std::string out_units = "mm";  // or "input"
};

// The unit the output is written in: millimetres, or the input's.
const char* OutputUnitName(const FilterArgs& a, const InputUnit& unit) {
  return a.out_units == "mm" ? "mm" : LengthUnitName(unit.unit);
}

// The cloud to write: the filtered one in millimetres, or the input as read
// with the removed points NaN, so kept points keep their bits in either unit.
PointCloud CloudToWrite(const FilterArgs& a, const PointCloud& as_read,
                        const v1::FilterResponse& resp) {
  if (a.out_units == "mm") return Take(wire::CloudFromProto(resp.cloud(), "cloud", wire::Limits{}));
  PointCloud out = as_read;
  const std::string& kept = resp.kept_mask();
  if (kept.size() != out.size())
    throw CommandFailed("the filter's kept mask has " + std::to_string(kept.size()) +
                        " entries for " + std::to_string(out.size()) + " points");
  for (std::size_t i = 0; i < out.size(); ++i)
    if (!kept[i]) out.points[i] = Eigen::Vector3f::Constant(NAN);
  return out;
}

// Kept points in grey by depth (near = bright), removed points red, no data
// black; a legend strip below the grid.
RgbImage RenderFilterPng(const PointCloud& cloud, const LinkClusteringResult& r) {
  constexpr uint32_t kLegend = 12;
  RgbImage img(cloud.width, cloud.height + kLegend);
  float z_lo = INFINITY, z_hi = -INFINITY;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (r.kept_mask[i]) {
      z_lo = std::min(z_lo, cloud.points[i].z());
      z_hi = std::max(z_hi, cloud.points[i].z());
    }
  const float span = z_hi > z_lo ? z_hi - z_lo : 1.f;
  for (uint32_t row = 0; row < cloud.height; ++row)
    for (uint32_t col = 0; col < cloud.width; ++col) {
      const std::size_t i = std::size_t{row} * cloud.width + col;
      if (r.labels[i] == LinkClusteringResult::kInvalid) continue;
      if (!r.kept_mask[i]) {
        img.at(col, row) = {255, 0, 0};
        continue;
      }
      const auto g = static_cast<uint8_t>(235.f - 175.f * (cloud.points[i].z() - z_lo) / span);
      img.at(col, row) = {g, g, g};
    }
  img.DrawText(2, static_cast<int>(cloud.height) + 3,
               "kept " + std::to_string(r.kept) + "  removed " + std::to_string(r.removed),
               {255, 255, 255});
  return img;
}

v1::FilterResponse FilterCloud(const FilterArgs& a, const PointCloud& cloud) {
  v1::FilterResponse resp;
  if (a.remote.remote()) {
    v1::FilterRequest req;
    wire::CloudToRequestProto(cloud, req.mutable_cloud());
    wire::FilterSettingsToProto(a.settings, req.mutable_settings());
    return Take(Connect(a.remote)->Filter(req));
  }
  PointCloud filtered = cloud;  // `cloud` stays whole for the picture
  LinkClusteringResult r;
  Check(RemoveOutliers(filtered, a.settings, r));
  wire::CloudToProto(filtered, resp.mutable_cloud());
  wire::FilterStatsToProto(r, resp.mutable_stats());
  resp.mutable_kept_mask()->assign(r.kept_mask.begin(), r.kept_mask.end());
  return resp;
}

void WriteFilterReport(const FilterArgs& a, const PointCloud& cloud, const v1::FilterStats& stats,
                       double seconds, const InputUnit& unit,
                       const std::vector<std::string>& doubts) {
  nlohmann::json j = {{"input", a.in},
                      {"output", a.out},
                      {"organized", cloud.organized()},
                      {"width", cloud.width},
                      {"height", cloud.height},
                      {"input_points", stats.input_points()},
                      {"valid_points", stats.valid_points()},
                      {"kept", stats.kept()},
                      {"removed", stats.removed()},
                      {"clusters", stats.clusters()},
                      {"removed_clusters", stats.removed_clusters()},
                      {"largest_cluster", stats.largest_cluster()},
                      {"seconds", seconds},
                      {"parameters",
                       {{"link_distance_mm", a.settings.link_distance_mm},
                        {"min_cluster_points", a.settings.min_cluster_points},
                        {"connectivity", a.settings.connectivity},
                        {"min_fraction_of_largest", a.settings.min_fraction_of_largest}}},
                      {"units",
                       {{"input", LengthUnitName(unit.unit)},
                        {"input_stated", unit.stated},
                        {"output", OutputUnitName(a, unit)},
                        {"doubts", doubts}}}};
  Check(WriteStringAtomically(a.report, j.dump(2) + "\n"));
}

void Filter(const FilterArgs& a) {
  const InputUnit unit = a.units.Cloud();
  const PointCloud as_read = Take(ReadPointCloud(a.in));
  if (!a.png.empty() && !as_read.organized())
    throw CommandFailed(a.in + ": --png needs an organized cloud (there is no grid to draw)");
  // The link distance is millimetres, so the filter sees millimetres.
  PointCloud cloud = as_read;
  ScaleToMillimetres(unit.unit, &cloud);
  const std::vector<std::string> doubts =
      UnitDoubts({"cloud " + a.in, "--units", ExtentOf(cloud), unit.stated}, nullptr);
  for (const std::string& d : doubts) WarnUnitDoubt(d);
  const auto t0 = std::chrono::steady_clock::now();
  // Both paths end in a FilterResponse, so they write the same files.
  const v1::FilterResponse resp = FilterCloud(a, cloud);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const v1::FilterStats& stats = resp.stats();
  Check(WritePointCloud(a.out, CloudToWrite(a, as_read, resp), PcdEncoding::kBinary, true,
                        OutputUnitName(a, unit)));
  spdlog::info("{}: {} valid points, kept {}, removed {} in {} clusters ({:.2f} ms)", a.in,
               stats.valid_points(), stats.kept(), stats.removed(), stats.clusters(),
               seconds * 1e3);
  if (!a.report.empty()) WriteFilterReport(a, cloud, stats, seconds, unit, doubts);
  if (a.png.empty()) return;
  // What the picture needs: which pixels had data and which were kept.
  LinkClusteringResult result;
  result.kept = stats.kept();
  result.removed = stats.removed();
  result.kept_mask.assign(resp.kept_mask().begin(), resp.kept_mask().end());
  result.labels.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    result.labels[i] = PointCloud::IsValid(cloud.points[i]) ? 0 : LinkClusteringResult::kInvalid;
  Check(WritePng(a.png, RenderFilterPng(cloud, result)));
}

}  // namespace

void AddFilterCommand(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("filter",
                         "Remove outliers (pulses, stripes) by link clustering; kept points are "
                         "never moved, removed points become NaN");
  auto a = std::make_shared<FilterArgs>();
  cmd->add_option("--in", a->in, "input cloud (.pcd/.ply)")->required();
  cmd->add_option("--out", a->out, "filtered cloud (.pcd keeps the grid)")->required();
  cmd->add_option("--link-distance", a->settings.link_distance_mm,
                  "points closer than this link (mm); the default removes outliers "
                  "thoroughly (before calibration), 0.85 keeps dents on steep walls "
                  "(before an error map)")
      ->capture_default_str();
  cmd->add_option("--min-cluster", a->settings.min_cluster_points,
                  "smaller components are outliers (points)")
      ->capture_default_str();
  cmd->add_option("--connectivity", a->settings.connectivity, "grid neighbours: 4 or 8")
      ->capture_default_str();
  cmd->add_option("--min-fraction", a->settings.min_fraction_of_largest,
                  "also remove components below this fraction of the largest (0 = off)")
      ->capture_default_str();
  AddUnitOptions(cmd, a->units, /*with_mesh=*/false);
  cmd->add_option("--out-units", a->out_units,
                  "mm, or input: write the kept points as read, bit for bit, in the input's unit")
      ->check(CLI::IsMember({"mm", "input"}))
      ->capture_default_str();
  cmd->add_option("--report", a->report, "JSON report of counts, timing and parameters");
  cmd->add_option("--png", a->png, "picture: kept by depth, removed red, no data black");
  AddRemoteOptions(cmd, a->remote);
  cmd->callback([a] {
    // Bad parameters are refused before any file is read.
    Check(ValidateLinkClusteringSettings(a->settings));
    Filter(*a);
  });
}

}  // namespace surfinspect::cli
