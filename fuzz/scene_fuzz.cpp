// Fuzz target: bytes as a scene file (parse_scene: the JSON, every reader, the geometry a scene
// builds). Checks: it returns a complete description or throws hapsim::Error; nothing else escapes,
// nothing crashes or hangs (a JSON nested 50 000 deep, 1e400). Paths in the scene resolve against a
// folder that does not exist, so a seed naming the shipped meshes fails fast instead of loading
// 22 MB of knee (the mesh target covers mesh files).
#include "file_fuzz_support.h"
#include "hapsim/scene/scene_file.h"
#include "scene_fuzz_caps.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hapsim::SceneLoadOptions options;
  options.data_dir = "/nonexistent/hapsim-fuzz-data";
  options.detail_caps = hapsim::fuzz::kSceneDetailCaps;
  hapsim::fuzz::expect_value_or_error([&] {
    (void)hapsim::parse_scene(hapsim::fuzz::as_text(data, size),
                              "/nonexistent/hapsim-fuzz/scene.json", options);
  });
  return 0;
}
