#include "poundsim/io/output_files.hpp"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
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

void create_folder(const std::filesystem::path& folder) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec || !std::filesystem::is_directory(folder)) {
    throw std::runtime_error(fmt::format("{}: cannot create the output folder{}{}", folder.string(), ec ? ": " : "",
                                         ec.message()));
  }
}

/// The process holding a flock on the file (dev, ino), from /proc/locks (Linux); 0 if unknown.
long flock_holder(dev_t dev, ino_t ino) {
  std::ifstream locks("/proc/locks");
  std::string line;
  const std::string where =
      fmt::format("{:02x}:{:02x}:{}", major(dev), minor(dev), static_cast<unsigned long long>(ino));
  while (std::getline(locks, line)) {
    // "1: FLOCK  ADVISORY  WRITE 12345 fd:01:6291461 0 EOF"
    std::istringstream fields(line);
    std::string number, type, mode, access, device;
    long pid = 0;
    if (!(fields >> number >> type)) continue;
    if (type == "->") fields >> type;  // a waiter, "1: -> FLOCK ..."
    if (type == "FLOCK" && fields >> mode >> access >> pid >> device && device == where) return pid;
  }
  return 0;
}

/// Whether `name` is a hidden temporary of OutputTransaction (".NAME.PID.tmp") written by a
/// process that is no longer running.
bool is_stale_temporary(const std::string& name) {
  if (name.size() < 7 || name.front() != '.' || !name.ends_with(".tmp")) return false;
  const std::string stem = name.substr(0, name.size() - 4);
  const std::size_t dot = stem.rfind('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == stem.size()) return false;
  long pid = 0;
  const char* first = stem.data() + dot + 1;
  const auto [end, error] = std::from_chars(first, stem.data() + stem.size(), pid);
  if (error != std::errc{} || end != stem.data() + stem.size() || pid <= 0) return false;
  return pid != static_cast<long>(::getpid()) && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

void remove_stale_temporaries(const std::filesystem::path& folder) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (is_stale_temporary(it->path().filename().string())) {
      std::error_code ignored;
      std::filesystem::remove(it->path(), ignored);
    }
  }
}

/// The folders this process holds locked, by device and inode, with how many hold each.
struct FolderLocks {
  std::mutex mutex;
  std::map<std::pair<std::uint64_t, std::uint64_t>, std::pair<int, int>> held;  ///< → (descriptor, holders)
};
FolderLocks& folder_locks() {
  static auto* locks = new FolderLocks;
  return *locks;
}

}  // namespace

OutputFolderLock::OutputFolderLock(const std::filesystem::path& folder) : folder_(folder) {
  std::error_code absent;
  const bool existed = std::filesystem::exists(folder, absent);
  create_folder(folder);
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    throw std::runtime_error(fmt::format("{}: cannot open the output folder: {}", folder.string(), std::strerror(errno)));
  }
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error = errno;
    ::close(fd);
    throw std::runtime_error(fmt::format("{}: cannot read the output folder: {}", folder.string(), std::strerror(error)));
  }
  FolderLocks& locks = folder_locks();
  const std::lock_guard guard(locks.mutex);
  const std::pair<std::uint64_t, std::uint64_t> key{info.st_dev, info.st_ino};
  if (auto it = locks.held.find(key); it != locks.held.end()) {
    ::close(fd);
    ++it->second.second;
  } else {
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      ::close(fd);
      if (error != EWOULDBLOCK) {
        throw std::runtime_error(fmt::format("{}: cannot lock the output folder: {}", folder.string(), std::strerror(error)));
      }
      const long holder = flock_holder(info.st_dev, info.st_ino);
      throw FolderBusy(fmt::format(
          "{}: another run is writing into this output folder ({}); wait for it to end, or give another --out",
          folder.string(), holder > 0 ? fmt::format("poundsim process {}", holder) : std::string("another process")));
    }
    locks.held.emplace(key, std::pair{fd, 1});
    remove_stale_temporaries(folder);
    created_ = !existed;
  }
  device_ = key.first;
  inode_ = key.second;
}

OutputFolderLock::~OutputFolderLock() {
  FolderLocks& locks = folder_locks();
  const std::lock_guard guard(locks.mutex);
  if (auto it = locks.held.find({device_, inode_}); it != locks.held.end() && --it->second.second == 0) {
    if (created_) {
      std::error_code not_empty;  // a folder that holds results stays
      std::filesystem::remove(folder_, not_empty);
    }
    ::close(it->second.first);  // releases the flock
    locks.held.erase(it);
  }
}

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

OutputTransaction::OutputTransaction(std::filesystem::path folder) : folder_(std::move(folder)), lock_(folder_) {
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
