// The calibration history's SQLite database (history/database.hpp, docs/history.md "The database").
#include "gyrocal/history/database.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <map>
#include <random>
#include <set>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/history/sha256.hpp"

namespace gyrocal::history {
namespace {

namespace fs = std::filesystem;

/// How long a connection waits for another's lock before SQLITE_BUSY, ms (database.hpp: 10 s).
constexpr int kBusyTimeoutMs = 10000;

/// The schema, version 1 (docs/history.md, "The database"). Every statement runs in the creating transaction.
constexpr const char* kSchemaV1[] = {
    R"(CREATE TABLE runs (
  id INTEGER PRIMARY KEY,
  unit TEXT NOT NULL,
  date TEXT NOT NULL,
  date_days REAL NOT NULL,
  date_source TEXT NOT NULL,
  sensor TEXT NOT NULL,
  record_path TEXT NOT NULL,
  record_sha256 TEXT NOT NULL,
  config_sha256 TEXT NOT NULL,
  gyrocal_version TEXT NOT NULL,
  method TEXT NOT NULL,
  compensation TEXT NOT NULL,
  note TEXT NOT NULL,
  rows_read INTEGER NOT NULL,
  rows_used INTEGER NOT NULL,
  outliers INTEGER NOT NULL,
  gaps INTEGER NOT NULL,
  misfit_tested INTEGER NOT NULL,
  misfit_p_value REAL,
  std_scale REAL NOT NULL,
  added TEXT NOT NULL,
  result_json TEXT NOT NULL,
  UNIQUE (unit, record_sha256)
))",
    R"(CREATE TABLE channels (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  position INTEGER NOT NULL,
  name TEXT NOT NULL,
  PRIMARY KEY (run_id, position)
))",
    R"(CREATE TABLE coefficients (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  position INTEGER NOT NULL,
  channel TEXT NOT NULL,
  name TEXT NOT NULL,
  value REAL,
  std REAL,
  unit TEXT NOT NULL,
  identifiable INTEGER NOT NULL,
  PRIMARY KEY (run_id, position)
))",
    R"(CREATE TABLE machine_errors (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  position INTEGER NOT NULL,
  name TEXT NOT NULL,
  value REAL,
  std REAL,
  unit TEXT NOT NULL,
  PRIMARY KEY (run_id, position)
))",
    "CREATE INDEX runs_by_unit ON runs (unit, date_days, id)",
    "CREATE INDEX coefficients_by_name ON coefficients (channel, name)",
    "CREATE INDEX machine_errors_by_name ON machine_errors (name)",
};

/// The tables of schema version 1: a file with gyrocal's application_id lacking one is not a whole history.
constexpr std::array<const char*, 4> kTables = {"runs", "channels", "coefficients", "machine_errors"};

// ---- RAII around the C API ----

struct DbClose {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
using DbHandle = std::unique_ptr<sqlite3, DbClose>;

/// A prepared statement: bind, step, read columns; every return code checked.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql, const fs::path& path) : db_(db), path_(&path) {
    const int rc = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr);
    if (rc != SQLITE_OK) fail(rc, "prepare");
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void bind(int i, std::string_view text) {
    // An empty view may hold no pointer, which SQLite would bind as NULL: bind "" instead.
    const char* data = text.data() != nullptr ? text.data() : "";
    check_bind(sqlite3_bind_text64(stmt_, i, data, text.size(), SQLITE_TRANSIENT, SQLITE_UTF8));
  }
  void bind(int i, std::int64_t v) { check_bind(sqlite3_bind_int64(stmt_, i, v)); }
  void bind(int i, double v) { check_bind(sqlite3_bind_double(stmt_, i, v)); }
  void bind(int i, const std::optional<double>& v) {
    if (v)
      bind(i, *v);
    else
      check_bind(sqlite3_bind_null(stmt_, i));
  }
  /// Steps once: true when a row is ready, false when done.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail(rc, "step");
  }
  void run() {
    while (step()) {
    }
  }
  /// Ready to run again with new bindings (the previous run's outcome was checked by step()).
  void reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  std::string text(int i) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, i));
    const int n = sqlite3_column_bytes(stmt_, i);
    return p ? std::string(p, static_cast<std::size_t>(n)) : std::string();
  }
  std::int64_t integer(int i) const { return sqlite3_column_int64(stmt_, i); }
  double real(int i) const { return sqlite3_column_double(stmt_, i); }
  std::optional<double> optional_real(int i) const {
    if (sqlite3_column_type(stmt_, i) == SQLITE_NULL) return std::nullopt;
    return sqlite3_column_double(stmt_, i);
  }

  [[noreturn]] void fail(int rc, const char* what) const;

 private:
  void check_bind(int rc) {
    if (rc != SQLITE_OK) fail(rc, "bind");
  }
  sqlite3* db_;
  const fs::path* path_;
  sqlite3_stmt* stmt_ = nullptr;
};

