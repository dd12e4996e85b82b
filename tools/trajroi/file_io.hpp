#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace trajroi::cli {

// The whole file as text; throws std::runtime_error naming the path when it cannot be read.
[[nodiscard]] std::string read_text_file(const std::filesystem::path& path);

// Writes `content` to a temporary file beside `path` and renames it over `path`, so readers
// never see a half-written file and a failure leaves any previous file untouched.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

}  // namespace trajroi::cli
