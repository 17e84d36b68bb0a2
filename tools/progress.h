#pragma once
// One-line progress on stderr ("step 40/100  12.3 s  left 18.5 s"), only when stderr is a
// terminal so logs and CI output stay clean.

#include <chrono>
#include <string>

namespace mcf {

class Progress {
 public:
  Progress(std::string what, long long total);
  ~Progress();
  void update(long long done, const std::string& extra = "");
  void finish();

 private:
  std::string what_;
  long long total_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace mcf
