#include "core/pipeline/inspection_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <set>

namespace surfinspect {
namespace {

std::set<std::string> Keys(const nlohmann::json& j) {
  std::set<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.insert(k);
  return keys;
}

TEST(InspectionReport, CharacteristicsCarryTheSchemaFields) {
  CharacteristicsResult r;
  CharacteristicResult surface;
  surface.name = "surface";
  surface.pass = true;
  surface.reason = "pass: ...";
  surface.tolerance = {-0.1, 0.2};
  surface.points = 10;
  surface.min_mm = -0.05;
  surface.max_mm = 0.15;
  surface.mean_mm = 0.01;
  surface.stddev_mm = 0.02;
  surface.rms_mm = 0.03;
  surface.fraction_within = 0.9;
  surface.allowed_fraction_outside = 0.1;
  CharacteristicResult point;
  point.name = "P1";
  point.type = CharacteristicType::kPoint;
  point.reason = "not measured: 0.0% of its CAD area seen";
  point.measured = false;
  point.coverage = 0;
  point.min_coverage = 0.9;
  r.characteristics = {surface, point};

  const nlohmann::json j = CharacteristicsJson(r);
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 2u);
  const std::set<std::string> common = {
      "name",   "type",    "verdict",   "reason", "tolerance_mm",    "points",   "min_mm",
      "max_mm", "mean_mm", "stddev_mm", "rms_mm", "fraction_within", "coverage", "min_coverage"};
  std::set<std::string> area_keys = common, point_keys = common;
  area_keys.insert("allowed_fraction_outside");
  point_keys.insert("value_mm");
  EXPECT_EQ(Keys(j[0]), area_keys);
  EXPECT_EQ(Keys(j[1]), point_keys);
  EXPECT_EQ(j[0]["type"], "surface");
  EXPECT_EQ(j[0]["verdict"], "pass");
  EXPECT_EQ(j[0]["tolerance_mm"], (nlohmann::json{{"lower", -0.1}, {"upper", 0.2}}));
  EXPECT_EQ(j[0]["points"], 10);
  EXPECT_EQ(j[0]["min_mm"], -0.05);
  EXPECT_EQ(j[0]["rms_mm"], 0.03);
  EXPECT_EQ(j[0]["fraction_within"], 0.9);
  EXPECT_EQ(j[1]["type"], "point");
  EXPECT_EQ(j[1]["verdict"], "not_measured");
  EXPECT_EQ(j[1]["coverage"], 0.0);
  EXPECT_EQ(j[1]["min_coverage"], 0.9);
  EXPECT_TRUE(j[0]["coverage"].is_null()) << "not computed";
  EXPECT_TRUE(j[1]["value_mm"].is_null()) << "unmeasured";
  EXPECT_TRUE(j[1]["mean_mm"].is_null());
  EXPECT_EQ(j[1]["points"], 0);
}

TEST(InspectionReport, DefectsCarryTheSchemaFields) {
  DefectsResult r;
  Defect d;
  d.id = 1;
  d.kind = DefectKind::kBump;
  d.centroid_mm = {1.5, -2, 60};
  d.area_mm2 = 12.5;
  d.extent_mm = 4;
  d.peak_mm = 0.25;
  d.peak_fitted = true;
  d.measured_extreme_mm = 0.27;
  d.noise_mm = 0.015;
  d.points = 180;
  d.region = "ridge";
  r.defects = {d};
  const nlohmann::json j = DefectsJson(r);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(Keys(j[0]), (std::set<std::string>{"id", "kind", "centroid_mm", "area_mm2", "extent_mm",
                                               "peak_mm", "peak_source", "measured_extreme_mm",
                                               "noise_mm", "points", "region"}));
  EXPECT_EQ(j[0]["id"], 1);
  EXPECT_EQ(j[0]["kind"], "bump");
  EXPECT_EQ(j[0]["centroid_mm"], (nlohmann::json{1.5, -2.0, 60.0}));
  EXPECT_EQ(j[0]["area_mm2"], 12.5);
  EXPECT_EQ(j[0]["extent_mm"], 4.0);
  EXPECT_EQ(j[0]["peak_mm"], 0.25);
  EXPECT_EQ(j[0]["peak_source"], "fit");
  EXPECT_EQ(j[0]["measured_extreme_mm"], 0.27);
  EXPECT_EQ(j[0]["noise_mm"], 0.015);
  EXPECT_EQ(j[0]["points"], 180);
  EXPECT_EQ(j[0]["region"], "ridge");
  EXPECT_EQ(DefectsJson(DefectsResult{}), nlohmann::json::array());
}

// ---- the codec against the hand-written report it replaced ----------------

// report.json as it was built key by key before the typed report: the
// oracle for byte-identical output.
nlohmann::json Or(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json HandWrittenReport(const ErrorMapResult& r, const ErrorMapSettings& settings,
                                 const PlanOutcome& outcome) {
  const ErrorMapStats& s = r.stats;
  nlohmann::json j;
  j["units"] = "mm";
  j["sign"] = "+ above the CAD surface (side of the CCW face normals), - below";
  j["settings"] = {{"tolerance_mm", settings.tolerance_mm},
                   {"max_distance_mm", Or(settings.max_distance_mm)},
                   {"allowed_fraction_outside", settings.allowed_fraction_outside},
                   {"histogram_bins", settings.histogram_bins},
                   {"split_components", settings.split_components}};
  j["points"] = {{"count", s.count},
                 {"valid", s.valid},
                 {"matched", s.matched},
                 {"unmatched_valid", s.valid - s.matched}};
  j["statistics"] = {{"min_mm", Or(s.min_mm)},   {"max_mm", Or(s.max_mm)},
                     {"mean_mm", Or(s.mean_mm)}, {"stddev_mm", Or(s.stddev_mm)},
                     {"rms_mm", Or(s.rms_mm)},   {"p1_mm", Or(s.p1_mm)},
                     {"p5_mm", Or(s.p5_mm)},     {"p50_mm", Or(s.p50_mm)},
                     {"p95_mm", Or(s.p95_mm)},   {"p99_mm", Or(s.p99_mm)}};
  const Verdict& v = r.verdict;
  j["tolerance"] = {{"band_mm", r.tolerance_mm},
                    {"within", v.within},
                    {"above", v.above},
                    {"below", v.below},
                    {"fraction_within", Or(v.fraction_within)},
                    {"fraction_outside", Or(v.fraction_outside)},
                    {"allowed_fraction_outside", settings.allowed_fraction_outside},
                    {"verdict", v.pass ? "pass" : "fail"},
                    {"reason", v.reason}};
  const Histogram& h = r.histogram;
  j["histogram"] = {
      {"min_mm", h.min_mm}, {"max_mm", h.max_mm},           {"bin_width_mm", h.bin_width_mm()},
      {"counts", h.counts}, {"below_range", h.below_range}, {"above_range", h.above_range}};
  j["color_range_mm"] = r.color_range_mm;
  auto stats = [](const ComponentStats& c) {
    return nlohmann::json{{"mean_mm", Or(c.mean_mm)},
                          {"rms_mm", Or(c.rms_mm)},
                          {"min_mm", Or(c.min_mm)},
                          {"max_mm", Or(c.max_mm)}};
  };
  if (!r.deviation_xyz_mm.empty())
    j["components"] = {{"frame", "part"},
                       {"x", stats(r.component_stats[0])},
                       {"y", stats(r.component_stats[1])},
                       {"z", stats(r.component_stats[2])},
                       {"normal", stats(r.component_stats[3])}};
  j["timing"] = {{"query_seconds", r.query_seconds},
                 {"order_seconds", r.order_seconds},
                 {"statistics_seconds", r.statistics_seconds},
                 {"certified_points", r.certified_points},
                 {"hint_alone_points", r.hint_alone_points}};
  j["schema"] = "surfinspect.report/2";
  j["verdict"] = outcome.pass() ? "pass" : "fail";
  nlohmann::json list = nlohmann::json::array();
  for (const CharacteristicResult& c : outcome.characteristics.characteristics) {
    nlohmann::json k = {
        {"name", c.name},
        {"type", CharacteristicTypeName(c.type)},
        {"verdict", c.pass       ? "pass"
                    : c.measured ? "fail"
                                 : "not_measured"},
        {"reason", c.reason},
        {"tolerance_mm", {{"lower", c.tolerance.lower_mm}, {"upper", c.tolerance.upper_mm}}},
        {"coverage", Or(c.coverage)},
        {"min_coverage", c.min_coverage},
        {"points", c.points},
        {"min_mm", Or(c.min_mm)},
        {"max_mm", Or(c.max_mm)},
        {"mean_mm", Or(c.mean_mm)},
        {"stddev_mm", Or(c.stddev_mm)},
        {"rms_mm", Or(c.rms_mm)},
        {"fraction_within", Or(c.fraction_within)}};
    if (c.type == CharacteristicType::kPoint)
      k["value_mm"] = Or(c.value_mm);
    else
      k["allowed_fraction_outside"] = c.allowed_fraction_outside;
    list.push_back(std::move(k));
  }
  j["characteristics"] = list;
  j["defects"] = nlohmann::json::array();
  for (const Defect& d : outcome.defects.defects)
    j["defects"].push_back(
        {{"id", d.id},
         {"kind", DefectKindName(d.kind)},
         {"centroid_mm", {d.centroid_mm.x(), d.centroid_mm.y(), d.centroid_mm.z()}},
         {"area_mm2", d.area_mm2},
         {"extent_mm", d.extent_mm},
         {"peak_mm", d.peak_mm},
         {"peak_source", d.peak_fitted ? "fit" : "median"},
         {"measured_extreme_mm", d.measured_extreme_mm},
         {"noise_mm", d.noise_mm},
         {"points", d.points},
         {"region", d.region}});
  return j;
}

// An error map's and a plan's results with every field set, some NaN.
struct Computed {
  ErrorMapResult map;
  ErrorMapSettings settings;
  PlanOutcome outcome;
};

Computed RandomResults(uint32_t seed, bool split) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> mm(-1.0, 1.0);
  auto maybe = [&](double v) { return rng() % 7 == 0 ? NAN : v; };
  Computed c;
  c.settings.tolerance_mm = 0.05 + std::abs(mm(rng));
  c.settings.max_distance_mm = rng() % 2 ? INFINITY : 5.0;
  c.settings.allowed_fraction_outside = 0.01;
  c.settings.histogram_bins = 41;
  c.settings.split_components = split;
  ErrorMapResult& r = c.map;
  r.stats = {1000 + rng() % 100,
             900,
             850 + rng() % 50,
             maybe(mm(rng)),
             maybe(mm(rng)),
             maybe(mm(rng)),
             maybe(mm(rng)),
             maybe(mm(rng)),
             mm(rng),
             mm(rng),
             mm(rng),
             mm(rng),
             maybe(mm(rng))};
  r.tolerance_mm = c.settings.tolerance_mm;
  r.color_range_mm = 0.5;
  r.verdict = {rng() % 2 == 0, 800, 20, 30, maybe(0.94), 0.06, "fail: 6% outside +-0.1 mm"};
  r.histogram.min_mm = -0.5;
  r.histogram.max_mm = 0.5;
  for (int k = 0; k < 41; ++k) r.histogram.counts.push_back(rng() % 1000);
  r.histogram.below_range = 3;
  r.histogram.above_range = 4;
  if (split) {
    r.deviation_xyz_mm.resize(1);
    for (ComponentStats& s : r.component_stats) s = {mm(rng), maybe(mm(rng)), mm(rng), mm(rng)};
  }
  r.query_seconds = 0.25;
  r.order_seconds = 0.01;
  r.statistics_seconds = 0.002;
  r.certified_points = 12;
  r.hint_alone_points = 7;
  for (int k = 0; k < 4; ++k) {
    CharacteristicResult ch;
    ch.name = "c\"" + std::to_string(k) + "\\u00e9";
    ch.type = static_cast<CharacteristicType>(k % 3);
    ch.pass = k % 2;
    ch.measured = k != 2;
    ch.coverage = k == 0 ? NAN : 0.25 * k;
    ch.min_coverage = 0.9;
    ch.reason = "why " + std::to_string(k);
    ch.tolerance = {-0.1 * (k + 1), 0.2};
    ch.points = k == 3 ? 0 : 10 * k;
    ch.min_mm = maybe(mm(rng));
    ch.max_mm = maybe(mm(rng));
    ch.mean_mm = maybe(mm(rng));
    ch.stddev_mm = maybe(mm(rng));
    ch.rms_mm = maybe(mm(rng));
    ch.fraction_within = maybe(0.5);
    ch.value_mm = maybe(mm(rng));
    ch.allowed_fraction_outside = 0.02;
    c.outcome.characteristics.characteristics.push_back(ch);
  }
  c.outcome.characteristics.pass = rng() % 2;
  for (int k = 1; k <= 3; ++k) {
    Defect d;
    d.id = k;
    d.kind = k % 2 ? DefectKind::kDent : DefectKind::kBump;
    d.centroid_mm = {mm(rng) * 100, mm(rng) * 100, mm(rng)};
    d.area_mm2 = 10 * std::abs(mm(rng));
    d.extent_mm = 3;
    d.peak_mm = mm(rng);
    d.peak_fitted = k == 1;
    d.measured_extreme_mm = k == 3 ? NAN : mm(rng);
    d.noise_mm = 0.015;
    d.points = 40 + k;
    d.region = k == 2 ? "" : "ridge";
    c.outcome.defects.defects.push_back(d);
  }
  return c;
}

TEST(InspectionReport, TextIsByteIdenticalToTheHandWrittenReport) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const Computed c = RandomResults(seed, seed % 2);
    ASSERT_EQ(ErrorMapReportText(c.map, c.settings, c.outcome),
              HandWrittenReport(c.map, c.settings, c.outcome).dump(2) + "\n")
        << "seed " << seed;
  }
}

