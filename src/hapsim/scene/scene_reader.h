// The JsonReader of scene files: besides naming every error's place (json_reader.h) it knows
// where the scene's paths point — relative to the scene file's folder, absolute, or "data:REL"
// under the scene's data folder (docs/scene-format.md, "Paths") — and the load's options
// (progress). scene_file.cpp reads the top level with it; the readers of a scene's parts
// (geometry_reader.h, device_reader.h, rig_reader.h, csg_reader.h) take it, so a path or a
// number fails the same way wherever it appears.
#pragma once

#include "hapsim/scene/json_reader.h"
#include "hapsim/scene/scene_file.h"

#include <filesystem>
#include <string>

namespace hapsim {

class SceneReader : public JsonReader {
 public:
  SceneReader(std::filesystem::path file, SceneLoadOptions options)
      : JsonReader(std::move(file)), options_(std::move(options)) {}

  [[nodiscard]] const SceneLoadOptions& options() const { return options_; }

  /// The scene's "data": {"default": DIR} folder under the data root ("data:REL" paths).
  void set_data_default(std::string folder) { data_default_ = std::move(folder); }

  /// `j` (a non-empty string, `what` for messages) as a path: "data:REL" under the data folder,
  /// absolute as written, else relative to the scene file's folder. Existence is not checked.
  [[nodiscard]] std::filesystem::path path(const Json& j, const std::string& ptr,
                                           const std::string& what) const;
  /// path(), and the file must exist (else an error at `ptr` naming it).
  [[nodiscard]] std::filesystem::path existing_file(const Json& j, const std::string& ptr,
                                                    const std::string& what) const;

  /// The data folder "data:REL" paths resolve against: options().data_dir, else the scene's
  /// default folder under the data root. An error at `ptr` when it does not exist.
  [[nodiscard]] std::filesystem::path data_dir(const std::string& ptr) const;

 private:
  SceneLoadOptions options_;
  std::string data_default_;
};

/// `s` with ASCII letters lower-cased (file endings and name rules match case-insensitively).
[[nodiscard]] std::string ascii_lower(std::string s);

}  // namespace hapsim
