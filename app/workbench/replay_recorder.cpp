#include <algorithm>

#include "acquisition/formats/output_file.hpp"
#include "app/workbench/replay.hpp"

namespace scanbench::app::workbench {

namespace {

constexpr int kMaxWait = 100000;  // the replay reader's bound on one wait

nlohmann::json mods_json(int mods) {
  nlohmann::json out = nlohmann::json::array();
  if (mods & render::keys::kModControl) out.push_back("ctrl");
  if (mods & render::keys::kModShift) out.push_back("shift");
  if (mods & render::keys::kModAlt) out.push_back("alt");
  return out;
}

const char* button_name(int button) {
  return button == 1 ? "right" : button == 2 ? "middle" : "left";
}

// One code point as UTF-8.
std::string utf8(unsigned c) {
  std::string out;
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xC0 | (c >> 6));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    out += static_cast<char>(0xE0 | (c >> 12));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (c >> 18));
    out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  }
  return out;
}

}  // namespace

ReplayRecorder::ReplayRecorder(render::WindowInput& inner, std::filesystem::path file,
                               std::function<bool()> takes_presses)
    : inner_(inner), file_(std::move(file)), takes_presses_(std::move(takes_presses)) {}

void ReplayRecorder::add(nlohmann::json event, int mods) {
  if (frames_since_event_ > 0) {
    moved_this_frame_ = false;
    // The event itself takes one of the frames a replay feeds.
    // In waits a replay reads (at most 100 000 frames each).
    for (int idle = frames_since_event_ - 1; idle > 0; idle -= kMaxWait)
      events_.push_back({{"wait", std::min(idle, kMaxWait)}});
    frames_since_event_ = 0;
  }
  if (mods != 0) event["mods"] = mods_json(mods);
  events_.push_back(std::move(event));
}

void ReplayRecorder::cursor_moved(double x, double y) {
  inner_.cursor_moved(x, y);
  if (frames_since_event_ == 0 && moved_this_frame_ && events_.back().contains("move")) {
    events_.back()["move"] = {x, y};  // the frame's last position is what counts
    return;
  }
  add({{"move", {x, y}}}, 0);
  moved_this_frame_ = true;
}

void ReplayRecorder::button(int button, bool pressed, int mods) {
  if (pressed && !takes_presses_()) return;
  inner_.button(button, pressed, mods);
  add({{pressed ? "press" : "release", button_name(button)}}, mods);
  moved_this_frame_ = false;
}

void ReplayRecorder::scrolled(double dx, double dy) {
  if (!takes_presses_()) return;
  inner_.scrolled(dx, dy);
  if (dy != 0.0) add({{"scroll", dy}}, 0);
  moved_this_frame_ = false;
}

void ReplayRecorder::key(int key, bool pressed, int mods) {
  if (pressed && !takes_presses_()) return;
  inner_.key(key, pressed, mods);
  const std::optional<std::string> name = key_name(key);
  if (!name) return;
  add({{pressed ? "key_down" : "key_up", *name}}, mods);
  moved_this_frame_ = false;
}

void ReplayRecorder::text(unsigned codepoint) {
  if (!takes_presses_()) return;
  inner_.text(codepoint);
  add({{"text", utf8(codepoint)}}, 0);
  moved_this_frame_ = false;
}

void ReplayRecorder::save() const {
  acquisition::OutputFile out(file_);
  out.write(nlohmann::json{{"events", events_}}.dump(1));
  out.write("\n");
  out.commit();
}

}  // namespace scanbench::app::workbench
