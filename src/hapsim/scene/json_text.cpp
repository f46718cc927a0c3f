#include "hapsim/scene/json_text.h"

#include "hapsim/core/error.h"

#include <algorithm>
#include <vector>

namespace hapsim {
namespace {

using Json = nlohmann::json;

// 1-based line and column of a byte offset, for JSON syntax errors.
std::string line_column(std::string_view text, std::size_t byte) {
  byte = std::min(byte, text.size());
  std::size_t line = 1;
  std::size_t column = 1;
  for (std::size_t i = 0; i < byte; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

// nlohmann's own DOM builder behind a SAX front that knows where it is.
class TrackingSax {
 public:
  TrackingSax(Json& root, std::size_t max_depth) : dom_(root, false), max_depth_(max_depth) {}

  bool null() { return next() && dom_.null(); }
  bool boolean(bool v) { return next() && dom_.boolean(v); }
  bool number_integer(Json::number_integer_t v) { return next() && dom_.number_integer(v); }
  bool number_unsigned(Json::number_unsigned_t v) { return next() && dom_.number_unsigned(v); }
  bool number_float(Json::number_float_t v, const std::string& s) {
    return next() && dom_.number_float(v, s);
  }
  bool string(std::string& v) { return next() && dom_.string(v); }
  bool binary(Json::binary_t& v) { return next() && dom_.binary(v); }
  bool start_object(std::size_t n) { return open(false) && dom_.start_object(n); }
  bool key(std::string& k) {
    path_.back().key = k;
    return dom_.key(k);
  }
  bool end_object() {
    path_.pop_back();
    return dom_.end_object();
  }
  bool start_array(std::size_t n) { return open(true) && dom_.start_array(n); }
  bool end_array() {
    path_.pop_back();
    return dom_.end_array();
  }
  template <class Exception>
  bool parse_error(std::size_t byte, const std::string& token, const Exception& e) {
    error_byte_ = byte;
    error_token_ = token;
    error_id_ = e.id;
    error_what_ = e.what();
    error_pointer_ = pointer(/*pending=*/true);
    return false;
  }

  [[nodiscard]] bool too_deep() const { return too_deep_; }
  [[nodiscard]] const std::string& too_deep_pointer() const { return too_deep_pointer_; }
  [[nodiscard]] int error_id() const { return error_id_; }
  [[nodiscard]] std::size_t error_byte() const { return error_byte_; }
  [[nodiscard]] const std::string& error_token() const { return error_token_; }
  [[nodiscard]] const std::string& error_what() const { return error_what_; }
  [[nodiscard]] const std::string& error_pointer() const { return error_pointer_; }

 private:
  struct Level {
    bool array = false;
    std::size_t count = 0;  // values begun in this array
    std::string key;        // the object's current key
  };

  // A value begins: in an array it is the next element.
  bool next() {
    if (!path_.empty() && path_.back().array) {
      ++path_.back().count;
    }
    return true;
  }
  bool open(bool array) {
    next();
    if (path_.size() >= max_depth_) {
      too_deep_ = true;
      too_deep_pointer_ = pointer(false);
      return false;
    }
    path_.push_back({array, 0, {}});
    return true;
  }
  // The pointer of the value last begun, or (pending) of the one being read when it failed.
  [[nodiscard]] std::string pointer(bool pending) const {
    std::string out;
    for (const Level& level : path_) {
      out += '/';
      if (level.array) {
        const std::size_t index = (&level == &path_.back() && pending)
                                      ? level.count
                                      : std::max<std::size_t>(level.count, 1) - 1;
        out += std::to_string(index);
      } else {
        for (char c : level.key) {
          out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
        }
      }
    }
    return out;
  }

  nlohmann::detail::json_sax_dom_parser<Json> dom_;
  std::size_t max_depth_;
  std::vector<Level> path_;
  bool too_deep_ = false;
  std::string too_deep_pointer_;
  int error_id_ = 0;
  std::size_t error_byte_ = 0;
  std::string error_token_;
  std::string error_what_;
  std::string error_pointer_;
};

}  // namespace

Json parse_json_text(std::string_view text, const std::string& file, std::size_t max_depth) {
  Json root;
  TrackingSax sax(root, max_depth);
  if (Json::sax_parse(text.begin(), text.end(), &sax)) {
    return root;
  }
  if (sax.too_deep()) {
    throw Error(file + ":" + sax.too_deep_pointer(),
                "JSON nested deeper than " + std::to_string(max_depth) +
                    " arrays and objects; expected a scene a few levels deep");
  }
  if (sax.error_id() == 406) {  // a number beyond a double's range
    std::string shown = sax.error_token();
    if (shown.size() > 40) {
      shown = shown.substr(0, 37) + "...";
    }
    throw Error(file + ":" + (sax.error_pointer().empty() ? "/" : sax.error_pointer()),
                "number " + shown +
                    " is beyond the range of a double (about 1.8e308); expected a finite number");
  }
  // e.byte is one past the offending character.
  const std::size_t byte = sax.error_byte() > 0 ? sax.error_byte() - 1 : 0;
  std::string what = sax.error_what();
  if (const auto pos = what.find("syntax error"); pos != std::string::npos) {
    what = what.substr(pos);
  }
  throw Error(file + ":" + line_column(text, byte), "invalid JSON: " + what);
}

}  // namespace hapsim
