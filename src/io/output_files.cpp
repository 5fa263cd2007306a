#include "poundsim/io/output_files.hpp"

#include <cerrno>
#include <cstring>
#include <mutex>
#include <set>
#include <stdexcept>
#include <system_error>

#include <unistd.h>

#include <nlohmann/json.hpp>

namespace poundsim::io {

namespace {

/// The transactions of the process that have not committed, for abandon_all_outputs(). Its
/// lock is held while a temporary is created or removed and while a transaction commits, so that
/// abandoning finds every temporary and never half a commit. Never destroyed: the signal thread
/// may use it while the main thread runs the static destructors.
struct Registry {
  std::mutex mutex;
  std::set<OutputTransaction*> open;
};
Registry& registry() {
  static auto* r = new Registry;
  return *r;
}

}  // namespace

OutputFile::~OutputFile() {
  if (file_ != nullptr) std::fclose(file_);
}

void OutputFile::flush() {
  if (buffer_.size() == 0) return;
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    throw std::runtime_error(
        fmt::format("{}: write failed: {}", path_.string(), std::strerror(errno)));
  }
  buffer_.clear();
}

void OutputFile::csv_field(std::string_view s) {
  if (s.find_first_of(",\"\n\r") == std::string_view::npos) {
    text(s);
    return;
  }
  character('"');
  for (const char c : s) {
    if (c == '"') character('"');
    character(c);
  }
  character('"');
}

void OutputFile::close() {
  if (file_ == nullptr) return;
  flush();
  const bool failed = std::ferror(file_) != 0;
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (failed || rc != 0) {
    throw std::runtime_error(fmt::format("{}: write failed", path_.string()));
  }
}

OutputTransaction::OutputTransaction(std::filesystem::path folder) : folder_(std::move(folder)) {
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec || !std::filesystem::is_directory(folder_)) {
    throw std::runtime_error(fmt::format("{}: cannot create the output folder{}{}",
                                         folder_.string(), ec ? ": " : "", ec.message()));
  }
  const std::lock_guard lock(registry().mutex);
  registry().open.insert(this);
}

OutputTransaction::~OutputTransaction() {
  const std::lock_guard lock(registry().mutex);
  registry().open.erase(this);
  if (committed_) return;
  for (Entry& e : entries_) {
    e.file.reset();
    std::error_code ec;
    std::filesystem::remove(e.temporary, ec);
  }
}

OutputFile& OutputTransaction::open(const std::string& name) {
  Entry e;
  e.final_path = folder_ / name;
  e.temporary = folder_ / fmt::format(".{}.{}.tmp", name, static_cast<long>(::getpid()));
  const std::lock_guard lock(registry().mutex);
  std::FILE* f = std::fopen(e.temporary.c_str(), "wb");
  if (f == nullptr) {
    throw std::runtime_error(
        fmt::format("{}: cannot create: {}", e.temporary.string(), std::strerror(errno)));
  }
  e.file = std::make_unique<OutputFile>(f, e.final_path);
  entries_.push_back(std::move(e));
  return *entries_.back().file;
}

std::filesystem::path folder_of(const std::filesystem::path& file) {
  return file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
}

void OutputTransaction::write_json(const std::string& name, const nlohmann::json& value) {
  OutputFile& f = open(name);
  f.text(value.dump(2));
  f.character('\n');
}

void OutputTransaction::commit() {
  for (Entry& e : entries_) e.file->close();
  const std::lock_guard lock(registry().mutex);
  for (Entry& e : entries_) {
    std::error_code ec;
    std::filesystem::rename(e.temporary, e.final_path, ec);
    if (ec) {
      throw std::runtime_error(
          fmt::format("{}: cannot move into place: {}", e.final_path.string(), ec.message()));
    }
  }
  committed_ = true;
}

void abandon_all_outputs() noexcept {
  // The lock is never released: the process is about to end, and no result may appear before.
  registry().mutex.lock();
  for (OutputTransaction* t : registry().open) {
    if (t->committed_) continue;
    for (const OutputTransaction::Entry& e : t->entries_) {
      // The file stays open (closing it could block on a full disk); its name goes.
      std::error_code ec;
      std::filesystem::remove(e.temporary, ec);
    }
  }
}

}  // namespace poundsim::io
