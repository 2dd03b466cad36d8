#include "core/report/viewer_page.h"

#include "absl/strings/str_cat.h"
#include "core/report/html_escape.h"
#include "core/report/viewer_assets.h"

namespace surfinspect {
namespace {

std::string DataUrl(absl::string_view base64) {
  return absl::StrCat("data:text/javascript;base64,", base64);
}

}  // namespace

nlohmann::json Vec3Json(const Eigen::Vector3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

nlohmann::json PaletteJson(const DeviationPalette& palette) {
  nlohmann::json colors = nlohmann::json::array();
  for (const Rgb& c : palette.colors) colors.insert(colors.end(), {c.r, c.g, c.b});
  return colors;
}

nlohmann::json MeshJson(const QuantisedPositions& vertices, const std::vector<uint32_t>& triangles,
                        std::string& blob) {
  return {{"vertices", vertices.size()},
          {"triangles", triangles.size() / 3},
          {"min", Vec3Json(vertices.min)},
          {"step", Vec3Json(vertices.step)},
          {"positions", AppendToPayload(blob, vertices.xyz)},
          {"indices", AppendToPayload(blob, triangles)}};
}

std::string ViewerHead(const std::string& title) {
  const ViewerAssets& a = GetViewerAssets();
  const nlohmann::json imports = {
      {"imports",
       {{"three", DataUrl(a.three_module_base64)},
        {"three/addons/controls/OrbitControls.js", DataUrl(a.orbit_controls_base64)}}}};
  return absl::StrCat("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n",
                      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n",
                      "<title>", HtmlEscape(title), "</title>\n<style>\n", a.viewer_css,
                      "</style>\n", "<script type=\"importmap\">", JsonForScript(imports),
                      "</script>\n", "</head><body>\n");
}

std::string ViewerPane(const std::string& toolbar_extra) {
  std::string views;
  for (const char* v : {"iso", "top", "bottom", "front", "back", "left", "right"})
    absl::StrAppend(&views, "<button type=\"button\" data-view=\"", v, "\">", v, "</button>");
  return absl::StrCat(
      "<section id=\"viewer-pane\"><div id=\"toolbar\">", views, toolbar_extra, "</div>\n",
      "<div id=\"viewer\"><canvas id=\"legend\" width=\"120\" height=\"320\"></canvas>"
      "<div id=\"labels\"></div><div id=\"hover\" hidden></div>"
      "<noscript><p>The 3D view needs JavaScript; the tables work without it.</p></noscript>"
      "</div>\n<p id=\"viewer-note\"></p></section>\n");
}

std::string ViewerScripts(const nlohmann::json& data, const std::string& payload_base64) {
  return absl::StrCat("<script type=\"application/json\" id=\"si-data\">", JsonForScript(data),
                      "</script>\n<script type=\"application/octet-stream\" id=\"si-payload\">",
                      payload_base64, "</script>\n<script type=\"module\" src=\"",
                      DataUrl(GetViewerAssets().viewer_base64), "\"></script>\n</body></html>\n");
}

}  // namespace surfinspect
