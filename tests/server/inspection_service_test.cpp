// Integration tests: a real surfinspectd on a free loopback port, called
// through the same RemoteClient the CLI and the cell-agent use.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <thread>

#include "client/remote/remote_client.h"
#include "core/io/mesh_hash.h"
#include "core/pipeline/inspection.h"
#include "core/pipeline/inspection_report.h"
#include "core/registration/calibration.h"
#include "core/simulation/demo_cell.h"
#include "proto/convert.h"
#include "tests/support/sanitizer.h"
#include "tests/support/server_process.h"
#include "tests/support/temp_dir.h"

namespace surfinspect {
namespace {

using client::RemoteClient;
using client::RemoteOptions;
using Clock = std::chrono::steady_clock;

struct Data {
  DemoCell cell = MakeDemoCell();
  PointCloud gauge_scan;        // viewpoint v1, sensor frame
  std::vector<ViewScan> views;  // three part scans with true poses
  PointCloud merged_world;      // their merge (for ErrorMap)
};

const Data& TestData() {
  static const Data* d = [] {
    auto* data = new Data();
    ScanOptions opt;
    opt.noise_sigma_mm = 0.015;
    opt.pulse_fraction = 0.003;
    opt.stripes = true;
    const DemoViewpoint& v1 = data->cell.viewpoints[0];
    data->gauge_scan = SimulateScan(data->cell.gauge, v1.world_from_gauge, v1.world_from_sensor,
                                    data->cell.intrinsics, opt)
                           ->cloud_in_sensor;
    opt.defects = {SurfaceDefect{{-60, 5, 60 - 3 * 0.16}, 6, 0.2}};
    for (int v = 0; v < 3; ++v) {
      opt.seed = 7 + v;
      const DemoViewpoint& vp = data->cell.viewpoints[v];
      data->views.push_back({vp.name,
                             SimulateScan(data->cell.part, data->cell.world_from_part,
                                          vp.world_from_sensor, data->cell.intrinsics, opt)
                                 ->cloud_in_sensor,
                             vp.world_from_sensor});
    }
    data->merged_world = RegisterToWorld(data->views)->cloud_in_world;
    return data;
  }();
  return *d;
}

std::unique_ptr<RemoteClient> ClientFor(const testing::ServerProcess& s, RemoteOptions o = {}) {
  o.target = s.target();
  if (o.timeout_s == 600) o.timeout_s = 60;
  return *RemoteClient::Connect(o);
}

v1::ErrorMapRequest ErrorMapRequest(const PointCloud& cloud) {
  v1::ErrorMapRequest req;
  wire::CloudToProto(cloud, req.mutable_cloud());
  wire::TransformToProto(TestData().cell.world_from_part, req.mutable_world_from_part());
  req.set_return_deviations(true);
  return req;
}

// A typed number equals the report's, NaN standing for its null.
void ExpectSame(double typed, const nlohmann::json& j, const std::string& what) {
  if (j.is_null())
    EXPECT_TRUE(std::isnan(typed)) << what;
  else
    EXPECT_EQ(typed, j.get<double>()) << what;
}

// The typed results of an ErrorMapResponse or InspectResult equal its report_json.
template <typename Msg>
void ExpectTypedEqualsJson(const Msg& m) {
  const nlohmann::json j = nlohmann::json::parse(m.report_json());
  EXPECT_EQ(m.part_verdict() == v1::VERDICT_PASS ? "pass" : "fail", j["verdict"]);
  EXPECT_EQ(m.verdict(), j["verdict"]);
  const v1::ErrorMapStatistics& s = m.statistics();
  EXPECT_EQ(s.count(), j["points"]["count"]);
  EXPECT_EQ(s.matched(), j["points"]["matched"]);
  for (const auto& [name, v] : {std::pair<const char*, double>{"min_mm", s.min_mm()},
                                {"max_mm", s.max_mm()},
                                {"mean_mm", s.mean_mm()},
                                {"rms_mm", s.rms_mm()},
                                {"p50_mm", s.p50_mm()},
                                {"p99_mm", s.p99_mm()}})
    ExpectSame(v, j["statistics"][name], name);
  EXPECT_EQ(s.within(), j["tolerance"]["within"]);
  EXPECT_EQ(s.tolerance_verdict() == v1::VERDICT_PASS ? "pass" : "fail", j["tolerance"]["verdict"]);
  ASSERT_EQ(static_cast<std::size_t>(m.characteristics_size()), j["characteristics"].size());
  for (int i = 0; i < m.characteristics_size(); ++i) {
    const v1::CharacteristicResult& c = m.characteristics(i);
    const nlohmann::json& cj = j["characteristics"][i];
    EXPECT_EQ(c.name(), cj["name"]);
    EXPECT_EQ(c.verdict() == v1::VERDICT_PASS   ? "pass"
              : c.verdict() == v1::VERDICT_FAIL ? "fail"
                                                : "not_measured",
              cj["verdict"])
        << c.name();
    ExpectSame(c.coverage(), cj["coverage"], c.name() + " coverage");
    ExpectSame(c.min_coverage(), cj["min_coverage"], c.name() + " min coverage");
    EXPECT_EQ(c.reason(), cj["reason"]);
    EXPECT_EQ(c.points(), cj["points"]);
    EXPECT_EQ(c.tolerance_mm().lower_mm(), cj["tolerance_mm"]["lower"]);
    EXPECT_EQ(c.tolerance_mm().upper_mm(), cj["tolerance_mm"]["upper"]);
    ExpectSame(c.mean_mm(), cj["mean_mm"], c.name() + " mean");
    ExpectSame(c.min_mm(), cj["min_mm"], c.name() + " min");
    ExpectSame(c.fraction_within(), cj["fraction_within"], c.name() + " fraction");
    if (cj.contains("value_mm")) ExpectSame(c.value_mm(), cj["value_mm"], c.name() + " value");
  }
  ASSERT_EQ(static_cast<std::size_t>(m.defects_size()), j["defects"].size());
  for (int i = 0; i < m.defects_size(); ++i) {
    const v1::DefectResult& d = m.defects(i);
    const nlohmann::json& dj = j["defects"][i];
    EXPECT_EQ(d.id(), dj["id"]);
    EXPECT_EQ(d.kind() == v1::DEFECT_DENT ? "dent" : "bump", dj["kind"]);
    EXPECT_EQ(d.peak_mm(), dj["peak_mm"]);
    EXPECT_EQ(d.peak_fitted() ? "fit" : "median", dj["peak_source"]);
    ExpectSame(d.measured_extreme_mm(), dj["measured_extreme_mm"], "measured extreme");
    ExpectSame(d.noise_mm(), dj["noise_mm"], "noise");
    EXPECT_EQ(d.area_mm2(), dj["area_mm2"]);
    EXPECT_EQ(d.points(), dj["points"]);
    EXPECT_EQ(d.region(), dj["region"]);
    ASSERT_EQ(d.centroid_mm_size(), 3);
    for (int a = 0; a < 3; ++a) EXPECT_EQ(d.centroid_mm(a), dj["centroid_mm"][a]);
  }
}

// A plan on the demo part: the ridge, two comparison points, defects on.
InspectionPlan DemoPlan() {
  auto plan = ParsePlanWithDefaults(nlohmann::json::parse(R"({
    "regions": [{"name": "ridge", "select": {"box_mm": [[-150, -25, 50], [150, 25, 70]]},
                 "tolerance_mm": {"lower": -0.15, "upper": 0.15}}],
    "points": [{"name": "centre", "position_mm": [0, 0, 60], "radius_mm": 3},
               {"name": "nowhere", "position_mm": [0, 0, 500]}],
    "defects": {"threshold_mm": 0.03, "min_area_mm2": 3.0}})"),
                                    TestData().cell.part, {});
  EXPECT_TRUE(plan.ok()) << plan.status();
  return *plan;
}

TEST(InspectionService, ThePlanTravelsTypedAndTheResultsAreTypedToo) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.started());
  auto client = ClientFor(server);
  const Data& d = TestData();
  const InspectionPlan plan = DemoPlan();
  v1::ErrorMapRequest req = ErrorMapRequest(d.merged_world);
  wire::PlanToProto(plan, req.mutable_plan());
  auto eresp = client->ErrorMap(req, d.cell.part);
  ASSERT_TRUE(eresp.ok()) << eresp.status();
  ExpectTypedEqualsJson(*eresp);
  // The same report as in-process with the same plan.
  auto part_index = *MeshIndex::Build(d.cell.part);
  const ErrorMapResult map =
      *ComputeErrorMap(*part_index, d.merged_world, d.cell.world_from_part, {});
  const PlanOutcome outcome = *EvaluatePlan(map, d.merged_world, d.cell.part, plan);
  nlohmann::json remote = nlohmann::json::parse(eresp->report_json());
  nlohmann::json local = EncodeReport(MakeInspectionReport(map, {}, outcome));
  remote.erase("timing");
  local.erase("timing");
  EXPECT_EQ(remote, local);
  EXPECT_EQ(remote["characteristics"].size(), 4u);
  EXPECT_EQ(eresp->characteristics(3).reason().substr(0, 13), "not measured:");
  EXPECT_EQ(eresp->characteristics(3).verdict(), v1::VERDICT_NOT_MEASURED);

  // Inspect: the plan in the part header.
  v1::PartHeader header;
  header.set_part_id("planned");
  wire::TransformToProto(d.cell.world_from_part, header.mutable_world_from_part());
  wire::PlanToProto(plan, header.mutable_plan());
  auto iresp = client->Inspect(header, d.cell.part, d.views, {});
  ASSERT_TRUE(iresp.ok()) << iresp.status();
  ExpectTypedEqualsJson(*iresp);
  InspectionSettings settings;
  settings.plan = plan;
  const InspectionResult r = *InspectPart(*part_index, d.cell.world_from_part, d.views, settings);
  EXPECT_EQ(iresp->characteristics_size(), 4);
  EXPECT_EQ(iresp->defects_size(), static_cast<int>(r.plan.defects.defects.size()));
  EXPECT_EQ(iresp->part_verdict() == v1::VERDICT_PASS, r.plan.pass());
}