TEST(InspectionReport, RoundTripKeepsTheStructAndTheBytes) {
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const Computed c = RandomResults(seed, seed % 2);
    InspectionReport report = MakeInspectionReport(c.map, c.settings, c.outcome);
    if (seed % 3 == 0) {  // what the CLI's errormap adds
      report.timing.read_seconds = 0.01;
      report.timing.total_seconds = 0.5;
      report.inputs = ReportInputs{"a.ply", "b.stl", ""};
      report.mesh = ReportMesh{100, 4, 0, 1};
      report.output_frame = "part";
    }
    if (seed % 4 == 0) {  // a STEP part, a cloud in metres, a doubt on the mesh
      report.cad = ReportCad{"p.stp", "STEP", "INCH", 0.01, 0.0064, true};
      report.input_units = ReportInputUnits{"m", "mm", true, false, {"mesh b.stl: small"}};
    }
    const std::string text = ReportText(report);
    const absl::StatusOr<InspectionReport> back = ParseReport(text);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_EQ(ReportText(*back), text) << "seed " << seed;
    EXPECT_EQ(back->verdict, report.verdict);
    EXPECT_EQ(back->characteristics, report.characteristics);
    EXPECT_EQ(back->defects, report.defects);
    EXPECT_EQ(back->stats.matched, report.stats.matched);
    EXPECT_EQ(back->histogram.counts, report.histogram.counts);
    EXPECT_EQ(back->components.has_value(), report.components.has_value());
    EXPECT_EQ(back->timing.total_seconds, report.timing.total_seconds);
    EXPECT_EQ(back->inputs.has_value(), report.inputs.has_value());
    EXPECT_EQ(back->output_frame, report.output_frame);
    ASSERT_EQ(back->input_units.has_value(), report.input_units.has_value());
    if (report.input_units) {
      EXPECT_EQ(back->input_units->cloud, "m");
      EXPECT_TRUE(back->input_units->cloud_stated);
      EXPECT_FALSE(back->input_units->mesh_stated);
      EXPECT_EQ(back->input_units->doubts, report.input_units->doubts);
      EXPECT_EQ(back->cad->tessellation_error_mm, 0.0064);
    }
    const bool same_p99 = back->stats.p99_mm == report.stats.p99_mm ||
                          (std::isnan(back->stats.p99_mm) && std::isnan(report.stats.p99_mm));
    EXPECT_TRUE(same_p99);
  }
}

