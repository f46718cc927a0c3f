// What users install links no benchmark oracle: the `hapsim` binary's ELF names none of CGAL's
// (GMP, MPFR), FCL's (and libccd), Embree's, orocos-kdl's or Google Benchmark's libraries among
// the shared libraries it needs (DT_NEEDED, what `readelf -d` lists). Those are for tests and
// benchmarks only: `hapsim bench` runs `hapsim-bench`, the program beside it that links them.
#include "hapsim_process.h"

#include <elf.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace hapsim::test {
namespace {

// The names in a 64-bit little-endian ELF's DT_NEEDED entries (its dynamic section, whose
// strings are in the section it links to).
std::vector<std::string> needed_libraries(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  Elf64_Ehdr header{};
  if (bytes.size() < sizeof header) {
    ADD_FAILURE() << path << ": not an ELF file";
    return {};
  }
  std::memcpy(&header, bytes.data(), sizeof header);
  if (std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0 || header.e_ident[EI_CLASS] != ELFCLASS64) {
    ADD_FAILURE() << path << ": not a 64-bit ELF file";
    return {};
  }
  const auto section = [&](std::size_t index) {
    Elf64_Shdr s{};
    const std::size_t at = header.e_shoff + index * header.e_shentsize;
    if (at + sizeof s <= bytes.size()) {
      std::memcpy(&s, bytes.data() + at, sizeof s);
    }
    return s;
  };
  std::vector<std::string> names;
  for (std::size_t i = 0; i < header.e_shnum; ++i) {
    const Elf64_Shdr dynamic = section(i);
    if (dynamic.sh_type != SHT_DYNAMIC) {
      continue;
    }
    const Elf64_Shdr strings = section(dynamic.sh_link);
    for (std::size_t at = dynamic.sh_offset;
         at + sizeof(Elf64_Dyn) <= dynamic.sh_offset + dynamic.sh_size &&
         at + sizeof(Elf64_Dyn) <= bytes.size();
         at += sizeof(Elf64_Dyn)) {
      Elf64_Dyn entry{};
      std::memcpy(&entry, bytes.data() + at, sizeof entry);
      if (entry.d_tag == DT_NULL) {
        break;
      }
      const std::size_t name_at = strings.sh_offset + entry.d_un.d_val;
      if (entry.d_tag == DT_NEEDED && name_at < bytes.size()) {
        names.emplace_back(bytes.c_str() + name_at);
      }
    }
  }
  return names;
}

// The libraries of the oracles (cmake/HapsimOracles.cmake) and of Google Benchmark.
const char* const kOracleLibraries[] = {"libembree",    "libfcl",  "libccd",        "libgmp",
                                        "libmpfr",      "libCGAL", "liborocos-kdl", "libkdl_parser",
                                        "libbenchmark", "libtbb"};

std::string oracle_in(const std::vector<std::string>& needed) {
  for (const std::string& name : needed) {
    for (const char* oracle : kOracleLibraries) {
      if (name.rfind(oracle, 0) == 0) {
        return name;
      }
    }
  }
  return {};
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) {
    out += (out.empty() ? "" : " ") + n;
  }
  return out;
}

TEST(HapsimLinksNoOracle, TheHapsimBinaryNeedsNoOracleLibrary) {
  const std::vector<std::string> needed = needed_libraries(HAPSIM_BIN_PATH);
  // The reader works: hapsim needs the C++ runtime, whatever else.
  ASSERT_NE(std::find(needed.begin(), needed.end(), "libstdc++.so.6"), needed.end())
      << joined(needed);
  EXPECT_EQ(oracle_in(needed), "") << HAPSIM_BIN_PATH << " needs: " << joined(needed);
}

// Every library the loader would map for `binary`, as `ldd` lists them (file names).
std::vector<std::string> loaded_libraries(const std::string& binary) {
  const std::string cmd = "ldd " + binary + " 2>&1";
  std::FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) {
    ADD_FAILURE() << "cannot run " << cmd;
    return {};
  }
  std::vector<std::string> loaded;
  char line[1024];
  while (std::fgets(line, sizeof line, pipe) != nullptr) {
    std::string name(line);
    name.erase(0, name.find_first_not_of(" \t"));
    name = name.substr(0, name.find_first_of(" \t\n"));
    loaded.push_back(std::filesystem::path(name).filename().string());
  }
  EXPECT_EQ(pclose(pipe), 0) << cmd << ": " << joined(loaded);
  EXPECT_NE(std::find(loaded.begin(), loaded.end(), "libstdc++.so.6"), loaded.end())
      << cmd << ": " << joined(loaded);
  return loaded;
}

