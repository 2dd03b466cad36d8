// artefacts.json: the calibrated artefacts of an acceptance test in the
// style of VDI/VDE 2634 Part 2 and 3, where each was placed and which
// viewpoint's scan sees it, and the maximum permissible errors. Positions
// are in the WORLD frame, mm; a position is a hint the fits start from (the
// true centre may be up to `search_mm` away). Schema "surfinspect.artefacts/1":
//   sphere:   {diameter_mm, u_diameter_mm, measurements: [{name, view, centre_mm}]}
//   ball_bar: {length_mm, u_length_mm, sphere_diameter_mm,
//              positions: [{name, a: {view, centre_mm}, b: {view, centre_mm}}]}
//   plate:    {u_flatness_mm, measurements: [{name, view, centre_mm, normal, radius_mm}]}
//   mpe_mm:   {PF, PS, SD, F}
//   search_mm, band_mm, outlier_share   optional (defaults below)
// The scan of a measurement seen from viewpoint V is SCANS/<name>/<V>.pcd.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

struct ArtefactView {
  std::string view;                                     // viewpoint name
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();  // world, hint
};

struct SphereMeasurement {
  std::string name;
  ArtefactView at;
};

struct BallBarPosition {
  std::string name;
  ArtefactView a, b;  // the two spheres; different views = a cross-view position
  bool cross_view() const { return a.view != b.view; }
};

struct PlateMeasurement {
  std::string name;
  ArtefactView at;                                    // centre of the evaluated disc
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // hint, unit
  double radius_mm = 40;                              // evaluated disc on the plate
};

struct MaxPermissibleErrors {
  double pf_mm = 0, ps_mm = 0, sd_mm = 0, f_mm = 0;
};

struct Artefacts {
  double sphere_diameter_mm = 0, sphere_diameter_u_mm = 0;
  std::vector<SphereMeasurement> spheres;
  double ball_bar_length_mm = 0, ball_bar_length_u_mm = 0, ball_bar_sphere_diameter_mm = 0;
  std::vector<BallBarPosition> ball_bar;
  double plate_flatness_u_mm = 0;
  std::vector<PlateMeasurement> plates;
  MaxPermissibleErrors mpe;
  double search_mm = 5.0;  // how far a true centre / plane may be from its hint
  double band_mm = 0.5;    // points kept within this distance of the first fit
  // Share of points with the largest residuals left out of PF and F. VDI/VDE
  // 2634 Part 2 (2012) allows 0.3 % when the report says so.
  double outlier_share = 0.003;
};

// The one validator: positive diameters and length, non-negative
// uncertainties and MPEs, unique names, at least one measurement of each
// kind, unit-length normals after normalisation, outlier_share in [0, 0.05).
// InvalidArgument "<source>: <field>: ..." otherwise.
absl::Status ValidateArtefacts(const Artefacts& a, const std::string& source);

// Parses and validates; `source` names the file in messages.
absl::StatusOr<Artefacts> ArtefactsFromJson(const nlohmann::json& j, const std::string& source);
// The one writer (schema above); ArtefactsFromJson(ArtefactsToJson(a)) == a.
nlohmann::json ArtefactsToJson(const Artefacts& a);

}  // namespace surfinspect
