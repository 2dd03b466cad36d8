// surfinspect: command-line front end. Runs each step in-process; the
// commands that take --server (client/cli/remote_args.h) call surfinspectd.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "client/cli/commands.h"
#include "core/process/buffer_reuse.h"
#include "core/process/huge_page_heap.h"

int main(int argc, char** argv) {
  surfinspect::ReuseFreedLargeBuffers();  // clouds are ~10 MB buffers, over and over
  // One command, 100+ MB of fresh buffers: faulted in 2 MiB pages where the
  // kernel allows (core/process/huge_page_heap.h); no result depends on it.
  surfinspect::BackHeapWithHugePages(surfinspect::kCliHeapReserveBytes);
  CLI::App app{
      "surfinspect: point-cloud filtering, calibration, registration and "
      "error maps against CAD (units: mm)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "surfinspect 0.1.0");
  // Logs and errors go to stderr so stdout stays clean for piping results.
  spdlog::set_default_logger(spdlog::stderr_color_mt("surfinspect"));
  spdlog::set_pattern("%^%l%$: %v");
  surfinspect::cli::AddInfoCommand(app);
  surfinspect::cli::AddFilterCommand(app);
  surfinspect::cli::AddSimulateCommands(app);
  surfinspect::cli::AddCalibrateCommand(app);
  surfinspect::cli::AddRegisterCommand(app);
  surfinspect::cli::AddInspectCommand(app);
  surfinspect::cli::AddHealthCommand(app);
  surfinspect::cli::AddErrorMapCommand(app);
  surfinspect::cli::AddAcceptanceCommand(app);
  surfinspect::cli::AddTrendCommand(app);
  surfinspect::cli::AddCadCommand(app);
  surfinspect::cli::AddHolesCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const surfinspect::cli::CommandFailed& e) {
    spdlog::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("unexpected: {}", e.what());
    return 2;
  }
  return 0;
}
