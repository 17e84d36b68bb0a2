#include "harness/stop_signals.h"

#include <atomic>

namespace mcf {
namespace {

// Written by the handler and read by the loop (any thread may take the signal): a lock-free atomic
// is safe to use in a signal handler.
std::atomic<int> g_received{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_stop_signal(int sig) {
  int expected = 0;
  if (g_received.compare_exchange_strong(expected, sig)) return;
  // The second signal: the default action (termination), which signal() and raise() may take
  // inside a handler. The signal is blocked while its handler runs and delivered on return.
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

StopSignals::StopSignals() {
  g_received = 0;
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  // Restarted system calls: a signal during a write or a read is not an I/O error of the run.
  action.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &action, &previous_int_);
  ::sigaction(SIGTERM, &action, &previous_term_);
}

StopSignals::~StopSignals() {
  ::sigaction(SIGINT, &previous_int_, nullptr);
  ::sigaction(SIGTERM, &previous_term_, nullptr);
}

int StopSignals::received() {
  return g_received.load();
}

std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace mcf
