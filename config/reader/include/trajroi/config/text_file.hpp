#pragma once

// The project's one "read a whole file" (configuration, trajectories, scenarios, points).
#include <filesystem>
#include <string>

namespace trajroi::config {

// The file's bytes. Throws ConfigError naming the path and the system's reason when it
// cannot be opened or read.
[[nodiscard]] std::string read_text_file(const std::filesystem::path& path);

}  // namespace trajroi::config
