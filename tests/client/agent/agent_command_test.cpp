// client/agent/agent_flags.cpp and client/agent/agent_command.cpp: the
// cell-agent's command line, and its commands' errors coming back as
// statuses (never an exit from the library).
#include "client/agent/agent_command.h"

#include <gtest/gtest.h>

#include <atomic>

#include "client/cell/part_files.h"
#include "core/io/io_mesh.h"
#include "tests/support/temp_dir.h"
#include "tests/support/test_meshes.h"

namespace surfinspect::client {
namespace {

TEST(AgentFlags, RunHelpNamesEveryFileOfThePartCatalogue) {
  CLI::App app{"cell-agent"};
  AgentArgs a;
  const AgentCommands c = AddAgentCommands(app, a);
  const std::string help = c.run->help();
  for (const PartFileEntry& e : PartFileCatalogue()) {
    EXPECT_NE(help.find(e.file_name), std::string::npos) << e.file_name;
    EXPECT_NE(help.find(std::string("(") + e.name + ")"), std::string::npos) << e.name;
  }
}

TEST(AgentFlags, RunFlagsFillTheArguments) {
  CLI::App app{"cell-agent"};
  AgentArgs a;
  const AgentCommands c = AddAgentCommands(app, a);
  app.parse("run --cell c.json --inbox in --results out --once --poll 0.5 --db none", false);
  EXPECT_TRUE(c.run->parsed());
  EXPECT_EQ(a.cell, "c.json");
  EXPECT_EQ(a.paths.inbox, "in");
  EXPECT_EQ(a.paths.results, "out");
  EXPECT_TRUE(a.once);
  EXPECT_EQ(a.poll_s, 0.5);
  EXPECT_EQ(a.db, "none");
}

// A one-viewpoint cell on a small box, without a server.
struct Cell {
  testing::TempDir dir;
  Cell() {
    EXPECT_TRUE(WriteMesh(dir.File("part.stl"), testing::Box({0, 0, 0}, {10, 10, 10})).ok());
    testing::WriteBytes(dir.File("cell.json"), R"({"name": "c1",
      "part": {"mesh": "part.stl", "world_from_part": {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0],
               [0, 0, 1, 0], [0, 0, 0, 1]]}},
      "viewpoints": [{"name": "v1"}]})");
  }
  AgentArgs Args() const {
    AgentArgs a;
    a.cell = dir.File("cell.json");
    a.paths.cell_dir = dir.path();
    a.once = true;
    return a;
  }
};

TEST(AgentCommand, ErrorsComeBackAsStatusesNamingTheCause) {
  Cell cell;
  std::atomic<bool> stop{false};
  AgentArgs a = cell.Args();
  auto r = RunCellCommand(a, AgentOutput{}, stop);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("no server"), std::string::npos) << r.status();
  EXPECT_NE(r.status().message().find("cell.json"), std::string::npos) << r.status();
  // A password on the command line is refused before any part is taken.
  a.server = "127.0.0.1:1";
  a.db = "postgresql://user:secret@localhost/db";
  r = RunCellCommand(a, AgentOutput{}, stop);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("password on the command line"), std::string::npos)
      << r.status();
  EXPECT_EQ(r.status().message().find("secret"), std::string::npos) << "redacted";
  a.cell = cell.dir.File("missing.json");
  EXPECT_FALSE(RunCellCommand(a, AgentOutput{}, stop).ok());
  EXPECT_FALSE(RunCalibrateCommand(a, AgentOutput{}, stop).ok());
  EXPECT_FALSE(RunVerifyCommand(a, AgentOutput{}).ok());
}

TEST(AgentCommand, StatusDirIsBesideTheCellUnlessSaid) {
  AgentArgs a;
  a.cell = "/cells/a/cell.json";
  EXPECT_EQ(StatusDir(a), "/cells/a");
  a.cell = "cell.json";
  EXPECT_EQ(StatusDir(a), ".");
  a.status_dir = "/var/lib/x";
  EXPECT_EQ(StatusDir(a), "/var/lib/x");
}

}  // namespace
}  // namespace surfinspect::client
