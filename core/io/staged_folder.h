// A folder of files that appears whole or not at all: its files are written
// into a staging folder, PARENT/.partial/NAME.<pid>.<n>, on the same file
// system as PARENT/NAME, and Commit renames the staging folder into place in
// one rename(2). A crash, a kill or a full disk before Commit leaves the
// target as it was (absent, or the previous set) and a leftover under
// PARENT/.partial/, which RemoveStagingLeftovers clears at the next start.
// PARENT/.partial itself is removed whenever it is left empty.
//
// The staging folder sits inside PARENT (not beside it) so that the rename
// never crosses a mount point, and under a hidden name so that readers that
// list PARENT's part folders (they skip names starting with '.') never see
// a set in the making.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

class StagedFolder {
 public:
  // Creates the staging folder for `target` (PARENT/NAME).
  static absl::StatusOr<StagedFolder> Begin(const std::string& target);
  StagedFolder(StagedFolder&& other) noexcept;
  StagedFolder& operator=(StagedFolder&&) = delete;
  ~StagedFolder();  // removes the staging folder unless committed, and an empty .partial

  // Where to write the files.
  const std::string& path() const { return staging_; }
  // Bytes of the files written into the staging folder so far.
  uint64_t Bytes() const;

  // Puts the files in place. A target that is absent or empty is replaced
  // by the staging folder in one rename. A target that already holds files
  // (a folder the user named, such as --out .) keeps them: the staged files
  // are renamed into it one by one, `last_file` last, and files of the same
  // names are replaced. The file system's entries are synced before and
  // after, so the set survives a power cut whole once Commit returns.
  absl::Status Commit(const std::string& last_file);

 private:
  StagedFolder(std::string target, std::string staging);
  std::string target_, staging_;
  bool committed_ = false;
};

// PARENT/.partial, where the staging folders of PARENT's sets live.
std::string StagingRoot(const std::string& parent);

// Removes every staging folder under PARENT/.partial (sets interrupted by a
// crash or a kill); returns their names. Call it only where no other process
// is writing sets into PARENT.
absl::StatusOr<std::vector<std::string>> RemoveStagingLeftovers(const std::string& parent);

}  // namespace surfinspect
