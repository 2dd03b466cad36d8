#include "tests/support/server_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <thread>

namespace surfinspect::testing {

std::string BinPath(const std::string& name) {
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (n <= 0) return name;
  self[n] = '\0';
  return (std::filesystem::path(self).parent_path() / name).string();
}

ServerProcess::ServerProcess(const std::vector<std::string>& extra) {
  int out[2];
  if (::pipe(out) != 0) return;
  char log_template[] = "/tmp/surfinspectd-test-XXXXXX";
  const int log_fd = ::mkstemp(log_template);
  log_ = log_template;
  pid_ = ::fork();
  if (pid_ == 0) {
    ::dup2(out[1], STDOUT_FILENO);
    if (log_fd >= 0) ::dup2(log_fd, STDERR_FILENO);
    ::close(out[0]);
    std::vector<std::string> args = {BinPath("surfinspectd"), "--listen", "127.0.0.1:0"};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    std::_Exit(127);
  }
  ::close(out[1]);
  if (log_fd >= 0) ::close(log_fd);
  // Read "surfinspectd listening on 127.0.0.1:PORT" (10 s at most).
  std::string line;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  ::fcntl(out[0], F_SETFL, O_NONBLOCK);
  while (std::chrono::steady_clock::now() < deadline && line.find('\n') == std::string::npos) {
    char buf[256];
    const ssize_t r = ::read(out[0], buf, sizeof(buf));
    if (r > 0)
      line.append(buf, static_cast<std::size_t>(r));
    else if (r == 0)
      break;  // the server exited (e.g. a bad flag) without listening
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::close(out[0]);
  const auto colon = line.rfind(':');
  if (line.rfind("surfinspectd listening on", 0) == 0 && colon != std::string::npos)
    port_ = std::atoi(line.c_str() + colon + 1);
}

ServerProcess::~ServerProcess() {
  Kill();
  if (!log_.empty()) std::remove(log_.c_str());
}

int ServerProcess::Terminate() {
  if (pid_ <= 0) return -1;
  ::kill(pid_, SIGTERM);
  int status = 0;
  ::waitpid(pid_, &status, 0);
  pid_ = -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void ServerProcess::Kill() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  ::waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

}  // namespace surfinspect::testing
