// The child's every way of ending, with /bin/sh scripts standing in for a
// worker: each must come back as its own status, within the limits.
#include "core/cad/limited_child.h"

#include <gtest/gtest.h>

#include <chrono>

namespace surfinspect {
namespace {

absl::Status Sh(const std::string& script, ChildLimits limits = {}) {
  return RunLimited({"/bin/sh", "-c", script}, limits, "the job");
}

TEST(LimitedChild, ExitZeroIsOk) { EXPECT_TRUE(Sh("echo fine; exit 0").ok()); }

TEST(LimitedChild, ExitTwoIsBadInputWithTheChildsWords) {
  const absl::Status st = Sh("echo 'line one' >&2; echo 'no such body' >&2; exit 2");
  EXPECT_EQ(st.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(st.message().find("the job failed: line one\nno such body"), std::string::npos) << st;
}

TEST(LimitedChild, StdoutIsCapturedWithoutColourCodes) {
  const absl::Status st = Sh("printf '\\033[31;1m**** ERR bad ****\\033[0m\\n'; exit 1");
  EXPECT_EQ(st.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(st.message().find(": **** ERR bad ****"), std::string::npos) << st;
  EXPECT_EQ(st.message().find('\x1b'), std::string::npos);
}

TEST(LimitedChild, ExitThreeIsOutOfMemory) {
  EXPECT_EQ(Sh("exit 3").code(), absl::StatusCode::kResourceExhausted);
}

TEST(LimitedChild, ACrashIsNamedBySignal) {
  const absl::Status st = Sh("kill -SEGV $$");
  EXPECT_EQ(st.code(), absl::StatusCode::kInternal);
  EXPECT_NE(st.message().find("crashed (signal 11"), std::string::npos) << st;
}

TEST(LimitedChild, AHangIsStoppedAtTheDeadline) {
  const auto t0 = std::chrono::steady_clock::now();
  // exec: the shell becomes sleep, so the kill reaches the sleeping process.
  const absl::Status st = Sh("exec sleep 30", {0.5, 4096});
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(st.code(), absl::StatusCode::kDeadlineExceeded);
  EXPECT_NE(st.message().find("took longer than 0.5 s"), std::string::npos) << st;
  EXPECT_LT(s, 10);
}

TEST(LimitedChild, AChildThatClosesItsOutputAndHangsIsStoppedToo) {
  const absl::Status st = Sh("exec sleep 30 >/dev/null 2>&1", {0.5, 4096});
  EXPECT_EQ(st.code(), absl::StatusCode::kDeadlineExceeded) << st;
}

TEST(LimitedChild, TheMemoryLimitHolds) {
  // 64 MB of address space: a shell that tries to hold 200 MB fails.
  const absl::Status st =
      Sh("x=$(head -c 200000000 /dev/zero | tr '\\0' a); echo ${#x}; exit 0", {30, 64});
  EXPECT_FALSE(st.ok());
}

TEST(LimitedChild, AMissingProgramIsNotFound) {
  EXPECT_EQ(RunLimited({"/nonexistent/worker"}, {}, "x").code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace surfinspect
