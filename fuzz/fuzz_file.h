#pragma once
// The readers take paths only: a fuzz target writes its input to a file of its own (one per
// process, in the temporary folder), with the extension that picks the reader, and reads that.

#include <unistd.h>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace mcf::fuzz {

/// Writes the input to this process's file ending in `extension` (".off", ...) and returns its
/// path; aborts if the file cannot be written, which is no finding of the reader.
inline std::string input_file(const std::uint8_t* data, std::size_t size, const char* extension) {
  static const std::string base =
      (std::filesystem::temp_directory_path() / ("mcfbench_fuzz_" + std::to_string(::getpid())))
          .string();
  const std::string path = base + extension;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr || std::fwrite(data, 1, size, f) != size || std::fclose(f) != 0) {
    std::perror(path.c_str());
    std::abort();
  }
  return path;
}

}  // namespace mcf::fuzz
