// `hapsim doctor` as a user runs it (docs/doctor.md): an RLIMIT_RTPRIO of 0 set with prlimit is
// reported as 0 in the JSON, and — where the limit decides, an unprivileged user — the real-time
// check is a warning whose fix is the limits.conf line; a raised limit makes it ok; a bad plugin
// path and a bad --secure folder are named failures (exit 1), not crashes.
#include "hapsim_process.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace hapsim {
namespace {

using test::run_hapsim;
using test::RunResult;
using test::temp_path;

bool have(const char* tool) {
  return std::system((std::string("command -v ") + tool + " > /dev/null 2>&1").c_str()) == 0;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const nlohmann::json& check_named(const nlohmann::json& report, const std::string& name) {
  for (const nlohmann::json& c : report.at("checks")) {
    if (c.at("name") == name) {
      return c;
    }
  }
  static const nlohmann::json none;
  ADD_FAILURE() << "no check named " << name << " in " << report.dump(2);
  return none;
}

// `hapsim doctor --json` (on stdout) run through `prefix` (prlimit, setpriv); the JSON parsed, the
// exit status in `status`. Stderr is dropped: stdout must be the JSON alone.
nlohmann::json doctor_json_through(const std::string& prefix, int& status,
                                   const std::string& name) {
  const auto out = temp_path(name);
  const std::string cmd =
      prefix + " " + HAPSIM_BIN_PATH + " doctor --json 2>/dev/null > " + out.string();
  const int raw = std::system(cmd.c_str());
  status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  const std::string text = read_text(out);
  return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
}

// An unprivileged user (nobody), so RLIMIT_RTPRIO decides, as it does for every non-root user.
std::string as_nobody() {
  return "setpriv --reuid=65534 --regid=65534 --clear-groups";
}

TEST(DoctorCommand, ReportsAnRtprioOfZeroSetWithPrlimit) {
  if (!have("prlimit")) {
    GTEST_SKIP() << "prlimit (util-linux) missing";
  }
  int status = -1;
  // As this user: the limit as set, whatever privilege makes of it.
  const nlohmann::json mine = doctor_json_through("prlimit --rtprio=0:0", status, "rt0.json");
  ASSERT_FALSE(mine.is_discarded()) << "stdout is not JSON";
  const nlohmann::json& rt = check_named(mine, "realtime");
  EXPECT_EQ(rt.at("details").at("rtprio_soft"), 0) << rt.dump(2);
  EXPECT_EQ(rt.at("details").at("rtprio_hard"), 0) << rt.dump(2);
  EXPECT_EQ(status, mine.at("ok").get<bool>() ? 0 : 1);
  if (rt.at("details").at("sched_fifo").get<bool>()) {
    // Root (CAP_SYS_NICE) sets SCHED_FIFO past a limit of 0: ok, and still the line for others.
    EXPECT_EQ(rt.at("status"), "ok") << rt.dump(2);
    EXPECT_TRUE(contains(rt.at("explanation"), "privilege")) << rt.dump(2);
  } else {
    EXPECT_EQ(rt.at("status"), "warn") << rt.dump(2);
  }
  EXPECT_TRUE(contains(rt.at("fix"), "/etc/security/limits.conf")) << rt.dump(2);

  if (::geteuid() != 0 || !have("setpriv")) {
    GTEST_SKIP() << "not root or no setpriv: the unprivileged case (the limit decides) not run";
  }
  // A build tree under a folder closed to others (/root/project in a bare root) cannot be run by
  // nobody at all: that says nothing about the limit.
  if (std::system((as_nobody() + " test -x " + HAPSIM_BIN_PATH).c_str()) != 0) {
    GTEST_SKIP() << "nobody cannot reach " << HAPSIM_BIN_PATH
                 << " (a folder above it is closed to others): the unprivileged case not run";
  }
  const nlohmann::json nobody =
      doctor_json_through("prlimit --rtprio=0:0 " + as_nobody(), status, "rt0-nobody.json");
  ASSERT_FALSE(nobody.is_discarded()) << "stdout is not JSON (as nobody)";
  const nlohmann::json& rt0 = check_named(nobody, "realtime");
  EXPECT_EQ(rt0.at("details").at("rtprio_soft"), 0) << rt0.dump(2);
  EXPECT_EQ(rt0.at("details").at("sched_fifo"), false) << rt0.dump(2);
  EXPECT_EQ(rt0.at("status"), "warn") << rt0.dump(2);
  EXPECT_TRUE(contains(rt0.at("explanation"), "RLIMIT_RTPRIO soft 0")) << rt0.dump(2);
  EXPECT_TRUE(contains(rt0.at("fix"), "/etc/security/limits.conf")) << rt0.dump(2);
  EXPECT_TRUE(contains(rt0.at("fix"), "rtprio 80")) << rt0.dump(2);
  EXPECT_TRUE(contains(rt0.at("fix"), "LimitRTPRIO=80")) << rt0.dump(2);
  // A warning is not a failure: exit 0 unless another check failed.
  EXPECT_EQ(status, nobody.at("ok").get<bool>() ? 0 : 1);
}

TEST(DoctorCommand, ARaisedRtprioLetsAnUnprivilegedUserHaveSchedFifo) {
  if (!have("prlimit") || !have("setpriv") || ::geteuid() != 0) {
    GTEST_SKIP() << "needs root, prlimit and setpriv";
  }
  if (std::system("prlimit --rtprio=80:80 true > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "raising RLIMIT_RTPRIO is not permitted here (no CAP_SYS_RESOURCE): the "
                    "nonzero case cannot be set up";
  }
  int status = -1;
  const nlohmann::json j =
      doctor_json_through("prlimit --rtprio=80:80 " + as_nobody(), status, "rt80.json");
  ASSERT_FALSE(j.is_discarded());
  const nlohmann::json& rt = check_named(j, "realtime");
  EXPECT_EQ(rt.at("details").at("rtprio_soft"), 80) << rt.dump(2);
  if (!rt.at("details").at("sched_fifo").get<bool>()) {
    GTEST_SKIP() << "SCHED_FIFO refused with RLIMIT_RTPRIO 80 (no real-time budget here): "
                 << rt.at("explanation");
  }
  EXPECT_EQ(rt.at("status"), "ok") << rt.dump(2);
  EXPECT_TRUE(rt.at("fix").get<std::string>().empty()) << rt.dump(2);
}

TEST(DoctorCommand, TheTableHasEveryCheckAndTheJsonFileTheSame) {
  const auto json_path = temp_path("doctor.json");
  const RunResult r = run_hapsim("doctor --json " + json_path.string());
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(r.exit_code, j.at("ok").get<bool>() ? 0 : 1) << r.output;
  for (const char* name :
       {"realtime", "memlock", "cpu-governor", "display", "pictures", "dds", "data", "3d-mouse"}) {
    const nlohmann::json& c = check_named(j, name);
    EXPECT_TRUE(c.at("status") == "ok" || c.at("status") == "warn" || c.at("status") == "fail");
    EXPECT_FALSE(c.at("explanation").get<std::string>().empty()) << name;
    if (c.at("status") != "ok") {
      EXPECT_FALSE(c.at("fix").get<std::string>().empty()) << name;
    }
    EXPECT_TRUE(contains(r.output, std::string("\n") + name + " ")) << name << "\n" << r.output;
  }
  EXPECT_TRUE(contains(r.output, "doctor: 8 checks")) << r.output;
  EXPECT_TRUE(contains(r.output, "wrote        " + json_path.string())) << r.output;
}

TEST(DoctorCommand, NoDisplayIsAWarningWithTheXvfbFix) {
  const RunResult r = test::run_hapsim_env("env -u DISPLAY -u WAYLAND_DISPLAY", "doctor");
  EXPECT_NE(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "display       warn    no DISPLAY or WAYLAND_DISPLAY"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "xvfb-run")) << r.output;
  // The viewer's own no-display error points here.
  const RunResult view =
      test::run_hapsim_env("env -u DISPLAY -u WAYLAND_DISPLAY",
                           "view " + std::string(HAPSIM_SCENES_DIR) + "/csg_block.json");
  EXPECT_EQ(view.exit_code, 2) << view.output;
  EXPECT_TRUE(contains(view.output, "no display")) << view.output;
  EXPECT_TRUE(contains(view.output, "run `hapsim doctor` for the fix")) << view.output;
}

TEST(DoctorCommand, ABadPluginPathIsANamedFailure) {
  const auto json_path = temp_path("doctor-bad-plugin.json");
  const RunResult r =
      run_hapsim("doctor --device plugin:/nonexistent/driver.so --json " + json_path.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "plugin        fail    cannot open the plugin: plugin "
                       "/nonexistent/driver.so: no such file"))
      << r.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("ok"), false);
  const nlohmann::json& p = check_named(j, "plugin");
  EXPECT_EQ(p.at("status"), "fail");
  EXPECT_TRUE(contains(p.at("details").at("error"), "/nonexistent/driver.so")) << p.dump(2);
  // Not a shared object at all: named too.
  const auto text = test::write_file("not-a-driver.so", "text, not ELF");
  const RunResult t = run_hapsim("doctor --device plugin:" + text.string());
  EXPECT_EQ(t.exit_code, 1) << t.output;
  EXPECT_TRUE(
      contains(t.output, "plugin        fail    cannot open the plugin: plugin " + text.string()))
      << t.output;
  // Not a plugin spec: a usage error (exit 2), one line.
  const RunResult u = run_hapsim("doctor --device spacemouse");
  EXPECT_EQ(u.exit_code, 2) << u.output;
  EXPECT_TRUE(contains(u.output, "expected plugin:PATH.so")) << u.output;
}

