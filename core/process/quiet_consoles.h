// Console output of dependencies, set once per program.
#pragma once

namespace surfinspect {

// Silences PCL's console: the readers return their own error messages, and
// PCL's would only repeat them on stderr. Call it once, first thing in main.
void QuietDependencyConsoles();

}  // namespace surfinspect
