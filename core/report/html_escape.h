// Text from outside (part ids, region and file names, plan fields) placed
// into an HTML page so that it can never become markup or script.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace surfinspect {

// & < > " ' as character references: safe in element content and in quoted
// attribute values.
std::string HtmlEscape(std::string_view text);

// `value` as JSON for a <script type="application/json"> element: <, > and
// & are written as \u003c, \u003e and \u0026 (they occur only inside JSON
// strings, where the escapes mean the same), so "</script>" or "<!--" in
// any string cannot end or change the element; U+2028/U+2029 are escaped
// too. JSON.parse of the element's text gives `value` back. Invalid UTF-8
// is replaced by U+FFFD.
std::string JsonForScript(const nlohmann::json& value);

}  // namespace surfinspect
