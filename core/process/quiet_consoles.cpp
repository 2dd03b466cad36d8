#include "core/process/quiet_consoles.h"

#include <pcl/console/print.h>

namespace surfinspect {

void QuietDependencyConsoles() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }

}  // namespace surfinspect
