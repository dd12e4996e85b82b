#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace trajroi::test {

// The folder of third-party captures, from TRAJROI_DATA_DIR (set by CMake on every test).
inline std::filesystem::path data_dir() {
  const char* dir = std::getenv("TRAJROI_DATA_DIR");
  return dir != nullptr ? std::filesystem::path(dir) : std::filesystem::path();
}

inline bool running_in_ci() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string_view(ci) == "true";
}

// The whole file, bytes as they are; throws naming the file when it cannot be read.
inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::string bytes(static_cast<std::size_t>(in.tellg()), '\0');
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

// A parameterised test's name for a data file: the file's base name, its characters other
// than letters and digits made '_' (gtest's rule for names), e.g. "ublox_zed_f9p_log".
inline std::string file_test_name(std::string_view path) {
  std::string name(path.substr(path.rfind('/') + 1));
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

// INSTANTIATE_TEST_SUITE_P's name generator for parameters that are a data file's path or
// name it in their `file`.
struct FileTestName {
  template <class T>
  std::string operator()(const ::testing::TestParamInfo<T>& info) const {
    if constexpr (std::is_convertible_v<T, std::string_view>) {
      return file_test_name(info.param);
    } else {
      return file_test_name(info.param.file);
    }
  }
};

// A path in the test's temporary folder that no other test process uses: ctest runs tests in
// parallel, each in its own process, so a fixed name would be shared between them.
inline std::filesystem::path scratch_path(std::string_view name) {
  return std::filesystem::path(::testing::TempDir()) / (std::to_string(::getpid()) + "_" + std::string(name));
}

}  // namespace trajroi::test

// Resolves `relative` inside the data folder into `path_var`. When the file is missing the
// test is skipped with the reason, except under CI (CI=true), where a missing capture fails.
#define TRAJROI_REQUIRE_DATA(path_var, relative)                                                                \
  const std::filesystem::path path_var = ::trajroi::test::data_dir() / (relative);                              \
  if (!std::filesystem::exists(path_var)) {                                                                     \
    if (::trajroi::test::running_in_ci()) {                                                                     \
      FAIL() << "test data missing under CI: " << path_var << " (TRAJROI_DATA_DIR='"                            \
             << ::trajroi::test::data_dir().string() << "')";                                                   \
    }                                                                                                           \
    GTEST_SKIP() << "test data not found: " << path_var << " (set TRAJROI_DATA_DIR to the shared data folder)"; \
  }
