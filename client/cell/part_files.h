// The catalogue of a part's files: every file an inspected part can leave,
// each with its catalogue name, its default file name, one line for help
// texts, and its writer. `surfinspect errormap` (its own paths, one flag per
// file), `surfinspect inspect` and the cell-agent (a results folder, the
// catalogue's names) write through it, so the programs, their help and the
// docs cannot disagree on what a part's files are.
//
// Which files a part gets is a PartFileSet: report.json always, the others
// by name ("ply", "csv", "png", "pdf", "html", "qif"), as cell.json's
// "outputs" and inspect's --outputs list them. By default every file but the
// CSV, which is the largest by far and one word away.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/errormap/error_map.h"
#include "core/pipeline/inspection_report.h"
#include "core/report/html_sections.h"
#include "core/report/qif_results.h"
#include "core/types/point_cloud.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect::client {

enum class PartFile { kReport, kPly, kCsv, kPng, kPdf, kHtml, kQif };
inline constexpr int kPartFileCount = 7;

struct PartFileEntry {
  PartFile file;
  const char* name;       // in "outputs" and --outputs; "report" is always written
  const char* file_name;  // in a part's results folder
  const char* what;       // one line, for help texts
  bool by_default;
  // Heavy files grow with the points (the PLY, the CSV, the HTML with its
  // embedded cloud): retention prunes them first (client/agent/retention.h).
  bool heavy;
};

// Every entry, report.json first (it is written last: its presence means the
// part's files are complete).
const std::array<PartFileEntry, kPartFileCount>& PartFileCatalogue();
const PartFileEntry& EntryOf(PartFile file);

// The files a part gets; report.json always.
class PartFileSet {
 public:
  static PartFileSet Defaults();
  static PartFileSet All();
  bool Has(PartFile file) const { return on_[static_cast<int>(file)]; }
  void Set(PartFile file, bool on);
  // The catalogue names it holds, report first ("report, ply, png").
  std::string Names() const;

 private:
  std::array<bool, kPartFileCount> on_{};
};

// A list of catalogue names ("ply", "csv", ...; "report" may be named too)
// as a set. InvalidArgument naming `where` and the unknown name, listing
// the known ones.
absl::StatusOr<PartFileSet> ParsePartFileSet(const std::vector<std::string>& names,
                                             const std::string& where);
// "ply, csv, png, pdf, html, qif": the names an "outputs" list may hold.
std::string PartFileNames();
// One line per entry, "  errormap.ply (ply): ...", with its default.
std::string PartFilesHelp();

// What the writers read. A writer reads only its own fields: the PLY and CSV
// the points, the error map's deviations (with its tolerance and colour
// range), the report the rest.
struct PartFileInputs {
  std::string part_id;
  std::string cell;  // "" = not known
  // The points the PLY and CSV carry, in `points_frame`, and the same points
  // in the part frame for the pictures; deviations in `error_map`.
  const PointCloud* points = nullptr;
  std::string points_frame = "world";
  const PointCloud* points_in_part = nullptr;
  const ErrorMapResult* error_map = nullptr;
  const InspectionReport* report = nullptr;
  std::string report_text;                       // report.json's bytes
  std::string png;                               // errormap.png's bytes
  const TriangleMesh* mesh_in_part = nullptr;    // the HTML's overlay; null = none
  std::vector<ViewpointCalibration> viewpoints;  // calibration status; empty = not known
  QifContext qif;                                // part, cell and points file of result.qif
};

// One file at `path`, written atomically. result.qif is written for a
// surfinspect.report/2 only (a report from an older server has no plan).
absl::Status WritePartFile(PartFile file, const std::string& path, const PartFileInputs& in);

// The files of `set` into `dir` under their catalogue names, as one whole
// set: written into a staging folder (core/io/staged_folder.h), report.json
// last, then renamed into place, so a failure, a kill or a full disk leaves
// no file of this set. A full disk is ResourceExhausted (core/io/
// disk_space.h: IsDiskFull). `bytes`, when given, receives the set's size;
// on a failure, what had been written before it.
absl::Status WritePartFiles(const std::string& dir, const PartFileSet& set,
                            const PartFileInputs& in, uint64_t* bytes = nullptr);

}  // namespace surfinspect::client
