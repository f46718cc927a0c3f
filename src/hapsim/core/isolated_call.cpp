#include "hapsim/core/isolated_call.h"

#include "hapsim/core/error.h"
#include "hapsim/core/sanitizer_build.h"

#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <new>

namespace hapsim {
namespace {

// The child's message to the parent: 'R' then the result, or 'E' then where, '\0', what.
constexpr char kResult = 'R';
constexpr char kFailure = 'E';

bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n <= 0) {
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

#if !HAPSIM_SHADOW_SANITIZER
// Bytes of address space this process holds now (the child starts with a copy of it). Not in a
// sanitized build, which sets no address-space limit (its shadow memory reserves terabytes).
std::size_t current_address_space() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}
#endif

[[noreturn]] void child_main(int fd, int said_fd, const IsolationLimits& limits,
                             const std::function<std::string()>& work) {
  // What the parser prints (Assimp's assertion text) goes to a scratch file the parent reads back.
  if (said_fd >= 0) {
    ::dup2(said_fd, STDOUT_FILENO);
    ::dup2(said_fd, STDERR_FILENO);
  }
  // The child dies by the signal itself, so the parent can name it. A handler inherited from the
  // host (a sanitizer's or a fuzzer's crash report, which starts a symbolizer: 0.4 s per crash)
  // would run in a process left with half a parser's state and nothing to report to.
  // Unblocked too: the forking thread's mask is inherited, and a blocked one would stay pending.
  sigset_t crash_signals;
  ::sigemptyset(&crash_signals);
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) {
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    ::sigaction(sig, &dfl, nullptr);
    ::sigaddset(&crash_signals, sig);
  }
  ::pthread_sigmask(SIG_UNBLOCK, &crash_signals, nullptr);
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  const auto cpu_s = static_cast<rlim_t>(std::ceil(limits.time_s)) + 1;
  const rlimit cpu{cpu_s, cpu_s + 1};
  ::setrlimit(RLIMIT_CPU, &cpu);
#if !HAPSIM_SHADOW_SANITIZER
  const rlim_t as = current_address_space() + limits.memory_bytes;
  const rlimit memory{as, as};
  ::setrlimit(RLIMIT_AS, &memory);
#endif
  std::string message;
  try {
    message = kResult + work();
  } catch (const Error& e) {
    message = kFailure + e.where() + '\0' + e.detail();
  } catch (const std::bad_alloc&) {
    message = kFailure + std::string() + '\0' + "needs more than " +
              std::to_string(limits.memory_bytes >> 20) + " MiB of memory";
  } catch (const std::exception& e) {
    message = kFailure + std::string() + '\0' + e.what();
  }
  const bool written = write_all(fd, message.data(), message.size());
  ::close(fd);
  ::_exit(written ? 0 : 3);  // no atexit handlers, no static destructors: the parent owns them
}

// The last line the child printed, cut to 200 characters; "" if none.
std::string last_line_said(int said_fd) {
  if (said_fd < 0) {
    return {};
  }
  std::string text(1 << 14, '\0');
  const off_t size = ::lseek(said_fd, 0, SEEK_END);
  const off_t from =
      size > static_cast<off_t>(text.size()) ? size - static_cast<off_t>(text.size()) : 0;
  const ssize_t n = ::pread(said_fd, text.data(), text.size(), from);
  text.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) {
    text.pop_back();
  }
  std::string line =
      text.substr(text.find_last_of('\n') == std::string::npos ? 0 : text.find_last_of('\n') + 1);
  if (line.size() > 200) {
    line = line.substr(0, 197) + "...";
  }
  return line;
}

std::string signal_text(int sig) {
  const char* name = ::strsignal(sig);
  return "signal " + std::to_string(sig) + (name != nullptr ? std::string(", ") + name : "");
}

}  // namespace

std::string run_isolated(const std::string& where, const std::string& what,
                         const IsolationLimits& limits, const std::function<std::string()>& work) {
  int fds[2];
  if (::pipe(fds) != 0) {
    throw Error(
        where, "cannot start " + what + " in a child process (pipe: " + std::strerror(errno) + ")");
  }
  // A scratch file for what the child prints (-1 if none can be made: it then prints nowhere).
  const int said_fd = ::memfd_create("hapsim-isolated-output", MFD_CLOEXEC);
  std::fflush(nullptr);  // nothing buffered is written twice
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    if (said_fd >= 0) {
      ::close(said_fd);
    }
    throw Error(where,
                "cannot start " + what + " in a child process (fork: " + std::strerror(err) + ")");
  }
  if (pid == 0) {
    ::close(fds[0]);
    child_main(fds[1], said_fd, limits, work);
  }
  ::close(fds[1]);

  std::string message;
  bool timed_out = false;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(limits.time_s));
  char buffer[1 << 16];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          deadline - std::chrono::steady_clock::now())
                          .count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (ready < 0 && errno == EINTR) {
      continue;
    }
    if (ready <= 0) {
      continue;
    }
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n <= 0) {
      break;  // end of the child's message (it exited or closed the pipe)
    }
    message.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (timed_out) {
    ::kill(pid, SIGKILL);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string said = last_line_said(said_fd);
  if (said_fd >= 0) {
    ::close(said_fd);
  }
  const std::string it_said = said.empty() ? std::string() : "; it said: " + said;

  if (timed_out || (WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU)) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%g", limits.time_s);
    throw Error(where, what + " did not finish within " + seconds + " s on this file (stopped" +
                           it_said + ")");
  }
  if (WIFSIGNALED(status)) {
    throw Error(where,
                what + " crashed on this file (" + signal_text(WTERMSIG(status)) + it_said + ")");
  }
  if (!message.empty() && message[0] == kResult && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    return message.substr(1);
  }
  if (!message.empty() && message[0] == kFailure) {
    const std::size_t split = message.find('\0', 1);
    const std::string child_where = message.substr(1, split - 1);
    const std::string detail =
        split == std::string::npos ? std::string() : message.substr(split + 1);
    throw Error(child_where.empty() ? where : child_where, detail);
  }
  throw Error(where, what + " ended without a result on this file (exit status " +
                         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + it_said +
                         ")");
}

}  // namespace hapsim
