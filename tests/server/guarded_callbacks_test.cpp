// The promise that no exception crosses an RPC, tested through surfinspectd's
// fault hook (--fault-inject, server/fault_hook.h): a guarded reactor or pool
// callback throws, the call ends with the guard's status, the server stays
// SERVING, and the next call of the same kind succeeds.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <sstream>

#include "client/remote/remote_client.h"
#include "proto/convert.h"
#include "tests/support/server_process.h"
#include "tests/support/test_meshes.h"

namespace surfinspect {
namespace {

using grpc::StatusCode;
using S = v1::InspectionService::Stub;

// A flat 100 x 100 mm plate at z = 0 and an organized 40 x 40 scan of it,
// 0.5 mm apart and 0.02 mm above, in the world frame (identity poses).
struct Plate {
  TriangleMesh mesh =
      testing::HeightField(-50, 50, -50, 50, 3, 3, [](double, double) { return 0; });
  PointCloud scan = [] {
    PointCloud c = PointCloud::Organized(40, 40);
    for (uint32_t r = 0; r < 40; ++r)
      for (uint32_t k = 0; k < 40; ++k)
        c.points[r * 40 + k] = Eigen::Vector3f(0.5f * k - 10, 0.5f * r - 10, 0.02f);
    return c;
  }();
};

const Plate& TestPlate() {
  static const Plate plate;
  return plate;
}

// Raw stub calls: the RemoteClient would retry RESOURCE_EXHAUSTED.
class Calls {
 public:
  explicit Calls(const std::string& target)
      : stub_(v1::InspectionService::NewStub(
            grpc::CreateChannel(target, grpc::InsecureChannelCredentials()))) {}

  template <typename Req, typename Resp>
  grpc::Status Unary(grpc::Status (S::*fn)(grpc::ClientContext*, const Req&, Resp*),
                     const Req& req) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    Resp resp;
    return ((*stub_).*fn)(&ctx, req, &resp);
  }
  grpc::Status Filter() {
    v1::FilterRequest req;
    wire::CloudToProto(TestPlate().scan, req.mutable_cloud());
    return Unary(&S::Filter, req);
  }
  grpc::Status Register() {
    v1::RegisterRequest req;
    v1::ViewScan* v = req.add_views();
    wire::TransformToProto(Eigen::Isometry3d::Identity(), v->mutable_world_from_sensor());
    wire::CloudToProto(TestPlate().scan, v->mutable_cloud());
    return Unary(&S::Register, req);
  }
  grpc::Status ErrorMap() {
    v1::ErrorMapRequest req;
    wire::CloudToProto(TestPlate().scan, req.mutable_cloud());
    wire::MeshToProto(TestPlate().mesh, req.mutable_part()->mutable_inline_());
    wire::TransformToProto(Eigen::Isometry3d::Identity(), req.mutable_world_from_part());
    return Unary(&S::ErrorMap, req);
  }
  // One part, one view in two chunks; `result` counts the result messages.
  grpc::Status Inspect(int* result = nullptr) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    auto stream = stub_->Inspect(&ctx);
    for (const v1::InspectRequest& m : InspectMessages())
      if (!stream->Write(m)) break;
    stream->WritesDone();
    v1::InspectResponse r;
    int results = 0;
    while (stream->Read(&r)) results += r.has_result();
    if (result) *result = results;
    return stream->Finish();
  }

 private:
  static std::vector<v1::InspectRequest> InspectMessages() {
    std::vector<v1::InspectRequest> msgs(5);
    v1::PartHeader* part = msgs[0].mutable_part();
    part->set_part_id("plate");
    wire::MeshToProto(TestPlate().mesh, part->mutable_part()->mutable_inline_());
    wire::TransformToProto(Eigen::Isometry3d::Identity(), part->mutable_world_from_part());
    v1::ViewHeader* view = msgs[1].mutable_view();
    view->set_name("top");
    view->set_width(40);
    view->set_height(40);
    wire::TransformToProto(Eigen::Isometry3d::Identity(), view->mutable_world_from_sensor());
    v1::PointCloud cloud;
    wire::CloudToProto(TestPlate().scan, &cloud);
    msgs[2].mutable_chunk()->set_xyz(cloud.xyz().substr(0, 1000));
    msgs[3].mutable_chunk()->set_xyz(cloud.xyz().substr(1000));
    msgs[4].mutable_end();
    return msgs;
  }
  std::unique_ptr<S> stub_;
};

