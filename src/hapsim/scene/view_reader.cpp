#include "hapsim/scene/view_reader.h"

namespace hapsim {

std::vector<SceneView> read_views(const JsonReader& reader, const JsonReader::Json& j,
                                  const std::string& ptr) {
  reader.object(j, ptr, "named camera views (name: {eye_m, target_m, fov_deg})");
  std::vector<SceneView> views;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string at = JsonReader::at(ptr, it.key());
    const JsonReader::Json& v = reader.object(it.value(), at, "a view {eye_m, target_m, fov_deg}");
    reader.allow_keys(v, at, {"description", "eye_m", "target_m", "fov_deg"});
    SceneView view;
    view.name = it.key();
    view.eye_m = reader.vec3(reader.required(v, at, "eye_m"), JsonReader::at(at, "eye_m"), "m");
    view.target_m =
        reader.vec3(reader.required(v, at, "target_m"), JsonReader::at(at, "target_m"), "m");
    view.fov_deg = reader.number_in(v, at, "fov_deg", 40.0, 1.0, 170.0, "degrees", true);
    if ((view.eye_m - view.target_m).norm() < 1e-6) {
      reader.fail(JsonReader::at(at, "eye_m"), "the eye is on its target: give them apart");
    }
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace hapsim
