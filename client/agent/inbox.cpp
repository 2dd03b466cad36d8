#include "client/agent/inbox.h"

#include <algorithm>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "core/io/atomic_file.h"
#include "core/io/staged_folder.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace fs = std::filesystem;

bool IsValidPartId(const std::string& id) {
  if (id.empty() || id.size() > 128 || id == "." || id == "..") return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

std::vector<std::string> CompleteParts(const std::string& inbox) {
  std::vector<std::string> parts;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(inbox, ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name[0] == '.' || !e.is_directory()) continue;
    if (fs::exists(e.path() / "DONE")) parts.push_back(name);
  }
  std::sort(parts.begin(), parts.end());
  return parts;
}

bool HasResults(const InboxLayout& layout, const std::string& id) {
  return fs::exists(fs::path(layout.results) / id / "report.json");
}

absl::StatusOr<std::vector<std::string>> RemoveUnfinishedSets(const std::string& results) {
  ASSIGN_OR_RETURN(std::vector<std::string> removed, RemoveStagingLeftovers(results));
  std::vector<fs::path> unfinished;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(results, ec)) {
    const std::string name = e.path().filename().string();
    if (!name.empty() && name[0] != '.' && e.is_directory() &&
        !fs::exists(e.path() / "report.json"))
      unfinished.push_back(e.path());
  }
  for (const fs::path& p : unfinished) {
    fs::remove_all(p, ec);
    if (ec)
      return absl::PermissionDeniedError(
          absl::StrCat("cannot remove ", p.string(), ": ", ec.message()));
    removed.push_back(p.filename().string());
  }
  return removed;
}

absl::Status MovePart(const std::string& inbox, const std::string& dest, const std::string& id) {
  std::error_code ec;
  fs::create_directories(dest, ec);
  if (ec) return absl::PermissionDeniedError(absl::StrCat(dest, ": ", ec.message()));
  fs::path target = fs::path(dest) / id;
  for (int n = 1; fs::exists(target); ++n) target = fs::path(dest) / absl::StrCat(id, ".", n);
  fs::rename(fs::path(inbox) / id, target, ec);
  if (ec)
    return absl::InternalError(absl::StrCat("cannot move ", id, " to ", dest, ": ", ec.message()));
  return absl::OkStatus();
}

absl::Status Quarantine(const InboxLayout& layout, const std::string& id, const std::string& why) {
  // error.txt goes in first, so the reason travels with the part.
  if (auto st =
          WriteStringAtomically((fs::path(layout.inbox) / id / "error.txt").string(), why + "\n");
      !st.ok())
    return st;
  return MovePart(layout.inbox, layout.quarantine, id);
}

}  // namespace surfinspect::client
