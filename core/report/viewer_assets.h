// The HTML report's script and style, generated at build time: three.js
// (pinned in core/report/viewer/package.json and package-lock.json, fetched
// by `npm ci` into the build folder) and the viewer's own files from
// core/report/viewer/, embedded by core/report/viewer/embed_assets.mjs.
#pragma once

#include "absl/strings/string_view.h"

namespace surfinspect {

struct ViewerAssets {
  absl::string_view three_version;          // e.g. "0.170.0"
  absl::string_view three_module_base64;    // build/three.module.min.js
  absl::string_view orbit_controls_base64;  // examples/jsm/controls/OrbitControls.js
  absl::string_view viewer_base64;          // viewer.js (ES module)
  absl::string_view viewer_css;             // viewer.css
};

const ViewerAssets& GetViewerAssets();

}  // namespace surfinspect
