#include "poundsim/io/study_database.hpp"

#include <stdexcept>

#include <fmt/format.h>
#include <sqlite3.h>

#include "poundsim/error.hpp"

namespace poundsim::io {

namespace {

/// A prepared statement, finalised on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) {
      throw std::runtime_error(fmt::format("sqlite: {} ({})", sqlite3_errmsg(db), sql));
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& text) {
    check(sqlite3_bind_text(stmt_, i, text.c_str(), static_cast<int>(text.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bind(int i, long value) {
    check(sqlite3_bind_int64(stmt_, i, value));
    return *this;
  }
  Statement& bind(int i, double value) {
    check(sqlite3_bind_double(stmt_, i, value));
    return *this;
  }
  /// true while there is a row.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw std::runtime_error(fmt::format("sqlite: {}", sqlite3_errmsg(db_)));
  }
  [[nodiscard]] std::string text(int i) const {
    const auto* p = sqlite3_column_text(stmt_, i);
    return p != nullptr ? std::string(reinterpret_cast<const char*>(p)) : std::string();
  }
  [[nodiscard]] long integer(int i) const { return static_cast<long>(sqlite3_column_int64(stmt_, i)); }
  [[nodiscard]] double real(int i) const { return sqlite3_column_double(stmt_, i); }

 private:
  void check(int rc) const {
    if (rc != SQLITE_OK) throw std::runtime_error(fmt::format("sqlite: {}", sqlite3_errmsg(db_)));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

}  // namespace

StudyDatabase::StudyDatabase(const std::filesystem::path& file, const std::string& fingerprint,
                             const nlohmann::json& definition)
    : file_(file) {
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK) {
    const std::string message = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error(fmt::format("{}: cannot open the study database: {}", file.string(), message));
  }
  sqlite3_busy_timeout(db_, 10000);
  exec("PRAGMA journal_mode = WAL");
  exec("PRAGMA synchronous = NORMAL");
  exec("CREATE TABLE IF NOT EXISTS study (key TEXT PRIMARY KEY, value TEXT NOT NULL)");
  exec("CREATE TABLE IF NOT EXISTS points (id INTEGER PRIMARY KEY, parameters TEXT NOT NULL, "
       "status TEXT NOT NULL, error TEXT, metrics TEXT, run_time REAL)");
  exec("CREATE TABLE IF NOT EXISTS baselines (key TEXT PRIMARY KEY, metrics TEXT NOT NULL)");
  Statement get(db_, "SELECT value FROM study WHERE key = 'fingerprint'");
  if (get.step()) {
    if (get.text(0) != fingerprint) {
      throw InputError(fmt::format(
          "{}: this database holds the results of a different study (other input or parameters); "
          "choose another output folder or delete it",
          file.string()));
    }
  } else {
    Statement put(db_, "INSERT INTO study (key, value) VALUES ('fingerprint', ?1), ('definition', ?2)");
    put.bind(1, fingerprint).bind(2, definition.dump());
    put.step();
  }
}

StudyDatabase::StudyDatabase(const std::filesystem::path& file) : file_(file) {
  if (!std::filesystem::exists(file)) {
    throw InputError(fmt::format("{}: no such study database", file.string()));
  }
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw InputError(fmt::format("{}: cannot open the study database", file.string()));
  }
  try {
    Statement check(db_, "SELECT value FROM study WHERE key = 'definition'");
    if (!check.step()) throw InputError(fmt::format("{}: not a poundsim study database", file.string()));
  } catch (const std::runtime_error&) {
    throw InputError(fmt::format("{}: not a poundsim study database", file.string()));
  }
}

StudyDatabase::~StudyDatabase() { sqlite3_close(db_); }

void StudyDatabase::exec(const std::string& sql) const {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message != nullptr ? message : "error";
    sqlite3_free(message);
    throw std::runtime_error(fmt::format("{}: sqlite: {} ({})", file_.string(), text, sql));
  }
}

std::set<long> StudyDatabase::finished() const {
  const std::lock_guard lock(mutex_);
  std::set<long> ids;
  Statement s(db_, "SELECT id FROM points");
  while (s.step()) ids.insert(s.integer(0));
  return ids;
}

void StudyDatabase::record(long id, const nlohmann::json& parameters, const std::string& status,
                           const std::string& error, const nlohmann::json& metrics, double run_time) {
  const std::lock_guard lock(mutex_);
  Statement s(db_, "INSERT OR REPLACE INTO points (id, parameters, status, error, metrics, run_time) "
                   "VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
  s.bind(1, id).bind(2, parameters.dump()).bind(3, status).bind(4, error).bind(5, metrics.dump()).bind(6, run_time);
  s.step();
}

std::optional<nlohmann::json> StudyDatabase::baseline(const std::string& key) const {
  const std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT metrics FROM baselines WHERE key = ?1");
  s.bind(1, key);
  if (!s.step()) return std::nullopt;
  return nlohmann::json::parse(s.text(0));
}

void StudyDatabase::record_baseline(const std::string& key, const nlohmann::json& metrics) {
  const std::lock_guard lock(mutex_);
  Statement s(db_, "INSERT OR REPLACE INTO baselines (key, metrics) VALUES (?1, ?2)");
  s.bind(1, key).bind(2, metrics.dump());
  s.step();
}

std::vector<StudyDatabase::Row> StudyDatabase::rows() const {
  const std::lock_guard lock(mutex_);
  std::vector<Row> out;
  Statement s(db_, "SELECT id, parameters, status, error, metrics, run_time FROM points ORDER BY id");
  while (s.step()) {
    out.push_back(Row{s.integer(0), nlohmann::json::parse(s.text(1)), s.text(2), s.text(3),
                      nlohmann::json::parse(s.text(4)), s.real(5)});
  }
  return out;
}

nlohmann::json StudyDatabase::definition() const {
  const std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT value FROM study WHERE key = 'definition'");
  return s.step() ? nlohmann::json::parse(s.text(0)) : nlohmann::json{};
}

}  // namespace poundsim::io
