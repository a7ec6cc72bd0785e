#include "interrupt.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <iostream>

#include "progress.h"

namespace semsegmap::app {

namespace {

std::atomic<bool> g_stop{false};
bool g_keep_outputs = false;

// Async-signal-safe only: an atomic store, write(2) and _exit(2).
extern "C" void onInterrupt(int) {
  if (g_stop.exchange(true)) {
    static const char kNow[] = "\nsemsegmap: interrupted again: exiting at once\n";
    const ssize_t ignored = ::write(STDERR_FILENO, kNow, sizeof kNow - 1);
    (void)ignored;
    ::_exit(kExitInterrupted);
  }
}

}  // namespace

void installInterruptHandler() {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  // Reads of the data restart instead of failing with EINTR: the frame in hand finishes.
  action.sa_flags = SA_RESTART;
  for (const int signal : {SIGINT, SIGTERM}) {
    // A signal the process was started deaf to (nohup, a background job of a script, whose
    // shell ignores Ctrl-C for it) stays ignored: the terminal's Ctrl-C is not meant for it.
    struct sigaction before {};
    if (sigaction(signal, nullptr, &before) == 0 && before.sa_handler == SIG_IGN) continue;
    sigaction(signal, &action, nullptr);
  }
}

StopToken stopToken() {
  return StopToken(g_stop);
}

bool stopRequested() {
  return g_stop.load(std::memory_order_relaxed);
}

int interruptedRun(const std::string& command, size_t done, size_t total,
                   const std::string& written) {
  return interruptedWork(
      command, "after " + std::to_string(done) + " of " + std::to_string(total) + " frames",
      done > 0 ? written + " holds the " + std::to_string(done) + " frames done" : "");
}

int interruptedWork(const std::string& command, const std::string& where, const std::string& kept) {
  endProgressLine();
  g_keep_outputs = !kept.empty();
  std::cerr << "semsegmap " << command << ": interrupted " << where << "; "
            << (kept.empty() ? std::string("nothing written") : kept) << "\n";
  return kExitInterrupted;
}

int interruptedStages(const std::string& command, const StageProgress& progress,
                      const std::string& out) {
  return interruptedWork(
      command, progress.where(),
      progress.started() ? out + " holds the work done, marked interrupted" : "");
}

bool interruptedRunKeepsOutputs() {
  return g_keep_outputs;
}

}  // namespace semsegmap::app
