// The Western Electric run rules on an individuals chart (Western Electric,
// Statistical Quality Control Handbook, 1956; Montgomery, Introduction to
// Statistical Quality Control, 7th ed., section 5.3.6), with zones in units
// of sigma around the centre line:
//   1: one point beyond 3 sigma;
//   2: two of three consecutive points beyond 2 sigma on the same side;
//   3: four of five consecutive points beyond 1 sigma on the same side;
//   4: eight consecutive points on the same side of the centre line.
// A violation is flagged on the point that completes the pattern, and only
// when that point is itself one of the points beyond (so a run of 9 flags
// rule 4 on its 8th and 9th points). Points exactly on a limit are not
// beyond it. Rules 2 and 3 count over the points there are near the start
// (the first two points beyond 2 sigma on one side break rule 2). For an in-control normal process
// the four together raise a false alarm about once in 92 points (Champ & Woodall, Technometrics 29,
// 1987: ARL0 = 91.75).
#pragma once

#include <cstddef>
#include <vector>

namespace surfinspect {

struct RuleViolation {
  int rule = 0;           // 1..4
  std::size_t index = 0;  // the point, 0-based
  bool operator==(const RuleViolation& o) const { return rule == o.rule && index == o.index; }
};

// Sorted by index, then rule. sigma_mm <= 0 flags nothing.
std::vector<RuleViolation> WesternElectricViolations(const std::vector<double>& values_mm,
                                                     double center_mm, double sigma_mm);

}  // namespace surfinspect
