#pragma once
/// @file
/// The results of a parametric study (or the evaluations of an optimisation) in an SQLite
/// database, written point by point as they finish, so that a study that is killed and run again
/// skips the finished points and loses none.
///
/// Tables:
///
///     study(key TEXT PRIMARY KEY, value TEXT)        definition: "fingerprint", "definition"
///     points(id INTEGER PRIMARY KEY, parameters TEXT, status TEXT, error TEXT,
///            metrics TEXT, run_time REAL)            one row per finished point (JSON texts)
///     baselines(key TEXT PRIMARY KEY, metrics TEXT)  bare-pounding references, shared by points
///     evaluations(design BLOB PRIMARY KEY,           an optimisation's evaluations (its database
///                 result BLOB)                       only): the design vector and its outcome,
///                                                    as CBOR (every double to the bit)
///
/// Each row is its own transaction (journal_mode = WAL, synchronous = NORMAL): a kill loses at
/// most the points still running.
///
/// The connection is closed by the destructor on every path, a refusal included, so that SQLite
/// removes its -wal and -shm files; a file that is not a study database is refused before
/// anything is written to it. Runs on SQLiteCpp (RAII connection, statements and transactions).

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace SQLite {
class Database;
}

namespace poundsim::io {

class StudyDatabase {
 public:
  /// Opens (creating if needed) `file`. Refused with InputError naming the file: a database made
  /// for another study (a different `fingerprint`), an SQLite database of another program, a file
  /// that is not an SQLite database or is damaged, a folder. Throws std::runtime_error naming the
  /// file when SQLite fails otherwise (e.g. the disk is full).
  StudyDatabase(const std::filesystem::path& file, const std::string& fingerprint,
                const nlohmann::json& definition);
  /// Opens an existing study database to read it (for export); it is never created. Throws
  /// InputError when it is missing or is not a study database, as above.
  explicit StudyDatabase(const std::filesystem::path& file);
  ~StudyDatabase();
  StudyDatabase(const StudyDatabase&) = delete;
  StudyDatabase& operator=(const StudyDatabase&) = delete;

  /// Ids of the points already finished (done or failed).
  [[nodiscard]] std::set<long> finished() const;
  /// Records one point. Thread-safe.
  void record(long id, const nlohmann::json& parameters, const std::string& status,
              const std::string& error, const nlohmann::json& metrics, double run_time);
  /// A stored baseline, if any. Thread-safe.
  [[nodiscard]] std::optional<nlohmann::json> baseline(const std::string& key) const;
  void record_baseline(const std::string& key, const nlohmann::json& metrics);

  /// Records an optimisation's evaluation: the design and its outcome, opaque bytes to the
  /// database. A design recorded before is refused (std::runtime_error): none is computed twice.
  /// Thread-safe.
  void record_evaluation(const std::string& design, const std::string& result);
  /// Every evaluation recorded, (design, result), in the order recorded (the table is made
  /// when the database has none).
  [[nodiscard]] std::vector<std::pair<std::string, std::string>> evaluations();

  struct Row {
    long id;
    nlohmann::json parameters;
    std::string status, error;
    nlohmann::json metrics;
    double run_time;
  };
  /// Every point, by id.
  [[nodiscard]] std::vector<Row> rows() const;
  [[nodiscard]] nlohmann::json definition() const;
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

  /// Closes every study database open in the process, each under its lock, and keeps them closed
  /// and locked: a thread that then uses one blocks. SQLite checkpoints and removes the -wal and
  /// -shm files, so a run stopped by a signal leaves a database that is one whole file. For the
  /// thread that handles SIGINT/SIGTERM just before it ends the process (not async-signal-safe:
  /// never from a signal handler).
  static void close_all_before_exit() noexcept;

 private:
  /// Refuses (InputError) a file that is not a study database; `fingerprint` null: any study.
  void check_is_study(const std::string* fingerprint) const;
  void enlist();
  void ensure_evaluations_table();
  bool has_evaluations_table_ = false;
  std::filesystem::path file_;
  std::unique_ptr<SQLite::Database> db_;
  mutable std::mutex mutex_;
};

}  // namespace poundsim::io
