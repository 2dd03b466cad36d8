#include "core/cad/limited_child.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace surfinspect {
namespace {

constexpr std::size_t kKeptStderr = 4096;

// In the child, between fork and exec: only async-signal-safe calls.
[[noreturn]] void ExecLimited(char* const* argv, const ChildLimits& limits, int err_fd) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  const rlim_t bytes = static_cast<rlim_t>(limits.memory_mb) << 20;
  const rlimit as{bytes, bytes}, core{0, 0};
  ::setrlimit(RLIMIT_AS, &as);
  ::setrlimit(RLIMIT_CORE, &core);
  ::dup2(err_fd, STDERR_FILENO);
  ::dup2(err_fd, STDOUT_FILENO);  // OpenCASCADE prints its messages on stdout
  ::execv(argv[0], argv);
  _exit(127);
}

// Reads the child's stderr (keeping its tail) until it closes or the deadline.
bool DrainUntil(int fd, std::chrono::steady_clock::time_point deadline, std::string* tail) {
  char buf[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<int64_t>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) return true;
    if (ready <= 0) continue;
    const ssize_t got = ::read(fd, buf, sizeof buf);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return true;
    tail->append(buf, static_cast<std::size_t>(got));
    if (tail->size() > 2 * kKeptStderr) tail->erase(0, tail->size() - kKeptStderr);
  }
}

// ESC [ ... letter: a terminal's colour code, as OCCT's messages carry.
std::string WithoutEscapes(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\x1b') {
      out += text[i];
      continue;
    }
    if (i + 1 < text.size() && text[i + 1] == '[')
      for (i += 2; i < text.size() && !std::isalpha(static_cast<unsigned char>(text[i])); ++i) {
      }
  }
  return out;
}

std::string LastLines(const std::string& text) {
  std::string t(absl::StripAsciiWhitespace(WithoutEscapes(text)));
  if (t.size() > kKeptStderr) t = t.substr(t.size() - kKeptStderr);
  return t.empty() ? "" : absl::StrCat(": ", t);
}

absl::Status StatusOfExit(int wstatus, const std::string& err, const ChildLimits& limits,
                          const std::string& what) {
  // Under RLIMIT_AS a thread that cannot get its stack fails pthread_create:
  // OCCT's mesher threads then abort the child, which is the memory limit too.
  const bool out_of_memory = err.find("bad_alloc") != std::string::npos ||
                             err.find("OutOfMemory") != std::string::npos ||
                             err.find("pthread_create") != std::string::npos;
  if (WIFSIGNALED(wstatus)) {
    if (out_of_memory)
      return absl::ResourceExhaustedError(absl::StrCat(what, " ran out of its ", limits.memory_mb,
                                                       " MB memory limit", LastLines(err)));
    const int sig = WTERMSIG(wstatus);
    return absl::InternalError(
        absl::StrCat(what, " crashed (signal ", sig, ": ", ::strsignal(sig), ")", LastLines(err)));
  }
  const int code = WEXITSTATUS(wstatus);
  if (code == 0) return absl::OkStatus();
  if (code == 3 || out_of_memory)
    return absl::ResourceExhaustedError(absl::StrCat(what, " ran out of its ", limits.memory_mb,
                                                     " MB memory limit", LastLines(err)));
  if (code == 127)
    return absl::NotFoundError(absl::StrCat(what,
                                            ": the program could not start (not executable, "
                                            "or it does not load within ",
                                            limits.memory_mb, " MB)"));
  if (code == 2) return absl::InvalidArgumentError(absl::StrCat(what, " failed", LastLines(err)));
  return absl::FailedPreconditionError(
      absl::StrCat(what, " failed (exit code ", code, ")", LastLines(err)));
}

}  // namespace

absl::Status RunLimited(const std::vector<std::string>& argv, const ChildLimits& limits,
                        const std::string& what) {
  if (argv.empty() || ::access(argv[0].c_str(), X_OK) != 0)
    return absl::NotFoundError(
        absl::StrCat(what, ": cannot run ", argv.empty() ? "nothing" : argv[0]));
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    return absl::ResourceExhaustedError(absl::StrCat(what, ": no pipe: ", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    return absl::ResourceExhaustedError(
        absl::StrCat(what, ": cannot fork: ", std::strerror(errno)));
  }
  if (pid == 0) ExecLimited(args.data(), limits, fds[1]);
  ::close(fds[1]);
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<int64_t>(limits.seconds * 1000));
  std::string err;
  bool in_time = DrainUntil(fds[0], deadline, &err);
  ::close(fds[0]);
  int wstatus = 0;
  // A child that closed stderr may still run: wait for it until the deadline.
  while (in_time && ::waitpid(pid, &wstatus, WNOHANG) == 0) {
    in_time = std::chrono::steady_clock::now() < deadline;
    if (in_time) ::usleep(5000);
  }
  if (!in_time) {
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
    }
  }
  if (!in_time)
    return absl::DeadlineExceededError(absl::StrCat(what, " took longer than ", limits.seconds,
                                                    " s and was stopped", LastLines(err)));
  return StatusOfExit(wstatus, err, limits, what);
}

}  // namespace surfinspect
