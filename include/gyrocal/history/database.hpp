#pragma once
// The calibration history: one SQLite database file (docs/history.md, "The database"), embedded (no server),
// which any SQLite client can open. Its schema is versioned (PRAGMA user_version) and marked as gyrocal's
// (PRAGMA application_id); every write is one transaction in WAL mode, so that concurrent writers and a
// killed process leave it consistent.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/history/run.hpp"

namespace gyrocal::history {

/// The schema version this gyrocal writes and reads (PRAGMA user_version).
inline constexpr int kSchemaVersion = 1;
/// PRAGMA application_id of a gyrocal history: the bytes "GYRH" (0x47595248).
inline constexpr std::int32_t kApplicationId = 0x47595248;
/// The default database, in the current folder (docs/interface.md).
inline constexpr const char* kDefaultDatabase = "gyrocal-history.sqlite";

class Database {
 public:
  enum class Mode {
    kRead,         ///< the file must exist and be a gyrocal history; nothing is written
    kReadWrite,    ///< the file must exist and be a gyrocal history
    kCreateWrite,  ///< as kReadWrite; a missing file is created with the schema
  };
  /// Opens the database at `path`. Throws gyrocal::Error naming the file, and leaves it untouched, when it is
  /// missing (kRead, kReadWrite), not an SQLite database, not gyrocal's (another application_id, or an SQLite
  /// file with tables of its own), of a newer schema than kSchemaVersion, or corrupt (PRAGMA quick_check).
  Database(const std::filesystem::path& path, Mode mode);
  ~Database();
  Database(Database&&) noexcept;
  Database& operator=(Database&&) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  /// Stores `run` in one transaction and returns its id. Refused (gyrocal::Error, nothing written) when the
  /// unit already holds a run with the same record_sha256 (naming that run's id and date), or when the unit's
  /// earlier runs are of another sensor or channel set (naming both). Concurrent writers wait for each other
  /// (a busy timeout of 10 s), then a refusal says the database is busy. `result_json`: the calibration
  /// result's whole text, kept with the run so that nothing of it is lost (result_json() returns it); may be
  /// empty. Also refused: a run whose unit is empty or longer than limits::kHistoryUnitBytes, whose note is
  /// longer than limits::kHistoryNoteBytes, whose date is not days_since_epoch's, whose record_sha256 is not
  /// 64 hex digits, or a unit that already holds limits::kHistoryRunsPerUnit runs.
  std::int64_t add(const Run& run, std::string_view result_json = {});
  /// The result text stored with run `id` (add's result_json); throws gyrocal::Error if there is no such run.
  std::string result_json(std::int64_t id) const;
  /// Every run of `unit`, ordered by date, then id; empty if the unit has none.
  std::vector<Run> runs(const std::string& unit) const;
  /// Every unit's serial, sorted.
  std::vector<std::string> units() const;
  /// The file's path, for messages.
  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gyrocal::history
