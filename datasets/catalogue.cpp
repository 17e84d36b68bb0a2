// Catalogue of real models from libcgal-demo's data.tar.gz. A model is extracted from the
// archive on first use into $MCFBENCH_CACHE/models and reused afterwards.

#include "datasets/catalogue.h"

#include "datasets/mesh_error.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

extern char** environ;

namespace mcf {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string>& model_names() {
  // Checked by the catalogue test to load and validate (manifold, no degenerate faces).
  static const std::vector<std::string> names = {"armadillo",
                                                 "bunny00",
                                                 "refined_elephant",
                                                 "mannequin-devil",
                                                 "knot1",
                                                 "knot2",
                                                 "man",
                                                 "elephant",
                                                 "camel",
                                                 "cow",
                                                 "dino",
                                                 "homer",
                                                 "bull",
                                                 "triceratops"};
  return names;
}

fs::path cache_dir() {
  if (const char* c = std::getenv("MCFBENCH_CACHE"); c && *c) return fs::path(c);
  const char* home = std::getenv("HOME");
  return fs::path(home && *home ? home : "/tmp") / ".cache" / "mcfbench";
}

// Where Debian puts the archive, then where scripts/setup.sh unpacks the .deb.
std::vector<fs::path> archive_candidates() {
  return {fs::path("/usr/share/doc/libcgal-dev/data.tar.gz"),
          cache_dir() / "cgal-demo" / "usr" / "share" / "doc" / "libcgal-dev" / "data.tar.gz"};
}

// Runs argv without a shell (model names never get interpreted); returns the exit status.
int run_process(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::vector<std::string> catalogue_models() {
  return model_names();
}

std::string catalogue_path(const std::string& model) {
  const auto& names = model_names();
  if (std::find(names.begin(), names.end(), model) == names.end()) {
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
    throw MeshError("cgal:" + model + ": unknown catalogue model (known: " + known + ")");
  }
  const fs::path models = cache_dir() / "models";
  const fs::path target = models / (model + ".off");
  std::error_code ec;
  if (fs::is_regular_file(target, ec)) return target.string();

  fs::path archive;
  std::string tried;
  for (const auto& c : archive_candidates()) {
    tried += (tried.empty() ? "" : ", ") + c.string();
    if (archive.empty() && fs::is_regular_file(c, ec)) archive = c;
  }
  if (archive.empty())
    throw MeshError("cgal:" + model + ": libcgal-demo's data.tar.gz not found (tried " + tried +
                    "); run scripts/setup.sh");

  // Extract into a private temporary folder, then rename into place: concurrent runs (sharded
  // benchmark jobs) never see a half-written file, and the last rename simply wins.
  fs::create_directories(models, ec);
  static std::atomic<unsigned> counter{0};
  const fs::path tmp = models / (".extract-" + model + "-" + std::to_string(::getpid()) + "-" +
                                 std::to_string(counter++));
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp, ec);
  if (ec)
    throw MeshError("cgal:" + model + ": cannot create " + tmp.string() + ": " + ec.message());
  const std::string member = "data/meshes/" + model + ".off";
  const int rc = run_process({"tar", "-xzf", archive.string(), "-C", tmp.string(), member});
  const fs::path extracted = tmp / member;
  if (rc != 0 || !fs::is_regular_file(extracted, ec)) {
    fs::remove_all(tmp, ec);
    throw MeshError("cgal:" + model + ": could not extract " + member + " from " +
                    archive.string() + " (tar exit status " + std::to_string(rc) + ")");
  }
  fs::rename(extracted, target, ec);
  std::error_code ignore;
  fs::remove_all(tmp, ignore);
  if (ec)
    throw MeshError("cgal:" + model + ": cannot move the extracted model to " + target.string() +
                    ": " + ec.message());
  return target.string();
}

}  // namespace mcf
