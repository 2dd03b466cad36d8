// The parts of a page that hosts the 3D viewer (core/report/viewer/viewer.js):
// the head with its style and the import map of three.js, the viewer pane,
// the payload packing, and the scripts at the end. report.html
// (html_report.h) and trend.html (core/history/trend_html.h) are built
// from them; `data.kind` tells the viewer which page it is on.
#pragma once

#include <Eigen/Core>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/report/deviation_palette.h"
#include "core/report/html_payload.h"

namespace surfinspect {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the page reads the payload as little-endian typed arrays");

// Appends `data` to the payload `blob` at a multiple of 4 bytes; returns
// [offset, bytes], which the viewer reads as a typed array.
template <typename T>
nlohmann::json AppendToPayload(std::string& blob, const std::vector<T>& data) {
  blob.resize((blob.size() + 3) / 4 * 4, '\0');
  const std::size_t offset = blob.size(), bytes = data.size() * sizeof(T);
  blob.resize(offset + bytes);
  if (bytes) std::memcpy(blob.data() + offset, data.data(), bytes);
  return nlohmann::json::array({offset, bytes});
}

nlohmann::json Vec3Json(const Eigen::Vector3d& v);

// The palette as 3 bytes per entry.
nlohmann::json PaletteJson(const DeviationPalette& palette);

// A quantised mesh for the viewer: {vertices, triangles, min, step,
// positions, indices}, its arrays appended to `blob`.
nlohmann::json MeshJson(const QuantisedPositions& vertices, const std::vector<uint32_t>& triangles,
                        std::string& blob);

// From <!doctype html> to <body>; `title` is escaped here.
std::string ViewerHead(const std::string& title);

// The toolbar (standard views, then `toolbar_extra`, trusted HTML), the
// viewer with its legend, labels and hover box, and the note below it.
std::string ViewerPane(const std::string& toolbar_extra);

// The data (JSON), the payload (base64) and the viewer module, then the
// end of the page.
std::string ViewerScripts(const nlohmann::json& data, const std::string& payload_base64);

}  // namespace surfinspect