// ... nor through the libraries it needs (the project's own shared libraries included).
TEST(HapsimLinksNoOracle, NoLibraryItLoadsIsAnOracle) {
  const std::vector<std::string> loaded = loaded_libraries(HAPSIM_BIN_PATH);
  EXPECT_EQ(oracle_in(loaded), "") << HAPSIM_BIN_PATH << " loads: " << joined(loaded);
}

#ifdef HAPSIM_PYTHON_MODULE_PATH
// The Python module is installed too: no oracle behind `import hapsim` either.
TEST(HapsimLinksNoOracle, NoLibraryThePythonModuleLoadsIsAnOracle) {
  if (!std::filesystem::exists(HAPSIM_PYTHON_MODULE_PATH)) {
    GTEST_SKIP() << HAPSIM_PYTHON_MODULE_PATH
                 << " not built (cmake --build --target hapsim_python)";
  }
  const std::vector<std::string> loaded = loaded_libraries(HAPSIM_PYTHON_MODULE_PATH);
  EXPECT_EQ(oracle_in(loaded), "") << HAPSIM_PYTHON_MODULE_PATH << " loads: " << joined(loaded);
}
#endif

#ifdef HAPSIM_BENCH_BIN_PATH
// The same reader finds the oracles where they are linked: hapsim-bench (the comparison rows).
TEST(HapsimLinksNoOracle, HapsimBenchIsWhereTheOraclesAre) {
  const std::vector<std::string> needed = needed_libraries(HAPSIM_BENCH_BIN_PATH);
#if defined(HAPSIM_HAVE_EMBREE) || defined(HAPSIM_HAVE_FCL)
  EXPECT_NE(oracle_in(needed), "") << joined(needed);
#endif
  EXPECT_EQ(std::filesystem::path(HAPSIM_BENCH_BIN_PATH).parent_path(),
            std::filesystem::path(HAPSIM_BIN_PATH).parent_path())
      << "hapsim bench looks for hapsim-bench beside hapsim";
}

// `hapsim bench` passes everything on: hapsim-bench's own help, its subcommands listed.
TEST(HapsimLinksNoOracle, HapsimBenchRunsHapsimBench) {
  const RunResult help = run_hapsim("bench --help");
  EXPECT_EQ(help.exit_code, 0) << help.output;
  for (const char* sub :
       {"collision", "step", "passivity", "snapshot", "contact", "fem", "soak", "network"}) {
    EXPECT_NE(help.output.find(sub), std::string::npos) << sub << "\n" << help.output;
  }
  const RunResult bad = run_hapsim("bench network --modes magic");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("see hapsim bench --help"), std::string::npos) << bad.output;
  const RunResult none = run_hapsim("bench");
  EXPECT_EQ(none.exit_code, 2) << none.output;
}
#endif

// Without hapsim-bench beside it (a copy of hapsim alone), `hapsim bench` says what it needs.
TEST(HapsimLinksNoOracle, HapsimBenchWithoutHapsimBenchSaysSoInOneLine) {
  const std::filesystem::path dir = temp_path("alone");
  std::filesystem::create_directories(dir);
  const std::filesystem::path copy = dir / "hapsim";
  std::filesystem::copy_file(HAPSIM_BIN_PATH, copy,
                             std::filesystem::copy_options::overwrite_existing);
  const std::string cmd = copy.string() + " bench collision --quick 2>&1";
  RunResult alone;
  std::FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) {
    alone.output += buffer;
  }
  const int status = pclose(pipe);
  alone.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  EXPECT_EQ(alone.exit_code, 2) << alone.output;
  EXPECT_EQ(alone.output,
            "hapsim: hapsim bench needs hapsim-bench, built with the benchmarks "
            "(cmake -DHAPSIM_BUILD_BENCH=ON, the default): no " +
                (dir / "hapsim-bench").string() + "\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hapsim::test
