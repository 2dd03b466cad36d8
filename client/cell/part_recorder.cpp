#include "client/cell/part_recorder.h"

#include <openssl/evp.h>
#include <sys/stat.h>

#include <cstring>
#include <filesystem>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/cell/part_files.h"
#include "core/history/part_record.h"
#include "core/history/triangle_summary.h"
#include "core/io/atomic_file.h"
#include "core/io/io_transform.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace fs = std::filesystem;
namespace {

// WriteErrorMapPly's record: float x y z scalar_deviation quality, uchar r g b.
constexpr std::size_t kPlyRecord = 23;

// A file's modification time in the store's format.
absl::StatusOr<std::string> ModifiedUtc(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return absl::NotFoundError(absl::StrCat(path, ": ", std::strerror(errno)));
  std::tm tm{};
  gmtime_r(&st.st_mtim.tv_sec, &tm);
  return absl::StrFormat("%04d-%02d-%02dT%02d:%02d:%02d.%06dZ", tm.tm_year + 1900, tm.tm_mon + 1,
                         tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                         static_cast<int>(st.st_mtim.tv_nsec / 1000));
}

absl::StatusOr<std::vector<TriangleStat>> Summary(const RecordContext& c, const PointCloud& world,
                                                  const std::vector<float>& deviation_mm) {
  BatchQuerySettings q;
  q.max_distance_mm = c.max_distance_mm;
  ASSIGN_OR_RETURN(auto closest, QueryClosest(*c.part, world, c.world_from_part.inverse(), q));
  std::vector<uint32_t> ids(closest.size());
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = closest[i].triangle_id;
  return SummarizeByTriangle(ids, deviation_mm,
                             static_cast<uint32_t>(c.part->mesh().num_triangles()));
}

}  // namespace

std::string PlanHash(const nlohmann::json& plan) {
  const std::string text = plan.dump();
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_Digest(text.data(), text.size(), md, &len, EVP_sha256(), nullptr);
  std::string hex;
  for (unsigned int i = 0; i < len; ++i) absl::StrAppendFormat(&hex, "%02x", md[i]);
  return hex;
}

std::string CalibrationStateJson(const CellConfig& cell) {
  nlohmann::json views = nlohmann::json::array();
  for (const CellViewpoint& vp : cell.viewpoints) {
    nlohmann::json v = {{"name", vp.name}, {"calibrated", vp.world_from_sensor.has_value()}};
    if (vp.world_from_sensor) v["world_from_sensor"] = TransformToJsonValue(*vp.world_from_sensor);
    views.push_back(std::move(v));
  }
  return nlohmann::json{{"viewpoints", views}}.dump();
}

RecordContext RecordContextOf(const CellConfig& cell, std::shared_ptr<const MeshIndex> part) {
  RecordContext c;
  c.cell = cell.name;
  c.plan_hash = cell.plan ? PlanHash(*cell.plan) : "";
  c.calibration_json = CalibrationStateJson(cell);
  c.world_from_part = cell.world_from_part;
  c.max_distance_mm = cell.error_map.max_distance_mm;
  c.part = std::move(part);
  return c;
}

absl::Status ReadErrorMapPly(const std::string& path, PointCloud* points,
                             std::vector<float>* deviation_mm) {
  auto bytes = ReadFileToString(path, std::size_t{4} << 30);
  if (!bytes.ok()) return bytes.status();
  const std::size_t end = bytes->find("end_header\n");
  const std::string header = bytes->substr(0, end == std::string::npos ? 0 : end);
  std::size_t count = 0;
  for (absl::string_view line : absl::StrSplit(header, '\n'))
    if (absl::ConsumePrefix(&line, "element vertex ") && !absl::SimpleAtoi(line, &count)) count = 0;
  if (end == std::string::npos ||
      header.find("format binary_little_endian 1.0\n") == std::string::npos ||
      header.find("property float scalar_deviation\nproperty float quality\n") ==
          std::string::npos ||
      bytes->size() - (end + 11) != count * kPlyRecord)
    return absl::DataLossError(absl::StrCat(path, ": not a surfinspect error-map PLY"));
  std::vector<Eigen::Vector3f> pts(count);
  deviation_mm->resize(count);
  const char* p = bytes->data() + end + 11;
  for (std::size_t i = 0; i < count; ++i, p += kPlyRecord) {
    std::memcpy(pts[i].data(), p, 12);
    std::memcpy(&(*deviation_mm)[i], p + 12, 4);
  }
  *points = PointCloud::Unorganized(std::move(pts));
  return absl::OkStatus();
}

