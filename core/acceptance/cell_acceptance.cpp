#include "core/acceptance/cell_acceptance.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace {

using json = nlohmann::json;

SphereSearch SearchFor(const Artefacts& a, const ArtefactView& at, double diameter) {
  SphereSearch s;
  s.centre_hint_mm = at.centre_mm;
  s.diameter_mm = diameter;
  s.search_mm = a.search_mm;
  s.band_mm = a.band_mm;
  return s;
}

// Keeps the figure with the largest |value|.
void Worst(AcceptanceFigure& fig, const std::string& name, double value, double u) {
  if (fig.measurement.empty() || std::abs(value) > std::abs(fig.value_mm)) {
    fig.measurement = name;
    fig.value_mm = value;
    fig.u_mm = u;
  }
}

void Judge(AcceptanceFigure& fig, double mpe) {
  fig.mpe_mm = mpe;
  fig.pass = std::abs(fig.value_mm) <= mpe;
}

absl::Status MeasureBallBar(const Artefacts& a,
                            const std::map<std::string, ViewCalibrationUncertainty>& views,
                            const WorldScanFn& scan, AcceptanceResult& r) {
  for (const BallBarPosition& bp : a.ball_bar) {
    SpacingResult s;
    s.position = bp;
    ASSIGN_OR_RETURN(auto cloud_a, scan(bp.name, bp.a.view));
    absl::StatusOr<PointCloud> cloud_b = cloud_a;
    if (bp.cross_view()) cloud_b = scan(bp.name, bp.b.view);
    if (!cloud_b.ok()) return cloud_b.status();
    const double d = a.ball_bar_sphere_diameter_mm;
    ASSIGN_OR_RETURN(
        auto fa, MeasureSphere(cloud_a, SearchFor(a, bp.a, d), a.outlier_share, bp.name + ".a"));
    ASSIGN_OR_RETURN(
        auto fb, MeasureSphere(*cloud_b, SearchFor(a, bp.b, d), a.outlier_share, bp.name + ".b"));
    s.a = std::move(fa);
    s.b = std::move(fb);
    s.spacing =
        ComputeSphereSpacing(s.a, views.at(bp.a.view), s.b, views.at(bp.b.view), !bp.cross_view(),
                             a.ball_bar_length_mm, a.ball_bar_length_u_mm);
    s.pass = std::abs(s.spacing.sd_mm) <= a.mpe.sd_mm;
    r.sd.push_back(std::move(s));
  }
  return absl::OkStatus();
}

absl::Status CheckViews(const Artefacts& a,
                        const std::map<std::string, ViewCalibrationUncertainty>& views) {
  std::vector<std::pair<std::string, std::string>> used;
  for (const auto& s : a.spheres) used.emplace_back(s.name, s.at.view);
  for (const auto& b : a.ball_bar)
    used.insert(used.end(), {{b.name, b.a.view}, {b.name, b.b.view}});
  for (const auto& p : a.plates) used.emplace_back(p.name, p.at.view);
  for (const auto& [name, view] : used)
    if (!views.count(view))
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": viewpoint ", view, " is not a calibrated viewpoint of the cell"));
  return absl::OkStatus();
}

json FigureJson(const AcceptanceFigure& f) {
  return {{"value", f.value_mm}, {"u", f.u_mm},    {"U", 2 * f.u_mm},
          {"mpe", f.mpe_mm},     {"pass", f.pass}, {"measurement", f.measurement}};
}

json CrossViewJson(const AcceptanceResult& r) {
  std::size_t n = 0, within = 0;
  double max_z = 0, sum_z2 = 0;
  for (const auto& s : r.sd) {
    if (!s.position.cross_view() || !(s.spacing.u_sd_mm > 0)) continue;
    const double z = s.spacing.sd_mm / s.spacing.u_sd_mm;
    ++n;
    within += std::abs(z) <= 3 ? 1 : 0;
    max_z = std::max(max_z, std::abs(z));
    sum_z2 += z * z;
  }
  return {{"positions", n},
          {"within_3u", within},
          {"max_abs_sd_over_u", max_z},
          {"rms_sd_over_u", n > 0 ? std::sqrt(sum_z2 / double(n)) : 0.0}};
}

}  // namespace

