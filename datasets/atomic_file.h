#pragma once
// Results are never half-written: write to a temporary file beside the target, then rename
// (atomic on POSIX within one file system).

#include <string>

namespace mcf {

/// Writes `content` to `path` atomically; creates parent folders. Throws std::runtime_error
/// naming the path on failure.
void write_file_atomic(const std::string& path, const std::string& content);

}  // namespace mcf
