// The results store: every inspected part's result in a database, so that
// SPC and the process trend can look across parts. One small interface with
// two backends that share one schema and its migrations (store_schema.h):
// SQLite, the embedded default (a file path, WAL mode), and PostgreSQL for a
// plant (a postgresql:// URL; many cells and agents write one database).
//
// Guarantees: a part is written in one transaction, so a reader or a crash
// never sees part of it; the key is (cell, part_id), and recording a key
// that is already there changes nothing and reports so (an agent restarted
// after a crash writes no duplicate). Deviations are in mm, + above the CAD
// surface. Times are UTC, ISO 8601 with microseconds ("2026-12-01T11:39:48.
// 123456Z"), so their text order is their time order.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace surfinspect {

// One characteristic's result on one part, as report.json gives it. NaN is
// NULL in the database.
struct CharacteristicRecord {
  std::string name;
  std::string type;  // "surface", "region", "point", "section", "hole" or "slot"
  // A point's value_mm, else mean_mm (NaN for holes and slots, whose
  // quantities are the fields below; the trend charts each, trend.h).
  double value_mm = NAN;
  double mean_mm = NAN, min_mm = NAN, max_mm = NAN, stddev_mm = NAN;
  double lower_mm = NAN, upper_mm = NAN;  // its tolerance (a hole's: of its diameter)
  std::string verdict;                    // "pass", "fail" or "not_measured"
  int64_t points = 0;                     // a hole's: its edge points
  // Holes and slots, as measured (NaN otherwise, and when not measured):
  // the diameter (a slot's width) and its deviation from nominal, the true
  // position and its zone's diameter, a slot's length with its deviation
  // and band.
  double size_mm = NAN, size_deviation_mm = NAN;
  double true_position_mm = NAN, position_tolerance_mm = NAN;
  double length_mm = NAN, length_deviation_mm = NAN;
  double length_lower_mm = NAN, length_upper_mm = NAN;
};

// The deviation field on one CAD triangle of one part: the points whose
// closest triangle it is. Only triangles with points are kept.
struct TriangleStat {
  uint32_t triangle_id = 0;
  uint32_t count = 0;
  float mean_mm = 0, min_mm = 0, max_mm = 0;
};

struct PartRecord {
  std::string cell, part_id;
  std::string inspected_utc;     // when the result was made (ISO 8601 UTC)
  std::string software_version;  // surfinspect's version
  std::string plan_hash;         // SHA-256 hex of the plan JSON ("" without a plan)
  std::string verdict;           // "pass" / "fail"
  std::vector<CharacteristicRecord> characteristics;
  std::string defects_json = "[]";      // report.json's "defects"
  std::string calibration_json = "{}";  // the viewpoints' calibration state
  std::string files_json = "{}";        // {"report": path, ...}
  uint32_t num_triangles = 0;           // the CAD mesh's triangle count
  std::vector<TriangleStat> triangles;  // sorted by triangle_id
};

// Which parts a query takes; empty fields take everything. Parts are ordered
// by inspected_utc, then cell, then part_id.
struct PartSelection {
  std::string cell;
  std::string since_utc;  // parts inspected at or after this time
  int last = 0;           // > 0: only the newest `last` of the parts selected
  bool with_triangles = false;
};

class ResultsStore {
 public:
  virtual ~ResultsStore() = default;
  // Writes the part in one transaction. True when written, false when the
  // (cell, part_id) was already recorded (then nothing changes).
  virtual absl::StatusOr<bool> Record(const PartRecord& part) = 0;
  virtual absl::StatusOr<bool> Contains(const std::string& cell, const std::string& part_id) = 0;
  // The selected parts in order, with their characteristics (and triangle
  // summaries when asked).
  virtual absl::StatusOr<std::vector<PartRecord>> Load(const PartSelection& selection) = 0;
  // The schema version the database is at.
  virtual absl::StatusOr<int> SchemaVersion() = 0;
  // The database as it may be logged: a URL without its password.
  virtual std::string Name() const = 0;
};

// A postgresql:// or postgres:// URL opens PostgreSQL, anything else is an
// SQLite file path (created when missing). The schema is created or migrated
// on open; a database of another application, or of a newer schema than this
// binary knows, is refused by name.
absl::StatusOr<std::unique_ptr<ResultsStore>> OpenResultsStore(const std::string& url_or_path);

bool IsPostgresUrl(const std::string& url_or_path);
// The URL with any password replaced by "***" (for logs and errors).
std::string RedactDatabaseUrl(const std::string& url_or_path);
// Now, in the store's time format.
std::string UtcNow();

}  // namespace surfinspect