/// The sentence for an SQLite error `rc` on the database at `path` while `doing`.
[[noreturn]] void sqlite_failure(sqlite3* db, int rc, const fs::path& path, std::string_view doing) {
  const int primary = rc & 0xff;
  const std::string detail = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  if (primary == SQLITE_BUSY || primary == SQLITE_LOCKED)
    throw Error(
        fmt::format("The history database {} is busy: another process held it for more than {} s while "
                    "gyrocal was {}; try again.",
                    path.string(), kBusyTimeoutMs / 1000, doing));
  if (primary == SQLITE_CORRUPT || primary == SQLITE_NOTADB)
    throw Error(fmt::format("The history database {} is corrupt ({}) while {}; it was left as it is.",
                            path.string(), detail, doing));
  if (primary == SQLITE_FULL)
    throw Error(
        fmt::format("Cannot write the history database {}: the disk is full ({}); nothing was stored.",
                    path.string(), detail));
  if (primary == SQLITE_READONLY || primary == SQLITE_PERM || primary == SQLITE_CANTOPEN)
    throw Error(fmt::format(
        "Cannot write the history database {} while {}: {} (the file, its folder, and any -wal or -shm file "
        "beside it must be writable by this user).",
        path.string(), doing, detail));
  throw Error(fmt::format("The history database {} failed while {}: {} (SQLite error {}).", path.string(),
                          doing, detail, rc));
}

void Statement::fail(int rc, const char* what) const {
  sqlite_failure(db_, rc, *path_, fmt::format("running a statement ({})", what));
}

/// Runs `sql` (no rows expected, or rows ignored).
void exec(sqlite3* db, const char* sql, const fs::path& path, std::string_view doing) {
  char* message = nullptr;
  const int rc = sqlite3_exec(db, sql, nullptr, nullptr, &message);
  sqlite3_free(message);
  if (rc != SQLITE_OK) sqlite_failure(db, rc, path, doing);
}

std::int64_t pragma_integer(sqlite3* db, const char* pragma, const fs::path& path) {
  Statement s(db, pragma, path);
  if (!s.step()) return 0;
  return s.integer(0);
}

/// Opens a connection with `flags`, with the busy timeout; extended error codes on.
DbHandle open_connection(const fs::path& path, int flags, std::string_view doing) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, flags | SQLITE_OPEN_NOFOLLOW, nullptr);
  DbHandle db(raw);
  if (rc != SQLITE_OK) sqlite_failure(db.get(), rc, path, doing);
  sqlite3_extended_result_codes(db.get(), 1);
  if (const int b = sqlite3_busy_timeout(db.get(), kBusyTimeoutMs); b != SQLITE_OK)
    sqlite_failure(db.get(), b, path, doing);
  return db;
}

std::string hex32(std::uint32_t v) {
  return fmt::format("0x{:08X}", v);
}

std::uint32_t big_endian32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