TEST(InspectionReport, AnErrorMapAloneHasNoPlanSections) {
  const Computed c = RandomResults(3, false);
  const nlohmann::json j = ErrorMapReportJson(c.map, c.settings);
  for (const char* key : {"schema", "verdict", "characteristics", "defects"})
    EXPECT_FALSE(j.contains(key)) << key;
  const absl::StatusOr<InspectionReport> back = DecodeReport(j);
  ASSERT_TRUE(back.ok());
  EXPECT_TRUE(back->schema.empty());
  EXPECT_EQ(EncodeReport(*back), j);
}

TEST(InspectionReport, DecodingNamesTheBadField) {
  const Computed c = RandomResults(5, true);
  const nlohmann::json good = EncodeReport(MakeInspectionReport(c.map, c.settings, c.outcome));
  struct Case {
    std::function<void(nlohmann::json&)> spoil;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](nlohmann::json& j) { j["characteristics"][1]["points"] = -1; },
       "report.characteristics[1].points: not a count"},
      {[](nlohmann::json& j) { j["characteristics"][0].erase("name"); },
       "report.characteristics[0].name: missing"},
      {[](nlohmann::json& j) { j["characteristics"][2]["tolerance_mm"]["upper"] = true; },
       "report.characteristics[2].tolerance_mm.upper: not a number"},
      {[](nlohmann::json& j) { j["defects"][1].erase("id"); }, "report.defects[1].id: missing"},
      {[](nlohmann::json& j) { j["defects"][0]["centroid_mm"] = "here"; },
       "report.defects[0].centroid_mm: not three numbers"},
      {[](nlohmann::json& j) {
         j["histogram"]["counts"] = {1, -2};
       },
       "report.histogram.counts: not a list of counts"},
      {[](nlohmann::json& j) { j["statistics"]["p99_mm"] = "big"; },
       "report.statistics.p99_mm: not a number"},
      {[](nlohmann::json& j) { j["tolerance"] = 3; }, "report.tolerance: not an object"},
      {[](nlohmann::json& j) { j["defects"] = nullptr; }, "report.defects: not an array"},
      {[](nlohmann::json& j) { j = nlohmann::json::array(); }, "report: not an object"},
  };
  for (const Case& k : cases) {
    nlohmann::json bad = good;
    k.spoil(bad);
    const absl::StatusOr<InspectionReport> r = DecodeReport(bad);
    ASSERT_FALSE(r.ok()) << k.message;
    EXPECT_EQ(r.status().code(), absl::StatusCode::kDataLoss);
    EXPECT_EQ(r.status().message(), k.message);
  }
  EXPECT_EQ(ParseReport("{").status().code(), absl::StatusCode::kDataLoss);
}