absl::StatusOr<AcceptanceResult> RunAcceptance(
    const Artefacts& a, const std::map<std::string, ViewCalibrationUncertainty>& views,
    const WorldScanFn& scan) {
  RETURN_IF_ERROR(ValidateArtefacts(a, "artefacts"));
  RETURN_IF_ERROR(CheckViews(a, views));
  AcceptanceResult r;
  for (const SphereMeasurement& m : a.spheres) {
    ASSIGN_OR_RETURN(auto cloud, scan(m.name, m.at.view));
    auto e =
        MeasureSphere(cloud, SearchFor(a, m.at, a.sphere_diameter_mm), a.outlier_share, m.name);
    if (!e.ok()) return e.status();
    Worst(r.pf, m.name, e->pf_mm, e->u_pf_mm);
    Worst(r.ps, m.name, e->ps_mm, std::hypot(e->u_ps_mm, a.sphere_diameter_u_mm));
    r.spheres.emplace_back(m.name, *std::move(e));
  }
  RETURN_IF_ERROR(MeasureBallBar(a, views, scan, r));
  for (const PlateMeasurement& m : a.plates) {
    ASSIGN_OR_RETURN(auto cloud, scan(m.name, m.at.view));
    PlaneSearch s;
    s.centre_hint_mm = m.at.centre_mm;
    s.normal_hint = m.normal;
    s.radius_mm = m.radius_mm;
    s.search_mm = a.search_mm;
    s.band_mm = a.band_mm;
    ASSIGN_OR_RETURN(auto f, MeasureFlatness(cloud, s, a.outlier_share, m.name));
    Worst(r.f, m.name, f.f_mm, std::hypot(f.u_f_mm, a.plate_flatness_u_mm));
    r.plates.emplace_back(m.name, std::move(f));
  }
  Judge(r.pf, a.mpe.pf_mm);
  Judge(r.ps, a.mpe.ps_mm);
  Judge(r.f, a.mpe.f_mm);
  r.pass = r.pf.pass && r.ps.pass && r.f.pass;
  for (const auto& s : r.sd) r.pass = r.pass && s.pass;
  return r;
}

json AcceptanceReportJson(const AcceptanceResult& r, const Artefacts& a) {
  json sd = json::array(), spheres = json::array(), plates = json::array();
  for (const auto& s : r.sd)
    sd.push_back({{"position", s.position.name},
                  {"views", {s.position.a.view, s.position.b.view}},
                  {"cross_view", s.position.cross_view()},
                  {"value", s.spacing.sd_mm},
                  {"u", s.spacing.u_sd_mm},
                  {"U", 2 * s.spacing.u_sd_mm},
                  {"u_fit", s.spacing.u_fit_mm},
                  {"u_calibration", s.spacing.u_calibration_mm},
                  {"u_artefact", s.spacing.u_artefact_mm},
                  {"length_mm", s.spacing.length_mm},
                  {"mpe", a.mpe.sd_mm},
                  {"pass", s.pass}});
  for (const auto& [name, e] : r.spheres)
    spheres.push_back({{"name", name},
                       {"centre_mm", {e.fit.centre.x(), e.fit.centre.y(), e.fit.centre.z()}},
                       {"diameter_mm", e.diameter_mm},
                       {"PF_mm", e.pf_mm},
                       {"u_PF_mm", e.u_pf_mm},
                       {"PS_mm", e.ps_mm},
                       {"u_PS_mm", e.u_ps_mm},
                       {"rms_mm", e.fit.rms},
                       {"points", e.kept},
                       {"left_out", e.left_out}});
  for (const auto& [name, f] : r.plates)
    plates.push_back({{"name", name},
                      {"F_mm", f.f_mm},
                      {"u_F_mm", f.u_f_mm},
                      {"rms_mm", f.fit.rms},
                      {"points", f.kept},
                      {"left_out", f.left_out}});
  return {
      {"schema", "surfinspect.acceptance/1"},
      {"guideline", "VDI/VDE 2634 Part 2 (PF, PS, SD, F) and Part 3 (SD across viewpoints)"},
      {"PF_mm", FigureJson(r.pf)},
      {"PS_mm", FigureJson(r.ps)},
      {"F_mm", FigureJson(r.f)},
      {"SD_mm", sd},
      {"verdict", r.pass ? "pass" : "fail"},
      {"uncertainty", "u: standard (k = 1); U = 2u (k = 2); pass: |value| <= mpe"},
      {"spheres", spheres},
      {"plates", plates},
      {"cross_view", CrossViewJson(r)},
      {"deviations",
       {absl::StrCat("PF and F leave out the ", 100 * a.outlier_share,
                     " % of points with the largest |residual| (the guideline allows 0.3 %)"),
        absl::StrCat("points are selected within ", a.band_mm, " mm of a first least-squares fit"),
        "one placement per sphere and plate measurement listed, not the guideline's full "
        "set of positions",
        "the ball bar is two spheres; its rod and mounts are not modelled"}}};
}

}  // namespace surfinspect
