#include "core/cad/cad_import.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/cad/limited_child.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/mesh_hash.h"
#include "core/types/status_macros.h"

namespace surfinspect {
namespace fs = std::filesystem;
namespace {

constexpr char kWorker[] = "surfinspect-cad-worker";

absl::StatusOr<CadReport> ReadReport(const std::string& path) {
  ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path, 64 << 20));
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded()) return absl::DataLossError(path + ": not JSON");
  return DecodeCadReport(j);
}

// The mesh and groups of a finished cache entry.
absl::StatusOr<CadMesh> ReadEntry(const std::string& obj, const std::string& json) {
  CadMesh m;
  ASSIGN_OR_RETURN(m.report, ReadReport(json));
  ASSIGN_OR_RETURN(m.mesh, ReadMesh(obj));
  ASSIGN_OR_RETURN(m.groups, ReadMeshGroups(obj, m.mesh));
  m.mesh_path = obj;
  return m;
}

absl::Status RunWorker(const std::string& path, const CadSettings& s, const std::string& obj,
                       const std::string& json) {
  ASSIGN_OR_RETURN(const std::string worker, CadWorkerPath());
  std::vector<std::string> argv = {worker,
                                   "--in",
                                   path,
                                   "--out",
                                   obj,
                                   "--report",
                                   json,
                                   "--chord-tolerance",
                                   absl::StrFormat("%.17g", s.tessellation.chord_tolerance_mm),
                                   "--angular-tolerance",
                                   absl::StrFormat("%.17g", s.tessellation.angular_tolerance_deg)};
  if (!s.tessellation.body.empty()) argv.insert(argv.end(), {"--body", s.tessellation.body});
  return RunLimited(argv, {s.limits.seconds, s.limits.memory_mb},
                    absl::StrCat("tessellating ", path));
}

// The settings checked and the file's SHA-256, read within the size limit.
absl::StatusOr<std::string> CheckedSha256(const std::string& path, const CadSettings& settings) {
  RETURN_IF_ERROR(ValidateCadSettings(settings));
  ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path, settings.limits.max_file_bytes));
  return Sha256Hex(bytes);
}

}  // namespace

absl::StatusOr<std::string> CadWorkerPath() {
  if (const char* env = std::getenv("SURFINSPECT_CAD_WORKER"); env && *env) return std::string(env);
  std::error_code ec;
  std::vector<fs::path> tried = {fs::read_symlink("/proc/self/exe", ec).parent_path() / kWorker,
                                 fs::path("/usr/local/bin") / kWorker,
                                 fs::path("/usr/bin") / kWorker};
  for (const fs::path& p : tried)
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  return absl::NotFoundError(
      absl::StrCat(kWorker,
                   " not found (looked beside this program, in "
                   "/usr/local/bin and /usr/bin; set SURFINSPECT_CAD_WORKER)"));
}

absl::StatusOr<CadReport> TessellateCadFile(const std::string& path, const CadSettings& settings,
                                            const std::string& obj_path,
                                            const std::string& report_path) {
  ASSIGN_OR_RETURN(const std::string sha, CheckedSha256(path, settings));
  RETURN_IF_ERROR(RunWorker(path, settings, obj_path, report_path));
  ASSIGN_OR_RETURN(CadReport report, ReadReport(report_path));
  report.source_sha256 = sha;
  return report;
}

std::string DefaultCadCache() {
  const char* own = std::getenv("SURFINSPECT_CAD_CACHE");
  if (own && *own) return own;
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg && *xdg) return (fs::path(xdg) / "surfinspect" / "cad").string();
  const char* home = std::getenv("HOME");
  if (home && *home) return (fs::path(home) / ".cache" / "surfinspect" / "cad").string();
  return "/tmp/surfinspect-cad-cache";
}

std::string CadCacheKey(const std::string& file_sha256, const TessellationSettings& s) {
  const std::string settings = absl::StrFormat(
      "chord=%.17g angle=%.17g body=%s v1", s.chord_tolerance_mm, s.angular_tolerance_deg, s.body);
  return Sha256Hex(file_sha256 + "\n" + settings).substr(0, 32);
}

absl::StatusOr<CadMesh> ImportCad(const std::string& path, const CadSettings& settings,
                                  const std::string& cache_dir) {
  ASSIGN_OR_RETURN(const std::string sha, CheckedSha256(path, settings));
  const std::string key = CadCacheKey(sha, settings.tessellation);
  const std::string obj = (fs::path(cache_dir) / (key + ".obj")).string();
  const std::string json = (fs::path(cache_dir) / (key + ".json")).string();
  std::error_code ec;
  // The worker writes the OBJ, then the report: a report means a whole entry.
  if (fs::exists(json, ec)) {
    if (auto m = ReadEntry(obj, json); m.ok()) {
      m->from_cache = true;
      m->report.source_sha256 = sha;
      return m;
    }
  }
  fs::create_directories(cache_dir, ec);
  if (ec)
    return absl::FailedPreconditionError(
        absl::StrCat(cache_dir, ": cannot create the CAD cache: ", ec.message()));
  RETURN_IF_ERROR(RunWorker(path, settings, obj, json));
  ASSIGN_OR_RETURN(CadMesh m, ReadEntry(obj, json));
  m.report.source_sha256 = sha;
  return m;
}

}  // namespace surfinspect
