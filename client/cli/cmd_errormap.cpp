// surfinspect errormap: the signed deviation of a measured cloud from the
// CAD mesh (paper §IV) as a coloured PLY, and optionally CSV, JSON report
// and PNG.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "client/cli/commands.h"
#include "core/atomic_file.h"
#include "core/error_map.h"
#include "core/error_map_output.h"
#include "core/error_map_png.h"
#include "core/io_mesh.h"
#include "core/io_point_cloud.h"
#include "core/io_transform.h"
#include "core/mesh_index.h"
#include "core/transform.h"

namespace surfinspect::cli {
namespace {

struct ErrorMapArgs {
  std::string cloud, mesh, world_from_part, out, csv, report, png;
  std::string frame = "part";
  std::string png_axis = "auto";
  ErrorMapSettings settings;
};

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void RunErrorMap(const ErrorMapArgs& a) {
  auto t0 = std::chrono::steady_clock::now();
  const PointCloud cloud_in_world = Take(ReadPointCloud(a.cloud));
  const Eigen::Isometry3d world_from_part = a.world_from_part.empty()
                                                ? Eigen::Isometry3d::Identity()
                                                : Take(ReadTransformJson(a.world_from_part));
  auto mesh = Take(ReadMesh(a.mesh));
  spdlog::info("read {} points and {} triangles in {:.3f} s", cloud_in_world.size(),
               mesh.num_triangles(), Seconds(t0));
  t0 = std::chrono::steady_clock::now();
  const std::unique_ptr<MeshIndex> index = Take(MeshIndex::Build(std::move(mesh)));
  const MeshIndexInfo& info = index->info();
  spdlog::info("mesh index built in {:.3f} s ({} boundary edges, {} degenerate triangles)",
               info.build_seconds, info.boundary_edges, info.degenerate_triangles);

  const ErrorMapResult r = Take(ComputeErrorMap(*index, cloud_in_world, world_from_part, a.settings));
  spdlog::info("distances for {} points in {:.3f} s", r.stats.count, r.query_seconds);

  // Files carry part-frame coordinates by default, so they overlay the CAD.
  const PointCloud cloud_in_part = TransformCloud(cloud_in_world, world_from_part.inverse());
  const PointCloud& written = a.frame == "world" ? cloud_in_world : cloud_in_part;
  Check(WriteErrorMapPly(a.out, written, r, a.frame));
  if (!a.csv.empty()) Check(WriteErrorMapCsv(a.csv, written, r));
  if (!a.png.empty()) {
    ErrorMapPngOptions png;
    png.view_axis = a.png_axis == "x" ? 0 : a.png_axis == "y" ? 1 : a.png_axis == "z" ? 2 : -1;
    Check(WriteErrorMapPng(a.png, cloud_in_part, r, ComputeBounds(index->mesh()), png));
  }
  if (!a.report.empty()) {
    nlohmann::json j = ErrorMapReportJson(r, a.settings);
    j["inputs"] = {{"cloud", a.cloud}, {"mesh", a.mesh}, {"world_from_part", a.world_from_part}};
    j["mesh"] = {{"triangles", info.triangles},
                 {"boundary_edges", info.boundary_edges},
                 {"nonmanifold_edges", info.nonmanifold_edges},
                 {"degenerate_triangles", info.degenerate_triangles}};
    j["output_frame"] = a.frame;
    Check(WriteStringAtomically(a.report, j.dump(2) + "\n"));
  }

  const ErrorMapStats& s = r.stats;
  std::printf("points: %zu (valid %zu, matched %zu within %g mm)\n", s.count, s.valid, s.matched,
              a.settings.max_distance_mm);
  std::printf("deviation mm: min %.4f  max %.4f  mean %.4f  std %.4f  rms %.4f\n", s.min_mm,
              s.max_mm, s.mean_mm, s.stddev_mm, s.rms_mm);
  std::printf("percentiles mm: p1 %.4f  p5 %.4f  p50 %.4f  p95 %.4f  p99 %.4f\n", s.p1_mm, s.p5_mm,
              s.p50_mm, s.p95_mm, s.p99_mm);
  std::printf("verdict: %s\n", r.verdict.reason.c_str());
  std::printf("wrote %s%s%s%s%s%s%s\n", a.out.c_str(), a.csv.empty() ? "" : ", ", a.csv.c_str(),
              a.report.empty() ? "" : ", ", a.report.c_str(), a.png.empty() ? "" : ", ", a.png.c_str());
}

}  // namespace

void AddErrorMapCommand(CLI::App& app) {
  auto a = std::make_shared<ErrorMapArgs>();
  auto* cmd = app.add_subcommand(
      "errormap", "Signed deviation of a cloud from the CAD mesh (+ above the surface, - below): "
                  "coloured PLY, CSV, JSON report, PNG");
  cmd->add_option("--cloud", a->cloud, "measured cloud, world frame (.pcd/.ply)")->required();
  cmd->add_option("--mesh", a->mesh, "CAD mesh, part frame (.stl/.obj/.ply/.off)")->required();
  cmd->add_option("--world-from-part", a->world_from_part, "transform JSON (default identity)");
  cmd->add_option("--out", a->out, "coloured binary PLY with a float 'deviation' property")->required();
  cmd->add_option("--csv", a->csv, "CSV x,y,z,deviation, one row per input point");
  cmd->add_option("--report", a->report, "JSON report");
  cmd->add_option("--png", a->png, "PNG: map, colour bar, histogram");
  cmd->add_option("--tolerance", a->settings.tolerance_mm, "tolerance band +-MM")
      ->check(CLI::PositiveNumber)->default_val(0.1);
  cmd->add_option("--max-distance", a->settings.max_distance_mm,
                  "points farther from the CAD are unmatched (NaN), mm")
      ->check(CLI::PositiveNumber)->default_val(5.0);
  cmd->add_option("--allowed-outside", a->settings.allowed_fraction_outside,
                  "fraction of matched points allowed outside the band for a pass")
      ->check(CLI::Range(0.0, 1.0))->default_val(0.0);
  cmd->add_option("--threads", a->settings.threads, "0 = all cores")->check(CLI::Range(0, 1024));
  cmd->add_flag("--split-components", a->settings.split_components,
                "also X/Y/Z and normal components (CSV columns, report)");
  cmd->add_option("--frame", a->frame, "coordinates written to PLY/CSV")
      ->check(CLI::IsMember({"part", "world"}))->default_val("part");
  cmd->add_option("--png-axis", a->png_axis, "view axis for merged clouds (auto = CAD's thinnest)")
      ->check(CLI::IsMember({"auto", "x", "y", "z"}))->default_val("auto");
  cmd->callback([a] { RunErrorMap(*a); });
}

}  // namespace surfinspect::cli
