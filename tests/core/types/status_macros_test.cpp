#include "core/types/status_macros.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace surfinspect {
namespace {

absl::Status Counted(int* calls, absl::Status result) {
  ++*calls;
  return result;
}

absl::Status TwoSteps(int* calls, absl::Status first, absl::Status second) {
  RETURN_IF_ERROR(Counted(calls, first));
  RETURN_IF_ERROR(Counted(calls, second));
  return absl::OkStatus();
}

TEST(StatusMacros, ReturnIfErrorStopsAtTheFirstErrorAndEvaluatesOnce) {
  int calls = 0;
  EXPECT_TRUE(TwoSteps(&calls, absl::OkStatus(), absl::OkStatus()).ok());
  EXPECT_EQ(calls, 2);
  calls = 0;
  const absl::Status st = TwoSteps(&calls, absl::NotFoundError("a"), absl::OkStatus());
  EXPECT_EQ(st, absl::NotFoundError("a"));
  EXPECT_EQ(calls, 1);
}

absl::StatusOr<std::unique_ptr<std::string>> MakeText(bool ok) {
  if (!ok) return absl::InvalidArgumentError("no text");
  return std::make_unique<std::string>("text");
}

// A move-only value is moved out; the declared name has the value's type.
absl::StatusOr<std::size_t> TextLength(bool ok) {
  ASSIGN_OR_RETURN(std::unique_ptr<std::string> text, MakeText(ok));
  ASSIGN_OR_RETURN(auto again, MakeText(ok));  // two on one function, distinct temporaries
  return text->size() + again->size();
}

TEST(StatusMacros, AssignOrReturnMovesTheValueOrReturnsTheStatus) {
  EXPECT_EQ(*TextLength(true), 8u);
  EXPECT_EQ(TextLength(false).status(), absl::InvalidArgumentError("no text"));
}

TEST(StatusMacros, AssignOrReturnAssignsToAnExistingVariable) {
  auto run = [](bool ok, std::string* out) -> absl::Status {
    std::unique_ptr<std::string> text;
    ASSIGN_OR_RETURN(text, MakeText(ok));
    *out = *text;
    return absl::OkStatus();
  };
  std::string out = "unset";
  EXPECT_FALSE(run(false, &out).ok());
  EXPECT_EQ(out, "unset");
  EXPECT_TRUE(run(true, &out).ok());
  EXPECT_EQ(out, "text");
}

}  // namespace
}  // namespace surfinspect
