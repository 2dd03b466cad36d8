// core/report/pdf_report.cpp and core/report/pdf_canvas.cpp: report.pdf
// read back with poppler's tools (pdftotext, pdfinfo, pdffonts, pdftoppm),
// which share no code with cairo's writer.
#include "core/report/pdf_report.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>

#include "core/pipeline/inspection_report.h"
#include "core/report/pdf_canvas.h"
#include "tests/support/png_decode.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using testing::TempDir;

const char kNasty[] = "<script>alert(\"x\")</script> & 'q' <b>";

bool HavePoppler() { return std::system("pdftotext -v >/dev/null 2>&1") == 0; }

std::string Shell(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  pclose(p);
  return out;
}

std::string NoSpace(const std::string& s) {
  std::string out;
  for (char c : s)
    if (!std::isspace(static_cast<unsigned char>(c))) out += c;
  return out;
}

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The "Pages:" count of pdfinfo's output; -1 when absent.
int Pages(const std::string& info) {
  const std::size_t at = info.find("Pages:");
  return at == std::string::npos ? -1 : std::atoi(info.c_str() + at + 6);
}

InspectionReport Report(const std::string& name) {
  nlohmann::json j = nlohmann::json::parse(R"({
    "verdict": "fail",
    "tolerance": {"band_mm": 0.1, "verdict": "fail", "reason": "2 points outside", "fraction_within": 0.5},
    "color_range_mm": 0.5, "points": {"count": 200, "valid": 200, "matched": 200},
    "statistics": {"min_mm": -0.5, "max_mm": 0.45, "mean_mm": -0.025, "rms_mm": 0.29},
    "histogram": {"min_mm": -0.5, "max_mm": 0.5, "counts": [10, 100, 90]},
    "characteristics": [{"type": "region", "verdict": "fail", "reason": "outside",
      "tolerance_mm": {"lower": -0.1, "upper": 0.1}, "points": 200, "min_mm": -0.5,
      "max_mm": 0.45, "mean_mm": -0.025, "fraction_within": 0.5}],
    "defects": [{"id": 7, "kind": "bump", "centroid_mm": [3, 4, 0], "area_mm2": 2,
                 "extent_mm": 1, "peak_mm": 0.45, "points": 5}]})");
  j["characteristics"][0]["name"] = name;
  j["defects"][0]["region"] = name;
  absl::StatusOr<InspectionReport> report = DecodeReport(j);
  EXPECT_TRUE(report.ok()) << report.status();
  return report.ok() ? *std::move(report) : InspectionReport{};
}

// A 20 x 10 organized cloud, deviation -0.5 .. +0.45 mm by column.
struct Cloud {
  PointCloud points;
  std::vector<float> deviation;
};

Cloud MakeCloud(bool organized) {
  Cloud c;
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 200; ++i) {
    pts.emplace_back(static_cast<float>(i % 20), static_cast<float>(i / 20),
                     0.1f * static_cast<float>(i % 3));
    c.deviation.push_back(static_cast<float>((i % 20) - 10) * 0.05f);
  }
  c.points = organized ? PointCloud() : PointCloud::Unorganized(pts);
  if (organized) {
    c.points.width = 20;
    c.points.height = 10;
    c.points.points = pts;
  }
  return c;
}

// The renderer's input: `report` over the cloud `c`.
PdfReportInput InputOf(const std::string& part_id, const InspectionReport& report, const Cloud& c) {
  PdfReportInput in;
  in.part_id = part_id;
  in.report = &report;
  in.points_in_part = &c.points;
  in.deviation_mm = &c.deviation;
  return in;
}

