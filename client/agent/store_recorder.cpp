#include "client/agent/store_recorder.h"

#include "absl/strings/str_cat.h"
#include "core/types/status_macros.h"

namespace surfinspect::client {

StoreRecorder::StoreRecorder(std::string db, RecordContext context, std::string results_root,
                             std::function<void(const std::string&)> on_error)
    : db_(std::move(db)),
      context_(std::move(context)),
      results_root_(std::move(results_root)),
      on_error_(std::move(on_error)) {}

absl::Status StoreRecorder::Open() {
  if (store_) return absl::OkStatus();
  ASSIGN_OR_RETURN(store_, OpenResultsStore(db_));
  return absl::OkStatus();
}

absl::Status StoreRecorder::CatchUp() {
  RETURN_IF_ERROR(Open());
  std::vector<std::string> skipped;
  auto written = CatchUpFromFiles(*store_, context_, results_root_, &skipped);
  for (const std::string& s : skipped) on_error_(absl::StrCat("not recorded: ", s));
  if (!written.ok()) {
    store_.reset();  // reconnect next time
    return written.status();
  }
  recorded_ += *written;
  behind_ = false;
  return absl::OkStatus();
}

void StoreRecorder::OnStored(const std::string& part_id, const std::string& dir) {
  absl::Status st;
  if (behind_) {
    st = CatchUp();
  } else if (st = Open(); st.ok()) {
    auto written = RecordPartFromFiles(*store_, context_, part_id, dir);
    st = written.status();
    if (written.ok()) recorded_ += *written ? 1 : 0;
    if (!st.ok() && st.code() != absl::StatusCode::kDataLoss) store_.reset();
  }
  if (!st.ok()) {
    behind_ = st.code() != absl::StatusCode::kDataLoss;
    on_error_(absl::StrCat(part_id, ": not recorded in the results store (its files are kept; ",
                           behind_ ? "recorded later from them" : "they cannot be read",
                           "): ", st.message()));
  }
}

}  // namespace surfinspect::client
