// Runs a fuzz target's LLVMFuzzerTestOneInput without libFuzzer (docs/fuzzing.md): over the
// committed seed corpus and then a few thousand inputs from a seeded generator, so every ctest
// run checks the same entry points the clang fuzzers explore, on any compiler. A failed check
// aborts (the test fails, naming the check); the input is written to replay-crash.bin in the
// working folder.
//
//   hapsim_fuzz_replay_<target> CORPUS_DIR_OR_FILE... [--random N] [--seed S] [--max-bytes M]
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The input being run, kept so a crash (abort) can be reproduced with the real fuzzer.
const Bytes* g_current = nullptr;
// The replay's own process: a child it forks (the mesh target's Assimp, isolated_call.h) inherits
// the handler, and its abort is the isolation working, not a failed check.
pid_t g_replay_pid = 0;

void run(const Bytes& input) {
  g_current = &input;
  // A copy of exactly `size` bytes on the heap: reading past it is caught by ASan builds.
  const std::unique_ptr<std::uint8_t[]> copy(new std::uint8_t[input.size() + 1]);
  std::copy(input.begin(), input.end(), copy.get());
  LLVMFuzzerTestOneInput(copy.get(), input.size());
  g_current = nullptr;
}

// Values that break arithmetic: NaN, infinities, huge and tiny numbers, signed zero.
constexpr std::array<double, 10> kNastyDoubles = {std::numeric_limits<double>::quiet_NaN(),
                                                  std::numeric_limits<double>::infinity(),
                                                  -std::numeric_limits<double>::infinity(),
                                                  std::numeric_limits<double>::max(),
                                                  std::numeric_limits<double>::lowest(),
                                                  std::numeric_limits<double>::denorm_min(),
                                                  -0.0,
                                                  1e308,
                                                  -1e-300,
                                                  4.0};

Bytes mutate(const Bytes& seed, std::mt19937_64& rng) {
  Bytes out = seed;
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    switch (rng() % 5) {
      case 0:  // flip a byte
        if (!out.empty()) {
          out[rng() % out.size()] ^= static_cast<std::uint8_t>(1U << (rng() % 8));
        }
        break;
      case 1: {  // a nasty double at an 8-byte-aligned offset past the control byte
        const double d = kNastyDoubles[rng() % kNastyDoubles.size()];
        if (out.size() >= 9) {
          const std::size_t at = 1 + 8 * (rng() % ((out.size() - 1) / 8));
          if (at + 8 <= out.size()) {
            std::memcpy(out.data() + at, &d, sizeof d);
          }
        }
        break;
      }
      case 2:  // truncate
        out.resize(out.empty() ? 0 : rng() % (out.size() + 1));
        break;
      case 3:  // extend with random bytes
        for (int i = static_cast<int>(rng() % 24); i > 0; --i) {
          out.push_back(static_cast<std::uint8_t>(rng()));
        }
        break;
      default:  // an extreme integer anywhere
        if (out.size() >= 4) {
          const std::uint32_t v = std::array<std::uint32_t, 5>{0U, 0xFFFFFFFFU, 0x80000000U,
                                                               0x7FFFFFFFU, 10'001U}[rng() % 5];
          std::memcpy(out.data() + rng() % (out.size() - 3), &v, sizeof v);
        }
        break;
    }
  }
  return out;
}

void on_abort(int) {
  if (g_current != nullptr && ::getpid() == g_replay_pid) {
    std::FILE* f = std::fopen("replay-crash.bin", "wb");
    if (f != nullptr) {
      std::fwrite(g_current->data(), 1, g_current->size(), f);
      std::fclose(f);
      std::fprintf(stderr, "replay: the failing input is in replay-crash.bin (%zu bytes)\n",
                   g_current->size());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> paths;
  long random_inputs = 0;
  std::uint64_t seed = 1;
  std::size_t max_bytes = 512;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--random" && has_value) {
      random_inputs = std::atol(argv[++i]);
    } else if (arg == "--seed" && has_value) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--max-bytes" && has_value) {
      max_bytes = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg.starts_with("--")) {
      std::cerr << "usage: " << argv[0]
                << " CORPUS_DIR_OR_FILE... [--random N] [--seed S] [--max-bytes M]\n";
      return 2;
    } else {
      paths.emplace_back(arg);
    }
  }
  g_replay_pid = ::getpid();
  std::signal(SIGABRT, on_abort);

  std::vector<Bytes> corpus;
  for (const std::filesystem::path& p : paths) {
    if (std::filesystem::is_directory(p)) {
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(p)) {
        if (entry.is_regular_file()) {
          files.push_back(entry.path());
        }
      }
      std::sort(files.begin(), files.end());  // the same order on every machine
      for (const auto& f : files) {
        corpus.push_back(read_file(f));
      }
    } else if (std::filesystem::is_regular_file(p)) {
      corpus.push_back(read_file(p));
    } else {
      std::cerr << "replay: " << p.string() << ": no such file or folder\n";
      return 2;
    }
  }
  for (const Bytes& input : corpus) {
    run(input);
  }

  std::mt19937_64 rng(seed);
  for (long i = 0; i < random_inputs; ++i) {
    Bytes input;
    if (i % 2 == 1 && !corpus.empty()) {
      input = mutate(corpus[rng() % corpus.size()], rng);
    } else {
      input.resize(rng() % (max_bytes + 1));
      for (std::uint8_t& b : input) {
        b = static_cast<std::uint8_t>(rng());
      }
    }
    run(input);
  }
  std::cout << "replay: " << corpus.size() << " corpus inputs and " << random_inputs
            << " generated inputs (seed " << seed << "), every check held\n";
  return 0;
}