TEST(PdfReport, ForeignStringsRenderLiterallyOnAnA4PageWithEmbeddedFonts) {
  if (!HavePoppler()) GTEST_SKIP() << "poppler-utils (pdftotext) not installed: PDF NOT CHECKED";
  const Cloud c = MakeCloud(true);
  const InspectionReport report = Report(kNasty);
  PdfReportInput in = InputOf(std::string("part \"1\" <i>&amp;</i> '") + kNasty, report, c);
  in.cell = "cell <7>";
  in.time_utc = "2026-12-01 10:00:00 UTC";
  TempDir dir;
  const std::string pdf = dir.File("r.pdf");
  ASSERT_TRUE(WritePdfReport(pdf, in).ok());
  const std::string text = NoSpace(Shell("pdftotext -raw '" + pdf + "' -"));
  EXPECT_NE(text.find(NoSpace(in.part_id)), std::string::npos) << text;
  // Name in the characteristics table and region in the defects table.
  const std::size_t first = text.find(NoSpace(kNasty));
  ASSERT_NE(first, std::string::npos) << text;
  EXPECT_NE(text.find(NoSpace(kNasty), first + 1), std::string::npos) << text;
  for (const char* s : {"cell<7>", "FAIL", "2026-12-0110:00:00UTC", "-0.025", "+0.450",
                        "surfinspect", "-0.100/+0.100", "50.00%"})
    EXPECT_NE(text.find(s), std::string::npos) << s;
  const std::string info = Shell("pdfinfo '" + pdf + "'");
  EXPECT_NE(info.find("595.276 x 841.89 pts (A4)"), std::string::npos) << info;
  EXPECT_EQ(Pages(info), 1) << info;
  std::istringstream fonts(Shell("pdffonts '" + pdf + "'"));
  std::string line;
  int listed = 0;
  for (int k = 0; std::getline(fonts, line); ++k) {
    if (k < 2) continue;  // the column titles and the rule
    std::vector<std::string> cols;
    std::istringstream words(line);
    for (std::string w; words >> w;) cols.push_back(w);
    ASSERT_GE(cols.size(), 6u) << line;
    EXPECT_EQ(cols[cols.size() - 5], "yes") << "not embedded: " << line;
    EXPECT_NE(line.find("DejaVu"), std::string::npos) << line;
    ++listed;
  }
  EXPECT_GE(listed, 2) << "regular and bold";
}

// The map of page 1, rasterised by pdftoppm: the grid view's colours
// are there, and the merged cloud's three views fill three slots.
TEST(PdfReport, RenderedMapAreaIsNotBlank) {
  if (!HavePoppler()) GTEST_SKIP() << "poppler-utils (pdftoppm) not installed: PDF NOT CHECKED";
  for (bool organized : {true, false}) {
    const Cloud c = MakeCloud(organized);
    const InspectionReport report = Report("top");
    const PdfReportInput in = InputOf("p1", report, c);
    TempDir dir;
    ASSERT_TRUE(WritePdfReport(dir.File("r.pdf"), in).ok());
    // 72 dpi: one pixel per PDF point.
    Shell("pdftoppm -f 1 -l 1 -r 72 -png '" + dir.File("r.pdf") + "' '" + dir.File("page") + "'");
    const RgbImage page = testing::DecodePng(testing::ReadBytes(dir.File("page-1.png")));
    ASSERT_NEAR(page.width, 595.3, 1) << "A4 at 72 dpi";
    ASSERT_NEAR(page.height, 841.9, 1);
    // The map slots: x 40..415 pt, from below the banner (y ~ 140) for 430 pt.
    auto coloured = [&](uint32_t y0, uint32_t y1) {
      std::size_t n = 0;
      for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = 40; x < 415; ++x) {
          const Rgb p = page.at(x, y);
          n += std::max({p.r, p.g, p.b}) - std::min({p.r, p.g, p.b}) > 60 ? 1 : 0;
        }
      return n;
    };
    EXPECT_GT(coloured(140, 570), organized ? 20000u : 3000u);
    // Bands of rows with colour: one grid view, or the three views.
    int bands = 0;
    bool in_band = false;
    for (uint32_t y = 140; y < 570; ++y) {
      const bool c = coloured(y, y + 1) > 0;
      bands += c && !in_band ? 1 : 0;
      in_band = c;
    }
    EXPECT_EQ(bands, organized ? 1 : 3);
  }
}

