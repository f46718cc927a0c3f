// `hapsim fk URDF --joints FILE.csv [--tip LINK]`: the tip pose (x,y,z,qw,qx,qy,qz, metres, base
// frame) for each row of joint values (radians or metres, in the chain's order).
// `hapsim ik URDF --poses FILE.csv [--tip LINK]`: joint values reaching each pose, and whether
// they do; each row starts from the previous row's answer (a path is tracked), the first from the
// middle of the limits.
#include "checked_output.h"
#include "commands.h"
#include "number_csv.h"

#include "hapsim/kinematics/inverse_kinematics.h"
#include "hapsim/kinematics/urdf_chain.h"

#include <cmath>
#include <cstdio>
#include <memory>

namespace hapsim::app {
namespace {

struct KinematicsOptions {
  std::string urdf;
  std::string rows;
  std::string base;
  std::string tip;
  std::string out_path;
};

SerialChain load_chain(const KinematicsOptions& opt) {
  UrdfChainOptions o;
  o.base_link = opt.base;
  o.tip_link = opt.tip;
  o.load_collision_meshes = false;  // not needed for FK/IK; a missing mesh must not stop them
  return load_urdf_chain(opt.urdf, o);
}

std::string joint_names(const SerialChain& chain) {
  std::string names;
  for (const ChainJoint& j : chain.joints()) {
    names += (names.empty() ? "" : ",") + j.name;
  }
  return names;
}

void write_pose(std::FILE* f, const Iso3& X) {
  Quat q(X.linear());
  if (q.w() < 0.0) {
    q.coeffs() = -q.coeffs();  // one of the two equal quaternions: w >= 0
  }
  std::fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", X.translation().x(),
               X.translation().y(), X.translation().z(), q.w(), q.x(), q.y(), q.z());
}

void run_fk(const KinematicsOptions& opt) {
  const SerialChain chain = load_chain(opt);
  const auto n = static_cast<std::size_t>(chain.dof());
  const auto rows = read_number_rows_csv(opt.rows, n, joint_names(chain), "joint rows");
  std::size_t outside = 0;
  for (const auto& q : rows) {
    outside += chain.within_limits(q) ? 0 : 1;
  }
  OutputFile out_file("--out", opt.out_path);
  std::FILE* out = out_file.get();
  std::fprintf(out, "x,y,z,qw,qx,qy,qz\n");
  for (const auto& q : rows) {
    write_pose(out, chain.forward(q));
    std::fprintf(out, "\n");
  }
  out_file.commit();
  std::FILE* info = out_file.info();
  std::fprintf(info, "hapsim fk: %zu rows, chain %s -> %s (%zu joints)%s\n", rows.size(),
               chain.base_link().c_str(), chain.tip_link().c_str(), n,
               outside > 0
                   ? (", " + std::to_string(outside) + " row(s) outside the joint limits").c_str()
                   : "");
}

void run_ik(const KinematicsOptions& opt) {
  const SerialChain chain = load_chain(opt);
  const auto n = static_cast<std::size_t>(chain.dof());
  const auto rows = read_number_rows_csv(opt.rows, 7, "x,y,z,qw,qx,qy,qz", "poses");
  std::vector<Iso3> targets;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const auto& v = rows[r];
    const Quat q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      throw CommandError(opt.rows + ": pose row " + std::to_string(r + 1) +
                         ": quaternion qw,qx,qy,qz has norm " + std::to_string(q.norm()) +
                         ", expected a unit quaternion");
    }
    Iso3 X = Iso3::Identity();
    X.linear() = q.normalized().toRotationMatrix();
    X.translation() = Vec3(v[0], v[1], v[2]);
    targets.push_back(X);
  }
  std::vector<double> seed(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const ChainJoint& j = chain.joints()[i];
    seed[i] = std::isfinite(j.lower) && std::isfinite(j.upper) ? 0.5 * (j.lower + j.upper) : 0.0;
  }
  OutputFile out_file("--out", opt.out_path);
  std::FILE* out = out_file.get();
  std::fprintf(out, "%s,reached\n", joint_names(chain).c_str());
  std::vector<double> q(n);
  std::size_t reached = 0;
  double worst_position_m = 0.0;
  double worst_rotation_rad = 0.0;
  for (const Iso3& X : targets) {
    const IkResult r = solve_ik(chain, X, seed, q);
    for (std::size_t i = 0; i < n; ++i) {
      std::fprintf(out, "%.17g,", q[i]);
    }
    std::fprintf(out, "%d\n", r.reached ? 1 : 0);
    if (r.reached) {
      ++reached;
      worst_position_m = std::max(worst_position_m, r.position_error_m);
      worst_rotation_rad = std::max(worst_rotation_rad, r.rotation_error_rad);
      seed = q;  // track the path
    }
  }
  out_file.commit();
  std::FILE* info = out_file.info();
  std::fprintf(info,
               "hapsim ik: %zu poses, %zu reached (largest error %.3g mm, %.3g deg), %zu "
               "unreachable; chain %s -> %s\n",
               targets.size(), reached, worst_position_m * 1e3,
               worst_rotation_rad * 180.0 / 3.14159265358979323846, targets.size() - reached,
               chain.base_link().c_str(), chain.tip_link().c_str());
}

CLI::App* add_common(CLI::App& app, const char* name, const char* help,
                     const std::shared_ptr<KinematicsOptions>& opt, const char* rows_option,
                     const char* rows_help) {
  CLI::App* cmd = app.add_subcommand(name, help);
  cmd->add_option("urdf", opt->urdf, "URDF file (read through urdfdom)")->required();
  cmd->add_option(rows_option, opt->rows, rows_help)->required();
  cmd->add_option("--base", opt->base, "First link of the chain (default: the URDF's root)");
  cmd->add_option("--tip", opt->tip, "Last link of the chain (default: the deepest leaf)");
  cmd->add_option("--out", opt->out_path, "Write the CSV here instead of standard output");
  return cmd;
}

}  // namespace

void add_kinematics_commands(CLI::App& app) {
  auto fk = std::make_shared<KinematicsOptions>();
  add_common(app, "fk", "Forward kinematics: tip pose for each row of joint values", fk, "--joints",
             "CSV of joint rows in the chain's order (rad or m; header optional)")
      ->callback([fk] { run_fk(*fk); });
  auto ik = std::make_shared<KinematicsOptions>();
  add_common(app, "ik", "Inverse kinematics: joint values reaching each pose", ik, "--poses",
             "CSV of x,y,z,qw,qx,qy,qz rows (metres, base frame; header optional)")
      ->callback([ik] { run_ik(*ik); });
}

}  // namespace hapsim::app