/// The checks of a file's first 100 bytes, before SQLite opens it (so that a file that is not a gyrocal
/// history is refused without SQLite creating anything beside it): the SQLite magic, the application_id, the
/// schema version. SQLite's own reading confirms them afterwards.
void check_header(const fs::path& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0)
    throw Error(fmt::format("Cannot open the history database {}: {}.", path.string(), std::strerror(errno)));
  if (S_ISLNK(st.st_mode))
    throw Error(fmt::format("The history database {} is a symbolic link: give the database file itself.",
                            path.string()));
  if (!S_ISREG(st.st_mode))
    throw Error(fmt::format("The history database {} is not a regular file (a folder, a device or a pipe).",
                            path.string()));
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > limits::kHistoryDatabaseBytes)
    throw Error(
        fmt::format("The history database {} holds {} bytes, more than the {} bytes gyrocal opens "
                    "(limits::kHistoryDatabaseBytes, docs/limits.md): start a new database.",
                    path.string(), size, limits::kHistoryDatabaseBytes));
  if (size == 0)
    throw Error(
        fmt::format("{} is an empty file, not a gyrocal history database; it was left as it is (give "
                    "the path of a database, or of a file that does not exist yet to create one).",
                    path.string()));
  unsigned char header[100] = {};
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0)
    throw Error(fmt::format("Cannot open the history database {}: {}.", path.string(), std::strerror(errno)));
  std::size_t got = 0;
  while (got < sizeof header) {
    const ssize_t n = ::read(fd, header + got, sizeof header - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  static constexpr char kMagic[] = "SQLite format 3";  // and its terminating zero: 16 bytes
  if (got < sizeof header || std::memcmp(header, kMagic, 16) != 0)
    throw Error(fmt::format("{} is not an SQLite database, so not a gyrocal history; it was left as it is.",
                            path.string()));
  const std::uint32_t application_id = big_endian32(header + 68);
  const std::uint32_t user_version = big_endian32(header + 60);
  if (application_id != static_cast<std::uint32_t>(kApplicationId))
    throw Error(
        fmt::format("{} is an SQLite database of another application (its application_id is {}, a "
                    "gyrocal history's {} \"GYRH\"); it was left as it is.",
                    path.string(), hex32(application_id), hex32(static_cast<std::uint32_t>(kApplicationId))));
  if (user_version > static_cast<std::uint32_t>(kSchemaVersion))
    throw Error(
        fmt::format("The history database {} has schema version {}, newer than the version {} this gyrocal "
                    "reads: use a newer gyrocal; it was left as it is.",
                    path.string(), user_version, kSchemaVersion));
}

/// SQLite's own view, read-only: the application_id and schema version, the tables, and PRAGMA quick_check.
void check_with_sqlite_connection(const fs::path& path) {
  DbHandle db = open_connection(path, SQLITE_OPEN_READONLY, "open");
  const std::int64_t application_id = pragma_integer(db.get(), "PRAGMA application_id", path);
  const std::int64_t version = pragma_integer(db.get(), "PRAGMA user_version", path);
  if (application_id != kApplicationId)
    throw Error(
        fmt::format("{} is an SQLite database of another application (its application_id is {}, a "
                    "gyrocal history's {} \"GYRH\"); it was left as it is.",
                    path.string(), hex32(static_cast<std::uint32_t>(application_id)),
                    hex32(static_cast<std::uint32_t>(kApplicationId))));
  if (version > kSchemaVersion)
    throw Error(
        fmt::format("The history database {} has schema version {}, newer than the version {} this gyrocal "
                    "reads: use a newer gyrocal; it was left as it is.",
                    path.string(), version, kSchemaVersion));
  if (version < kSchemaVersion)
    throw Error(
        fmt::format("The history database {} has schema version {}, not a version gyrocal wrote (it writes "
                    "{}); it was left as it is.",
                    path.string(), version, kSchemaVersion));
  {
    Statement q(db.get(), "PRAGMA quick_check", path);
    std::string first;
    std::size_t problems = 0;
    // One problem a line (a row may hold several lines): the message names the first and counts the others.
    while (q.step()) {
      const std::string text = q.text(0);
      if (text == "ok") continue;
      const std::size_t before = problems;
      std::size_t at = 0;
      while (at < text.size()) {
        const std::size_t end = std::min(text.find('\n', at), text.size());
        const std::string line = text.substr(at, end - at);
        at = end + 1;
        if (line.empty() || line.starts_with("*** in database")) continue;
        if (problems++ == 0) first = line;
      }
      if (problems == before && problems++ == 0) first = text.substr(0, text.find('\n'));  // any other answer
    }
    if (problems > 0)
      throw Error(
          fmt::format("The history database {} is corrupt (PRAGMA quick_check: {}{}); it was left as it is: "
                      "restore it from a backup.",
                      path.string(), first, problems > 1 ? fmt::format(", and {} more", problems - 1) : ""));
  }
  for (const char* table : kTables) {
    Statement t(db.get(), "SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND name = ?1", path);
    t.bind(1, std::string_view(table));
    if (!t.step() || t.integer(0) != 1)
      throw Error(
          fmt::format("The history database {} lacks the table {} of a gyrocal history (schema version {}); "
                      "it was left as it is.",
                      path.string(), table, kSchemaVersion));
  }
}

/// check_with_sqlite_connection, leaving nothing beside a file it refuses. A read-only connection to a file
/// in WAL mode creates the -wal and -shm files when they are missing (SQLite needs them to read), and cannot
/// remove them when it closes; a healthy database's are removed by the next writer's close, but a refused
/// file has none, so the ones this check created (they did not exist before it, and the -wal is still empty)
/// are removed.
void check_with_sqlite(const fs::path& path) {
  const fs::path wal = path.string() + "-wal", shm = path.string() + "-shm";
  std::error_code ec;
  const bool had_wal = fs::exists(wal, ec), had_shm = fs::exists(shm, ec);
  try {
    check_with_sqlite_connection(path);
  } catch (const Error&) {
    if (!had_wal && fs::exists(wal, ec) && fs::file_size(wal, ec) == 0) {
      fs::remove(wal, ec);
      if (!had_shm) fs::remove(shm, ec);
    }
    throw;
  }
}

/// The UTC time now, ISO 8601 ("2026-11-27T11:20:48").
std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

/// Creates the database at `path` if it does not exist: written whole in a temporary file beside it, then
/// linked to `path` only if `path` still does not exist (link() never replaces), so that no process ever sees
/// a half-made database and a file that appeared meanwhile (another gyrocal's database) is kept.
void create_if_missing(const fs::path& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) return;
  if (errno != ENOENT)
    throw Error(fmt::format("Cannot open the history database {}: {}.", path.string(), std::strerror(errno)));
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw Error(fmt::format("Cannot create the history database {}: its folder {} does not exist.",
                            path.string(), folder.string()));
  std::random_device rd;
  const fs::path temp =
      folder / fmt::format(".{}.{}-{:08x}.creating", path.filename().string(), ::getpid(), rd());
  struct Cleanup {
    const fs::path& p;
    ~Cleanup() {
      std::error_code ec;
      for (const char* suffix : {"", "-wal", "-shm", "-journal"})
        fs::remove(fs::path(p.string() + suffix), ec);
    }
  } cleanup{temp};
  {
    DbHandle db = open_connection(temp, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, "create");
    exec(db.get(), "PRAGMA journal_mode = WAL", temp, "creating the database");
    exec(db.get(), "BEGIN IMMEDIATE", temp, "creating the database");
    for (const char* sql : kSchemaV1) exec(db.get(), sql, temp, "creating the database");
    exec(db.get(), fmt::format("PRAGMA application_id = {}", kApplicationId).c_str(), temp,
         "creating the database");
    exec(db.get(), fmt::format("PRAGMA user_version = {}", kSchemaVersion).c_str(), temp,
         "creating the database");
    exec(db.get(), "COMMIT", temp, "creating the database");
    // Closing the last connection checkpoints the WAL into the file and removes the -wal and -shm files.
  }
  int linked = ::link(temp.c_str(), path.c_str());
  if (linked != 0 && (errno == EPERM || errno == ENOTSUP || errno == ENOSYS))
    // A file system without hard links: a rename that never replaces (Linux 3.15).
    linked = ::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, path.c_str(), RENAME_NOREPLACE);
  if (linked != 0) {
    if (errno == EEXIST) return;  // another process created it meanwhile: that one is opened
    throw Error(
        fmt::format("Cannot create the history database {}: {}.", path.string(), std::strerror(errno)));
  }
}

