// The pictures in docs/images against a fresh run of scripts/make-doc-images.sh, as CI runs it:
// every committed picture is one the script makes, and each fresh picture matches its committed
// one within a tolerance (compare_images: the fraction of pixels whose largest channel difference
// exceeds 8 levels, and each channel's mean absolute difference). A picture left behind when what
// the program draws changed (another scene, camera, colour, layout) fails here, naming the picture;
// regenerate them with the script, look at them, and commit them (docs/testing.md).
#include "apps/hapsim_process.h"
#include "support/test_data.h"

#include "hapsim/render/image_compare.h"
#include "hapsim/render/png_image.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

namespace hapsim {
namespace {

struct DocImage {
  const char* name;
  /// Drawn from ../shared/data (skipped without it, unless HAPSIM_REQUIRE_DATA=1).
  bool real_data;
};

// Everything docs/images holds, as the script makes it.
constexpr DocImage kImages[] = {
    {"viewer-knee", false},
    {"viewer-teleop", false},
    {"viewer-teleop-gp7", true},
    {"viewer-knee-vhf", true},
    {"snapshot-knee-hand-fig6", false},
    {"snapshot-knee-hand-anaglyph", false},
    {"python_stiffness_sweep", false},
    {"python_contact_methods", false},
    {"python_glove_palpation", false},
    {"assessment_picture", false},
    {"assessment_force_total", false},
    {"assessment_learning_curve", false},
};

// {max mean |diff| of any channel (levels), max fraction of pixels differing by > 8 levels}: the
// renderer's reference tolerance (tests/render/scene_reference_test.cpp), for every picture.
// Offscreen renders (EGL, llvmpipe) and matplotlib plots are the same bytes run after run on one
// machine (another CPU or Mesa version moves edges by a level or a pixel). The viewer's
// screenshots differ run to run in the panels' figures (time, rates, a stall count) and the force
// history: measured at most 0.25% of pixels and 0.55 levels, idle or with both cores busy. A stale
// picture differs by more: the pick-and-place as it lets go instead of at rest 3.1%, the knee's
// skin 12 levels less red 2.6%, the old cylinder knee 29%.
constexpr ImageTolerance kTolerance{2.0, 0.01};

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(DocImages, EveryPictureInTheDocsMatchesAFreshRunOfTheScript) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "xvfb-run missing (scripts/setup.sh installs it): the viewer's pictures "
                    "cannot be drawn";
  }
  // The script takes the Python module from the build the binary is in (build/X/python).
  const std::filesystem::path module =
      std::filesystem::path(HAPSIM_BIN_PATH).parent_path().parent_path() / "python" / "hapsim";
  if (!std::filesystem::exists(module / "__init__.py")) {
    GTEST_SKIP() << "the Python module is not built in " << module.parent_path()
                 << " (docs/python.md): the examples' plots cannot be drawn";
  }
  const std::filesystem::path docs = std::filesystem::path(HAPSIM_SOURCE_DIR) / "docs" / "images";
  const std::filesystem::path out = test::temp_path("doc_images");
  std::filesystem::remove_all(out);
  const std::filesystem::path log = test::temp_path("doc_images.log");
  const std::string data = test::data_path("").string();
  const std::string cmd = "HAPSIM_DATA='" + data + "' bash " + std::string(HAPSIM_SOURCE_DIR) +
                          "/scripts/make-doc-images.sh " + out.string() + " " + HAPSIM_BIN_PATH +
                          " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string output = read_text(log);
  std::filesystem::remove(log);
  ASSERT_EQ(status, 0) << cmd << "\n" << output;

  // Nothing in docs/images that the script does not make (a picture nobody regenerates goes stale).
  std::set<std::string> known;
  for (const DocImage& image : kImages) {
    known.insert(std::string(image.name) + ".png");
  }
  for (const auto& entry : std::filesystem::directory_iterator(docs)) {
    EXPECT_TRUE(known.count(entry.path().filename().string()) == 1)
        << "docs/images/" << entry.path().filename().string()
        << " is not made by scripts/make-doc-images.sh: add it to the script (and to this "
           "test's list) or delete it";
  }

  bool all_data = true;
  std::vector<std::string> skipped;
  bool stale = false;
  for (const DocImage& image : kImages) {
    const std::string file = std::string(image.name) + ".png";
    const std::filesystem::path fresh = out / file;
    const std::filesystem::path committed = docs / file;
    if (!std::filesystem::exists(fresh)) {
      if (image.real_data &&
          output.find("skipped " + std::string(image.name) + ":") != std::string::npos) {
        all_data = false;
        skipped.push_back(image.name);
      } else {
        ADD_FAILURE() << "scripts/make-doc-images.sh did not write " << file << "\n" << output;
      }
      continue;
    }
    if (!std::filesystem::exists(committed)) {
      ADD_FAILURE() << "docs/images/" << file << " is missing: run scripts/make-doc-images.sh "
                    << "(this run's picture: " << fresh.string() << ")";
      stale = true;
      continue;
    }
    const RgbaImage a = read_png(fresh.string());
    const RgbaImage b = read_png(committed.string());

    const ImageDiff d = compare_images(a.rgba, b.rgba, a.width, a.height);
    const bool same_size = a.width == b.width && a.height == b.height;
    if (!same_size || !d.within(kTolerance)) {
      stale = true;
      ADD_FAILURE() << "docs/images/" << file << " is stale: "
                    << (same_size ? d.describe()
                                  : "committed " + std::to_string(b.width) + "x" +
                                        std::to_string(b.height) + ", drawn now " +
                                        std::to_string(a.width) + "x" + std::to_string(a.height))
                    << " (allowed: " << 100.0 * kTolerance.max_differing_fraction
                    << "% of pixels, mean " << kTolerance.max_mean_abs_diff << " levels). "
                    << "Regenerate the pictures with `bash scripts/make-doc-images.sh`, look at "
                    << "them and commit them (this run's picture: " << fresh.string() << ")";
    } else {
      std::filesystem::remove(fresh);
    }
  }
  if (!stale) {
    std::filesystem::remove_all(out);
  }
  std::string names;
  for (const std::string& s : skipped) {
    names += (names.empty() ? "" : ", ") + s;
  }
  HAPSIM_SKIP_WITHOUT_DATA(all_data, "the real data for " << names << " is not in " << data
                                                          << " (the other pictures matched)");
}

}  // namespace
}  // namespace hapsim
