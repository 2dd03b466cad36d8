#include "core/pipeline/report_section.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

// 3 decimals: 1 um for millimetres. +0.0 turns -0 into 0, so a value that
// rounds to zero is written "0.0" whatever its sign was.
double Round3(double v) { return std::round(v * 1000.0) / 1000.0 + 0.0; }

void AppendRounded(const Eigen::Vector3d& v, std::vector<double>& out) {
  for (int k = 0; k < 3; ++k) out.push_back(Round3(v[k]));
}

// Largest component positive (the first of equal ones), so that the same
// plane always gets the same normal.
Eigen::Vector3d Signed(const Eigen::Vector3d& n) {
  Eigen::Index largest = 0;
  n.cwiseAbs().maxCoeff(&largest);
  return n[largest] < 0 ? Eigen::Vector3d(-n) : n;
}

// The unit normal of the plane holding every vector of `in_plane` (their
// scatter's least eigenvector); when they span a line only, a plane
// through that line.
Eigen::Vector3d NormalOf(const std::vector<Eigen::Vector3d>& in_plane) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& u : in_plane) scatter += u * u.transpose();
  if (!(scatter.trace() > 0)) return Eigen::Vector3d::Zero();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  const Eigen::Vector3d lambda = eig.eigenvalues();  // ascending
  // Unit vectors: an eigenvalue is a sum of squared cosines, so 1e-9 of
  // the largest is far below any real second direction.
  if (lambda[1] > 1e-9 * lambda[2]) return Signed(eig.eigenvectors().col(0).normalized());
  const Eigen::Vector3d line = eig.eigenvectors().col(2);
  Eigen::Index least = 0;
  line.cwiseAbs().minCoeff(&least);
  return Signed(line.cross(Eigen::Vector3d::Unit(least)).normalized());
}

}  // namespace

CutPlane PlaneOfCut(const SectionCut& cut) {
  std::vector<Eigen::Vector3d> in_plane;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t vertices = 0;
  for (const auto& line : cut.polylines)
    for (std::size_t i = 0; i < line.size(); ++i) {
      sum += line[i];
      ++vertices;
      if (i + 1 < line.size() && (line[i + 1] - line[i]).norm() > 0)
        in_plane.push_back((line[i + 1] - line[i]).normalized());
    }
  Eigen::Vector3d feet = Eigen::Vector3d::Zero();
  for (const SectionWhisker& w : cut.whiskers) {
    feet += w.at_mm;
    if (w.direction.norm() > 0) in_plane.push_back(w.direction.normalized());
  }
  CutPlane plane;
  if (vertices > 0)
    plane.point_mm = sum / static_cast<double>(vertices);
  else if (!cut.whiskers.empty())
    plane.point_mm = feet / static_cast<double>(cut.whiskers.size());
  plane.normal = NormalOf(in_plane);
  return plane;
}

std::vector<ReportSection> ReportSectionsOf(const PlanOutcome& outcome) {
  std::vector<const CharacteristicResult*> judged;
  for (const CharacteristicResult& c : outcome.characteristics.characteristics)
    if (c.type == CharacteristicType::kSection) judged.push_back(&c);
  std::vector<ReportSection> out;
  for (std::size_t k = 0; k < outcome.sections.size(); ++k) {
    const SectionCut& cut = outcome.sections[k];
    ReportSection s;
    if (k < judged.size()) s.name = judged[k]->name, s.tolerance = judged[k]->tolerance;
    const CutPlane plane = PlaneOfCut(cut);
    for (int i = 0; i < 3; ++i)
      s.point_mm[i] = Round3(plane.point_mm[i]), s.normal[i] = Round3(plane.normal[i]);
    for (const auto& line : cut.polylines) {
      ReportPolyline& p = s.polylines.emplace_back();
      for (const Eigen::Vector3d& v : line) AppendRounded(v, p.xyz_mm);
    }
    for (const SectionWhisker& w : cut.whiskers) {
      AppendRounded(w.at_mm, s.whiskers.at_mm);
      AppendRounded(w.direction, s.whiskers.direction);
      s.whiskers.deviation_mm.push_back(Round3(w.deviation_mm));
    }
    out.push_back(std::move(s));
  }
  return out;
}

absl::Status CheckReportSections(const std::vector<ReportSection>& sections) {
  for (std::size_t k = 0; k < sections.size(); ++k) {
    const ReportSection& s = sections[k];
    for (std::size_t j = 0; j < s.polylines.size(); ++j)
      if (s.polylines[j].xyz_mm.size() % 3 != 0)
        return absl::DataLossError(absl::StrCat("report.sections[", k, "].polylines[", j,
                                                "].xyz_mm: not x, y, z triples"));
    const ReportWhiskers& w = s.whiskers;
    if (w.at_mm.size() != 3 * w.size() || w.direction.size() != 3 * w.size())
      return absl::DataLossError(
          absl::StrCat("report.sections[", k,
                       "].whiskers: at_mm and direction must hold x, y, z per deviation_mm"));
  }
  return absl::OkStatus();
}

}  // namespace surfinspect
