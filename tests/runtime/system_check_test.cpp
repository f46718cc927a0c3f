// runtime/system_check.h, the checks of `hapsim doctor`: each judgement from given facts (an
// RLIMIT_RTPRIO of 0 with SCHED_FIFO refused is a warning with the limits.conf line as its fix),
// and the probes leave the process as they found it (no SCHED_FIFO, no locked memory).
#include "hapsim/runtime/system_check.h"

#include <gtest/gtest.h>

#include <sched.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace hapsim {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("hapsim_system_check_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(SystemCheck, RtprioZeroWithFifoRefusedWarnsWithTheLimitsConfLine) {
  RealtimeFacts f;
  f.rtprio = {0, 0};
  f.priority = 80;
  f.fifo_permitted = false;
  f.privileged = false;
  const SystemCheck c = judge_realtime(f);
  EXPECT_EQ(c.name, "realtime");
  EXPECT_EQ(c.status, CheckStatus::kWarn);
  EXPECT_TRUE(contains(c.explanation, "RLIMIT_RTPRIO soft 0 (hard 0) is below 80"))
      << c.explanation;
  EXPECT_TRUE(contains(c.explanation, "normal scheduling")) << c.explanation;
  EXPECT_TRUE(contains(c.fix, "/etc/security/limits.conf")) << c.fix;
  EXPECT_TRUE(contains(c.fix, "- rtprio 80")) << c.fix;
  EXPECT_TRUE(contains(c.fix, "LimitRTPRIO=80")) << c.fix;
  EXPECT_EQ(c.details.at("rtprio_soft"), 0);
  EXPECT_EQ(c.details.at("rtprio_hard"), 0);
  EXPECT_EQ(c.details.at("sched_fifo"), false);
}

TEST(SystemCheck, ASoftLimitBelowAHardOneThatAllowsItSaysUlimit) {
  RealtimeFacts f;
  f.rtprio = {0, 99};
  const SystemCheck c = judge_realtime(f);
  EXPECT_EQ(c.status, CheckStatus::kWarn);
  EXPECT_TRUE(contains(c.fix, "ulimit -r 80")) << c.fix;
}

TEST(SystemCheck, FifoGrantedByPrivilegeIsOkAndStillNamesTheLineForOthers) {
  RealtimeFacts f;
  f.rtprio = {0, 0};
  f.fifo_permitted = true;
  f.privileged = true;
  const SystemCheck c = judge_realtime(f);
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_TRUE(contains(c.explanation, "privilege")) << c.explanation;
  EXPECT_TRUE(contains(c.fix, "limits.conf")) << c.fix;
}

TEST(SystemCheck, FifoGrantedByTheLimitIsOkWithNothingToFix) {
  RealtimeFacts f;
  f.rtprio = {95, 95};
  f.fifo_permitted = true;
  const SystemCheck c = judge_realtime(f);
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_TRUE(c.fix.empty()) << c.fix;
  EXPECT_EQ(c.details.at("rtprio_soft"), 95);
}

TEST(SystemCheck, FifoRefusedDespiteTheLimitPointsAtTheContainer) {
  RealtimeFacts f;
  f.rtprio = {std::nullopt, std::nullopt};  // unlimited
  f.fifo_permitted = false;
  const SystemCheck c = judge_realtime(f);
  EXPECT_EQ(c.status, CheckStatus::kWarn);
  EXPECT_EQ(c.details.at("rtprio_soft"), "unlimited");
  EXPECT_TRUE(contains(c.fix, "SYS_NICE")) << c.fix;
}

TEST(SystemCheck, TheRealtimeProbeLeavesThisThreadsSchedulingAlone) {
  const int before = sched_getscheduler(0);
  const RealtimeFacts f = probe_realtime(80);
  EXPECT_EQ(sched_getscheduler(0), before);
  EXPECT_EQ(f.priority, 80);
}

