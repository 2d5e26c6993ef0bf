#include "app/workbench/replay.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>

#include "acquisition/formats/json_input.hpp"
#include "core/errors.hpp"
#include "core/text.hpp"
#include "render/window/window_device.hpp"

namespace scanbench::app::workbench {

namespace {

using Kind = ReplayEvent::Kind;
using nlohmann::json;

constexpr std::uintmax_t kMaxReplayBytes = 16u << 20;

// Events a replay may expand to (waits, drags and texts are many): about
// nine hours at 30 frames a second.
constexpr std::size_t kMaxEvents = 1000000;

// Window coordinates beyond this are not on any screen [pixels].
constexpr double kMaxCoordinatePx = 1e6;

struct Reader {
  std::filesystem::path file;
  std::string where;

  acquisition::JsonPlace place() const { return {file.string(), where}; }

  [[noreturn]] void refuse(const std::string& problem) const { place().refuse(problem); }

  std::array<double, 2> pair(const json& j, double lo, double hi, const char* what, const char* x,
                             const char* y) const {
    if (!j.is_array() || j.size() != 2) refuse(std::string("expected ") + what);
    return {acquisition::finite_number(j[0], lo, hi, place(), x),
            acquisition::finite_number(j[1], lo, hi, place(), y)};
  }

  // A place P (replay.hpp).
  ReplayPlace point(const json& j) const {
    ReplayPlace out;
    if (j.is_array()) {
      out.at =
          pair(j, -kMaxCoordinatePx, kMaxCoordinatePx, "a point [x, y] in window pixels", "x", "y");
      return out;
    }
    if (j.is_string()) {
      out.kind = ReplayPlace::Kind::kWidget;
      out.widget = widget_name(j);
      return out;
    }
    const char* kinds =
        "a place is [x, y], a widget's name, or an object with one of \"widget\", "
        "\"pixel\", \"view3d\" (and an \"offset\")";
    if (!j.is_object()) refuse(kinds);
    int named = 0;
    for (const auto& [key, value] : j.items()) {
      if (key == "widget") {
        out.kind = ReplayPlace::Kind::kWidget;
        out.widget = widget_name(value);
      } else if (key == "pixel") {
        out.kind = ReplayPlace::Kind::kPixel;
        out.at = pair(value, -kMaxCoordinatePx, kMaxCoordinatePx, "a pixel [column, row]", "column",
                      "row");
      } else if (key == "view3d") {
        out.kind = ReplayPlace::Kind::kView3d;
        out.at = pair(value, 0.0, 1.0, "view3d [x, y] in fractions of the view (0 to 1)", "x", "y");
      } else if (key == "offset") {
        out.offset = pair(value, -kMaxCoordinatePx, kMaxCoordinatePx,
                          "an offset [dx, dy] in window pixels", "dx", "dy");
        continue;
      } else {
        refuse("unknown key \"" + key + "\" in a place; " + kinds);
      }
      ++named;
    }
    if (named != 1) refuse(kinds);
    return out;
  }

  std::string widget_name(const json& j) const {
    if (!j.is_string() || j.get<std::string>().empty() || j.get<std::string>().size() > 256 ||
        !core::is_valid_utf8(j.get<std::string>()))
      refuse("a widget is named by a string of 1 to 256 bytes of UTF-8");
    return j.get<std::string>();
  }

  // A file the replay writes, relative to the events file's folder: checked
  // now, so that a replay never stops half-way for a bad path.
  std::filesystem::path output(const json& j, const char* what, const char* extension) const {
    const std::string expected = std::string(what) + " names a " + extension + " file";
    if (!j.is_string() || j.get<std::string>().empty()) refuse(expected);
    std::filesystem::path out(j.get<std::string>());
    if (out.is_relative()) out = file.parent_path() / out;
    if (out.extension() != extension) refuse(expected);
    const std::filesystem::path folder = out.parent_path().empty() ? "." : out.parent_path();
    if (!std::filesystem::is_directory(folder))
      refuse("the " + std::string(what) + "'s folder " + folder.string() + " does not exist");
    return out;
  }

  int button(const json& j) const {
    static const std::map<std::string, int> names = {{"left", 0}, {"right", 1}, {"middle", 2}};
    if (!j.is_string() || !names.count(j.get<std::string>()))
      refuse("a button is \"left\", \"right\" or \"middle\"");
    return names.at(j.get<std::string>());
  }

  int key(const json& j) const {
    if (!j.is_string()) refuse("a key is a name such as \"Z\" or \"Enter\"");
    const std::string name = j.get<std::string>();
    const std::optional<int> code = key_code(name);
    if (!code) refuse("unknown key \"" + name + "\"");
    return *code;
  }