std::string ReadLog(const testing::ServerProcess& server) {
  std::ifstream in(server.log_path());
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

struct FaultCase {
  std::string spec;  // --fault-inject KIND:SITE
  StatusCode code;   // what the faulted call ends with
  std::string message;
  std::function<grpc::Status(Calls&)> call;
};

class GuardedCallbacks : public ::testing::TestWithParam<FaultCase> {};

TEST_P(GuardedCallbacks, TheFaultedCallEndsWithTheGuardsStatusAndTheServerServesOn) {
  const FaultCase& c = GetParam();
  testing::ServerProcess server({"--fault-inject", c.spec});
  ASSERT_TRUE(server.started()) << ReadLog(server);
  Calls calls(server.target());
  const grpc::Status faulted = c.call(calls);
  EXPECT_EQ(faulted.error_code(), c.code) << faulted.error_message();
  EXPECT_EQ(faulted.error_message(), c.message);
  const std::string site = c.spec.substr(c.spec.find(':') + 1);
  EXPECT_NE(ReadLog(server).find(site + ": "), std::string::npos)
      << "one log line names the call:\n"
      << ReadLog(server);

  client::RemoteOptions o;
  o.target = server.target();
  o.timeout_s = 10;
  auto client = *client::RemoteClient::Connect(o);
  EXPECT_EQ(*client->Health(), "SERVING");
  const grpc::Status next = c.call(calls);
  EXPECT_TRUE(next.ok()) << next.error_code() << ": " << next.error_message();
}

grpc::Status CallInspect(Calls& calls) { return calls.Inspect(); }
grpc::Status CallFilter(Calls& calls) { return calls.Filter(); }
grpc::Status CallRegister(Calls& calls) { return calls.Register(); }
grpc::Status CallErrorMap(Calls& calls) { return calls.ErrorMap(); }

INSTANTIATE_TEST_SUITE_P(
    Faults, GuardedCallbacks,
    ::testing::Values(FaultCase{"bad_alloc:Inspect.Start", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in Inspect.Start", CallInspect},
                      FaultCase{"bad_alloc:Inspect.OnReadDone", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in Inspect.OnReadDone", CallInspect},
                      FaultCase{"bad_alloc:Inspect.OnWriteDone", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in Inspect.OnWriteDone", CallInspect},
                      FaultCase{"bad_alloc:Inspect.Compute", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in Inspect.Compute", CallInspect},
                      FaultCase{"bad_alloc:Inspect.Finish", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in Inspect.Finish", CallInspect},
                      FaultCase{"bad_alloc:Filter.Start", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in Filter.Start", CallFilter},
                      FaultCase{"bad_alloc:Register.Run", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in Register.Run", CallRegister},
                      FaultCase{"bad_alloc:ErrorMap.Done", StatusCode::RESOURCE_EXHAUSTED,
                                "out of memory in ErrorMap.Done", CallErrorMap},
                      FaultCase{"runtime_error:Filter.Run", StatusCode::INTERNAL,
                                "internal error: fault injected at Filter.Run", CallFilter},
                      FaultCase{"unknown:Inspect.Compute", StatusCode::INTERNAL,
                                "internal error: unknown exception", CallInspect}),
    [](const ::testing::TestParamInfo<FaultCase>& info) {
      std::string name;
      for (char ch : info.param.spec)
        if (std::isalnum(static_cast<unsigned char>(ch))) name += ch;
      return name;
    });

// Without the hook every call runs normally, and the Inspect result arrives.
TEST(GuardedCallbacks, WithoutAFaultEveryCallSucceeds) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.started());
  Calls calls(server.target());
  int results = 0;
  EXPECT_TRUE(calls.Inspect(&results).ok());
  EXPECT_EQ(results, 1);
  EXPECT_TRUE(calls.Filter().ok());
  EXPECT_TRUE(calls.Register().ok());
  EXPECT_TRUE(calls.ErrorMap().ok());
}

// A COUNT makes that many calls fail; the one after succeeds.
TEST(GuardedCallbacks, CountFaultsThatManyCalls) {
  testing::ServerProcess server({"--fault-inject", "bad_alloc:Filter.Run:2"});
  ASSERT_TRUE(server.started());
  Calls calls(server.target());
  EXPECT_EQ(calls.Filter().error_code(), StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(calls.Filter().error_code(), StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(calls.Filter().ok());
}

TEST(GuardedCallbacks, ABadFaultSpecStopsTheServerBeforeItListens) {
  for (const char* spec : {"bad_alloc", "oom:Filter.Run", "bad_alloc:WorkPool.Worker",
                           "bad_alloc:Filter.Run:0", "bad_alloc:Filter.Run:x"}) {
    testing::ServerProcess server({"--fault-inject", spec});
    EXPECT_FALSE(server.started()) << spec;
    EXPECT_NE(ReadLog(server).find("--fault-inject"), std::string::npos) << spec;
  }
}

}  // namespace
}  // namespace surfinspect
