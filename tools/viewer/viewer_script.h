// `patchcull view --script FILE`: timed input events that drive the viewer for tests and
// recordings, deterministic by frame number (not wall time). One event per line, `#` starts a
// comment, blank lines are skipped:
//   FRAME orbit DX DY        left-drag by DX, DY pixels (orbit the scene's centre)
//   FRAME look DX DY         right-drag (fly: turn the view)
//   FRAME zoom STEPS         mouse wheel steps (positive: closer)
//   FRAME key NAME           a key press (viewer_settings.h's names; movement keys held that frame)
//   FRAME set NAME VALUE     a setting, as the panel changes it (viewer_settings.h apply_setting)
//   FRAME screenshot PATH    the window's content after that frame, as a PNG
//   FRAME quit               close the viewer after that frame
// FRAME is a frame number (0 = the first frame), non-decreasing down the file; events of a frame
// apply in file order, before it is rendered (screenshot and quit: after). No GL here: the file is
// checked completely before the window opens.
#pragma once

#include <string>
#include <vector>

#include "viewer_settings.h"

namespace patchcull::cli {

struct ScriptEvent {
    enum class Kind { orbit, look, zoom, key, set, screenshot, quit };
    int frame = 0;
    int line = 0;  ///< 1-based line in the file
    Kind kind = Kind::quit;
    float x = 0, y = 0;  ///< orbit/look: pixels; zoom: steps (x)
    ViewerKey key = ViewerKey::quit;
    std::string name, value;  ///< set: NAME VALUE; screenshot: PATH in value
};

struct ViewerScript {
    std::string path;
    std::vector<ScriptEvent> events;  ///< in file order (frames non-decreasing)
};

/// Parses a script's text; path is used in messages. Throws patchcull::Error with one line
/// "PATH:LINE: what is wrong" at the first malformed line (unknown event, key or setting, a bad
/// number, missing or extra fields, a frame number out of 0..10000000 or smaller than the line
/// before's). Settings are checked against apply_setting.
ViewerScript parse_viewer_script(const std::string& text, const std::string& path);
/// Reads and parses the file; throws patchcull::Error "--script: cannot read 'PATH'" when it
/// cannot be read.
ViewerScript load_viewer_script(const std::string& path);

}  // namespace patchcull::cli
