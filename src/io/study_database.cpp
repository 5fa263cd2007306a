#include "poundsim/io/study_database.hpp"

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <system_error>

#include <SQLiteCpp/Database.h>
#include <SQLiteCpp/Exception.h>
#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>
#include <fmt/format.h>
#include <sqlite3.h>

#include "poundsim/error.hpp"

namespace poundsim::io {

namespace {

/// The study databases open in the process, for close_all_before_exit(). Never destroyed: the
/// thread that handles a signal may use it while the main thread runs the static destructors.
struct Registry {
  std::mutex mutex;
  std::set<StudyDatabase*> open;
};
Registry& registry() {
  static auto* r = new Registry;
  return *r;
}

/// An SQLite failure as the error it is: a file that is not an SQLite database, or a damaged one,
/// is bad input (InputError); anything else (a full disk, an I/O error) fails the run.
[[noreturn]] void rethrow(const std::filesystem::path& file, const SQLite::Exception& e) {
  const int code = e.getErrorCode();
  if (code == SQLITE_NOTADB || code == SQLITE_CORRUPT) {
    throw InputError(fmt::format("{}: not an SQLite database, or a damaged one ({}); move it away or choose "
                                 "another output folder",
                                 file.string(), e.what()));
  }
  throw std::runtime_error(fmt::format("{}: sqlite: {}", file.string(), e.what()));
}

nlohmann::json parse(const std::filesystem::path& file, const std::string& text, const char* what) {
  nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
  if (value.is_discarded()) {
    throw InputError(fmt::format("{}: not a poundsim study database ({} is not JSON: {})", file.string(), what,
                                 text.substr(0, 60)));
  }
  return value;
}

/// A blob's length as SQLite takes it (an int): refused, not narrowed, past 2 GiB.
int blob_size(const std::filesystem::path& file, const std::string& bytes) {
  if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw std::runtime_error(fmt::format("{}: an evaluation of {} bytes is more than SQLite stores", file.string(), bytes.size()));
  }
  return static_cast<int>(bytes.size());
}

}  // namespace

StudyDatabase::StudyDatabase(const std::filesystem::path& file, const std::string& fingerprint,
                             const nlohmann::json& definition)
    : file_(file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) {
    throw InputError(fmt::format("{}: is a folder, not a study database", file.string()));
  }
  try {
    db_ = std::make_unique<SQLite::Database>(file.string(), SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE, 10000);
    // Anything the file holds is checked before the first write: a file that is not this study's
    // database stays as it was. An empty database (a new file) becomes one.
    bool empty = false;
    {
      SQLite::Statement tables(*db_, "SELECT count(*) FROM sqlite_master");
      tables.executeStep();
      empty = tables.getColumn(0).getInt64() == 0;
    }
    if (!empty) check_is_study(&fingerprint);
    db_->exec("PRAGMA journal_mode = WAL");
    db_->exec("PRAGMA synchronous = NORMAL");
    if (empty) {
      // One transaction: a kill leaves a study database or an empty one, nothing in between.
      SQLite::Transaction transaction(*db_);
      db_->exec("CREATE TABLE study (key TEXT PRIMARY KEY, value TEXT NOT NULL);"
                "CREATE TABLE points (id INTEGER PRIMARY KEY, parameters TEXT NOT NULL, status TEXT NOT NULL, "
                "error TEXT, metrics TEXT, run_time REAL);"
                "CREATE TABLE baselines (key TEXT PRIMARY KEY, metrics TEXT NOT NULL)");
      SQLite::Statement put(*db_, "INSERT INTO study (key, value) VALUES ('fingerprint', ?1), ('definition', ?2)");
      put.bind(1, fingerprint);
      put.bind(2, definition.dump());
      put.exec();
      transaction.commit();
    }
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
  enlist();
}

StudyDatabase::StudyDatabase(const std::filesystem::path& file) : file_(file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    throw InputError(fmt::format("{}: no such study database", file.string()));
  }
  if (std::filesystem::is_directory(file, ec)) {
    throw InputError(fmt::format("{}: is a folder, not a study database", file.string()));
  }
  try {
    // Only read, but not opened read-only: the last connection to close removes -wal and -shm
    // only if it may write. A file the system protects is still opened, read-only.
    db_ = std::make_unique<SQLite::Database>(file.string(), SQLite::OPEN_READWRITE, 10000);
    check_is_study(nullptr);
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
  enlist();
}

void StudyDatabase::check_is_study(const std::string* fingerprint) const {
  if (!db_->tableExists("study") || !db_->tableExists("points") || !db_->tableExists("baselines")) {
    throw InputError(fmt::format("{}: not a poundsim study database (it lacks the tables study, points and "
                                 "baselines); move it away or choose another output folder",
                                 file_.string()));
  }
  // A damaged page would otherwise surface in the middle of the run.
  SQLite::Statement check(*db_, "PRAGMA quick_check(1)");
  if (check.executeStep() && check.getColumn(0).getString() != "ok") {
    throw InputError(fmt::format("{}: a damaged study database ({}); move it away or choose another output folder",
                                 file_.string(), check.getColumn(0).getString()));
  }
  SQLite::Statement get(*db_, "SELECT value FROM study WHERE key = 'fingerprint'");
  if (!get.executeStep()) {
    throw InputError(fmt::format("{}: not a poundsim study database (no fingerprint)", file_.string()));
  }
  if (fingerprint != nullptr && get.getColumn(0).getString() != *fingerprint) {
    throw InputError(fmt::format(
        "{}: this database holds the results of a different study (other input or parameters); "
        "choose another output folder or delete it",
        file_.string()));
  }
}

