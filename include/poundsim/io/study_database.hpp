#pragma once
/// @file
/// The results of a parametric study in an SQLite database, written point by point as they
/// finish, so that a study that is killed and run again skips the finished points and loses none.
///
/// Tables:
///
///     study(key TEXT PRIMARY KEY, value TEXT)        definition: "fingerprint", "definition"
///     points(id INTEGER PRIMARY KEY, parameters TEXT, status TEXT, error TEXT,
///            metrics TEXT, run_time REAL)            one row per finished point (JSON texts)
///     baselines(key TEXT PRIMARY KEY, metrics TEXT)  bare-pounding references, shared by points
///
/// Each row is its own transaction (journal_mode = WAL, synchronous = NORMAL): a kill loses at
/// most the points still running.

#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

struct sqlite3;

namespace poundsim::io {

class StudyDatabase {
 public:
  /// Opens (creating if needed) `file`. A database made for another study — a different
  /// `fingerprint` — is refused with InputError naming the file. Throws std::runtime_error when
  /// SQLite fails.
  StudyDatabase(const std::filesystem::path& file, const std::string& fingerprint,
                const nlohmann::json& definition);
  /// Opens an existing database read-only (for export). Throws InputError if it is not a study.
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

 private:
  void exec(const std::string& sql) const;
  sqlite3* db_ = nullptr;
  std::filesystem::path file_;
  mutable std::mutex mutex_;
};

}  // namespace poundsim::io
