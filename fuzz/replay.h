// The replay table of the normal build (see fuzz_target.h).
#pragma once

#include <map>
#include <string>

#include "fuzz/fuzz_target.h"

namespace surfinspect::fuzz {

std::map<std::string, TargetFn>& Targets();

}  // namespace surfinspect::fuzz
