#include "hapsim/scene/json_text.h"

#include "hapsim/core/error.h"

#include <gtest/gtest.h>

#include <string>

namespace hapsim {
namespace {

// where() and detail() of the error parsing `text` throws.
std::pair<std::string, std::string> error_of(const std::string& text, std::size_t depth = 100) {
  try {
    (void)parse_json_text(text, "f.json", depth);
  } catch (const Error& e) {
    return {e.where(), e.detail()};
  }
  return {"", ""};
}

TEST(JsonText, ParsesWhatNlohmannParses) {
  const std::string text = R"({"a": [1, 2.5, {"b/c": null, "d": [true, "x"]}], "e": -3})";
  EXPECT_EQ(parse_json_text(text, "f.json"), nlohmann::json::parse(text));
}

TEST(JsonText, NumberBeyondADoubleIsNamedByItsPointer) {
  EXPECT_EQ(error_of(R"({"run": {"duration_s": 1e400}})").first, "f.json:/run/duration_s");
  EXPECT_EQ(error_of(R"({"a": [0, [1, -1e999]]})").first, "f.json:/a/1/1");
  EXPECT_EQ(error_of(R"({"a/b~": 1e400})").first, "f.json:/a~1b~0");
  EXPECT_EQ(error_of("1e400").first, "f.json:/");
  EXPECT_NE(error_of("[1e400]").second.find("1e400"), std::string::npos);
}

TEST(JsonText, NestingBeyondTheLimitIsRefusedAtItsPointer) {
  EXPECT_NO_THROW((void)parse_json_text("[[[[]]]]", "f.json", 4));
  EXPECT_EQ(error_of("[[[[[]]]]]", 4).first, "f.json:/0/0/0/0");
  EXPECT_EQ(error_of(R"({"a": {"b": [{"c": 1}]}})", 3).first, "f.json:/a/b/0");
  const std::size_t depth = 100000;  // would exhaust the stack if walked recursively
  const auto [where, what] = error_of(std::string(depth, '[') + std::string(depth, ']'));
  EXPECT_EQ(where.substr(0, 14), "f.json:/0/0/0/");
  EXPECT_NE(what.find("nested deeper than 100"), std::string::npos) << what;
}

TEST(JsonText, SyntaxErrorsKeepLineAndColumn) {
  EXPECT_EQ(error_of("{\n  \"a\": 1,\n  oops\n}").first, "f.json:3:3");
  EXPECT_NE(error_of("{\"a\": }").second.find("invalid JSON"), std::string::npos);
}

}  // namespace
}  // namespace hapsim
