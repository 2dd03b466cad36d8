// The PCL peers' console: our readers give their own errors, and PCL's
// warnings would only interleave with the bench's table on stderr.
#pragma once

#include <pcl/console/print.h>

namespace surfinspect::bench {

inline void QuietPcl() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }

}  // namespace surfinspect::bench
