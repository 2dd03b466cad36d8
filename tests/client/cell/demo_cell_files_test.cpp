#include "client/cell/demo_cell_files.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "client/cell/cell_config.h"
#include "core/io/io_point_cloud.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::client {
namespace {

TEST(DemoCellFiles, WritesEveryFile) {
  testing::TempDir dir;
  DemoWriteOptions opt;
  opt.parts = 1;
  opt.scan.pulse_fraction = 0.003;
  ASSERT_TRUE(WriteDemoCell(dir.path(), MakeDemoCell(), opt).ok());
  for (const char* f : {"part.stl", "gauge.stl", "cell.json", "truth/parts.json",
                        "gauge_scans/v1.pcd", "scans/part-001/v5.pcd", "truth/part-001/v3.json"})
    EXPECT_TRUE(std::filesystem::exists(dir.File(f))) << f;
  auto scan = ReadPointCloud(dir.File("scans/part-001/v1.pcd"));
  ASSERT_TRUE(scan.ok());
  EXPECT_EQ(scan->width, 1024u);
  EXPECT_EQ(scan->height, 768u);
  // The cell file it writes is one the cell reader accepts.
  auto cell = ReadCellConfig(dir.File("cell.json"));
  ASSERT_TRUE(cell.ok()) << cell.status();
  EXPECT_EQ(cell->viewpoints.size(), 5u);
}

TEST(DemoCellFiles, NamesAFolderItCannotCreate) {
  testing::TempDir dir;
  const std::string blocker = dir.File("file");
  testing::WriteBytes(blocker, "not a folder");
  const absl::Status st = WriteDemoCell(blocker + "/cell", MakeDemoCell(), {});
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find(blocker), absl::string_view::npos) << st;
}

}  // namespace
}  // namespace surfinspect::client
