#include "hapsim/core/isolated_call.h"

#include "hapsim/core/error.h"
#include "hapsim/core/sanitizer_build.h"

#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace hapsim {
namespace {

// The message of the hapsim::Error `work` ends in (its where() checked), "" if none.
std::string failure(const std::function<std::string()>& work, double time_s = 10.0,
                    std::size_t memory_bytes = std::size_t{2} << 30,
                    const std::string& expected_where = "input.ply") {
  IsolationLimits limits;
  limits.time_s = time_s;
  limits.memory_bytes = memory_bytes;
  try {
    (void)run_isolated("input.ply", "the parser", limits, work);
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), expected_where);
    return e.detail();
  }
  return "";
}

TEST(IsolatedCall, ReturnsTheChildsBytesExactly) {
  std::string big(3'000'000, '\0');  // larger than a pipe's buffer, with NUL bytes
  for (std::size_t i = 0; i < big.size(); ++i) {
    big[i] = static_cast<char>(i * 7919 % 251);
  }
  EXPECT_EQ(run_isolated("x", "the parser", {}, [&] { return big; }), big);
  EXPECT_EQ(run_isolated("x", "the parser", {}, [] { return std::string(); }), "");
}

TEST(IsolatedCall, ACrashInTheChildIsAnErrorNamingTheInput) {
  // In every build, a sanitizer's included: the child dies by the signal itself (a crash handler
  // inherited from the host would report it instead, slowly, from a half-parsed state).
  const std::string message = failure([]() -> std::string {
    std::raise(SIGSEGV);
    return "unreachable";
  });
  EXPECT_NE(message.find("the parser crashed on this file"), std::string::npos) << message;
  EXPECT_NE(message.find("signal 11"), std::string::npos) << message;
  const std::string aborted = failure([]() -> std::string { std::abort(); });
  EXPECT_NE(aborted.find("signal 6"), std::string::npos) << aborted;
}

TEST(IsolatedCall, TheHostsCrashHandlerDoesNotRunInTheChild) {
  // A host application's (or a sanitizer's, or a fuzzer's) handler: in the child it would turn
  // the crash into an exit that reports nothing, or a slow report from a half-parsed state.
  struct sigaction host {};
  host.sa_handler = [](int) { ::_exit(42); };
  struct sigaction before {};
  ASSERT_EQ(::sigaction(SIGSEGV, &host, &before), 0);
  const std::string message = failure([]() -> std::string {
    std::raise(SIGSEGV);
    return "unreachable";
  });
  ::sigaction(SIGSEGV, &before, nullptr);
  EXPECT_NE(message.find("the parser crashed on this file (signal 11"), std::string::npos)
      << message;
}

TEST(IsolatedCall, AHangIsStoppedAtTheTimeLimit) {
  const std::string message = failure(
      []() -> std::string {
        for (;;) {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
      },
      0.3);
  EXPECT_NE(message.find("did not finish within 0.3 s"), std::string::npos) << message;
}

TEST(IsolatedCall, AnErrorThrownInTheChildKeepsItsWhereAndText) {
  const std::string message =
      failure([]() -> std::string { throw Error("input.ply:/vertex/3", "a bad vertex"); }, 10.0,
              std::size_t{2} << 30, "input.ply:/vertex/3");
  EXPECT_EQ(message, "a bad vertex");
}

#if !HAPSIM_SHADOW_SANITIZER
TEST(IsolatedCall, RunawayAllocationMeetsTheMemoryLimit) {
  const std::string message = failure(
      []() -> std::string {
        std::vector<std::vector<char>> hoard;
        hoard.reserve(64);
        for (int i = 0; i < 64; ++i) {
          hoard.emplace_back(std::size_t{64} << 20, 'x');  // 4 GiB in all
        }
        return "unreachable";
      },
      30.0, std::size_t{256} << 20);
  EXPECT_NE(message.find("needs more than 256 MiB of memory"), std::string::npos) << message;
}
#endif

}  // namespace
}  // namespace hapsim