/// The kind of sensor and the channel set, as a refusal names them.
std::string describe(const std::string& sensor, const std::vector<std::string>& channels) {
  if (sensor == "accelerometer") return "an accelerometer";
  if (sensor != "imu") return "a " + sensor;
  std::string s = "an IMU with channels ";
  for (std::size_t i = 0; i < channels.size(); ++i) s += (i ? "," : "") + channels[i];
  return s;
}

/// The checks of a run before it is stored (database.hpp, add).
void validate(const Run& run, const fs::path& path) {
  const auto control = [](std::string_view s) {
    return std::any_of(s.begin(), s.end(),
                       [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
  };
  if (run.unit.empty() || run.unit.find_first_not_of(" \t") == std::string::npos)
    throw Error(fmt::format("A run for {} needs a unit serial (--unit); it is empty.", path.string()));
  if (run.unit.size() > limits::kHistoryUnitBytes)
    throw Error(
        fmt::format("--unit: the serial '{}...' is {} bytes long, longer than {} "
                    "(limits::kHistoryUnitBytes).",
                    run.unit.substr(0, 32), run.unit.size(), limits::kHistoryUnitBytes));
  if (control(run.unit))
    throw Error(
        "--unit: the serial holds a control character (a tab, a line break, ...); write it on one line.");
  if (run.note.size() > limits::kHistoryNoteBytes)
    throw Error(fmt::format("--note: the note is {} bytes long, longer than {} (limits::kHistoryNoteBytes).",
                            run.note.size(), limits::kHistoryNoteBytes));
  // A serial and a note are text that JSON, the report and a terminal show: UTF-8, no control character (an
  // escape sequence would reach the terminal of whoever reads the history).
  if (!valid_utf8(run.unit))
    throw Error("--unit: the serial is not valid UTF-8 text; give it as text (letters, digits, signs).");
  if (!valid_utf8(run.note)) throw Error("--note: the note is not valid UTF-8 text.");
  if (control(run.note))
    throw Error(
        "--note: the note holds a control character (a line break, an escape, ...); write it on one line.");
  days_since_epoch(run.date, "the run's date");
  if (!is_sha256_hex(run.record_sha256))
    throw Error(
        fmt::format("The run's record_sha256 '{}' is not a SHA-256 (64 lower-case hexadecimal digits).",
                    run.record_sha256.substr(0, 80)));
  if (!run.config_sha256.empty() && !is_sha256_hex(run.config_sha256))
    throw Error(
        fmt::format("The run's config_sha256 '{}' is not a SHA-256 (64 lower-case hexadecimal digits).",
                    run.config_sha256.substr(0, 80)));
  if (run.sensor != "gyro" && run.sensor != "accelerometer" && run.sensor != "imu")
    throw Error(fmt::format("The run's sensor '{}' is not gyro, accelerometer or imu.", run.sensor));
  if (run.channels.empty()) throw Error("The run names no channel.");
}

/// Rolls back unless committed.
class Transaction {
 public:
  Transaction(sqlite3* db, const fs::path& path) : db_(db), path_(path) {
    exec(db_, "BEGIN IMMEDIATE", path_, "starting to add a run");
  }
  void commit() {
    exec(db_, "COMMIT", path_, "committing the run");
    done_ = true;
  }
  ~Transaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;

 private:
  sqlite3* db_;
  const fs::path& path_;
  bool done_ = false;
};

}  // namespace

struct Database::Impl {
  fs::path path;
  DbHandle db;
};

Database::Database(const fs::path& path, Mode mode) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  if (mode == Mode::kCreateWrite) create_if_missing(path);
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) throw Error(fmt::format("The history database {} does not exist.", path.string()));
    throw Error(fmt::format("Cannot open the history database {}: {}.", path.string(), std::strerror(errno)));
  }
  // Checked before SQLite writes anything: a file that is not a gyrocal history is refused and left untouched
  // (SQLite opening it for writing could create a journal or WAL beside it).
  check_header(path);
  check_with_sqlite(path);
  if (mode == Mode::kRead) {
    // Read-write at the file level but no write allowed (query_only): as the last connection to close it
    // folds the WAL back and removes the -wal and -shm files, which a read-only connection cannot. A file the
    // user may only read is opened read-only by SQLite itself.
    impl_->db = open_connection(path, SQLITE_OPEN_READWRITE, "open");
    exec(impl_->db.get(), "PRAGMA query_only = ON", path, "opening");
  } else {
    impl_->db = open_connection(path, SQLITE_OPEN_READWRITE, "open for writing");
    exec(impl_->db.get(), "PRAGMA journal_mode = WAL", path, "opening");
  }
  exec(impl_->db.get(), "PRAGMA foreign_keys = ON", path, "opening");
}