TEST(PdfReport, BadInputsAreErrorsNotCrashes) {
  const Cloud c = MakeCloud(true);
  const InspectionReport report = Report("r");
  PdfReportInput in;
  EXPECT_EQ(RenderPdfReport(in).status().code(), absl::StatusCode::kInvalidArgument);
  in.report = &report;
  in.points_in_part = &c.points;
  const std::vector<float> short_dev(3, 0.f);
  in.deviation_mm = &short_dev;
  EXPECT_EQ(RenderPdfReport(in).status().code(), absl::StatusCode::kInvalidArgument);
  in.deviation_mm = &c.deviation;
  const InspectionReport empty;  // no tolerance band, no colour range
  in.report = &empty;
  EXPECT_EQ(RenderPdfReport(in).status().code(), absl::StatusCode::kDataLoss);
  in.report = &report;
  in.part_id = std::string("bad utf8 \xff\xfe and nul ") + '\0' + " end";
  auto bytes = RenderPdfReport(in);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  EXPECT_EQ(bytes->substr(0, 5), "%PDF-");
  if (HavePoppler()) {
    TempDir out;
    testing::WriteBytes(out.File("u.pdf"), *bytes);
    const std::string text = Shell("pdftotext -raw '" + out.File("u.pdf") + "' -");
    EXPECT_NE(text.find("\xEF\xBF\xBD end"), std::string::npos) << "text after the NUL is kept";
  }
  TempDir dir;
  EXPECT_FALSE(WritePdfReport(dir.File("no/such/dir/r.pdf"), in).ok());
}

// The PDF of `report` over MakeCloud(true), as pdftotext reads it, without
// spaces.
std::string PdfText(const InspectionReport& report) {
  const Cloud c = MakeCloud(true);
  TempDir dir;
  EXPECT_TRUE(WritePdfReport(dir.File("r.pdf"), InputOf("p", report, c)).ok());
  return NoSpace(Shell("pdftotext -raw '" + dir.File("r.pdf") + "' -"));
}

// A hole's row: its diameter with the deviation, its true position against
// the zone and the arc seen, in the characteristics table.
TEST(PdfReport, AHoleRowShowsSizeTruePositionAndArc) {
  if (!HavePoppler()) GTEST_SKIP() << "poppler-utils not installed: PDF NOT CHECKED";
  InspectionReport report = Report("r");
  ReportCharacteristic h;
  h.name = "H1";
  h.type = "hole";
  h.verdict = "fail";
  h.tolerance = {-0.1, 0.1};
  h.position_tolerance_mm = 0.3;
  h.points = 180;
  h.true_position_mm = 0.31;
  h.measured_diameter_mm = 8.012;
  h.diameter_deviation_mm = 0.012;
  h.arc_coverage_deg = 351;
  report.characteristics.push_back(h);
  const std::string text = PdfText(report);
  for (const char* s :
       {"\u00d88.012(+0.012)", "TP0.310/0.300", "arc351\u00b0", "\u00d8-0.100/+0.100", "TP0.300"})
    EXPECT_NE(text.find(s), std::string::npos) << s << "\n" << text;
}

// An aligned part prints its alignment's lines and the references' table.
TEST(PdfReport, AnAlignedPartPrintsItsAlignment) {
  if (!HavePoppler()) GTEST_SKIP() << "poppler-utils not installed: PDF NOT CHECKED";
  InspectionReport report = Report("r");
  ReportAlignment a;
  a.mode = "rps";
  a.aligned = true;
  a.correction_mm = 0.412;
  a.correction_deg = 0.21;
  a.max_correction_mm = 0.3;
  a.max_correction_deg = 1;
  a.within_max_correction = false;
  a.rms_before_mm = 0.2;
  a.rms_after_mm = 0.004;
  a.matrix.assign(16, 0);
  a.references = {{"A1", "hole", true, {0, 0, 0}, {0.1, 0, 0}, 120, {{{1, 0, 0}, 0.25, 0.003}}}};
  report.alignment = a;
  const std::string text = PdfText(report);
  for (const char* s : {"Alignment", "rps:corrected0.412mm/0.2100deg(allowed0.3mm/1deg)",
                        "Alignmentreferences", "A1hole", "+0.250", "+0.003"})
    EXPECT_NE(text.find(s), std::string::npos) << s << "\n" << text;
}