void StudyDatabase::enlist() {
  const std::lock_guard lock(registry().mutex);
  registry().open.insert(this);
}

StudyDatabase::~StudyDatabase() {
  const std::lock_guard lock(registry().mutex);
  registry().open.erase(this);
}

void StudyDatabase::close_all_before_exit() noexcept {
  // Neither lock is released: the process is about to end, and nothing may use a closed database.
  registry().mutex.lock();
  for (StudyDatabase* db : registry().open) {
    db->mutex_.lock();
    db->db_.reset();
  }
}

std::set<long> StudyDatabase::finished() const {
  const std::lock_guard lock(mutex_);
  std::set<long> ids;
  try {
    SQLite::Statement s(*db_, "SELECT id FROM points");
    while (s.executeStep()) ids.insert(s.getColumn(0).getInt64());
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
  return ids;
}

void StudyDatabase::record(long id, const nlohmann::json& parameters, const std::string& status,
                           const std::string& error, const nlohmann::json& metrics, double run_time) {
  const std::lock_guard lock(mutex_);
  try {
    SQLite::Statement s(*db_, "INSERT OR REPLACE INTO points (id, parameters, status, error, metrics, run_time) "
                              "VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
    s.bind(1, static_cast<std::int64_t>(id));
    s.bind(2, parameters.dump());
    s.bind(3, status);
    s.bind(4, error);
    s.bind(5, metrics.dump());
    s.bind(6, run_time);
    s.exec();
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
}

std::optional<nlohmann::json> StudyDatabase::baseline(const std::string& key) const {
  const std::lock_guard lock(mutex_);
  try {
    SQLite::Statement s(*db_, "SELECT metrics FROM baselines WHERE key = ?1");
    s.bind(1, key);
    if (!s.executeStep()) return std::nullopt;
    return parse(file_, s.getColumn(0).getString(), "a baseline's metrics");
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
}

void StudyDatabase::record_baseline(const std::string& key, const nlohmann::json& metrics) {
  const std::lock_guard lock(mutex_);
  try {
    SQLite::Statement s(*db_, "INSERT OR REPLACE INTO baselines (key, metrics) VALUES (?1, ?2)");
    s.bind(1, key);
    s.bind(2, metrics.dump());
    s.exec();
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
}

void StudyDatabase::record_evaluation(const std::string& design, const std::string& result) {
  const std::lock_guard lock(mutex_);
  try {
    // Plain INSERT: a design is computed once, so a second row for it would be a defect.
    ensure_evaluations_table();
    SQLite::Statement s(*db_, "INSERT INTO evaluations (design, result) VALUES (?1, ?2)");
    s.bind(1, design.data(), blob_size(file_, design));
    s.bind(2, result.data(), blob_size(file_, result));
    s.exec();
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
}

void StudyDatabase::ensure_evaluations_table() {
  // Only an optimisation's database has the table: a study's stays as it was. Made once, not
  // asked again at every evaluation recorded.
  if (has_evaluations_table_) return;
  db_->exec("CREATE TABLE IF NOT EXISTS evaluations (design BLOB PRIMARY KEY, result BLOB NOT NULL)");
  has_evaluations_table_ = true;
}

std::vector<std::pair<std::string, std::string>> StudyDatabase::evaluations() {
  const std::lock_guard lock(mutex_);
  std::vector<std::pair<std::string, std::string>> out;
  try {
    ensure_evaluations_table();
    SQLite::Statement s(*db_, "SELECT design, result FROM evaluations ORDER BY rowid");
    while (s.executeStep()) {
      const SQLite::Column design = s.getColumn(0), result = s.getColumn(1);
      out.emplace_back(std::string(static_cast<const char*>(design.getBlob()), static_cast<std::size_t>(design.getBytes())),
                       std::string(static_cast<const char*>(result.getBlob()), static_cast<std::size_t>(result.getBytes())));
    }
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
  return out;
}

std::vector<StudyDatabase::Row> StudyDatabase::rows() const {
  const std::lock_guard lock(mutex_);
  std::vector<Row> out;
  try {
    SQLite::Statement s(*db_, "SELECT id, parameters, status, error, metrics, run_time FROM points ORDER BY id");
    while (s.executeStep()) {
      out.push_back(Row{s.getColumn(0).getInt64(), parse(file_, s.getColumn(1).getString(), "a point's parameters"),
                        s.getColumn(2).getString(), s.getColumn(3).getString(),
                        parse(file_, s.getColumn(4).getString(), "a point's metrics"), s.getColumn(5).getDouble()});
    }
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
  return out;
}

nlohmann::json StudyDatabase::definition() const {
  const std::lock_guard lock(mutex_);
  try {
    SQLite::Statement s(*db_, "SELECT value FROM study WHERE key = 'definition'");
    return s.executeStep() ? parse(file_, s.getColumn(0).getString(), "the study's definition") : nlohmann::json{};
  } catch (const SQLite::Exception& e) {
    rethrow(file_, e);
  }
}

}  // namespace poundsim::io