Database::~Database() = default;
Database::Database(Database&&) noexcept = default;
Database& Database::operator=(Database&&) noexcept = default;

const fs::path& Database::path() const {
  return impl_->path;
}

std::int64_t Database::add(const Run& run, std::string_view result_json) {
  const fs::path& path = impl_->path;
  sqlite3* db = impl_->db.get();
  validate(run, path);
  // The normalised date: "T" upper case, no "Z" (UTC is stated by the schema).
  std::string date = run.date;
  if (!date.empty() && (date.back() == 'Z' || date.back() == 'z')) date.pop_back();
  if (date.size() > 10) date[10] = 'T';
  const double days = days_since_epoch(date, "the run's date");

  Transaction tx(db, path);
  {
    Statement dup(db, "SELECT id, date FROM runs WHERE unit = ?1 AND record_sha256 = ?2", path);
    dup.bind(1, run.unit);
    dup.bind(2, run.record_sha256);
    if (dup.step())
      throw Error(
          fmt::format("Unit {} already holds run {} ({}) of the same record (SHA-256 {}) in {}; nothing was "
                      "added.",
                      run.unit, dup.integer(0), dup.text(1), run.record_sha256, path.string()));
  }
  {
    Statement first(db, "SELECT id, date, sensor FROM runs WHERE unit = ?1 ORDER BY id LIMIT 1", path);
    first.bind(1, run.unit);
    if (first.step()) {
      const std::int64_t id = first.integer(0);
      const std::string earlier_date = first.text(1), sensor = first.text(2);
      std::vector<std::string> channels;
      Statement ch(db, "SELECT name FROM channels WHERE run_id = ?1 ORDER BY position", path);
      ch.bind(1, id);
      while (ch.step()) channels.push_back(ch.text(0));
      std::vector<std::string> a = channels, b = run.channels;
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      if (sensor != run.sensor || a != b)
        throw Error(
            fmt::format("Unit {} in {} holds runs of {} (run {}, {}), but this result is of {}: a unit's "
                        "runs are of one sensor and channel set; nothing was added.",
                        run.unit, path.string(), describe(sensor, channels), id, earlier_date,
                        describe(run.sensor, run.channels)));
    }
  }
  {
    Statement count(db, "SELECT count(*) FROM runs WHERE unit = ?1", path);
    count.bind(1, run.unit);
    if (count.step() && count.integer(0) >= static_cast<std::int64_t>(limits::kHistoryRunsPerUnit))
      throw Error(
          fmt::format("Unit {} in {} already holds {} runs, the most a unit may hold "
                      "(limits::kHistoryRunsPerUnit); nothing was added.",
                      run.unit, path.string(), count.integer(0)));
  }
  std::int64_t id = 0;
  {
    Statement ins(
        db,
        "INSERT INTO runs (unit, date, date_days, date_source, sensor, record_path, record_sha256, "
        "config_sha256, gyrocal_version, method, compensation, note, rows_read, rows_used, outliers, gaps, "
        "misfit_tested, misfit_p_value, std_scale, added, result_json) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, "
        "?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18, ?19, ?20, ?21)",
        path);
    ins.bind(1, run.unit);
    ins.bind(2, date);
    ins.bind(3, days);
    ins.bind(4, run.date_source);
    ins.bind(5, run.sensor);
    ins.bind(6, run.record_path);
    ins.bind(7, run.record_sha256);
    ins.bind(8, run.config_sha256);
    ins.bind(9, run.gyrocal_version);
    ins.bind(10, run.method);
    ins.bind(11, run.compensation);
    ins.bind(12, run.note);
    ins.bind(13, run.quality.rows_read);
    ins.bind(14, run.quality.rows_used);
    ins.bind(15, run.quality.outliers);
    ins.bind(16, run.quality.gaps);
    ins.bind(17, std::int64_t{run.quality.misfit_tested ? 1 : 0});
    ins.bind(18, run.quality.misfit_p_value);
    ins.bind(19, run.quality.std_scale);
    ins.bind(20, utc_now());
    ins.bind(21, result_json);
    ins.run();
    id = sqlite3_last_insert_rowid(db);
  }
  {
    Statement ins(db, "INSERT INTO channels (run_id, position, name) VALUES (?1, ?2, ?3)", path);
    for (std::size_t i = 0; i < run.channels.size(); ++i) {
      ins.reset();
      ins.bind(1, id);
      ins.bind(2, static_cast<std::int64_t>(i));
      ins.bind(3, run.channels[i]);
      ins.run();
    }
  }
  Statement coefficient(db,
                        "INSERT INTO coefficients (run_id, position, channel, name, value, std, unit, "
                        "identifiable) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
                        path);
  for (std::size_t i = 0; i < run.coefficients.size(); ++i) {
    const CoefficientValue& c = run.coefficients[i];
    Statement& ins = coefficient;
    ins.reset();
    ins.bind(1, id);
    ins.bind(2, static_cast<std::int64_t>(i));
    ins.bind(3, c.channel);
    ins.bind(4, c.name);
    ins.bind(5, c.value);
    ins.bind(6, c.std);
    ins.bind(7, c.unit);
    ins.bind(8, std::int64_t{c.identifiable ? 1 : 0});
    ins.run();
  }
  Statement machine_error(
      db,
      "INSERT INTO machine_errors (run_id, position, name, value, std, unit) VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
      path);
  for (std::size_t i = 0; i < run.machine_errors.size(); ++i) {
    const MachineErrorValue& m = run.machine_errors[i];
    Statement& ins = machine_error;
    ins.reset();
    ins.bind(1, id);
    ins.bind(2, static_cast<std::int64_t>(i));
    ins.bind(3, m.name);
    ins.bind(4, m.value);
    ins.bind(5, m.std);
    ins.bind(6, m.unit);
    ins.run();
  }
  tx.commit();
  return id;
}