TEST(InspectionReport, FieldListsCarryTheReportsKeysAndValues) {
  const Computed c = RandomResults(8, false);
  const InspectionReport report = MakeInspectionReport(c.map, c.settings, c.outcome);
  const nlohmann::json j = EncodeReport(report);
  std::vector<std::string> keys;
  for (const ReportField& f : StatisticsFields(report)) {
    keys.push_back(f.key);
    EXPECT_EQ(f.value, j["statistics"][f.key]) << f.key;
  }
  EXPECT_EQ(keys, (std::vector<std::string>{"min_mm", "max_mm", "mean_mm", "stddev_mm", "rms_mm",
                                            "p1_mm", "p5_mm", "p50_mm", "p95_mm", "p99_mm"}));
  for (const ReportField& f : PointCountFields(report)) EXPECT_EQ(f.value, j["points"][f.key]);
  for (const ReportField& f : ToleranceCountFields(report))
    EXPECT_EQ(f.value, j["tolerance"][f.key]) << f.key;
  EXPECT_EQ(ToleranceCountFields(report).size(), 4u);
  for (const ReportField& f : SettingsFields(report)) EXPECT_EQ(f.value, j["settings"][f.key]);
  // The CAD and the units follow, under their report.json keys.
  InspectionReport with = report;
  with.cad = ReportCad{"p.stp", "STEP", "INCH", 0.01, 0.0064, true};
  with.input_units = ReportInputUnits{"m", "mm", true, false, {"a doubt"}};
  const nlohmann::json w = EncodeReport(with);
  std::size_t cad = 0, units = 0;
  for (const ReportField& f : SettingsFields(with)) {
    if (f.key.rfind("cad.", 0) == 0) {
      EXPECT_EQ(f.value, w["cad"][f.key.substr(4)]) << f.key;
      ++cad;
    }
    if (f.key.rfind("input_units.", 0) == 0) {
      EXPECT_EQ(f.value, w["input_units"][f.key.substr(12)]) << f.key;
      ++units;
    }
  }
  EXPECT_EQ(cad, 6u);
  EXPECT_EQ(units, 5u);
}

}  // namespace
}  // namespace surfinspect
