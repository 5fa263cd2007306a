#pragma once
/// @file
/// Output files that appear whole or not at all.
///
/// Each file is written to a hidden temporary in the output folder and renamed to its final name
/// only by commit(), after every file has been written and closed without error. A run that
/// fails (or an OutputTransaction destroyed without commit) leaves no new or half-written file.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

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
    if (buffer_.size() > (1u << 20)) flush();
  }
  /// Appends a number in the shortest form that reads back to the same double.
  void number(double x) { fmt::format_to(std::back_inserter(buffer_), "{}", x); }
  void text(std::string_view s) { buffer_.append(s); }
  void character(char c) { buffer_.push_back(c); }
  void flush();
  /// Flushes and closes; throws std::runtime_error naming the file on any write error.
  void close();

 private:
  std::FILE* file_;
  std::filesystem::path path_;
  fmt::memory_buffer buffer_;
};

/// The folder that `file` is written in: its parent, or the current folder for a bare name.
[[nodiscard]] std::filesystem::path folder_of(const std::filesystem::path& file);

class OutputTransaction {
 public:
  /// Creates `folder` if needed. Throws std::runtime_error when it cannot.
  explicit OutputTransaction(std::filesystem::path folder);
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();

  /// Starts the file `name` (a plain file name) in the folder.
  OutputFile& open(const std::string& name);
  /// Writes `value` as the whole file `name`: indented by two, with a final newline.
  void write_json(const std::string& name, const nlohmann::json& value);
  /// Closes every file and renames it into place.
  void commit();

 private:
  struct Entry {
    std::filesystem::path temporary, final_path;
    std::unique_ptr<OutputFile> file;
  };
  std::filesystem::path folder_;
  std::vector<Entry> entries_;
  bool committed_ = false;
};

}  // namespace poundsim::io
