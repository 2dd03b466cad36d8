// The inbox protocol between a scanner and the cell-agent:
//   INBOX/<part-id>/<viewpoint>.pcd   one organized scan per viewpoint
//   INBOX/<part-id>/DONE              written last: the part is complete
// A part leaves the inbox only after its results are on disk: it is moved
// (rename) to ARCHIVE/<part-id>, or to QUARANTINE/<part-id> with error.txt
// when it can never succeed (corrupt scan, invalid request).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect::client {

struct InboxLayout {
  std::string inbox, results, archive, quarantine;
};

// Complete parts (with DONE), oldest name first; ignores hidden entries.
std::vector<std::string> CompleteParts(const std::string& inbox);
// A part id is a plain folder name: [A-Za-z0-9._-], 1..128 chars, no dots only.
bool IsValidPartId(const std::string& id);
// Results already on disk (report.json is written last).
bool HasResults(const InboxLayout& layout, const std::string& part_id);
// Sets whose writing a crash or a kill interrupted: RESULTS/.partial/*
// (client/cell/part_files.h stages each set there) and, from versions that
// wrote in place, part folders without report.json. Removes them and
// returns their names; their parts are still in the inbox and are
// inspected again. Only for the one agent that owns RESULTS.
absl::StatusOr<std::vector<std::string>> RemoveUnfinishedSets(const std::string& results);
// Moves INBOX/<id> to DEST/<id> (DEST/<id>.N if taken).
absl::Status MovePart(const std::string& inbox, const std::string& dest, const std::string& id);
absl::Status Quarantine(const InboxLayout& layout, const std::string& id, const std::string& why);

}  // namespace surfinspect::client
