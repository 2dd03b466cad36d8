#include "core/history/western_electric.h"

namespace surfinspect {
namespace {

// +1 when the point is beyond k sigma above the centre, -1 below, 0 otherwise.
int Side(double z, double k) { return z > k ? 1 : z < -k ? -1 : 0; }

// `need` of the `window` points ending at i are beyond k sigma on the side
// of point i, which is beyond itself. Near the start the window is what
// there is: any earlier point would complete it.
bool CountRule(const std::vector<double>& z, std::size_t i, std::size_t window, int need,
               double k) {
  const int side = Side(z[i], k);
  if (side == 0) return false;
  int count = 0;
  for (std::size_t j = i + 1 >= window ? i + 1 - window : 0; j <= i; ++j)
    count += Side(z[j], k) == side ? 1 : 0;
  return count >= need;
}

}  // namespace

std::vector<RuleViolation> WesternElectricViolations(const std::vector<double>& values_mm,
                                                     double center_mm, double sigma_mm) {
  std::vector<RuleViolation> out;
  if (!(sigma_mm > 0)) return out;
  std::vector<double> z;
  for (double v : values_mm) z.push_back((v - center_mm) / sigma_mm);
  int run = 0, run_side = 0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    const int side = Side(z[i], 0.0);
    run = side != 0 && side == run_side ? run + 1 : (side != 0 ? 1 : 0);
    run_side = side;
    if (Side(z[i], 3.0) != 0) out.push_back({1, i});
    if (CountRule(z, i, 3, 2, 2.0)) out.push_back({2, i});
    if (CountRule(z, i, 5, 4, 1.0)) out.push_back({3, i});
    if (run >= 8) out.push_back({4, i});
  }
  return out;
}

}  // namespace surfinspect
