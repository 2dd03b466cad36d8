// The OBJ line walk shared by the OBJ byte check and the OBJ group reader:
// every line with a token, comments (from '#') cut.
#pragma once

#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {

// Calls visit(tokens, line number) for every OBJ line with a token; stops at
// the first error visit returns.
template <typename Visit>
absl::Status ForEachObjLine(std::string_view bytes, Visit&& visit) {
  LineScanner lines(bytes);
  std::string_view line;
  std::vector<std::string_view> tok;
  while (lines.Next(&line)) {
    SplitWhitespace(line.substr(0, line.find('#')), &tok);
    if (tok.empty()) continue;
    RETURN_IF_ERROR(visit(tok, lines.line_number()));
  }
  return absl::OkStatus();
}

}  // namespace surfinspect
