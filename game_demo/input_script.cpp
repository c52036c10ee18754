#include "game_demo/input_script.h"
#include "runtime/io/regular_file.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <sstream>

namespace sinew::demo {
namespace {

// Splits on spaces and tabs, after dropping a '#' comment.
std::vector<std::string_view> tokens_of(std::string_view line) {
  if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// Frames are bounded so that a tap's release (frame + 1) cannot overflow.
constexpr int kMaxFrame = 100'000'000;

}  // namespace

Expected<InputScript> InputScript::parse(std::string_view text, const std::string& source) {
  InputScript script;
  int line_number = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    const auto tokens = tokens_of(line);
    if (tokens.empty()) continue;
    const std::string where = "line " + std::to_string(line_number);
    if (tokens.size() != 3) {
      return make_error(ErrorCode::kInvalidData, source, where, std::string(line),
                        "expected three fields: frame key down|up|tap");
    }
    int frame = 0;
    const auto [stop, ec] = std::from_chars(tokens[0].data(), tokens[0].data() + tokens[0].size(), frame);
    if (ec != std::errc() || stop != tokens[0].data() + tokens[0].size() || frame < 0 || frame > kMaxFrame) {
      return make_error(ErrorCode::kInvalidData, source, where + " frame", tokens[0],
                        "expected a frame number from 0 to " + std::to_string(kMaxFrame));
    }
    const auto key = demo_key_from_name(tokens[1]);
    if (!key) {
      return make_error(ErrorCode::kInvalidData, source, where + " key", tokens[1],
                        "expected one of w a s d up down left right shift q e space tab f1 esc");
    }
    const std::string_view event = tokens[2];
    if (event == "down" || event == "up") {
      script.events_.push_back({frame, *key, event == "down"});
    } else if (event == "tap") {
      script.events_.push_back({frame, *key, true});
      script.events_.push_back({frame + 1, *key, false});
    } else {
      return make_error(ErrorCode::kInvalidData, source, where + " event", event, "expected down, up or tap");
    }
  }
  std::stable_sort(script.events_.begin(), script.events_.end(),
                   [](const Event& a, const Event& b) { return a.frame < b.frame; });
  return script;
}

Expected<InputScript> InputScript::load(const std::string& path) {
  SINEW_RETURN_IF_ERROR(check_regular_file(path));
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIoError, path, "", "", "cannot open the input script");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return make_error(ErrorCode::kIoError, path, "", "", "cannot read the input script");
  return parse(text.str(), path);
}

KeySnapshot InputScript::keys_at(int frame) const {
  KeySnapshot keys;
  for (const Event& e : events_) {
    if (e.frame > frame) break;
    keys.set(e.key, e.down);
  }
  return keys;
}

int InputScript::last_frame() const { return events_.empty() ? -1 : events_.back().frame; }

}  // namespace sinew::demo

namespace sinew::demo {

ControlResult script_controls(const InputScript& script, int frame, FollowCamera& camera) {
  return apply_controls(script.keys_at(frame), script.keys_at(frame - 1), kScriptStepSeconds, camera);
}

}  // namespace sinew::demo
