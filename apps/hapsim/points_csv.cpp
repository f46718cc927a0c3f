#include "points_csv.h"

#include "number_csv.h"

namespace hapsim::app {

std::vector<Vec3> read_points_csv(const std::filesystem::path& path) {
  std::vector<Vec3> points;
  for (const std::vector<double>& r : read_number_rows_csv(path, 3, "x,y,z", "points")) {
    points.emplace_back(r[0], r[1], r[2]);
  }
  return points;
}

}  // namespace hapsim::app
