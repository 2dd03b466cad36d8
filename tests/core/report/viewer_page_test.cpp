#include "core/report/viewer_page.h"

#include <gtest/gtest.h>

#include <cstring>

namespace surfinspect {
namespace {

TEST(ViewerPage, PayloadArraysStartAtMultiplesOfFourBytes) {
  std::string blob;
  const nlohmann::json a = AppendToPayload(blob, std::vector<uint8_t>{1, 2, 3});
  const nlohmann::json b = AppendToPayload(blob, std::vector<float>{1.5f, -2.0f});
  const nlohmann::json c = AppendToPayload(blob, std::vector<uint32_t>{});
  EXPECT_EQ(a, nlohmann::json::array({0, 3}));
  EXPECT_EQ(b, nlohmann::json::array({4, 8}));  // padded from 3 to 4
  EXPECT_EQ(c, nlohmann::json::array({12, 0}));
  ASSERT_EQ(blob.size(), 12u);
  float back[2];
  std::memcpy(back, blob.data() + 4, 8);
  EXPECT_EQ(back[0], 1.5f);
  EXPECT_EQ(back[1], -2.0f);
}

TEST(ViewerPage, MeshJsonDescribesTheQuantisedMesh) {
  std::string blob;
  const QuantisedPositions v = QuantisePositions({{0, 0, 0}, {10, 0, 0}, {0, 5, 0}});
  const nlohmann::json m = MeshJson(v, {0, 1, 2}, blob);
  EXPECT_EQ(m["vertices"], 3);
  EXPECT_EQ(m["triangles"], 1);
  EXPECT_EQ(m["positions"], nlohmann::json::array({0, 18}));
  EXPECT_EQ(m["indices"], nlohmann::json::array({20, 12}));
  EXPECT_EQ(m["min"], nlohmann::json::array({0.0, 0.0, 0.0}));
}

TEST(ViewerPage, HeadEscapesTheTitleAndScriptsCannotBeClosedByTheData) {
  const std::string head = ViewerHead("part <1> & \"x\"");
  EXPECT_NE(head.find("<title>part &lt;1&gt; &amp; &quot;x&quot;</title>"), std::string::npos);
  EXPECT_NE(head.find("<script type=\"importmap\">"), std::string::npos);
  const std::string end = ViewerScripts({{"kind", "report"}, {"name", "</script><b>"}}, "QUJD");
  EXPECT_EQ(end.find("</script><b>"), std::string::npos);
  EXPECT_NE(end.find("id=\"si-payload\">QUJD</script>"), std::string::npos);
  EXPECT_NE(end.find("<script type=\"module\" src=\"data:text/javascript;base64,"),
            std::string::npos);
  EXPECT_EQ(end.substr(end.size() - 15), "</body></html>\n");
}

TEST(ViewerPage, PaneHasTheStandardViewsAndTheExtraControls) {
  const std::string pane = ViewerPane("<label>extra</label>");
  for (const char* v : {"iso", "top", "bottom", "front", "back", "left", "right"})
    EXPECT_NE(pane.find(std::string("data-view=\"") + v + "\""), std::string::npos) << v;
  EXPECT_NE(pane.find("right</button><label>extra</label></div>"), std::string::npos);
  EXPECT_NE(pane.find("<canvas id=\"legend\""), std::string::npos);
}

}  // namespace
}  // namespace surfinspect
