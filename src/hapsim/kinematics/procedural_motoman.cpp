#include "hapsim/kinematics/procedural_motoman.h"

#include "hapsim/kinematics/dh_chain.h"

#include <numbers>
#include <vector>

namespace hapsim {

SerialChain make_procedural_motoman() {
  constexpr double kPi = std::numbers::pi;
  // Limits and speeds: gp7.urdf (joint_1_s .. joint_6_t).
  const std::vector<DhRow> rows{
      {.a_m = 0.04,
       .alpha_rad = -kPi / 2,
       .d_m = 0.33,
       .lower = -2.967,
       .upper = 2.967,
       .max_velocity = 6.5448,
       .name = "joint_1_s"},
      {.a_m = 0.445,
       .theta_rad = -kPi / 2,
       .lower = -1.1344,
       .upper = 2.5307,
       .max_velocity = 5.4977,
       .name = "joint_2_l"},
      {.a_m = 0.04,
       .alpha_rad = -kPi / 2,
       .lower = -1.2217,
       .upper = 3.3161,
       .max_velocity = 7.1558,
       .name = "joint_3_u"},
      {.alpha_rad = kPi / 2,
       .d_m = 0.44,
       .lower = -3.3161,
       .upper = 3.3161,
       .max_velocity = 9.5993,
       .name = "joint_4_r"},
      {.alpha_rad = -kPi / 2,
       .lower = -2.3561,
       .upper = 2.3561,
       .max_velocity = 9.5993,
       .name = "joint_5_b"},
      {.d_m = 0.08,
       .lower = -6.2944,
       .upper = 6.2944,
       .max_velocity = 17.4845,
       .name = "joint_6_t"},
  };
  return make_dh_chain(rows);
}

}  // namespace hapsim