// Many rows continue on further pages, each with the table's header.
TEST(PdfReport, LongTablesContinueOnMorePages) {
  if (!HavePoppler()) GTEST_SKIP() << "poppler-utils not installed: PDF NOT CHECKED";
  const Cloud c = MakeCloud(true);
  InspectionReport report = Report("r");
  for (int i = 0; i < 120; ++i) {
    ReportCharacteristic ch = report.characteristics[0];
    ch.name = "row-" + std::to_string(i);
    report.characteristics.push_back(ch);
  }
  TempDir dir;
  ASSERT_TRUE(WritePdfReport(dir.File("r.pdf"), InputOf("p", report, c)).ok());
  const std::string info = Shell("pdfinfo '" + dir.File("r.pdf") + "'");
  EXPECT_GE(Pages(info), 2) << info;
  std::istringstream text(Shell("pdftotext -raw '" + dir.File("r.pdf") + "' -"));
  std::multiset<std::string> words;
  for (std::string w; text >> w;) words.insert(w);
  for (int i = 0; i < 120; ++i) EXPECT_EQ(words.count("row-" + std::to_string(i)), 1u) << i;
  EXPECT_GE(words.count("characteristic"), 2u) << "the header repeats on the next page";
}

// Seven sections: pages of section plots after page 1, six to a page, each
// plot titled with its name and captioned with its exaggeration; the
// whiskers outside the band are drawn in the palette's colours.
TEST(PdfReport, SectionsGetPagesOfPlots) {
  if (!HavePoppler()) GTEST_SKIP() << "poppler-utils not installed: PDF NOT CHECKED";
  const Cloud c = MakeCloud(true);
  InspectionReport report = Report("r");
  for (int k = 0; k < 7; ++k) {
    ReportSection s;
    s.name = "cut-" + std::to_string(k);
    s.point_mm = {0, 0, 0};
    s.normal = {1, 0, 0};
    s.tolerance = {-0.1, 0.1};
    ReportPolyline line;
    for (int i = 0; i <= 20; ++i) line.xyz_mm.insert(line.xyz_mm.end(), {0.0, i - 10.0, 0.0});
    s.polylines = {line};
    for (int i = 0; i < 40; ++i) {
      s.whiskers.at_mm.insert(s.whiskers.at_mm.end(), {0.0, i / 2.0 - 10, 0.0});
      s.whiskers.direction.insert(s.whiskers.direction.end(), {0.0, 0.0, 1.0});
      s.whiskers.deviation_mm.push_back(i % 2 ? 0.4 : -0.4);
    }
    report.sections.push_back(s);
  }
  TempDir dir;
  ASSERT_TRUE(WritePdfReport(dir.File("r.pdf"), InputOf("p", report, c)).ok());
  EXPECT_EQ(Pages(Shell("pdfinfo '" + dir.File("r.pdf") + "'")), 3) << "page 1, then 6 + 1";
  const std::string text = Shell("pdftotext -raw '" + dir.File("r.pdf") + "' -");
  for (int k = 0; k < 7; ++k) EXPECT_NE(text.find("cut-" + std::to_string(k)), std::string::npos);
  // Extent 20 mm, band 0.2 mm: 0.05 * 20 / 0.2 = 5.
  EXPECT_EQ(Count(text, "whiskers x 5, band -0.100..+0.100 mm"), 7u) << text;
  EXPECT_EQ(Count(text, "Sections (mm in the section plane)"), 2u);
  // Page 3 holds one plot: strongly coloured pixels (whiskers at +-0.4 mm,
  // outside the band) in its first cell and none in the others.
  Shell("pdftoppm -f 3 -l 3 -r 72 -png '" + dir.File("r.pdf") + "' '" + dir.File("pg") + "'");
  const RgbImage page = testing::DecodePng(testing::ReadBytes(dir.File("pg-3.png")));
  auto coloured = [&](uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1) {
    std::size_t n = 0;
    for (uint32_t y = y0; y < y1; ++y)
      for (uint32_t x = x0; x < x1; ++x) {
        const Rgb p = page.at(x, y);
        n += std::max({p.r, p.g, p.b}) - std::min({p.r, p.g, p.b}) > 60 ? 1 : 0;
      }
    return n;
  };
  EXPECT_GT(coloured(40, 290, 60, 300), 100u);
  EXPECT_EQ(coloured(300, 555, 60, 800), 0u);
  EXPECT_EQ(coloured(40, 290, 310, 800), 0u);
}

TEST(PdfCanvas, SoftwareVersionNamesTheProject) {
  EXPECT_EQ(SoftwareVersion().rfind("surfinspect ", 0), 0u);
  EXPECT_EQ(SoftwareVersion().find("unknown"), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
