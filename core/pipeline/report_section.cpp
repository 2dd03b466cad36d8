#include "core/pipeline/report_section.h"

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

}  // namespace

std::vector<ReportSection> ReportSectionsOf(const PlanOutcome& outcome) {
  std::vector<const CharacteristicResult*> judged;
  for (const CharacteristicResult& c : outcome.characteristics.characteristics)
    if (c.type == CharacteristicType::kSection) judged.push_back(&c);
  std::vector<ReportSection> out;
  for (std::size_t k = 0; k < outcome.sections.size(); ++k) {
    const SectionCut& cut = outcome.sections[k];
    ReportSection s;
    if (k < judged.size()) s.name = judged[k]->name, s.tolerance = judged[k]->tolerance;
    for (int i = 0; i < 3; ++i)
      s.point_mm[i] = Round3(cut.plane.point_mm[i]), s.normal[i] = Round3(cut.plane.normal[i]);
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