TEST(SystemCheck, MemoryLockFollowsTheHapticLoopsRule) {
  MemoryLockFacts f;
  f.memlock = {std::uint64_t{8} << 20, std::uint64_t{8} << 20};
  f.root = false;
  f.mlockall_works = true;
  SystemCheck c = judge_memory_lock(f);
  EXPECT_EQ(c.status, CheckStatus::kWarn);  // finite and not root: the loop does not lock
  EXPECT_TRUE(contains(c.explanation, "8 MiB")) << c.explanation;
  EXPECT_TRUE(contains(c.fix, "memlock unlimited")) << c.fix;
  EXPECT_TRUE(contains(c.fix, "LimitMEMLOCK=infinity")) << c.fix;
  f.root = true;
  c = judge_memory_lock(f);
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_EQ(c.details.at("haptic_loop_locks"), true);
  f.mlockall_works = false;
  f.mlockall_errno = EPERM;
  EXPECT_EQ(judge_memory_lock(f).status, CheckStatus::kWarn);
  f.sanitizer = true;
  EXPECT_TRUE(contains(judge_memory_lock(f).explanation, "sanitizer"));
}

TEST(SystemCheck, TheMemoryProbeLeavesNothingLocked) {
  (void)probe_memory_lock();
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmLck:", 0) == 0) {
      EXPECT_EQ(std::stol(line.substr(6)), 0) << line;
    }
  }
}

TEST(SystemCheck, CpuGovernorUnknownPerformanceOrWarn) {
  const auto root = scratch("cpu");
  SystemCheck c = check_cpu_governor(root);
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_EQ(c.details.at("governor"), "unknown");
  for (const char* cpu : {"cpu0", "cpu1"}) {
    std::filesystem::create_directories(root / cpu / "cpufreq");
    std::ofstream(root / cpu / "cpufreq" / "scaling_governor") << "performance\n";
  }
  std::filesystem::create_directories(root / "cpufreq");  // not a CPU
  c = check_cpu_governor(root);
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_EQ(c.details.at("governor"), "performance");
  std::ofstream(root / "cpu1" / "cpufreq" / "scaling_governor") << "powersave\n";
  c = check_cpu_governor(root);
  EXPECT_EQ(c.status, CheckStatus::kWarn);
  EXPECT_EQ(c.details.at("governor"), "mixed");
  EXPECT_TRUE(contains(c.fix, "performance")) << c.fix;
  EXPECT_EQ(c.details.at("governors").at("powersave").get<std::vector<int>>(), std::vector<int>{1});
}

TEST(SystemCheck, DdsWarnsOnLoopbackOnlyAndFailsOnAMissingConfig) {
  const auto dir = scratch("dds");
  const auto config = dir / "loopback.xml";
  std::ofstream(config) << "<CycloneDDS/>";
  const NetworkInterface lo{"lo", true, true, false, {"127.0.0.1"}};
  const NetworkInterface eth{"eth0", true, false, true, {"192.0.2.2"}};
  const NetworkInterface tun{"tun0", true, false, false, {"10.8.0.2"}};
  const NetworkInterface down{"eth1", false, false, true, {}};

  SystemCheck c = judge_dds(nullptr, config, {lo, down});
  EXPECT_EQ(c.status, CheckStatus::kWarn);
  EXPECT_TRUE(contains(c.explanation, "only loopback")) << c.explanation;
  EXPECT_TRUE(contains(c.explanation, "CYCLONEDDS_URI not set")) << c.explanation;

  c = judge_dds(nullptr, config, {lo, eth});
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_TRUE(contains(c.explanation, "eth0 (192.0.2.2, multicast)")) << c.explanation;

  c = judge_dds(nullptr, config, {lo, tun});
  EXPECT_EQ(c.status, CheckStatus::kWarn);
  EXPECT_TRUE(contains(c.fix, "--peer")) << c.fix;

  const std::string missing = "file://" + (dir / "nope.xml").string();
  c = judge_dds(missing.c_str(), config, {lo, eth});
  EXPECT_EQ(c.status, CheckStatus::kFail);
  EXPECT_TRUE(contains(c.explanation, (dir / "nope.xml").string())) << c.explanation;

  const std::string mine = "file://" + config.string() + ",<CycloneDDS><Domain/></CycloneDDS>";
  c = judge_dds(mine.c_str(), config, {lo, eth});
  EXPECT_EQ(c.status, CheckStatus::kOk) << c.explanation;
  EXPECT_EQ(c.details.at("CYCLONEDDS_URI"), mine);

  c = judge_dds(nullptr, dir / "not-there.xml", {lo, eth});
  EXPECT_EQ(c.status, CheckStatus::kFail);
}