#ifdef HAPSIM_EXAMPLE_DRIVER
TEST(DoctorCommand, TheExamplePluginOpensAndIsNamed) {
  const RunResult r = run_hapsim(std::string("doctor --device plugin:") + HAPSIM_EXAMPLE_DRIVER +
                                 " --driver-config radius_m=0.01");
  EXPECT_NE(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "plugin        ok      opened driver 'example-circle-press'"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "rated 5.0 N")) << r.output;
  // A config the driver refuses: its own message, a failure.
  const RunResult bad = run_hapsim(std::string("doctor --device plugin:") + HAPSIM_EXAMPLE_DRIVER +
                                   " --driver-config colour=red");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_TRUE(contains(bad.output, "unknown key 'colour'")) << bad.output;
}
#endif

TEST(DoctorCommand, ABadSecureFolderIsANamedFailure) {
  const RunResult missing = run_hapsim("doctor --secure /nonexistent/keys");
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_TRUE(contains(missing.output,
                       "secure        fail    --secure /nonexistent/keys: no such key folder"))
      << missing.output;
  EXPECT_TRUE(contains(missing.output, "hapsim keys init")) << missing.output;

  const auto empty = temp_path("empty-keys");
  std::filesystem::create_directories(empty);
  const RunResult not_keys = run_hapsim("doctor --secure " + empty.string());
  EXPECT_EQ(not_keys.exit_code, 1) << not_keys.output;
  EXPECT_TRUE(contains(not_keys.output, "not a key folder: " + (empty / "session").string()))
      << not_keys.output;

  const auto keys = temp_path("doctor-keys");
  std::filesystem::remove_all(keys);
  const RunResult init =
      run_hapsim("keys init " + keys.string() + " --session doctor --device bench1");
  ASSERT_EQ(init.exit_code, 0) << init.output;
  const RunResult good = run_hapsim("doctor --secure " + keys.string());
  EXPECT_TRUE(contains(good.output, "secure        ok      --secure " + keys.string() +
                                        ": session 'doctor', identities bench1, instructor, "
                                        "serve, viewer check out"))
      << good.output;
  // A private key others can read: that identity is refused, by name, with the reason.
  ::chmod((keys / "identities" / "viewer" / "key.pem").c_str(), 0644);
  const RunResult loose = run_hapsim("doctor --secure " + keys.string() + " --identity viewer");
  EXPECT_EQ(loose.exit_code, 1) << loose.output;
  EXPECT_TRUE(
      contains(loose.output,
               "viewer: " + (keys / "identities" / "viewer" / "key.pem").string() + ": mode 0644"))
      << loose.output;
}

TEST(DoctorCommand, AGivenDataFolderThatIsMissingFails) {
  const RunResult r = run_hapsim("doctor --data /nonexistent/data");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "data          fail    --data /nonexistent/data: no such folder"))
      << r.output;
}

}  // namespace
}  // namespace hapsim
