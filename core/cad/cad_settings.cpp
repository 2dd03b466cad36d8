#include "core/cad/cad_settings.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "absl/strings/str_cat.h"

namespace surfinspect {
namespace {

absl::Status InRange(const char* field, double v, double lo, double hi, const char* unit) {
  if (std::isfinite(v) && v >= lo && v <= hi) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(field, " must be in [", lo, ", ", hi, "] ", unit, " (got ", v, ")"));
}

}  // namespace

absl::Status ValidateCadSettings(const CadSettings& s) {
  if (auto st = InRange("chord_tolerance_mm", s.tessellation.chord_tolerance_mm, 1e-4, 10, "mm");
      !st.ok())
    return st;
  if (auto st =
          InRange("angular_tolerance_deg", s.tessellation.angular_tolerance_deg, 1, 60, "degrees");
      !st.ok())
    return st;
  if (auto st = InRange("limits.seconds", s.limits.seconds, 1, 86400, "s"); !st.ok()) return st;
  if (s.limits.memory_mb < 64)
    return absl::InvalidArgumentError(
        absl::StrCat("limits.memory_mb must be at least 64 (got ", s.limits.memory_mb, ")"));
  if (s.limits.max_file_bytes == 0)
    return absl::InvalidArgumentError("limits.max_file_bytes must be positive");
  return absl::OkStatus();
}

bool IsCadPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs";
}

}  // namespace surfinspect
