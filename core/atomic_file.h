#pragma once
// Results are never half-written: write to a temporary file beside the target, then rename
// (atomic on POSIX within one file system). Neither are they lost to a crash of the machine (power
// loss, kernel panic, a cluster node going down): the temporary file's data reach the disk before
// the rename, and the folder's entry after it (fsync both; rename alone orders nothing on disk, so
// ext4 or XFS could keep the new name of an empty file).

#include <filesystem>
#include <string>

namespace mcf {

/// Writes `content` to `path` atomically; creates parent folders. Throws std::runtime_error
/// naming the path on failure. The temporary file is `PATH.tmp.HOST.PID`: named by machine and
/// process, so writers of one path on several machines sharing a file system (two jobs of a
/// cluster) never write the same temporary file. One a killed writer of this machine left is
/// removed by the next write of `path` here.
void write_file_atomic(const std::string& path, const std::string& content);

/// The `HOST` of this machine's temporary files: its host name, with any character other than
/// letters, digits, '-' and '_' replaced by '_' (so the PID stays the part after the last dot).
std::string temporary_host_name();

/// Flushes a file's data, or a folder's entries, to the disk (fsync). Throws std::runtime_error
/// naming the path if the file cannot be opened or the disk reports an error; a file system that
/// cannot sync a folder (EINVAL, as some network and FUSE file systems answer) is not an error.
void sync_to_disk(const std::filesystem::path& path);

/// Moves the written temporary file `tmp` onto `target` durably: syncs `tmp`, renames it, syncs the
/// folder. On failure removes `tmp` and throws std::runtime_error naming `target`.
void publish_durably(const std::filesystem::path& tmp, const std::filesystem::path& target);

/// Removes this machine's temporary files of `path` (`PATH.tmp.HOST.PID` with this HOST, and the
/// older `PATH.tmp.PID`) whose PID is not a live process here: left by a writer that was killed
/// between writing and renaming. Temporary files of other targets, of live processes and of
/// other machines (whose processes cannot be seen from here) are left alone. Returns how many
/// were removed; never throws.
int remove_stale_temporaries(const std::string& path);

}  // namespace mcf