TEST(SystemCheck, DataFolderFoundMissingOrGivenWrong) {
  const auto data = scratch("data");
  std::filesystem::create_directories(data / "knee_vhf_left");
  ::unsetenv("HAPSIM_DATA");
  SystemCheck c = check_data_folder({}, data);
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_TRUE(contains(c.explanation, "knee_vhf_left")) << c.explanation;
  EXPECT_EQ(c.details.at("from"), "beside the checkout");

  c = check_data_folder({}, data / "absent");
  EXPECT_EQ(c.status, CheckStatus::kWarn);
  EXPECT_TRUE(contains(c.fix, "HAPSIM_DATA")) << c.fix;

  ::setenv("HAPSIM_DATA", data.c_str(), 1);
  c = check_data_folder({}, data / "absent");
  EXPECT_EQ(c.status, CheckStatus::kOk);
  EXPECT_EQ(c.details.at("from"), "HAPSIM_DATA");
  ::setenv("HAPSIM_DATA", (data / "gone").c_str(), 1);
  c = check_data_folder({}, data);
  EXPECT_EQ(c.status, CheckStatus::kWarn);  // found beside the checkout, but the variable is wrong
  ::unsetenv("HAPSIM_DATA");

  c = check_data_folder(data / "no-such", data);
  EXPECT_EQ(c.status, CheckStatus::kFail);
  EXPECT_TRUE(contains(c.explanation, "no-such")) << c.explanation;
}

TEST(SystemCheck, APluginThatDoesNotLoadIsANamedFailure) {
  const auto dir = scratch("plugin");
  SystemCheck c = check_plugin_device(dir / "missing.so", "");
  EXPECT_EQ(c.status, CheckStatus::kFail);
  EXPECT_TRUE(contains(c.explanation, "missing.so")) << c.explanation;
  EXPECT_FALSE(c.fix.empty());
  std::ofstream(dir / "text.so") << "not a shared object";
  c = check_plugin_device(dir / "text.so", "");
  EXPECT_EQ(c.status, CheckStatus::kFail);
  EXPECT_TRUE(contains(c.explanation, "text.so")) << c.explanation;
}

TEST(SystemCheck, TheReportCountsFailuresAndWarnings) {
  std::vector<SystemCheck> checks(3);
  checks[0] = {"a", CheckStatus::kOk, "fine", "", nlohmann::json::object()};
  checks[1] = {"b", CheckStatus::kWarn, "meh", "do this", nlohmann::json::object()};
  EXPECT_FALSE(any_failed(checks));
  checks[2] = {"c", CheckStatus::kFail, "broken", "do that", nlohmann::json::object()};
  EXPECT_TRUE(any_failed(checks));
  const nlohmann::json j = checks_json(checks);
  EXPECT_EQ(j.at("ok"), false);
  EXPECT_EQ(j.at("failed"), 1);
  EXPECT_EQ(j.at("warnings"), 1);
  EXPECT_EQ(j.at("checks").at(1).at("status"), "warn");
  EXPECT_EQ(j.at("checks").at(1).at("fix"), "do this");
  const std::string table = format_checks_table(checks);
  EXPECT_TRUE(contains(table, "fix: do that")) << table;
  EXPECT_TRUE(contains(table, "1 failed, 1 warning(s) (exit status 1)")) << table;
}

}  // namespace
}  // namespace hapsim
