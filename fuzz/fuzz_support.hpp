#pragma once
/// @file
/// What the fuzz targets share: a scratch folder of the process's own, and the rule that decides
/// what a finding is. A poundsim::InputError is the reader's normal answer to bad input; any other
/// exception escaping a reader is a finding, as are crashes, sanitizer reports, timeouts and
/// oversized allocations (libFuzzer and the sanitizers catch those).

#include <cxxabi.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <typeinfo>

#include "poundsim/error.hpp"

namespace poundsim::fuzz {

/// This process's scratch folder: one per process, because libFuzzer may run several workers
/// (-jobs, -fork) at once. Removed at a normal exit; a crash leaves it in the temp folder.
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "poundsim-fuzz-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("poundsim fuzz: mkdtemp");
      std::abort();
    }
    return std::filesystem::path(pattern);
  }();
  // Registered after `dir` is built, so it runs before `dir` is destroyed.
  static const int cleanup = std::atexit([] {
    std::error_code ec;
    std::filesystem::remove_all(scratch_dir(), ec);
  });
  (void)cleanup;
  return dir;
}

/// Writes `data` to `path`, replacing it; aborts on failure (that is the harness's fault).
inline void write_file(const std::filesystem::path& path, std::string_view data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.close();
  if (!out) {
    std::fprintf(stderr, "poundsim fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

/// Prints what escaped and aborts, which libFuzzer records as a crash with its reproducer.
[[noreturn]] inline void finding(const char* mangled_type, const char* what) {
  int status = 0;
  const std::unique_ptr<char, void (*)(void*)> type(abi::__cxa_demangle(mangled_type, nullptr, nullptr, &status),
                                                    std::free);
  std::fprintf(stderr, "\n==poundsim fuzz== FINDING: an exception other than poundsim::InputError escaped: %s: %s\n",
               status == 0 && type ? type.get() : mangled_type, what);
  std::fflush(stderr);
  std::abort();
}

/// Runs `read`; an InputError is a normal outcome, anything else a finding. With
/// POUNDSIM_FUZZ_VERBOSE set, prints each outcome (to check what seeds or findings reach).
template <class Read>
void expect_only_input_errors(Read&& read) {
  static const bool verbose = std::getenv("POUNDSIM_FUZZ_VERBOSE") != nullptr;
  try {
    read();
    if (verbose) std::fprintf(stderr, "poundsim fuzz: read\n");
  } catch (const poundsim::InputError& e) {
    // The documented answer to bad input.
    if (verbose) std::fprintf(stderr, "poundsim fuzz: InputError: %s\n", e.what());
  } catch (const std::exception& e) {
    finding(typeid(e).name(), e.what());
  } catch (...) {
    finding("(not a std::exception)", "");
  }
}

}  // namespace poundsim::fuzz
