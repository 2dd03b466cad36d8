// client/agent/mqtt_events.cpp: URLs, the settings' validator, cell.json's
// "mqtt" block, topics and payloads (against the report they summarise).
// The publisher against a real broker is tests/client/agent/mqtt_e2e_test.py.
#include "client/agent/mqtt_events.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {

using nlohmann::json;

std::string ErrorOf(const MqttSettings& s) {
  return std::string(ValidateMqttSettings(s).message());
}

MqttSettings Valid() {
  MqttSettings s;
  s.url = "tcp://127.0.0.1:1883";
  return s;
}

TEST(MqttUrl, SchemesHostsAndPorts) {
  auto a = ParseMqttUrl("tcp://broker.plant:1884");
  ASSERT_TRUE(a.ok());
  EXPECT_FALSE(a->tls);
  EXPECT_EQ(a->host, "broker.plant");
  EXPECT_EQ(a->port, 1884);
  auto b = ParseMqttUrl("mqtts://broker");
  ASSERT_TRUE(b.ok());
  EXPECT_TRUE(b->tls);
  EXPECT_EQ(b->port, 8883);
  EXPECT_EQ(ParseMqttUrl("tcp://h")->port, 1883);
  EXPECT_NE(ParseMqttUrl("http://h:1883").status().message().find("unknown scheme \"http\""),
            std::string::npos);
  EXPECT_FALSE(ParseMqttUrl("broker:1883").ok());
  EXPECT_FALSE(ParseMqttUrl("tcp://h:0").ok());
  EXPECT_FALSE(ParseMqttUrl("tcp://h:99999").ok());
  EXPECT_FALSE(ParseMqttUrl("tcp://:1883").ok());
}

TEST(MqttSettings, ValidatorNamesTheProblem) {
  EXPECT_TRUE(ValidateMqttSettings(Valid()).ok());
  MqttSettings s = Valid();
  s.topic_prefix = "plant/#";
  EXPECT_NE(ErrorOf(s).find("wildcard"), std::string::npos);
  s.topic_prefix = "plant/+/x";
  EXPECT_NE(ErrorOf(s).find("wildcard"), std::string::npos);
  s.topic_prefix = "plant/";
  EXPECT_NE(ErrorOf(s).find("empty level"), std::string::npos);
  s = Valid();
  s.keepalive_s = 2;
  EXPECT_NE(ErrorOf(s).find("keep-alive"), std::string::npos);
  s = Valid();
  s.tls_ca = "/etc/hostname";
  EXPECT_NE(ErrorOf(s).find("not mqtts://"), std::string::npos);
  s.url = "mqtts://h";
  EXPECT_TRUE(ValidateMqttSettings(s).ok());
  s.tls_ca = "/no/such/ca.pem";
  EXPECT_NE(ErrorOf(s).find("CA file: no such file /no/such/ca.pem"), std::string::npos);
  s.tls_ca.clear();
  s.tls_cert = "/etc/hostname";
  EXPECT_NE(ErrorOf(s).find("needs its key"), std::string::npos);
  s = Valid();
  s.password_file = "/etc/hostname";
  EXPECT_NE(ErrorOf(s).find("needs a username"), std::string::npos);
}

TEST(MqttSettings, CellJsonBlockResolvesPathsBesideTheFile) {
  CellConfig cell;
  cell.path = "/plant/cells/a/cell.json";
  cell.raw = {{"mqtt",
               {{"url", "mqtts://b:8883"},
                {"tls_ca", "ca.pem"},
                {"password_file", "/etc/pw"},
                {"keepalive_s", 10}}}};
  auto s = MqttSettingsFromCell(cell);
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->url, "mqtts://b:8883");
  EXPECT_EQ(s->tls_ca, "/plant/cells/a/ca.pem");
  EXPECT_EQ(s->password_file, "/etc/pw");
  EXPECT_EQ(s->keepalive_s, 10);
  EXPECT_EQ(s->topic_prefix, "surfinspect/v1");
  cell.raw["mqtt"]["tls-ca"] = "x";
  EXPECT_NE(MqttSettingsFromCell(cell).status().message().find("mqtt.tls-ca: unknown key"),
            std::string::npos);
  cell.raw = {{"mqtt", {{"url", 5}}}};
  EXPECT_NE(MqttSettingsFromCell(cell).status().message().find("mqtt.url: not a string"),
            std::string::npos);
  cell.raw = json::object();
  EXPECT_TRUE(MqttSettingsFromCell(cell)->url.empty());  // no block: MQTT off
}