std::vector<Run> Database::runs(const std::string& unit) const {
  const fs::path& path = impl_->path;
  sqlite3* db = impl_->db.get();
  // One read transaction, so that the four queries see one state of the database.
  exec(db, "BEGIN", path, "reading runs");
  struct End {
    sqlite3* db;
    ~End() { sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr); }
  } end{db};
  std::vector<Run> out;
  std::map<std::int64_t, std::size_t> index;
  {
    Statement q(
        db,
        "SELECT id, unit, date, date_source, sensor, record_path, record_sha256, config_sha256, "
        "gyrocal_version, method, compensation, note, rows_read, rows_used, outliers, gaps, misfit_tested, "
        "misfit_p_value, std_scale FROM runs WHERE unit = ?1 ORDER BY date_days, id",
        path);
    q.bind(1, unit);
    while (q.step()) {
      Run r;
      r.id = q.integer(0);
      r.unit = q.text(1);
      r.date = q.text(2);
      r.date_source = q.text(3);
      r.sensor = q.text(4);
      r.record_path = q.text(5);
      r.record_sha256 = q.text(6);
      r.config_sha256 = q.text(7);
      r.gyrocal_version = q.text(8);
      r.method = q.text(9);
      r.compensation = q.text(10);
      r.note = q.text(11);
      r.quality.rows_read = q.integer(12);
      r.quality.rows_used = q.integer(13);
      r.quality.outliers = q.integer(14);
      r.quality.gaps = q.integer(15);
      r.quality.misfit_tested = q.integer(16) != 0;
      r.quality.misfit_p_value = q.optional_real(17);
      r.quality.std_scale = q.real(18);
      index[r.id] = out.size();
      out.push_back(std::move(r));
    }
  }
  if (out.empty()) return out;
  {
    Statement q(db,
                "SELECT c.run_id, c.name FROM channels c JOIN runs r ON r.id = c.run_id WHERE r.unit = ?1 "
                "ORDER BY c.run_id, c.position",
                path);
    q.bind(1, unit);
    while (q.step()) out[index.at(q.integer(0))].channels.push_back(q.text(1));
  }
  {
    Statement q(
        db,
        "SELECT c.run_id, c.channel, c.name, c.value, c.std, c.unit, c.identifiable FROM coefficients c "
        "JOIN runs r ON r.id = c.run_id WHERE r.unit = ?1 ORDER BY c.run_id, c.position",
        path);
    q.bind(1, unit);
    while (q.step()) {
      CoefficientValue c;
      c.channel = q.text(1);
      c.name = q.text(2);
      c.value = q.optional_real(3);
      c.std = q.optional_real(4);
      c.unit = q.text(5);
      c.identifiable = q.integer(6) != 0;
      out[index.at(q.integer(0))].coefficients.push_back(std::move(c));
    }
  }
  {
    Statement q(db,
                "SELECT m.run_id, m.name, m.value, m.std, m.unit FROM machine_errors m JOIN runs r ON r.id = "
                "m.run_id WHERE r.unit = ?1 ORDER BY m.run_id, m.position",
                path);
    q.bind(1, unit);
    while (q.step()) {
      MachineErrorValue m;
      m.name = q.text(1);
      m.value = q.optional_real(2);
      m.std = q.optional_real(3);
      m.unit = q.text(4);
      out[index.at(q.integer(0))].machine_errors.push_back(std::move(m));
    }
  }
  return out;
}

std::vector<std::string> Database::units() const {
  Statement q(impl_->db.get(), "SELECT DISTINCT unit FROM runs ORDER BY unit", impl_->path);
  std::vector<std::string> out;
  while (q.step()) out.push_back(q.text(0));
  return out;
}

std::string Database::result_json(std::int64_t id) const {
  Statement q(impl_->db.get(), "SELECT result_json FROM runs WHERE id = ?1", impl_->path);
  q.bind(1, id);
  if (!q.step())
    throw Error(fmt::format("The history database {} holds no run {}.", impl_->path.string(), id));
  return q.text(0);
}

}  // namespace gyrocal::history
