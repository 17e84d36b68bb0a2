#pragma once
// Results are never half-written: write to a temporary file beside the target, then rename
// (atomic on POSIX within one file system).

#include <string>

namespace mcf {

/// Writes `content` to `path` atomically; creates parent folders. Throws std::runtime_error
/// naming the path on failure. The temporary file is `PATH.tmp.PID`; one a killed writer left
/// (its process no longer exists on this machine) is removed by the next write of `path`.
void write_file_atomic(const std::string& path, const std::string& content);

/// Removes `PATH.tmp.PID` files beside `path` whose PID is not a live process on this machine
/// (left by a writer that was killed between writing and renaming). Temporary files of other
/// targets and of live processes are left alone. Returns how many were removed; never throws.
int remove_stale_temporaries(const std::string& path);

}  // namespace mcf
