#pragma once
/// @file
/// Output files that appear whole or not at all.
///
/// Each file is written to a hidden temporary in the output folder and renamed to its final name
/// only by commit(), after every file has been written and closed without error. A run that
/// fails (or an OutputTransaction destroyed without commit) leaves no new or half-written file.
/// A run stopped by a signal leaves none either: the program's signal thread calls
/// abandon_all_outputs() before the signal ends the process.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/compile.h>
#include <fmt/format.h>
#include <nlohmann/json_fwd.hpp>

namespace poundsim::io {

/// A buffered text file inside an OutputTransaction.
class OutputFile {
 public:
  OutputFile(std::FILE* file, std::filesystem::path path) : file_(file), path_(std::move(path)) {}
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();

  template <typename... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(buffer_), format, std::forward<Args>(args)...);
    written();
  }
  /// Appends a number in the shortest form that reads back to the same double.
  void number(double x) {
    // A compiled format: the same shortest round-trip digits (fmt's Dragonbox) without parsing
    // "{}" at every number — a history row is mostly numbers, one per channel per step.
    fmt::format_to(fmt::appender(buffer_), FMT_COMPILE("{}"), x);
    written();
  }
  void text(std::string_view s) {
    buffer_.append(s);
    written();
  }
  void character(char c) { buffer_.push_back(c); }
  /// Appends `s` as one CSV field (RFC 4180): as it is, or — when it holds a comma, a double
  /// quote or a line break — in double quotes with every double quote doubled (CsvWriter's).
  void csv_field(std::string_view s);
  void flush();
  /// Flushes and closes; throws std::runtime_error naming the file on any write error.
  void close();

 private:
  /// Writes the buffer out once it holds a megabyte: a long history streams to its file instead
  /// of growing in memory.
  void written() {
    if (buffer_.size() > (1u << 20)) flush();
  }
  std::FILE* file_;
  std::filesystem::path path_;
  fmt::memory_buffer buffer_;
};

/// A CSV table (RFC 4180) written row by row into an OutputFile; every CSV poundsim writes goes
/// through it. Fields are separated by commas and each row ends with a line feed; text is quoted
/// only when it holds a comma, a double quote or a line break; a number is written in the
/// shortest form that reads back to the same double, an integer as an integer, a missing value
/// as an empty field.
class CsvWriter {
 public:
  explicit CsvWriter(OutputFile& file) : file_(file) {}
  CsvWriter& text(std::string_view s) {
    separate();
    file_.csv_field(s);
    return *this;
  }
  CsvWriter& number(double x) {
    separate();
    file_.number(x);
    return *this;
  }
  CsvWriter& integer(std::int64_t n) {
    separate();
    file_.print("{}", n);
    return *this;
  }
  CsvWriter& empty() {
    separate();
    return *this;
  }
  /// Text fields, e.g. a header's fixed names.
  CsvWriter& texts(std::initializer_list<std::string_view> fields) {
    for (const std::string_view f : fields) text(f);
    return *this;
  }
  void end_row() {
    file_.character('\n');
    first_ = true;
  }

 private:
  void separate() {
    if (!first_) file_.character(',');
    first_ = false;
  }
  OutputFile& file_;
  bool first_ = true;
};

/// The folder that `file` is written in: its parent, or the current folder for a bare name.
[[nodiscard]] std::filesystem::path folder_of(const std::filesystem::path& file);

/// One run at a time in an output folder. Holds an exclusive advisory lock (flock) on the folder
/// itself, so no lock file is ever left behind: the kernel releases the lock when the process
/// ends, however it ends. Locks taken by one process on the same folder share one lock, so a run
/// may open several transactions in its folder. Taking it also removes the hidden temporaries
/// (`.NAME.PID.tmp`) that a crashed run of a process no longer alive left in the folder. A folder
/// it created is removed again when the last lock on it ends and nothing was written there.
class OutputFolderLock {
 public:
  /// Creates `folder` if needed and locks it. Throws FolderBusy naming the folder and the process
  /// holding it when another process holds it, std::runtime_error when it cannot be created.
  explicit OutputFolderLock(const std::filesystem::path& folder);
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;
  ~OutputFolderLock();

 private:
  std::filesystem::path folder_;
  std::uint64_t device_ = 0, inode_ = 0;  ///< The folder's identity: its key among the process's locks.
  bool created_ = false;                   ///< Whether the first lock of the process created it.
};

/// Another process is writing into the output folder a run asked for.
class FolderBusy : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class OutputTransaction {
 public:
  /// Creates `folder` if needed and locks it (OutputFolderLock). Throws std::runtime_error when
  /// it cannot be created, FolderBusy when another process writes into it.
  explicit OutputTransaction(std::filesystem::path folder);
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();

  /// Starts the file `name` (a plain file name) in the folder.
  OutputFile& open(const std::string& name);
  /// Writes `value` as the whole file `name`: indented by two, with a final newline.
  void write_json(const std::string& name, const nlohmann::json& value);
  /// Closes every file and renames it into place: all of them, or none if the process is
  /// stopped meanwhile (abandon_all_outputs).
  void commit();

 private:
  friend void abandon_all_outputs() noexcept;
  struct Entry {
    std::filesystem::path temporary, final_path;
    std::unique_ptr<OutputFile> file;
  };
  std::filesystem::path folder_;
  OutputFolderLock lock_;
  std::vector<Entry> entries_;
  bool committed_ = false;
};

/// Removes the temporaries of every OutputTransaction of the process that has not committed, and
/// keeps any from opening a file or committing from then on (that thread blocks), so that no new
/// result appears, whole or in part. For the thread that handles SIGINT/SIGTERM just before it
/// ends the process (it is not async-signal-safe: never from a signal handler).
void abandon_all_outputs() noexcept;

}  // namespace poundsim::io
