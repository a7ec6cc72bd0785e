// What the library tells its user while it works: a note says what it assumed or chose (a
// rig read from defaults, scans left out), a warning what may change the result. Both go to
// stderr as one line ("note: ..." / "warning: ..."), unless an app installs its own sink: the
// CLI's ends an open progress line first, so that a message never trails a progress bar.
#pragma once

#include <functional>
#include <string>

namespace semsegmap {

void note(const std::string& text);
void warn(const std::string& text);

// The whole line ("note: ...", no newline) to `sink`; an empty sink restores stderr.
void setMessageSink(std::function<void(const std::string& line)> sink);

}  // namespace semsegmap