  int mods(const json& event) const {
    if (!event.contains("mods")) return 0;
    if (!event["mods"].is_array()) refuse("mods is a list of \"ctrl\", \"shift\", \"alt\"");
    int out = 0;
    for (const json& m : event["mods"]) {
      const std::string name = m.is_string() ? m.get<std::string>() : "";
      if (name == "ctrl") {
        out |= render::keys::kModControl;
      } else if (name == "shift") {
        out |= render::keys::kModShift;
      } else if (name == "alt") {
        out |= render::keys::kModAlt;
      } else {
        refuse("mods is a list of \"ctrl\", \"shift\", \"alt\"");
      }
    }
    return out;
  }

  int count(const json& j, const char* what) const {
    return static_cast<int>(acquisition::whole_number(j, 0, 100000, place(), what));
  }

  // Refuses keys the event's kind does not take ("mods" goes with any).
  void check_keys(const json& event) const {
    static const std::map<std::string, std::vector<std::string_view>> kinds = {
        {"move", {"move", "mods"}},
        {"press", {"press", "mods"}},
        {"release", {"release", "mods"}},
        {"click", {"click", "button", "mods"}},
        {"drag", {"drag", "button", "steps", "mods"}},
        {"scroll", {"scroll", "at", "mods"}},
        {"key", {"key", "mods"}},
        {"key_down", {"key_down", "mods"}},
        {"key_up", {"key_up", "mods"}},
        {"hold", {"hold", "frames", "mods"}},
        {"text", {"text", "mods"}},
        {"wait", {"wait", "mods"}},
        {"screenshot", {"screenshot", "mods"}},
        {"layout", {"layout", "mods"}}};
    for (const auto& [kind, keys] : kinds) {
      if (!event.contains(kind)) continue;
      for (const auto& [key, value] : event.items()) {
        if (std::find(keys.begin(), keys.end(), key) == keys.end())
          refuse("unknown key \"" + key + "\" in a " + kind + " event");
      }
      return;
    }
    refuse("unknown event: " + event.begin().key());
  }
};

void add_key(std::vector<ReplayEvent>& out, int key, bool pressed, int mods) {
  ReplayEvent e;
  e.kind = Kind::kKey;
  e.key = key;
  e.pressed = pressed;
  e.mods = mods;
  out.push_back(e);
}

void add_button(std::vector<ReplayEvent>& out, int button, bool pressed, int mods) {
  ReplayEvent e;
  e.kind = Kind::kButton;
  e.button = button;
  e.pressed = pressed;
  e.mods = mods;
  out.push_back(e);
}

void add_move(std::vector<ReplayEvent>& out, const ReplayPlace& from, const ReplayPlace& to,
              double t) {
  ReplayEvent e;
  e.kind = Kind::kMove;
  e.from = from;
  e.to = to;
  e.t = t;
  out.push_back(e);
}

void add_move(std::vector<ReplayEvent>& out, const ReplayPlace& at) {
  add_move(out, at, at, 0.0);
}

void add_waits(std::vector<ReplayEvent>& out, int frames) {
  if (frames == 0) return;
  ReplayEvent e;
  e.kind = Kind::kWait;
  e.frames = frames;
  out.push_back(e);
}

// UTF-8 to code points (ASCII and 2–4 byte sequences).
std::vector<unsigned> codepoints(const std::string& text, const Reader& reader) {
  if (!core::is_valid_utf8(text)) reader.refuse("text is not valid UTF-8");
  std::vector<unsigned> out;
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const int length = c < 0x80         ? 1
                       : (c >> 5) == 6  ? 2
                       : (c >> 4) == 14 ? 3
                       : (c >> 3) == 30 ? 4
                                        : 0;
    if (length == 0 || i + static_cast<std::size_t>(length) > text.size())
      reader.refuse("text is not valid UTF-8");
    unsigned value = length == 1 ? c : c & (0xFFu >> (length + 1));
    for (int k = 1; k < length; ++k)
      value = (value << 6) |
              (static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]) & 0x3Fu);
    out.push_back(value);
    i += static_cast<std::size_t>(length);
  }
  return out;
}

// A mouse entry's events, appended to `out`; false when `e` is none.
bool add_pointer_event(const json& e, const Reader& reader, int mods,
                       std::vector<ReplayEvent>& out) {
  if (e.contains("move")) {
    add_move(out, reader.point(e["move"]));
  } else if (e.contains("press") || e.contains("release")) {
    const bool press = e.contains("press");
    add_button(out, reader.button(press ? e["press"] : e["release"]), press, mods);
  } else if (e.contains("click")) {
    const ReplayPlace at = reader.point(e["click"]);
    const int button = e.contains("button") ? reader.button(e["button"]) : 0;
    add_move(out, at);
    add_button(out, button, true, mods);
    add_button(out, button, false, mods);
  } else if (e.contains("drag")) {
    if (!e["drag"].is_array() || e["drag"].size() != 2)
      reader.refuse("drag is [P0, P1]: two places");
    const ReplayPlace from = reader.point(e["drag"][0]);
    const ReplayPlace to = reader.point(e["drag"][1]);
    const int button = e.contains("button") ? reader.button(e["button"]) : 0;
    const int steps = std::max(1, e.contains("steps") ? reader.count(e["steps"], "steps") : 10);
    add_move(out, from, to, 0.0);
    add_button(out, button, true, mods);
    for (int s = 1; s <= steps; ++s) add_move(out, from, to, static_cast<double>(s) / steps);
    add_button(out, button, false, mods);
  } else if (e.contains("scroll")) {
    const double steps =
        acquisition::finite_number(e["scroll"], -1000.0, 1000.0, reader.place(), "scroll");
    if (e.contains("at")) add_move(out, reader.point(e["at"]));
    ReplayEvent s;
    s.kind = Kind::kScroll;
    s.scroll = steps;
    out.push_back(s);
  } else {
    return false;
  }
  return true;
}

