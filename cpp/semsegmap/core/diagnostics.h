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

// How messages name an option the user gives: as the command line spells it ("--odometry FILE")
// or, in the Python module, as the keyword argument ("odometry=FILE"), so that an error tells
// each user what they can type.
enum class OptionSpelling { kCommandLine, kKeyword };
void setOptionSpelling(OptionSpelling spelling);
// `name` as the command line has it ("ground-truth"); `value` a placeholder ("FILE") or, when
// `literal`, a value to type as is ("lidar": quoted as a Python string for keywords).
std::string optionText(const std::string& name, const std::string& value, bool literal = false);

}  // namespace semsegmap