TEST(MqttTopics, PrefixCellPartEvent) {
  MqttSettings s = Valid();
  EXPECT_EQ(PartTopic(s, "cell-a", "p-1", "result"), "surfinspect/v1/cell-a/p-1/result");
  EXPECT_EQ(StatusTopic(s, "cell-a"), "surfinspect/v1/cell-a/status");
  EXPECT_EQ(ClientIdOf(s, "cell-a"), "surfinspect-agent-cell-a");
  s.topic_prefix = "plant3/line2";
  EXPECT_EQ(PartTopic(s, "c", "p", "started"), "plant3/line2/c/p/started");
}

TEST(MqttPayloads, ResultSummarisesTheReport) {
  testing::TempDir dir;
  const json report = {{"schema", "surfinspect.report/2"},
                       {"verdict", "fail"},
                       {"statistics", {{"min_mm", -0.4}, {"max_mm", 0.2}}},
                       {"characteristics",
                        {{{"name", "surface"},
                          {"type", "surface"},
                          {"verdict", "pass"},
                          {"reason", "ok"},
                          {"tolerance_mm", {{"lower", -0.3}, {"upper", 0.3}}}},
                         {{"name", "ridge"},
                          {"type", "region"},
                          {"verdict", "fail"},
                          {"reason", "too high"},
                          {"tolerance_mm", {{"lower", -0.15}, {"upper", 0.15}}}}}},
                       {"defects", json::array({{{"id", 1}}, {{"id", 2}}})}};
  std::ofstream(dir.File("report.json")) << report.dump();
  std::ofstream(dir.File("result.qif")) << "<QIFDocument/>";
  auto text = ResultPayload("cell-a", "p-1", dir.path(), report.dump(), "2026-12-01T10:00:00.000Z");
  ASSERT_TRUE(text.ok()) << text.status();
  const json p = json::parse(*text);
  EXPECT_EQ(p["schema"], "surfinspect.event.result/1");
  EXPECT_EQ(p["part_id"], "p-1");
  EXPECT_EQ(p["cell"], "cell-a");
  EXPECT_EQ(p["verdict"], "fail");
  EXPECT_EQ(p["characteristics"], 2);
  ASSERT_EQ(p["failed"].size(), 1u);
  EXPECT_EQ(p["failed"][0]["name"], "ridge");
  EXPECT_EQ(p["failed"][0]["reason"], "too high");
  EXPECT_EQ(p["defects"], 2);
  EXPECT_EQ(p["min_mm"], -0.4);
  EXPECT_EQ(p["files"]["report"], dir.File("report.json"));
  EXPECT_EQ(p["files"]["qif"], dir.File("result.qif"));
  EXPECT_FALSE(p["files"].contains("errormap_ply"));  // only files that exist
  // Every copy of the event has the same key; other results another one.
  auto again = ResultPayload("cell-a", "p-1", dir.path(), report.dump(), "2026-12-02T00:00:00Z");
  EXPECT_EQ(json::parse(*again)["idempotency_key"], p["idempotency_key"]);
  json other = report;
  other["verdict"] = "pass";
  auto changed = ResultPayload("cell-a", "p-1", dir.path(), other.dump(), "t");
  EXPECT_NE(json::parse(*changed)["idempotency_key"], p["idempotency_key"]);
  EXPECT_FALSE(ResultPayload("c", "p", dir.path(), "{", "t").ok());
}

TEST(MqttPayloads, StartedAndStatus) {
  const json s = json::parse(StartedPayload("c", "p", "t"));
  EXPECT_EQ(s["schema"], "surfinspect.event.started/1");
  EXPECT_EQ(s["part_id"], "p");
  EXPECT_EQ(s["idempotency_key"], json::parse(StartedPayload("c", "p", "u"))["idempotency_key"]);
  const json st = json::parse(StatusPayload("c", "online", "", "t"));
  EXPECT_EQ(st["state"], "online");
  EXPECT_EQ(st["cell"], "c");
  EXPECT_EQ(EventTimeNow().size(), std::string("2026-12-01T10:00:00.000Z").size());
}

}  // namespace
}  // namespace surfinspect::client
