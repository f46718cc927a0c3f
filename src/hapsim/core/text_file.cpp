#include "hapsim/core/text_file.h"

#include "hapsim/core/error.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

namespace hapsim {

std::string read_text_file(const std::filesystem::path& path, std::size_t max_bytes,
                           std::string_view what) {
  const std::string where = path.string();
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    throw Error(where, "cannot open the " + std::string(what) + " (" +
                           (ec ? ec.message() : std::string("no such file")) + ")");
  }
  if (std::filesystem::is_directory(status)) {
    throw Error(where, "cannot open the " + std::string(what) + ": it is a folder");
  }
  // Opening a FIFO blocks until something writes to it: assess and calibrate glove hung forever.
  if (std::filesystem::is_fifo(status) || std::filesystem::is_socket(status)) {
    throw Error(where, "cannot open the " + std::string(what) +
                           ": it is a pipe or a socket, not a file (hapsim reads files)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw Error(where, "cannot open the " + std::string(what) + " (" + std::strerror(errno) + ")");
  }
  std::string text;
  constexpr std::size_t kChunk = 1 << 16;
  char buffer[kChunk];
  while (in) {
    in.read(buffer, static_cast<std::streamsize>(kChunk));
    const auto n = static_cast<std::size_t>(in.gcount());
    if (text.size() + n > max_bytes) {
      const std::string limit = max_bytes % (1U << 20) == 0
                                    ? std::to_string(max_bytes >> 20) + " MiB"
                                    : std::to_string(max_bytes) + " bytes";
      throw Error(where, "larger than " + limit + "; expected a " + std::string(what) +
                             " (is this the right file?)");
    }
    if (const void* nul = std::memchr(buffer, '\0', n); nul != nullptr) {
      const auto at =
          text.size() + static_cast<std::size_t>(static_cast<const char*>(nul) - buffer);
      throw Error(where, "not a text file (a NUL byte at byte " + std::to_string(at) +
                             "); expected a " + std::string(what));
    }
    text.append(buffer, n);
  }
  if (in.bad()) {
    throw Error(where, "cannot read the " + std::string(what));
  }
  return text;
}

}  // namespace hapsim