// A result larger than one gRPC message is refused by the service, with the
// sizes, and logged as the refusal: the transport would otherwise fail it
// after the server had logged the call as OK.
TEST(InspectionService, AResultOverTheMessageLimitIsRefusedWithItsSize) {
  testing::ServerProcess server({"--max-message-mb", "2"});
  ASSERT_TRUE(server.started());
  RemoteOptions o;
  o.chunk_bytes = 256 << 10;
  auto client = ClientFor(server, o);
  const Data& d = TestData();
  v1::PartHeader header;
  header.set_part_id("big");
  wire::TransformToProto(d.cell.world_from_part, header.mutable_world_from_part());
  header.set_return_deviations(true);
  auto r = client->Inspect(header, d.cell.part, d.views, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition) << r.status();
  EXPECT_NE(r.status().message().find("RESPONSE_TOO_LARGE: the Inspect result is "),
            std::string::npos)
      << r.status();
  EXPECT_NE(r.status().message().find("message limit of 2 MiB"), std::string::npos);
  EXPECT_EQ(*client->Health(), "SERVING");
  server.Terminate();
  std::ifstream log(server.log_path());
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("Inspect from"), std::string::npos);
  EXPECT_NE(text.find("FAILED_PRECONDITION (RESPONSE_TOO_LARGE"), std::string::npos) << text;
}

