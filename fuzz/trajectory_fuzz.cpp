// Fuzz target: bytes as a trajectory CSV (parse_trajectory_csv). Checks: it returns a trajectory
// whose invariants hold (times strictly increasing, finite, unit quaternions; sample_at stays
// finite anywhere, NaN time included) or throws hapsim::Error; nothing else escapes.
#include "file_fuzz_support.h"
#include "hapsim/script/trajectory.h"

#include <cmath>
#include <limits>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hapsim::fuzz::expect_value_or_error([&] {
    const hapsim::Trajectory t =
        hapsim::parse_trajectory_csv(hapsim::fuzz::as_text(data, size), "fuzz.csv");
    HAPSIM_FUZZ_CHECK(!t.empty(), "a parsed trajectory has samples");
    for (std::size_t i = 0; i < t.size(); ++i) {
      const hapsim::DeviceInput& s = t.samples[i];
      HAPSIM_FUZZ_CHECK(std::isfinite(s.time_s) && s.p_world.allFinite(), "samples are finite");
      HAPSIM_FUZZ_CHECK(std::abs(s.q_world.norm() - 1.0) < 1e-9, "quaternions are unit");
      HAPSIM_FUZZ_CHECK(i == 0 || s.time_s > t.samples[i - 1].time_s, "times increase");
    }
    for (const double time_s : {t.start_time_s() - 1.0, 0.5 * (t.start_time_s() + t.end_time_s()),
                                t.end_time_s() + 1.0}) {
      HAPSIM_FUZZ_CHECK(t.sample_at(time_s).p_world.allFinite(), "sample_at is finite");
    }
    (void)t.sample_at(std::numeric_limits<double>::quiet_NaN());
  });
  return 0;
}
