#include "core/process/quiet_consoles.h"

#include <gtest/gtest.h>
#include <pcl/console/print.h>

namespace surfinspect {
namespace {

TEST(QuietConsoles, PclPrintsOnlyWhatItMustAlwaysPrint) {
  const pcl::console::VERBOSITY_LEVEL before = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_DEBUG);
  ASSERT_EQ(pcl::console::getVerbosityLevel(), pcl::console::L_DEBUG);
  QuietDependencyConsoles();
  EXPECT_EQ(pcl::console::getVerbosityLevel(), pcl::console::L_ALWAYS);
  EXPECT_FALSE(pcl::console::isVerbosityLevelEnabled(pcl::console::L_ERROR));
  EXPECT_FALSE(pcl::console::isVerbosityLevelEnabled(pcl::console::L_WARN));
  pcl::console::setVerbosityLevel(before);
}

}  // namespace
}  // namespace surfinspect