TEST(InspectionService, EveryRpcMatchesInProcess) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.started());
  auto client = ClientFor(server);
  const Data& d = TestData();
  EXPECT_EQ(*client->Health(), "SERVING");

  // Filter: same grid, same kept points, bit for bit.
  v1::FilterRequest freq;
  wire::CloudToProto(d.views[0].cloud_in_sensor, freq.mutable_cloud());
  auto fresp = client->Filter(freq);
  ASSERT_TRUE(fresp.ok()) << fresp.status();
  const PointCloud local_filtered =
      *ApplyFilter(d.views[0].cloud_in_sensor, *ClusterLinks(d.views[0].cloud_in_sensor, {}));
  ASSERT_EQ(fresp->cloud().xyz().size(), local_filtered.size() * 12);
  EXPECT_EQ(0, std::memcmp(fresp->cloud().xyz().data(), local_filtered.points.data(),
                           local_filtered.size() * 12));

  // Calibrate: identical pose (the gauge mesh is small next to the scan,
  // so the client sends it inline).
  const DemoViewpoint& v1 = d.cell.viewpoints[0];
  v1::CalibrateRequest creq;
  wire::TransformToProto(v1.world_from_gauge, creq.mutable_world_from_gauge());
  wire::TransformToProto(v1.nominal_world_from_sensor, creq.mutable_initial_world_from_sensor());
  wire::CloudToProto(d.gauge_scan, creq.mutable_scan());
  CalibrationSettings cs;
  wire::IcpSettingsToProto(cs.icp, creq.mutable_icp());
  auto cresp = client->Calibrate(creq, d.cell.gauge);
  ASSERT_TRUE(cresp.ok()) << cresp.status();
  auto gauge_index = *MeshIndex::Build(d.cell.gauge);
  const CalibrationResult local_cal = *CalibrateViewpoint(
      *gauge_index, v1.world_from_gauge, d.gauge_scan, v1.nominal_world_from_sensor, cs);
  EXPECT_TRUE((wire::TransformFromProto(cresp->world_from_sensor(), "w")->matrix() -
               local_cal.world_from_sensor.matrix())
                  .cwiseAbs()
                  .maxCoeff() < 1e-12);

  // Register: the same merged points.
  v1::RegisterRequest rreq;
  for (const auto& v : d.views) {
    v1::ViewScan* s = rreq.add_views();
    s->set_name(v.name);
    wire::TransformToProto(v.world_from_sensor, s->mutable_world_from_sensor());
    wire::CloudToProto(v.cloud_in_sensor, s->mutable_cloud());
  }
  auto rresp = client->Register(rreq, nullptr);
  ASSERT_TRUE(rresp.ok()) << rresp.status();
  ASSERT_EQ(rresp->merged().width(), d.merged_world.size());
  EXPECT_EQ(0, std::memcmp(rresp->merged().xyz().data(), d.merged_world.points.data(),
                           d.merged_world.size() * 12));

  // ErrorMap: same deviations, same report apart from timing.
  auto eresp = client->ErrorMap(ErrorMapRequest(d.merged_world), d.cell.part);
  ASSERT_TRUE(eresp.ok()) << eresp.status();
  auto part_index = *MeshIndex::Build(d.cell.part);
  const ErrorMapResult local_map =
      *ComputeErrorMap(*part_index, d.merged_world, d.cell.world_from_part, {});
  const std::vector<float> remote_dev = wire::UnpackFloats(eresp->deviations());
  ASSERT_EQ(remote_dev.size(), local_map.deviation_mm.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < remote_dev.size(); ++i)
    differing += std::memcmp(&remote_dev[i], &local_map.deviation_mm[i], 4) != 0;
  EXPECT_EQ(differing, 0u);
  nlohmann::json remote_report = nlohmann::json::parse(eresp->report_json());
  const PlanOutcome local_outcome =
      *EvaluatePlan(local_map, d.merged_world, d.cell.part, PlanFromSettings({}));
  nlohmann::json local_report =
      nlohmann::json::parse(ErrorMapReportText(local_map, {}, local_outcome));
  remote_report.erase("timing");
  local_report.erase("timing");
  EXPECT_EQ(remote_report, local_report);
  ExpectTypedEqualsJson(*eresp);

  // Inspect (stream): same verdict and deviations as InspectPart.
  v1::PartHeader header;
  header.set_part_id("p1");
  wire::TransformToProto(d.cell.world_from_part, header.mutable_world_from_part());
  header.set_return_deviations(true);
  header.set_return_png(true);
  std::vector<std::string> stages;
  auto iresp = client->Inspect(header, d.cell.part, d.views, [&](const v1::Progress& p) {
    stages.push_back(v1::Progress::Stage_Name(p.stage()));
  });
  ASSERT_TRUE(iresp.ok()) << iresp.status();
  const InspectionResult local = *InspectPart(*part_index, d.cell.world_from_part, d.views, {});
  EXPECT_TRUE(iresp->deviations() == wire::PackFloats(local.error_map.deviation_mm));
  EXPECT_EQ(iresp->verdict(), local.error_map.verdict.pass ? "pass" : "fail");
  EXPECT_EQ(iresp->png().substr(1, 3), "PNG");
  EXPECT_EQ(std::count(stages.begin(), stages.end(), "STAGE_VIEW_RECEIVED"), 3);
  EXPECT_EQ(std::count(stages.begin(), stages.end(), "STAGE_VIEW_FILTERED"), 3);
  EXPECT_EQ(std::count(stages.begin(), stages.end(), "STAGE_ERROR_MAP"), 1);
}

// Raw stub calls, so malformed requests reach the server as they are.
class RawCalls {
 public:
  explicit RawCalls(const std::string& target)
      : stub_(v1::InspectionService::NewStub(
            grpc::CreateChannel(target, grpc::InsecureChannelCredentials()))) {}
  template <typename Req, typename Resp, typename Fn>
  grpc::Status Call(Fn fn, const Req& req) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    Resp resp;
    return ((*stub_).*fn)(&ctx, req, &resp);
  }
  grpc::Status Inspect(const std::vector<v1::InspectRequest>& msgs) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    auto stream = stub_->Inspect(&ctx);
    for (const auto& m : msgs)
      if (!stream->Write(m)) break;
    stream->WritesDone();
    v1::InspectResponse r;
    while (stream->Read(&r)) {
    }
    return stream->Finish();
  }
  std::unique_ptr<v1::InspectionService::Stub> stub_;
};

