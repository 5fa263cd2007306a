#include "poundsim/io/output_files.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include <unistd.h>

#include <nlohmann/json.hpp>

namespace poundsim::io {

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
}

OutputTransaction::~OutputTransaction() {
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

}  // namespace poundsim::io
