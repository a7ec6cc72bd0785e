// Ctrl-C (SIGINT) and SIGTERM during a run: the program's choice, made here and not in the
// library. The first signal asks the run to stop between frames (the library's loops take the
// stop request as a StopToken, core/stop_token.h), so that the frames done are written whole; a
// second one ends the process at once, for a user who will not wait for the frame in hand.
#pragma once

#include <cstddef>
#include <string>

#include "semsegmap/core/stop_token.h"

namespace semsegmap::app {

// The exit code of a run a signal ended, as a shell gives a process SIGINT killed (128 + 2).
inline constexpr int kExitInterrupted = 130;

// Installs the handlers (sigaction; the handler only sets a lock-free atomic flag, or on the
// second signal _exits), except for a signal the process inherited as ignored. For the commands
// that check stopToken() between frames only: any other keeps the default action, so Ctrl-C still
// ends it at once.
void installInterruptHandler();
StopToken stopToken();
bool stopRequested();

// After a run the stop request ended early: prints one line on stderr, e.g. "semsegmap localize:
// interrupted after 12 of 40 frames; data/out holds the 12 frames done" (or, with no frame done,
// that nothing was written), and returns kExitInterrupted. `written` names the outputs.
int interruptedRun(const std::string& command, size_t done, size_t total,
                   const std::string& written);
// The same for work that is more than one run of frames (the experiments, training): `where` says
// how far it got ("in localize S2 at 3 of 10", "after 2 of 8 epochs"), `kept` what the outputs
// hold; an empty `kept` says nothing was written (main then removes the outputs).
int interruptedWork(const std::string& command, const std::string& where, const std::string& kept);
// interruptedWork for an experiment that reported its stages to `progress`: `out` holds the work
// done, marked interrupted, unless not even one frame was done.
class StageProgress;
int interruptedStages(const std::string& command, const StageProgress& progress,
                      const std::string& out);
// Whether an interrupted run wrote outputs worth keeping (a frame or more done): main keeps its
// outputs then, and removes them as a failed run's otherwise.
bool interruptedRunKeepsOutputs();

}  // namespace semsegmap::app