// Building an inline mesh's index reserves its memory first: a mesh whose
// index does not fit the budget is RESOURCE_EXHAUSTED, named, before it is
// built, and the same call with a smaller mesh goes through.
TEST(InspectionService, AnInlineMeshIndexThatDoesNotFitIsRefusedBeforeItIsBuilt) {
  testing::ServerProcess server({"--max-memory-mb", "2"});
  ASSERT_TRUE(server.started());
  RawCalls raw(server.target());
  const Data& d = TestData();
  PointCloud few = d.merged_world;
  few.points.resize(100);
  few.width = 100;
  few.height = 1;
  v1::ErrorMapRequest req = ErrorMapRequest(few);
  wire::MeshToProto(d.cell.part, req.mutable_part()->mutable_inline_());  // 4440 triangles
  using S = v1::InspectionService::Stub;
  const grpc::Status refused =
      raw.Call<v1::ErrorMapRequest, v1::ErrorMapResponse>(&S::ErrorMap, req);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused.error_message().find("part mesh index"), std::string::npos)
      << refused.error_message();
  TriangleMesh small = d.cell.part;
  small.triangles.resize(1000);
  wire::MeshToProto(small, req.mutable_part()->mutable_inline_());
  const grpc::Status ok = raw.Call<v1::ErrorMapRequest, v1::ErrorMapResponse>(&S::ErrorMap, req);
  EXPECT_TRUE(ok.ok()) << ok.error_message();
}

