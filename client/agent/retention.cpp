#include "client/agent/retention.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/cell/part_files.h"
#include "core/io/disk_space.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::system_clock;

struct Item {
  std::string id;
  fs::path path;
  Clock::time_point time;
  uint64_t bytes = 0;
};

Clock::time_point ToSystem(fs::file_time_type t) {
  return std::chrono::time_point_cast<Clock::duration>(t - fs::file_time_type::clock::now() +
                                                       Clock::now());
}

uint64_t SizeOf(const fs::path& p) {
  std::error_code ec;
  uint64_t bytes = 0;
  if (fs::is_regular_file(p, ec)) return fs::file_size(p, ec);
  for (const auto& e : fs::recursive_directory_iterator(p, ec))
    if (e.is_regular_file(ec)) bytes += e.file_size(ec);
  return bytes;
}

uint64_t HeavyBytes(const fs::path& dir) {
  uint64_t bytes = 0;
  for (const PartFileEntry& e : PartFileCatalogue())
    if (e.heavy) bytes += SizeOf(dir / e.file_name);
  return bytes;
}

// Part folders of `root`, newest first: a results folder by its
// report.json (the set's completion), an archived part by its folder.
std::vector<Item> PartsIn(const std::string& root, bool results,
                          uint64_t (*bytes_of)(const fs::path&)) {
  std::vector<Item> items;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name[0] == '.' || !e.is_directory(ec)) continue;
    const fs::path stamp = results ? e.path() / "report.json" : e.path();
    const auto time = fs::last_write_time(stamp, ec);
    if (ec) continue;  // a results folder without its report is not a set
    items.push_back({name, e.path(), ToSystem(time), bytes_of(e.path())});
  }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return std::tie(a.time, a.id) > std::tie(b.time, b.id);
  });
  return items;
}

// The items beyond `limit`, oldest last as they came.
std::vector<const Item*> Due(const std::vector<Item>& items, const RetentionLimit& limit,
                             Clock::time_point now) {
  std::vector<const Item*> due;
  uint64_t total = 0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    total += items[i].bytes;
    const double age_days = std::chrono::duration<double>(now - items[i].time).count() / 86400.0;
    if ((limit.parts > 0 && i >= static_cast<std::size_t>(limit.parts)) ||
        (limit.gb > 0 && static_cast<double>(total) > limit.gb * 1e9) ||
        (limit.days > 0 && age_days > limit.days))
      due.push_back(&items[i]);
  }
  return due;
}

absl::Status RemoveTree(const fs::path& p) {
  std::error_code ec;
  fs::remove_all(p, ec);
  if (ec)
    return absl::PermissionDeniedError(
        absl::StrCat("cannot prune ", p.string(), ": ", ec.message()));
  return absl::OkStatus();
}

absl::StatusOr<RetentionLimit> LimitOf(const nlohmann::json& j, const std::string& where) {
  RetentionLimit l;
  if (!j.is_object()) return absl::InvalidArgumentError(where + ": must be an object");
  for (const auto& [key, value] : j.items()) {
    if (key != "days" && key != "gb" && key != "parts")
      return absl::InvalidArgumentError(
          absl::StrCat(where, ": unknown field \"", key, "\" (known: days, gb, parts)"));
    if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0)
      return absl::InvalidArgumentError(absl::StrCat(where, ".", key, ": a number >= 0 expected"));
  }
  l.days = j.value("days", 0.0);
  l.gb = j.value("gb", 0.0);
  const double parts = j.value("parts", 0.0);
  if (parts != std::floor(parts) || parts > 1e9)
    return absl::InvalidArgumentError(where + ".parts: a whole number expected");
  l.parts = static_cast<int>(parts);
  return l;
}

}  // namespace

absl::StatusOr<RetentionConfig> RetentionConfigOf(const CellConfig& cell) {
  RetentionConfig c;
  const nlohmann::json r = cell.raw.value("retention", nlohmann::json::object());
  const std::string where = cell.path + ": retention";
  if (!r.is_object()) return absl::InvalidArgumentError(where + ": must be an object");
  for (const auto& [key, value] : r.items()) {
    RetentionLimit* limit = key == "heavy"     ? &c.heavy
                            : key == "light"   ? &c.light
                            : key == "archive" ? &c.archive
                                               : nullptr;
    if (limit == nullptr)
      return absl::InvalidArgumentError(
          absl::StrCat(where, ": unknown kind \"", key, "\" (known: heavy, light, archive)"));
    absl::StatusOr<RetentionLimit> l = LimitOf(value, absl::StrCat(where, ".", key));
    if (!l.ok()) return l.status();
    *limit = *l;
  }
  return c;
}

namespace {

// RESULTS/<part> beyond `limit`: the heavy files, or (`whole`) the folder.
absl::Status PruneResults(const InboxLayout& layout, const RetentionLimit& limit, bool whole,
                          const SettledFn& settled, Clock::time_point now, PruneResult& r) {
  if (!limit.any()) return absl::OkStatus();
  const std::vector<Item> items = PartsIn(layout.results, true, whole ? SizeOf : HeavyBytes);
  for (const Item* item : Due(items, limit, now)) {
    if (item->bytes == 0) continue;  // its heavy files are gone already
    if (settled && !settled(item->id)) {
      ++r.unsettled;
      continue;
    }
    if (whole) {
      RETURN_IF_ERROR(RemoveTree(item->path));
    } else {
      for (const PartFileEntry& e : PartFileCatalogue())
        if (e.heavy) RETURN_IF_ERROR(RemoveTree(item->path / e.file_name));
    }
    r.bytes += item->bytes;
    ++(whole ? r.light : r.heavy);
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<PruneResult> Prune(const InboxLayout& layout, const RetentionConfig& config,
                                  const SettledFn& settled, Clock::time_point now) {
  PruneResult r;
  RETURN_IF_ERROR(PruneResults(layout, config.light, true, settled, now, r));
  RETURN_IF_ERROR(PruneResults(layout, config.heavy, false, settled, now, r));
  if (config.archive.any()) {
    const std::vector<Item> archived = PartsIn(layout.archive, false, SizeOf);
    for (const Item* item : Due(archived, config.archive, now)) {
      RETURN_IF_ERROR(RemoveTree(item->path));
      r.bytes += item->bytes;
      ++r.archive;
    }
  }
  return r;
}

std::string PruneText(const PruneResult& r) {
  std::string out =
      absl::StrCat("pruned ", r.heavy, " parts' heavy files, ", r.light, " results folders, ",
                   r.archive, " archived parts (", MebibytesText(r.bytes), ")");
  if (r.unsettled > 0)
    absl::StrAppend(&out, "; ", r.unsettled,
                    " due but kept: not yet recorded in the database or delivered over MQTT");
  return out;
}

}  // namespace surfinspect::client
