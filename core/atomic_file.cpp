#include "core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace mcf {

namespace fs = std::filesystem;

std::string temporary_host_name() {
  static const std::string name = [] {
    char buffer[256] = {};
    std::string host = ::gethostname(buffer, sizeof buffer - 1) == 0 ? buffer : "";
    if (host.empty()) host = "localhost";
    for (char& ch : host)
      if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_') ch = '_';
    return host;
  }();
  return name;
}

int remove_stale_temporaries(const std::string& path) {
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + ".tmp.";
  int removed = 0;
  std::error_code ec;
  fs::directory_iterator it(dir, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    // HOST.PID, or PID alone (written before temporary files named their machine: this one's).
    std::string digits = name.substr(prefix.size());
    if (const auto dot = digits.rfind('.'); dot != std::string::npos) {
      if (digits.substr(0, dot) != temporary_host_name()) continue;
      digits = digits.substr(dot + 1);
    }
    if (digits.empty() || digits.size() > 9 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      continue;
    const pid_t pid = pid_t(std::stol(digits));
    // Only a process that is certainly gone (ESRCH): a live one (EPERM included) may be writing.
    // The check is local, hence only this machine's files: on a shared file system a writer on
    // another machine would look dead.
    if (pid <= 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    std::error_code rm;
    if (fs::remove(it->path(), rm)) ++removed;
  }
  return removed;
}

void sync_to_disk(const fs::path& path) {
  // fsync on a read-only descriptor flushes the file's (or folder's) data all the same: it acts on
  // the inode, so a file another stream wrote and closed needs no descriptor of its writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    throw std::runtime_error(path.string() + ": cannot open to sync: " + std::strerror(errno));
  int rc;
  do rc = ::fsync(fd);
  while (rc != 0 && errno == EINTR);
  const int sync_errno = errno;
  ::close(fd);
  if (rc != 0 && !(sync_errno == EINVAL && fs::is_directory(path)))
    throw std::runtime_error(path.string() + ": sync to disk failed: " + std::strerror(sync_errno));
}

void publish_durably(const fs::path& tmp, const fs::path& target) {
  std::error_code ec;
  try {
    sync_to_disk(tmp);
  } catch (const std::exception& e) {
    fs::remove(tmp, ec);
    throw std::runtime_error(target.string() + ": " + e.what());
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(target.string() + ": cannot rename temporary file: " + ec.message());
  }
  sync_to_disk(target.has_parent_path() ? target.parent_path() : fs::path("."));
}

void write_file_atomic(const std::string& path, const std::string& content) {
  const fs::path target(path);
  if (target.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec)
      throw std::runtime_error(path + ": cannot create the folder " +
                               target.parent_path().string() + ": " + ec.message());
  }
  remove_stale_temporaries(path);
  const fs::path tmp =
      target.string() + ".tmp." + temporary_host_name() + "." + std::to_string(::getpid());
  // POSIX calls rather than a stream: the message names the cause the system gave (no space left
  // on device, read-only file system, quota exceeded), which a stream does not keep.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0)
    throw std::runtime_error(path + ": cannot create " + tmp.string() + ": " +
                             std::strerror(errno));
  const char* data = content.data();
  size_t left = content.size();
  int write_errno = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      write_errno = n < 0 ? errno : EIO;
      break;
    }
    data += n;
    left -= size_t(n);
  }
  if (::close(fd) != 0 && write_errno == 0 && errno != EINTR) write_errno = errno;
  if (write_errno != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(path + ": write failed: " + std::strerror(write_errno));
  }
  publish_durably(tmp, target);
}

}  // namespace mcf