// A packed cloud is charged for its declared grid, not for its bytes: a
// 125 kB request for a million points does not fit a 16 MiB budget (72 B a
// point), and the same grid of 100x100 does.
TEST(InspectionService, APackedCloudIsChargedForItsWholeGrid) {
  testing::ServerProcess server({"--max-memory-mb", "16"});
  ASSERT_TRUE(server.started());
  RawCalls raw(server.target());
  using S = v1::InspectionService::Stub;
  auto filter = [&](uint32_t side) {
    v1::FilterRequest r;
    r.mutable_cloud()->set_width(side);
    r.mutable_cloud()->set_height(side);
    r.mutable_cloud()->set_valid_bits(std::string((side * side + 7) / 8, '\0'));
    return raw.Call<v1::FilterRequest, v1::FilterResponse>(&S::Filter, r);
  };
  const grpc::Status big = filter(1000);
  EXPECT_EQ(big.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << big.error_message();
  EXPECT_NE(big.error_message().find("memory"), std::string::npos) << big.error_message();
  const grpc::Status small = filter(100);
  EXPECT_NE(small.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << small.error_message();
}

TEST(InspectionService, BadRequestsGetTheRightCodeAndTheServerStaysUp) {
  testing::ServerProcess server({"--max-points", "2000000", "--max-triangles", "100000"});
  ASSERT_TRUE(server.started());
  RawCalls raw(server.target());
  using S = v1::InspectionService::Stub;
  using grpc::StatusCode;
  const Data& d = TestData();
  v1::InlineMesh good_mesh;
  wire::MeshToProto(d.cell.part, &good_mesh);
  auto cloud = [](uint32_t w, uint32_t h, std::size_t bytes, float fill = 1.f) {
    v1::PointCloud c;
    c.set_width(w);
    c.set_height(h);
    std::vector<float> v(bytes / 4, fill);
    c.set_xyz(std::string(reinterpret_cast<const char*>(v.data()), bytes));
    return c;
  };
  std::vector<std::pair<std::string, std::pair<grpc::Status, StatusCode>>> cases;
  auto filter = [&](const v1::PointCloud& c, const v1::FilterSettings& s = {}) {
    v1::FilterRequest r;
    *r.mutable_cloud() = c;
    *r.mutable_settings() = s;
    return raw.Call<v1::FilterRequest, v1::FilterResponse>(&S::Filter, r);
  };
  cases.push_back({"empty cloud", {filter(cloud(0, 0, 0)), StatusCode::INVALID_ARGUMENT}});
  cases.push_back({"truncated xyz", {filter(cloud(10, 10, 1000)), StatusCode::INVALID_ARGUMENT}});
  cases.push_back(
      {"inf coordinate", {filter(cloud(4, 4, 192, INFINITY)), StatusCode::INVALID_ARGUMENT}});
  cases.push_back(
      {"too many points", {filter(cloud(5000, 5000, 12)), StatusCode::RESOURCE_EXHAUSTED}});
  // Packed clouds (valid_bits): a few bytes can declare many points, and
  // the points limit still holds; malformed bits are refused by name.
  auto packed = [](uint32_t w, uint32_t h, std::size_t bit_bytes) {
    v1::PointCloud c;
    c.set_width(w);
    c.set_height(h);
    c.set_valid_bits(std::string(bit_bytes, '\0'));  // no point has data; xyz stays empty
    return c;
  };
  cases.push_back({"packed: too many points",
                   {filter(packed(5000, 5000, 5000 * 5000 / 8)), StatusCode::RESOURCE_EXHAUSTED}});
  cases.push_back({"packed: bits of the wrong length",
                   {filter(packed(4, 4, 3)), StatusCode::INVALID_ARGUMENT}});
  v1::PointCloud miscounted = packed(4, 4, 2);
  miscounted.set_valid_bits(std::string("\x01\0", 2));  // one point set, xyz empty
  cases.push_back(
      {"packed: xyz short of the bits", {filter(miscounted), StatusCode::INVALID_ARGUMENT}});
  v1::FilterSettings neg;
  neg.set_link_distance_mm(-1);
  cases.push_back(
      {"negative link distance", {filter(cloud(4, 4, 192), neg), StatusCode::INVALID_ARGUMENT}});
  v1::FilterSettings nan_link;
  nan_link.set_link_distance_mm(NAN);
  cases.push_back(
      {"NaN link distance", {filter(cloud(4, 4, 192), nan_link), StatusCode::INVALID_ARGUMENT}});
  v1::FilterSettings conn;
  conn.set_connectivity(6);
  cases.push_back(
      {"connectivity 6", {filter(cloud(4, 4, 192), conn), StatusCode::INVALID_ARGUMENT}});

  auto errormap = [&](v1::ErrorMapRequest r) {
    return raw.Call<v1::ErrorMapRequest, v1::ErrorMapResponse>(&S::ErrorMap, r);
  };
  v1::ErrorMapRequest em;
  *em.mutable_cloud() = cloud(4, 4, 192);
  wire::TransformToProto(Eigen::Isometry3d::Identity(), em.mutable_world_from_part());
  *em.mutable_part()->mutable_inline_() = good_mesh;
  v1::ErrorMapRequest no_mesh = em;
  no_mesh.clear_part();
  cases.push_back({"missing mesh", {errormap(no_mesh), StatusCode::INVALID_ARGUMENT}});
  v1::ErrorMapRequest unknown_hash = em;
  unknown_hash.mutable_part()->set_sha256(std::string(64, 'a'));
  cases.push_back({"unknown mesh hash", {errormap(unknown_hash), StatusCode::FAILED_PRECONDITION}});
  v1::ErrorMapRequest short_transform = em;
  short_transform.mutable_world_from_part()->mutable_row_major()->RemoveLast();
  cases.push_back(
      {"15-value transform", {errormap(short_transform), StatusCode::INVALID_ARGUMENT}});
  v1::ErrorMapRequest scaled = em;
  scaled.mutable_world_from_part()->set_row_major(0, 2.0);
  cases.push_back({"non-rigid transform", {errormap(scaled), StatusCode::INVALID_ARGUMENT}});
  v1::ErrorMapRequest bad_index = em;
  std::string tris = bad_index.part().inline_().triangles();
  const uint32_t huge = 999999999;
  std::memcpy(tris.data(), &huge, 4);
  bad_index.mutable_part()->mutable_inline_()->set_triangles(tris);
  cases.push_back(
      {"triangle index out of range", {errormap(bad_index), StatusCode::INVALID_ARGUMENT}});
  v1::ErrorMapRequest degenerate = em;
  std::string verts(36, '\0');
  degenerate.mutable_part()->mutable_inline_()->set_vertices(verts);
  degenerate.mutable_part()->mutable_inline_()->set_triangles(
      std::string("\0\0\0\0\1\0\0\0\2\0\0\0", 12));
  cases.push_back(
      {"only degenerate triangles", {errormap(degenerate), StatusCode::INVALID_ARGUMENT}});
  v1::ErrorMapRequest ragged = em;
  ragged.mutable_part()->mutable_inline_()->set_vertices("12345");
  cases.push_back({"ragged vertex bytes", {errormap(ragged), StatusCode::INVALID_ARGUMENT}});
  v1::ErrorMapRequest neg_tol = em;
  neg_tol.mutable_settings()->set_tolerance_mm(-0.1);
  cases.push_back({"negative tolerance", {errormap(neg_tol), StatusCode::INVALID_ARGUMENT}});

  v1::CalibrateRequest cal;
  *cal.mutable_scan() = cloud(4, 4, 192);
  wire::TransformToProto(Eigen::Isometry3d::Identity(), cal.mutable_world_from_gauge());
  cases.push_back({"calibrate without initial pose",
                   {raw.Call<v1::CalibrateRequest, v1::CalibrateResponse>(&S::Calibrate, cal),
                    StatusCode::INVALID_ARGUMENT}});
  cases.push_back(
      {"register without views",
       {raw.Call<v1::RegisterRequest, v1::RegisterResponse>(&S::Register, v1::RegisterRequest{}),
        StatusCode::INVALID_ARGUMENT}});

  v1::InspectRequest part_msg, view_msg, chunk_msg, end_msg;
  part_msg.mutable_part()->set_part_id("x");
  *part_msg.mutable_part()->mutable_part()->mutable_inline_() = good_mesh;
  wire::TransformToProto(Eigen::Isometry3d::Identity(),
                         part_msg.mutable_part()->mutable_world_from_part());
  view_msg.mutable_view()->set_name("v1");
  view_msg.mutable_view()->set_width(2);
  view_msg.mutable_view()->set_height(2);
  wire::TransformToProto(Eigen::Isometry3d::Identity(),
                         view_msg.mutable_view()->mutable_world_from_sensor());
  chunk_msg.mutable_chunk()->set_xyz(std::string(24, '\0'));
  end_msg.mutable_end();
  cases.push_back(
      {"inspect: view before part", {raw.Inspect({view_msg}), StatusCode::INVALID_ARGUMENT}});
  cases.push_back(
      {"inspect: truncated view",
       {raw.Inspect({part_msg, view_msg, chunk_msg, end_msg}), StatusCode::INVALID_ARGUMENT}});
  cases.push_back(
      {"inspect: no end marker", {raw.Inspect({part_msg}), StatusCode::INVALID_ARGUMENT}});
  cases.push_back({"inspect: too many bytes",
                   {raw.Inspect({part_msg, view_msg, chunk_msg, chunk_msg, chunk_msg}),
                    StatusCode::INVALID_ARGUMENT}});

  ASSERT_GE(cases.size(), 15u);
  for (const auto& [name, c] : cases) {
    EXPECT_EQ(c.first.error_code(), c.second) << name << ": " << c.first.error_message();
    EXPECT_FALSE(c.first.error_message().empty()) << name;
  }

  // Bad plans: INVALID_ARGUMENT naming the field, in ErrorMap and Inspect.
  std::vector<std::pair<grpc::Status, std::string>> plans;
  v1::ErrorMapRequest inverted = em;
  v1::Box* box = inverted.mutable_plan()->add_regions()->mutable_select()->mutable_box_mm();
  inverted.mutable_plan()->mutable_regions(0)->set_name("r");
  for (double v : {5.0, 0.0, 0.0}) box->add_min_mm(v);
  for (double v : {1.0, 1.0, 1.0}) box->add_max_mm(v);
  plans.push_back({errormap(inverted), "plan.regions[0].select.box_mm"});
  v1::ErrorMapRequest out_of_range = em;
  v1::PlanRegion* tri = out_of_range.mutable_plan()->add_regions();
  tri->set_name("t");
  tri->mutable_select()->mutable_triangles()->add_ids(d.cell.part.num_triangles());
  plans.push_back({errormap(out_of_range), "plan.regions[0].select.triangles[0]"});
  v1::ErrorMapRequest band = em;
  v1::ComparisonPoint* p = band.mutable_plan()->add_points();
  p->set_name("p");
  for (double v : {0.0, 0.0, 60.0}) p->add_position_mm(v);
  p->mutable_tolerance_mm()->set_lower_mm(0.2);
  p->mutable_tolerance_mm()->set_upper_mm(0.1);
  plans.push_back({errormap(band), "plan.points[0].tolerance_mm"});
  v1::ErrorMapRequest short_position = em;
  short_position.mutable_plan()->add_points()->set_name("q");
  plans.push_back({errormap(short_position), "plan.points[0].position_mm"});
  v1::InspectRequest no_selector = part_msg;
  no_selector.mutable_part()->mutable_plan()->add_regions()->set_name("r");
  plans.push_back({raw.Inspect({no_selector}), "part.plan.regions[0].select"});
  v1::ErrorMapRequest nowhere = em;  // the demo part has no hole at the ridge's middle
  v1::PlanHole* hole = nowhere.mutable_plan()->add_holes();
  hole->set_name("h");
  for (double v : {0.0, 0.0, 60.0}) hole->add_position_mm(v);
  for (double v : {0.0, 0.0, 1.0}) hole->add_axis(v);
  hole->set_diameter_mm(8);
  plans.push_back({errormap(nowhere), "plan.holes[0].position_mm"});
  v1::ErrorMapRequest no_axis = em;
  v1::PlanHole* flat = no_axis.mutable_plan()->add_holes();
  for (double v : {-110.0, 0.0, 58.4}) flat->add_position_mm(v);
  for (double v : {0.0, 0.0, 0.0}) flat->add_axis(v);
  plans.push_back({errormap(no_axis), "plan.holes[0].axis"});
  v1::ErrorMapRequest far_edge = em;
  v1::PlanEdgePoint* edge = far_edge.mutable_plan()->add_edge_points();
  edge->set_name("e");
  for (double v : {0.0, 0.0, 60.0}) edge->add_position_mm(v);
  plans.push_back({errormap(far_edge), "plan.edge_points[0].position_mm"});
  for (const auto& [st, field] : plans) {
    EXPECT_EQ(st.error_code(), StatusCode::INVALID_ARGUMENT) << field << ": " << st.error_message();
    EXPECT_NE(st.error_message().find(field), std::string::npos) << st.error_message();
  }
  auto client = ClientFor(server);
  EXPECT_EQ(*client->Health(), "SERVING");
}

// A large unorganized cloud: the merged part, `copies` times (1.3 * 10^6
// points each).
PointCloud BigUnorganizedCloud(int copies) {
  const Data& d = TestData();
  PointCloud big = d.merged_world;
  for (int k = 1; k < copies; ++k)
    big.points.insert(big.points.end(), d.merged_world.points.begin(), d.merged_world.points.end());
  big.width = static_cast<uint32_t>(big.size());
  return big;
}

// The server measures it directly: from gRPC's cancellation to the end of
// the work, one log line per cancelled call. The promise is well under 100
// ms (in a sanitized build the polls come kSanitizerSlowdown times later).
// Expects between `min_calls` and `max_calls` such lines.
void ExpectPromptStops(const testing::ServerProcess& server, const std::string& method,
                       std::size_t min_calls, std::size_t max_calls) {
  std::ifstream log(server.log_path());
  std::string line;
  std::vector<std::pair<double, std::string>> stops;
  std::string calls;
  const std::string marker = "work stopped ";
  while (std::getline(log, line)) {
    if (line.find(method) != std::string::npos) calls += line + "\n";
    if (auto at = line.find(marker); at != std::string::npos)
      stops.emplace_back(std::stod(line.substr(at + marker.size())), line);
  }
  ASSERT_GE(stops.size(), min_calls) << "one log line per cancelled call:\n" << calls;
  ASSERT_LE(stops.size(), max_calls) << "one log line per cancelled call:\n" << calls;
  for (const auto& [ms, text] : stops) EXPECT_LT(ms, 100.0 * testing::kSanitizerSlowdown) << text;
}

TEST(InspectionService, CancelledAndDeadlineExceededCallsStopPromptly) {
  // One worker: if a cancelled call kept computing, the next call would
  // queue behind it.
  testing::ServerProcess server({"--threads", "1"});
  ASSERT_TRUE(server.started());
  const Data& d = TestData();
  const PointCloud big = BigUnorganizedCloud(4);
  auto client = ClientFor(server);
  const auto t0 = Clock::now();
  ASSERT_TRUE(client->ErrorMap(ErrorMapRequest(big), d.cell.part).ok());
  const double full_s = std::chrono::duration<double>(Clock::now() - t0).count();

  v1::FilterRequest small;
  wire::CloudToProto(d.views[0].cloud_in_sensor, small.mutable_cloud());
  for (const bool use_deadline : {true, false}) {
    grpc::ClientContext ctx;
    // Well into the computation (the request's transfer takes a fraction of
    // the full call), whatever the machine's speed.
    const auto into_work = std::chrono::milliseconds(static_cast<int64_t>(400 * full_s));
    if (use_deadline) ctx.set_deadline(std::chrono::system_clock::now() + into_work);
    v1::ErrorMapRequest req = ErrorMapRequest(big);
    req.mutable_part()->set_sha256(MeshSha256(d.cell.part));  // cached by the first call
    v1::ErrorMapResponse resp;
    auto stub = v1::InspectionService::NewStub(
        grpc::CreateChannel(server.target(), grpc::InsecureChannelCredentials()));
    std::thread canceller;
    if (!use_deadline)
      canceller = std::thread([&] {
        std::this_thread::sleep_for(into_work);
        ctx.TryCancel();
      });
    const grpc::Status st = stub->ErrorMap(&ctx, req, &resp);
    if (canceller.joinable()) canceller.join();
    EXPECT_EQ(st.error_code(),
              use_deadline ? grpc::StatusCode::DEADLINE_EXCEEDED : grpc::StatusCode::CANCELLED);
    // The worker must be free again at once: a small call right after
    // finishes far sooner than the rest of the big one would have taken.
    const auto t1 = Clock::now();
    ASSERT_TRUE(client->Filter(small).ok());
    const double after_s = std::chrono::duration<double>(Clock::now() - t1).count();
    EXPECT_LT(after_s, std::max(0.5, 0.5 * full_s)) << "full " << full_s << " s";
  }
  ExpectPromptStops(server, "ErrorMap", 2, 2);
}

// Filter on an unorganized cloud takes the voxel path (sort by cell, link
// cells, number components): cancelled at 20%, 40%, 60% and 80% of a full
// call, each phase stops as promptly.
TEST(InspectionService, CancelledFilterOfAnUnorganizedCloudStopsPromptly) {
  testing::ServerProcess server({"--threads", "1"});
  ASSERT_TRUE(server.started());
  v1::FilterRequest req;  // three copies: the filtered cloud fits the 64 MiB response limit
  wire::CloudToProto(BigUnorganizedCloud(3), req.mutable_cloud());
  auto client = ClientFor(server);
  const auto t0 = Clock::now();
  const auto first = client->Filter(req);
  ASSERT_TRUE(first.ok()) << first.status();
  const double full_s = std::chrono::duration<double>(Clock::now() - t0).count();
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(-1);  // a call that finishes returns the whole cloud
  auto stub = v1::InspectionService::NewStub(
      grpc::CreateCustomChannel(server.target(), grpc::InsecureChannelCredentials(), args));
  std::size_t cancelled = 0;
  for (const double fraction : {0.2, 0.4, 0.6, 0.8}) {
    grpc::ClientContext ctx;
    std::thread canceller([&] {
      std::this_thread::sleep_for(
          std::chrono::milliseconds(static_cast<int64_t>(1000 * fraction * full_s)));
      ctx.TryCancel();
    });
    v1::FilterResponse resp;
    const grpc::Status st = stub->Filter(&ctx, req, &resp);
    canceller.join();
    // A call that finished before the cancellation arrived is not counted.
    if (st.error_code() == grpc::StatusCode::CANCELLED)
      ++cancelled;
    else
      EXPECT_TRUE(st.ok()) << st.error_message();
  }
  EXPECT_GE(cancelled, 2u) << "full call " << full_s << " s";
  // A call cancelled while its 63 MB request was still arriving never
  // reached the service, so it logs nothing; the later ones must have.
  ExpectPromptStops(server, "Filter", 2, cancelled);
}

TEST(InspectionService, EightClientsTwentyMixedCallsNoErrors) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.started());
  const Data& d = TestData();
  v1::FilterRequest freq;
  wire::CloudToProto(d.views[1].cloud_in_sensor, freq.mutable_cloud());
  std::vector<std::future<int>> clients;
  for (int c = 0; c < 8; ++c)
    clients.push_back(std::async(std::launch::async, [&, c] {
      auto client = ClientFor(server);
      int errors = 0;
      for (int k = 0; k < 20; ++k) {
        absl::Status st;
        switch ((c + k) % 3) {
          case 0:
            st = client->Filter(freq).status();
            break;
          case 1:
            st =
                client->ErrorMap(ErrorMapRequest(d.views[2].cloud_in_sensor), d.cell.part).status();
            break;
          default:
            st = client->Health().status();
            break;
        }
        errors += st.ok() ? 0 : 1;
      }
      return errors;
    }));
  int errors = 0;
  for (auto& f : clients) errors += f.get();
  EXPECT_EQ(errors, 0);
}

