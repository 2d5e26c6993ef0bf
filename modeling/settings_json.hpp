// Settings structs as JSON, whole: every field but the thread counts (which
// never change a result). The journal stores each command's settings this
// way, so a command can be read back and replayed; missing keys take the
// struct's defaults and unknown keys are ignored, so settings written by an
// older or newer scanbench still read.
#pragma once

#include <string>

namespace scanbench::modeling {

// Instantiated for acquisition::GeometrySettings, acquisition::ScanFileSettings,
// registration::MergeSettings, registration::RegistrationSettings and
// modeling::RegisterCommandSettings.
template <typename Settings>
std::string settings_to_json(const Settings& settings);

// Throws core::InputError naming `origin` (e.g. "command 7") and the key when
// `json` is not a JSON object or a value has the wrong type.
template <typename Settings>
Settings settings_from_json(const std::string& json, const std::string& origin);

}  // namespace scanbench::modeling
