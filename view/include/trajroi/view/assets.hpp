#pragma once

// The page `trajroi view` serves (view/web/), compiled in by view/embed_assets.cmake.
#include <string>
#include <vector>

namespace trajroi::view {

struct EmbeddedFile {
  std::string name;  // "index.html", "view.js"
  std::string content;
};

[[nodiscard]] const std::vector<EmbeddedFile>& page_files();

}  // namespace trajroi::view
