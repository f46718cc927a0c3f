#include "hapsim/core/device_profile.h"

#include "hapsim/core/error.h"
#include "hapsim/core/device_io.h"

#include <string>

namespace hapsim {
namespace {

// A workspace given as a radius (CHAI3D's `m_workspaceRadius`) becomes the cube that bounds the
// sphere: conservative enough for "is the tool still reachable" checks, cheap to test.
Box3 cube_workspace(double half_side_m) {
  return Box3(Vec3::Constant(-half_side_m), Vec3::Constant(half_side_m));
}

std::vector<DeviceProfile> make_builtin_profiles() {
  std::vector<DeviceProfile> profiles;

  // Values: /work/shared/data/tissue_device_values.csv, rows "CHAI3D default limits", i.e.
  // chai3d/chai3d@7c76b1f:src/devices/CPhantomDevices.cpp and CDeltaDevices.cpp (rendering
  // limits, conservative, not datasheet peaks).
  {
    DeviceProfile p;
    p.name = "touch";
    p.display_name = "3D Systems Touch (desktop stylus)";
    p.max_force_n = 3.3;              // CHAI3D CPhantomDevices.cpp
    p.max_continuous_force_n = 0.88;  // datasheet value; NOT verified in a source text (CSV row)
    p.max_stiffness_n_per_m = 400.0;  // CHAI3D
    p.max_damping_n_s_per_m = 4.0;    // CHAI3D
    p.workspace_world = cube_workspace(0.075);  // CHAI3D workspace radius 0.075 m
    p.source =
        "CHAI3D CPhantomDevices.cpp (3.3 N, 400 N/m, 4 N s/m, r 0.075 m); continuous 0.88 N from "
        "the commonly quoted datasheet (not verified in a source text)";
    profiles.push_back(p);
  }
  {
    DeviceProfile p;
    p.name = "phantom_omni";
    p.display_name = "SensAble PHANTOM Omni (desktop stylus)";
    p.max_force_n = 3.3;              // CHAI3D CPhantomDevices.cpp
    p.max_continuous_force_n = 0.88;  // ASSUMPTION: Touch datasheet value (the Omni's successor)
    p.max_stiffness_n_per_m = 700.0;  // CHAI3D
    p.max_damping_n_s_per_m = 5.0;    // CHAI3D
    p.workspace_world = cube_workspace(0.10);  // CHAI3D workspace radius 0.10 m
    p.source =
        "CHAI3D CPhantomDevices.cpp (3.3 N, 700 N/m, 5 N s/m, r 0.10 m); continuous force is an "
        "assumption (Touch datasheet)";
    profiles.push_back(p);
  }
  {
    DeviceProfile p;
    p.name = "omega3";
    p.display_name = "Force Dimension omega.3 (high-end desktop)";
    p.max_force_n = 12.0;              // CHAI3D CDeltaDevices.cpp
    p.max_continuous_force_n = 12.0;   // datasheet "12 N continuous"; NOT verified in a source
    p.max_stiffness_n_per_m = 5000.0;  // CHAI3D
    p.max_damping_n_s_per_m = 30.0;    // CHAI3D
    p.workspace_world = cube_workspace(0.075);  // CHAI3D workspace radius 0.075 m
    p.source =
        "CHAI3D CDeltaDevices.cpp (12 N, 5000 N/m, 30 N s/m, r 0.075 m); continuous 12 N from the "
        "commonly quoted datasheet (not verified in a source text)";
    profiles.push_back(p);
  }
  {
    DeviceProfile p;
    p.name = "falcon";
    p.display_name = "Novint Falcon";
    p.max_force_n = 8.0;                       // CHAI3D CDeltaDevices.cpp (Novint's table: > 8.9 N)
    p.max_continuous_force_n = 8.0;            // ASSUMPTION: no continuous rating found
    p.max_stiffness_n_per_m = 3000.0;          // CHAI3D
    p.max_damping_n_s_per_m = 20.0;            // CHAI3D
    p.workspace_world = cube_workspace(0.04);  // CHAI3D radius 0.04 m (Novint: 4x4x4 in cube)
    p.source =
        "CHAI3D CDeltaDevices.cpp (8 N, 3000 N/m, 20 N s/m, r 0.04 m); Novint table on the H3DAPI "
        "wiki (> 8.9 N, 4x4x4 in); continuous force is an assumption";
    profiles.push_back(p);
  }
  {
    // Seed 001 (Burdea et al., knee palpation), section 2: "pneumatic micro actuators ... return
    // about 4N per fingertip", "designed for four fingers", "total force of about 4N/actuator",
    // "rise time of 14 ms", "relaxing time of 62 ms".
    DeviceProfile p;
    p.name = "rutgers_master";
    p.display_name = "Rutgers Master (pneumatic force glove, 4 fingers)";
    p.max_force_n = 0.0;  // no tip actuator: a glove pushes on the fingers only
    p.finger_count = 4;
    p.max_finger_force_n = 4.0;                // seed 001 s.2
    p.max_continuous_force_n = 4.0;            // ASSUMPTION: pneumatic, no thermal limit stated
    p.max_stiffness_n_per_m = 400.0;           // ASSUMPTION: not in the seed or CSV (4 N at 10 mm)
    p.max_damping_n_s_per_m = 0.0;             // ASSUMPTION: unknown, render no damping
    p.workspace_world = cube_workspace(0.75);  // ASSUMPTION: Polhemus-tracked hand, ~1.5 m
    p.max_force_rate_n_per_s = 4.0 / 0.014;    // derived: full 4 N in the 14 ms rise time
    p.source =
        "seed 001 s.2 (about 4 N per fingertip, 4 fingers, 14 ms rise time); stiffness, workspace "
        "and continuous force are assumptions";
    profiles.push_back(p);
  }
  {
    // No hardware: generous limits so tests and scripted scenes see the simulation's own forces,
    // still finite so the clamp is exercised.
    DeviceProfile p;
    p.name = "simulated";
    p.display_name = "Simulated device (scripted or recorded trajectory)";
    p.max_force_n = 100.0;
    p.max_continuous_force_n = 100.0;
    p.max_stiffness_n_per_m = 1.0e5;
    p.max_damping_n_s_per_m = 1000.0;
    p.workspace_world = cube_workspace(1.0);
    p.finger_count = kMaxFingers;
    p.max_finger_force_n = 50.0;
    p.max_joint_torque_nm = 100.0;
    p.source = "hapsim choice: generous limits for simulation, not a real device";
    profiles.push_back(p);
  }
  return profiles;
}

}  // namespace

const std::vector<DeviceProfile>& builtin_device_profiles() {
  static const std::vector<DeviceProfile> profiles = make_builtin_profiles();
  return profiles;
}

std::vector<std::string> device_profile_names() {
  std::vector<std::string> names;
  for (const DeviceProfile& p : builtin_device_profiles()) {
    names.push_back(p.name);
  }
  return names;
}

const DeviceProfile& device_profile(std::string_view name) {
  for (const DeviceProfile& p : builtin_device_profiles()) {
    if (p.name == name) {
      return p;
    }
  }
  std::string known;
  for (const DeviceProfile& p : builtin_device_profiles()) {
    known += (known.empty() ? "" : ", ") + p.name;
  }
  throw Error("device profile",
              "unknown device '" + std::string(name) + "'; known devices: " + known);
}

}  // namespace hapsim
