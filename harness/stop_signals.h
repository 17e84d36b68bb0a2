#pragma once
// SIGINT (Ctrl-C) and SIGTERM (what Slurm and other schedulers send at a time limit, before a
// SIGKILL some seconds later) as a request to stop: the handler only records the signal, and the
// loop that installed it checks `StopSignals::received()` where stopping loses nothing but the
// work in progress (between a flow's steps, between cells). A second signal ends the process at
// once, as if no handler were installed, so a run that does not get to its next check can still be
// stopped from the keyboard.

#include <csignal>
#include <string>

namespace mcf {

/// Installs the handlers for SIGINT and SIGTERM while it lives; restores the previous ones when
/// destroyed. One at a time per process.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// The first of the two signals received since the handlers were installed, or 0.
  static int received();

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

/// "SIGINT", "SIGTERM", else "signal N".
std::string signal_name(int signal);

}  // namespace mcf