// The events one entry of the file stands for, appended to `out`.
void add_event(const json& e, const Reader& reader, std::vector<ReplayEvent>& out) {
  reader.check_keys(e);
  const int mods = reader.mods(e);
  if (add_pointer_event(e, reader, mods, out)) return;
  if (e.contains("key")) {
    const int key = reader.key(e["key"]);
    add_key(out, key, true, mods);
    add_key(out, key, false, mods);
  } else if (e.contains("key_down") || e.contains("key_up")) {
    const bool down = e.contains("key_down");
    add_key(out, reader.key(down ? e["key_down"] : e["key_up"]), down, mods);
  } else if (e.contains("hold")) {
    const int key = reader.key(e["hold"]);
    add_key(out, key, true, mods);
    add_waits(out, e.contains("frames") ? reader.count(e["frames"], "frames") : 10);
    add_key(out, key, false, mods);
  } else if (e.contains("text")) {
    if (!e["text"].is_string()) reader.refuse("text is a string");
    for (const unsigned c : codepoints(e["text"].get<std::string>(), reader)) {
      ReplayEvent t;
      t.kind = Kind::kText;
      t.codepoint = c;
      out.push_back(t);
    }
  } else if (e.contains("wait")) {
    add_waits(out, reader.count(e["wait"], "wait"));
  } else if (e.contains("screenshot") || e.contains("layout")) {
    const bool shot = e.contains("screenshot");
    ReplayEvent s;
    s.kind = shot ? Kind::kScreenshot : Kind::kLayout;
    s.file = shot ? reader.output(e["screenshot"], "screenshot", ".png")
                  : reader.output(e["layout"], "layout", ".json");
    out.push_back(s);
  }
}

}  // namespace

namespace {

// The named keys; letters and digits are named by themselves.
const std::map<std::string, int>& named_keys() {
  namespace k = render::keys;
  static const std::map<std::string, int> names = {
      {"Enter", k::kEnter},         {"Escape", k::kEscape}, {"Tab", k::kTab},
      {"Backspace", k::kBackspace}, {"Delete", k::kDelete}, {"Left", k::kLeft},
      {"Right", k::kRight},         {"Up", k::kUp},         {"Down", k::kDown},
      {"Home", k::kHome},           {"End", k::kEnd},       {"Space", k::kSpace}};
  return names;
}

}  // namespace

std::optional<int> key_code(const std::string& name) {
  if (name.size() == 1 &&
      ((name[0] >= 'A' && name[0] <= 'Z') || (name[0] >= '0' && name[0] <= '9')))
    return name[0];
  const auto found = named_keys().find(name);
  if (found == named_keys().end()) return std::nullopt;
  return found->second;
}

std::optional<std::string> key_name(int code) {
  if ((code >= 'A' && code <= 'Z') || (code >= '0' && code <= '9'))
    return std::string(1, static_cast<char>(code));
  for (const auto& [name, value] : named_keys()) {
    if (value == code) return name;
  }
  return std::nullopt;
}

std::vector<ReplayEvent> read_replay(const std::filesystem::path& file) {
  Reader reader{file, ""};
  const json root = acquisition::read_json_file(file, kMaxReplayBytes);
  if (!root.is_object() || !root.contains("events") || !root["events"].is_array())
    reader.refuse("expected {\"events\": [...]}");
  acquisition::refuse_unknown_keys(root, {"events"}, reader.place());
  std::vector<ReplayEvent> out;
  std::size_t frames = 0;  // the events fed, a wait's frames each one
  const json& events = root["events"];
  for (std::size_t k = 0; k < events.size(); ++k) {
    reader.where = "events[" + std::to_string(k) + "]";
    const json& e = events[k];
    if (!e.is_object() || e.empty())
      reader.refuse("an event is an object such as {\"key\": \"Z\"}");
    const std::size_t first = out.size();
    add_event(e, reader, out);
    for (std::size_t i = first; i < out.size(); ++i) {
      out[i].entry = k;
      frames += out[i].kind == Kind::kWait ? static_cast<std::size_t>(out[i].frames) : 1;
    }
    if (frames > kMaxEvents) {
      reader.refuse("the replay expands to more than " + std::to_string(kMaxEvents) +
                    " events (frames): split it");
    }
  }
  return out;
}

}  // namespace scanbench::app::workbench
