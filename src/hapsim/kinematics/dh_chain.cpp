#include "hapsim/kinematics/dh_chain.h"

#include <vector>

namespace hapsim {

namespace {

// The constant part of a row: Rz(θ)·Tz(d)·Tx(a)·Rx(α). The joint's motion (about or along z of
// the previous frame) comes before it; Rz and Tz commute, so this holds for both joint types.
Iso3 dh_constant(const DhRow& r) {
  Iso3 X = Iso3::Identity();
  X.rotate(Eigen::AngleAxisd(r.theta_rad, Vec3::UnitZ()));
  X.translate(Vec3(0.0, 0.0, r.d_m));
  X.translate(Vec3(r.a_m, 0.0, 0.0));
  X.rotate(Eigen::AngleAxisd(r.alpha_rad, Vec3::UnitX()));
  return X;
}

}  // namespace

SerialChain make_dh_chain(std::span<const DhRow> rows) {
  std::vector<ChainJoint> joints;
  Iso3 previous = Iso3::Identity();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const DhRow& r = rows[i];
    ChainJoint j;
    j.name = r.name.empty() ? "joint_" + std::to_string(i + 1) : r.name;
    j.type = r.type;
    j.X_parent_joint = previous;
    j.axis = Vec3::UnitZ();
    j.lower = r.lower;
    j.upper = r.upper;
    j.max_velocity = r.max_velocity;
    j.child_link = "link_" + std::to_string(i + 1);
    joints.push_back(std::move(j));
    previous = dh_constant(r);
  }
  return SerialChain("link_0", std::move(joints), previous, "link_" + std::to_string(rows.size()));
}

}  // namespace hapsim