absl::StatusOr<PartRecord> MakePartRecord(const RecordContext& c, const std::string& part_id,
                                          const std::string& report_json, const std::string& where,
                                          const PointCloud& world,
                                          const std::vector<float>& deviation_mm,
                                          const std::vector<uint32_t>& triangle_id) {
  PartRecord r;
  r.cell = c.cell;
  r.part_id = part_id;
  r.inspected_utc = UtcNow();
  r.software_version = kSoftwareVersion;
  r.plan_hash = c.plan_hash;
  r.calibration_json = c.calibration_json.empty() ? "{}" : c.calibration_json;
  RETURN_IF_ERROR(FillFromReportJson(report_json, where, &r));
  if (!c.part) return r;
  r.num_triangles = static_cast<uint32_t>(c.part->mesh().num_triangles());
  ASSIGN_OR_RETURN(r.triangles, triangle_id.empty() ? Summary(c, world, deviation_mm)
                                                    : SummarizeByTriangle(triangle_id, deviation_mm,
                                                                          r.num_triangles));
  return r;
}

absl::StatusOr<PartRecord> PartRecordFromFiles(const RecordContext& c, const std::string& part_id,
                                               const std::string& dir) {
  const std::string report_path = (fs::path(dir) / "report.json").string();
  auto report = ReadFileToString(report_path, std::size_t{64} << 20);
  if (!report.ok()) return report.status();
  ASSIGN_OR_RETURN(auto when, ModifiedUtc(report_path));
  PointCloud world;
  std::vector<float> deviation;
  if (c.part) {
    const std::string ply = (fs::path(dir) / EntryOf(PartFile::kPly).file_name).string();
    RETURN_IF_ERROR(ReadErrorMapPly(ply, &world, &deviation));
  }
  ASSIGN_OR_RETURN(auto r, MakePartRecord(c, part_id, *report, report_path, world, deviation));
  r.inspected_utc = when;
  nlohmann::json files = {{"report", report_path}};
  for (PartFile file : {PartFile::kPly, PartFile::kPng, PartFile::kCsv}) {
    const char* name = EntryOf(file).file_name;
    if (fs::exists(fs::path(dir) / name)) files[name] = (fs::path(dir) / name).string();
  }
  r.files_json = files.dump();
  return r;
}

absl::StatusOr<bool> RecordPartFromFiles(ResultsStore& store, const RecordContext& context,
                                         const std::string& part_id, const std::string& dir) {
  ASSIGN_OR_RETURN(auto record, PartRecordFromFiles(context, part_id, dir));
  return store.Record(record);
}

absl::StatusOr<int> CatchUpFromFiles(ResultsStore& store, const RecordContext& context,
                                     const std::string& results_root,
                                     std::vector<std::string>* skipped) {
  std::error_code ec;
  std::vector<std::string> ids;
  for (const auto& e : fs::directory_iterator(results_root, ec))
    if (e.is_directory() && fs::exists(e.path() / "report.json"))
      ids.push_back(e.path().filename().string());
  if (ec) return absl::NotFoundError(absl::StrCat(results_root, ": ", ec.message()));
  std::sort(ids.begin(), ids.end());
  int written = 0;
  for (const std::string& id : ids) {
    ASSIGN_OR_RETURN(auto there, store.Contains(context.cell, id));
    if (there) continue;
    auto record = PartRecordFromFiles(context, id, (fs::path(results_root) / id).string());
    if (!record.ok()) {  // this part's files: skip it; the store's trouble: stop
      if (skipped) skipped->push_back(absl::StrCat(id, ": ", record.status().message()));
      continue;
    }
    ASSIGN_OR_RETURN(auto w, store.Record(*record));
    written += w ? 1 : 0;
  }
  return written;
}

}  // namespace surfinspect::client