TEST(InspectionService, GracefulShutdownFinishesTheCallInFlight) {
  testing::ServerProcess server({"--threads", "1", "--drain-seconds", "20"});
  ASSERT_TRUE(server.started());
  const Data& d = TestData();
  auto client = ClientFor(server);
  ASSERT_TRUE(client->Health().ok());
  v1::PartHeader header;
  header.set_part_id("drain");
  wire::TransformToProto(d.cell.world_from_part, header.mutable_world_from_part());
  auto call =
      std::async(std::launch::async, [&] { return client->Inspect(header, d.cell.part, d.views); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto t0 = Clock::now();
  const int exit_code = server.Terminate();
  const auto result = call.get();
  EXPECT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(exit_code, 0);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 20.0);
}

TEST(InspectionService, BearerToken) {
  testing::TempDir dir;
  testing::WriteBytes(dir.File("token"), "s3cret-token\n");
  testing::ServerProcess server({"--auth-token-file", dir.File("token")});
  ASSERT_TRUE(server.started());
  v1::FilterRequest req;
  wire::CloudToProto(TestData().views[0].cloud_in_sensor, req.mutable_cloud());
  auto anonymous = ClientFor(server);
  EXPECT_EQ(anonymous->Filter(req).status().code(), absl::StatusCode::kUnauthenticated);
  RemoteOptions wrong;
  wrong.auth_token = "guess";
  EXPECT_EQ(ClientFor(server, wrong)->Filter(req).status().code(),
            absl::StatusCode::kUnauthenticated);
  RemoteOptions right;
  right.auth_token = "s3cret-token";
  EXPECT_TRUE(ClientFor(server, right)->Filter(req).ok());
  // Health stays open for probes that carry no token.
  EXPECT_EQ(*anonymous->Health(), "SERVING");

  testing::ServerProcess open_server;  // token off
  ASSERT_TRUE(open_server.started());
  EXPECT_TRUE(ClientFor(open_server)->Filter(req).ok());
}

// openssl, run by the test: a CA `ca`, a server certificate for
// localhost/127.0.0.1 and a client certificate `client`, both signed by it,
// plus a client certificate `stranger` from an unrelated CA.
void MakeCertificates(const testing::TempDir& dir) {
  const std::string quiet = " >/dev/null 2>&1";
  auto ca = [&](const std::string& name) {
    return "openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=" + name + " -keyout " +
           name + ".key -out " + name + ".crt" + quiet;
  };
  auto signed_by = [&](const std::string& name, const std::string& issuer, const std::string& ext) {
    return "openssl req -newkey rsa:2048 -nodes -subj /CN=" + name + " -keyout " + name +
           ".key -out " + name + ".csr" + quiet + " && openssl x509 -req -in " + name +
           ".csr -CA " + issuer + ".crt -CAkey " + issuer + ".key -CAcreateserial -days 2" + ext +
           " -out " + name + ".crt" + quiet;
  };
  const std::string cmd =
      "cd " + dir.path() + " && " + ca("ca") + " && " + ca("other-ca") +
      " && printf 'subjectAltName=DNS:localhost,IP:127.0.0.1\\n' > san.ext && " +
      signed_by("server", "ca", " -extfile san.ext") + " && " + signed_by("client", "ca", "") +
      " && " + signed_by("stranger", "other-ca", "");
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "openssl failed: " << cmd;
}

TEST(InspectionService, TlsWithAGeneratedCertificate) {
  testing::TempDir dir;
  ASSERT_NO_FATAL_FAILURE(MakeCertificates(dir));
  testing::ServerProcess server(
      {"--tls-cert", dir.File("server.crt"), "--tls-key", dir.File("server.key")});
  ASSERT_TRUE(server.started());
  RemoteOptions tls;
  tls.tls_ca_file = dir.File("ca.crt");
  tls.timeout_s = 10;
  v1::FilterRequest req;
  wire::CloudToProto(TestData().views[0].cloud_in_sensor, req.mutable_cloud());
  EXPECT_TRUE(ClientFor(server, tls)->Filter(req).ok());
  RemoteOptions plain;
  plain.timeout_s = 3;
  EXPECT_FALSE(ClientFor(server, plain)->Filter(req).ok());
}

// mTLS: only a client whose certificate the --tls-client-ca signed gets in.
TEST(InspectionService, MutualTlsRequiresAClientCertificateFromTheCa) {
  testing::TempDir dir;
  ASSERT_NO_FATAL_FAILURE(MakeCertificates(dir));
  testing::ServerProcess server({"--tls-cert", dir.File("server.crt"), "--tls-key",
                                 dir.File("server.key"), "--tls-client-ca", dir.File("ca.crt")});
  ASSERT_TRUE(server.started());
  v1::FilterRequest req;
  wire::CloudToProto(TestData().views[0].cloud_in_sensor, req.mutable_cloud());
  RemoteOptions o;
  o.tls_ca_file = dir.File("ca.crt");
  o.timeout_s = 3;
  EXPECT_FALSE(ClientFor(server, o)->Filter(req).ok()) << "no client certificate";
  o.tls_cert_file = dir.File("stranger.crt");
  o.tls_key_file = dir.File("stranger.key");
  EXPECT_FALSE(ClientFor(server, o)->Filter(req).ok()) << "certificate from another CA";
  o.tls_cert_file = dir.File("client.crt");
  o.tls_key_file = dir.File("client.key");
  o.timeout_s = 10;
  EXPECT_TRUE(ClientFor(server, o)->Filter(req).ok());
  EXPECT_EQ(*ClientFor(server, o)->Health(), "SERVING");
}

TEST(InspectionService, OverAdmissionIsResourceExhaustedNotACrash) {
  testing::ServerProcess server({"--threads", "1", "--max-calls", "1"});
  ASSERT_TRUE(server.started());
  const Data& d = TestData();
  std::vector<std::future<absl::Status>> calls;
  for (int k = 0; k < 4; ++k)
    calls.push_back(std::async(std::launch::async, [&] {
      return ClientFor(server)->ErrorMap(ErrorMapRequest(d.merged_world), d.cell.part).status();
    }));
  int ok = 0, exhausted = 0;
  for (auto& c : calls) {
    const absl::Status st = c.get();
    ok += st.ok();
    exhausted += absl::IsResourceExhausted(st);
  }
  EXPECT_GE(ok, 1);
  EXPECT_GE(exhausted, 1);
  EXPECT_EQ(ok + exhausted, 4);
  EXPECT_EQ(*ClientFor(server)->Health(), "SERVING");
}

// GET http://127.0.0.1:PORT/metrics with a plain socket.
std::string HttpGet(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string out;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) {
    const std::string req = "GET " + path + " HTTP/1.0\r\nHost: localhost\r\n\r\n";
    if (::write(fd, req.data(), req.size()) == static_cast<ssize_t>(req.size())) {
      char buf[4096];
      ssize_t n;
      while ((n = ::read(fd, buf, sizeof(buf))) > 0) out.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return out;
}

int FreePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
  socklen_t len = sizeof(addr);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  ::close(fd);
  return ntohs(addr.sin_port);
}

TEST(InspectionService, PrometheusMetricsCountCallsPointsAndCache) {
  const int metrics_port = FreePort();
  testing::ServerProcess server({"--metrics-listen", "127.0.0.1:" + std::to_string(metrics_port)});
  ASSERT_TRUE(server.started());
  const Data& d = TestData();
  auto client = ClientFor(server);
  // A cloud much smaller than the mesh, so the client sends the mesh by hash
  // (a miss, then inline), then by hash again (a hit).
  const PointCloud small = PointCloud::Unorganized(std::vector<Eigen::Vector3f>(
      d.merged_world.points.begin(), d.merged_world.points.begin() + 500));
  ASSERT_TRUE(client->ErrorMap(ErrorMapRequest(small), d.cell.part).ok());
  ASSERT_TRUE(client->ErrorMap(ErrorMapRequest(small), d.cell.part).ok());
  v1::FilterRequest bad;
  EXPECT_FALSE(client->Filter(bad).ok());
  const std::string text = HttpGet(metrics_port, "/metrics");
  EXPECT_NE(text.find("surfinspect_rpcs_total{code=\"OK\",method=\"ErrorMap\"} 2"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("surfinspect_rpcs_total{code=\"INVALID_ARGUMENT\",method=\"Filter\"} 1"),
            std::string::npos);
  EXPECT_NE(text.find("surfinspect_mesh_cache_lookups_total{result=\"hit\"} 1"), std::string::npos);
  EXPECT_NE(text.find("surfinspect_rpc_duration_seconds_count{method=\"ErrorMap\"} 3"),
            std::string::npos);
  EXPECT_NE(text.find("surfinspect_points_processed_total " + std::to_string(2 * small.size())),
            std::string::npos);
}

}  // namespace
}  // namespace surfinspect
