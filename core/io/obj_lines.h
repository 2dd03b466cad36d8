// The OBJ line walk shared by the OBJ byte check and the OBJ group reader:
// every line with a token, comments cut. A comment starts at a '#' that
// begins a token: a '#' inside one is part of it, as in the group name
// `color:#ff0000` that surfinspect cad writes (docs/cad.md).
#pragma once

#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/io/text_parse.h"
#include "core/types/status_macros.h"

namespace surfinspect {

// The line up to a '#' that begins a token.
inline std::string_view WithoutObjComment(std::string_view line) {
  for (std::size_t i = 0; i < line.size(); ++i)
    if (line[i] == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t'))
      return line.substr(0, i);
  return line;
}

// Calls visit(tokens, line number) for every OBJ line with a token; stops at
// the first error visit returns.
template <typename Visit>
absl::Status ForEachObjLine(std::string_view bytes, Visit&& visit) {
  LineScanner lines(bytes);
  std::string_view line;
  std::vector<std::string_view> tok;
  while (lines.Next(&line)) {
    SplitWhitespace(WithoutObjComment(line), &tok);
    if (tok.empty()) continue;
    RETURN_IF_ERROR(visit(tok, lines.line_number()));
  }
  return absl::OkStatus();
}

}  // namespace surfinspect
