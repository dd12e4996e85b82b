#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "trajroi/config/text_file.hpp"

namespace trajroi::cli {

// The whole file as text (the project's one reader); throws naming the path when it cannot be read.
using config::read_text_file;

// Writes `content` to a temporary file beside `path` and renames it over `path`, so readers
// never see a half-written file and a failure leaves any previous file untouched.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

}  // namespace trajroi::cli
