#include "client/cell/part_files.h"

#include <algorithm>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/atomic_file.h"
#include "core/io/disk_space.h"
#include "core/io/staged_folder.h"
#include "core/report/error_map_output.h"
#include "core/report/html_report.h"
#include "core/report/pdf_report.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {
namespace {

constexpr std::array<PartFileEntry, kPartFileCount> kCatalogue = {{
    {PartFile::kReport, "report", "report.json",
     "the verdict, statistics, characteristics and defects (always written, last)", true, false},
    {PartFile::kPly, "ply", "errormap.ply",
     "every point with its deviation and colour (CloudCompare, MeshLab)", true, true},
    {PartFile::kCsv, "csv", "deviations.csv", "one row per point: x, y, z, deviation", false, true},
    {PartFile::kPng, "png", "errormap.png", "the coloured map with its legend and histogram", true,
     false},
    {PartFile::kPdf, "pdf", "report.pdf", "the printable report for the quality file", true, false},
    {PartFile::kHtml, "html", "report.html", "the interactive 3D report, one self-contained page",
     true, true},
    {PartFile::kQif, "qif", "result.qif", "QIF 3.0 Results for quality systems", true, false},
}};

absl::Status Need(bool present, const char* what, PartFile file) {
  if (present) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(EntryOf(file).file_name, ": no ", what, " to write it from"));
}

absl::Status WritePoints(PartFile file, const std::string& path, const PartFileInputs& in) {
  RETURN_IF_ERROR(Need(in.points && in.error_map, "points and deviations", file));
  if (file == PartFile::kPly)
    return WriteErrorMapPly(path, *in.points, *in.error_map, in.points_frame);
  return WriteErrorMapCsv(path, *in.points, *in.error_map);
}

absl::Status WritePdf(const std::string& path, const PartFileInputs& in) {
  RETURN_IF_ERROR(
      Need(in.report && in.points_in_part && in.error_map, "report and points", PartFile::kPdf));
  PdfReportInput pdf;
  pdf.part_id = in.part_id;
  pdf.cell = in.cell;
  pdf.report = in.report;
  pdf.points_in_part = in.points_in_part;
  pdf.deviation_mm = &in.error_map->deviation_mm;
  return WritePdfReport(path, pdf);
}

absl::Status WriteHtml(const std::string& path, const PartFileInputs& in) {
  RETURN_IF_ERROR(
      Need(in.report && in.points_in_part && in.error_map, "report and points", PartFile::kHtml));
  HtmlReportInput html;
  html.report = in.report;
  html.points_in_part = in.points_in_part;
  html.deviation_mm = &in.error_map->deviation_mm;
  html.mesh_in_part = in.mesh_in_part;
  html.context = {in.part_id, in.cell, in.viewpoints};
  return WriteHtmlReport(path, html);
}

// QIF is mapped from a surfinspect.report/2 (its characteristics); a report
// of another schema (from a server that predates it) gets no result.qif.
absl::Status WriteQif(const std::string& path, const PartFileInputs& in) {
  RETURN_IF_ERROR(Need(in.report != nullptr, "report", PartFile::kQif));
  if (in.report->schema != kReportSchema) return absl::OkStatus();
  return WriteQifResults(path, *in.report, in.qif);
}

}  // namespace

const std::array<PartFileEntry, kPartFileCount>& PartFileCatalogue() { return kCatalogue; }

const PartFileEntry& EntryOf(PartFile file) { return kCatalogue[static_cast<int>(file)]; }

PartFileSet PartFileSet::Defaults() {
  PartFileSet set;
  for (const PartFileEntry& e : kCatalogue) set.Set(e.file, e.by_default);
  return set;
}

PartFileSet PartFileSet::All() {
  PartFileSet set;
  for (const PartFileEntry& e : kCatalogue) set.Set(e.file, true);
  return set;
}

void PartFileSet::Set(PartFile file, bool on) {
  on_[static_cast<int>(file)] = on || file == PartFile::kReport;
}

std::string PartFileSet::Names() const {
  std::vector<std::string> names;
  for (const PartFileEntry& e : kCatalogue)
    if (Has(e.file)) names.push_back(e.name);
  return absl::StrJoin(names, ", ");
}

absl::StatusOr<PartFileSet> ParsePartFileSet(const std::vector<std::string>& names,
                                             const std::string& where) {
  PartFileSet set;
  set.Set(PartFile::kReport, true);
  for (const std::string& name : names) {
    const auto it = std::find_if(kCatalogue.begin(), kCatalogue.end(),
                                 [&](const PartFileEntry& e) { return name == e.name; });
    if (it == kCatalogue.end())
      return absl::InvalidArgumentError(
          absl::StrCat(where, ": unknown output \"", name, "\" (known: ", PartFileNames(), ")"));
    set.Set(it->file, true);
  }
  return set;
}

std::string PartFileNames() {
  std::vector<std::string> names;
  for (const PartFileEntry& e : kCatalogue)
    if (e.file != PartFile::kReport) names.push_back(e.name);
  return absl::StrJoin(names, ", ");
}

std::string PartFilesHelp() {
  std::string out;
  for (const PartFileEntry& e : kCatalogue)
    absl::StrAppend(&out, "  ", e.file_name, " (", e.name, "): ", e.what,
                    e.file == PartFile::kReport ? ""
                    : e.by_default              ? "; default on"
                                                : "; default off",
                    "\n");
  return out;
}

absl::Status WritePartFile(PartFile file, const std::string& path, const PartFileInputs& in) {
  switch (file) {
    case PartFile::kReport:
      return WriteStringAtomically(path, in.report_text);
    case PartFile::kPly:
    case PartFile::kCsv:
      return WritePoints(file, path, in);
    case PartFile::kPng:
      return WriteStringAtomically(path, in.png);
    case PartFile::kPdf:
      return WritePdf(path, in);
    case PartFile::kHtml:
      return WriteHtml(path, in);
    case PartFile::kQif:
      return WriteQif(path, in);
  }
  return absl::InternalError("unknown part file");
}

namespace {

// The files of `set` into `dir`, report.json last.
absl::Status WriteEach(const std::string& dir, const PartFileSet& set, const PartFileInputs& in) {
  for (const PartFileEntry& e : kCatalogue)
    if (e.file != PartFile::kReport && set.Has(e.file))
      RETURN_IF_ERROR(WritePartFile(e.file, absl::StrCat(dir, "/", e.file_name), in));
  return WritePartFile(PartFile::kReport,
                       absl::StrCat(dir, "/", EntryOf(PartFile::kReport).file_name), in);
}

}  // namespace

absl::Status WritePartFiles(const std::string& dir, const PartFileSet& set,
                            const PartFileInputs& in, uint64_t* bytes) {
  if (bytes != nullptr) *bytes = 0;
  absl::StatusOr<StagedFolder> staged = StagedFolder::Begin(dir);
  if (!staged.ok()) return AsDiskFull(staged.status(), dir);
  absl::Status st = WriteEach(staged->path(), set, in);
  if (bytes != nullptr) *bytes = staged->Bytes();
  if (st.ok()) st = staged->Commit(EntryOf(PartFile::kReport).file_name);
  // Told before the staged files go, while a full disk is still full.
  return AsDiskFull(st, dir);
}

}  // namespace surfinspect::client
