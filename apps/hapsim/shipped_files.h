// The shipped files the commands read (the loopback-only Cyclone DDS config, the scenes, the
// assessment report's script): PREFIX/share/hapsim/... when `hapsim` is installed, else the
// source tree's, whose paths the build gives (HAPSIM_BUILD_TREE_*, apps/CMakeLists.txt).
#pragma once

#include "hapsim/core/install_dirs.h"

#ifndef HAPSIM_DEFAULT_DDS_CONFIG
#define HAPSIM_DEFAULT_DDS_CONFIG \
  ::hapsim::shipped_path("config/cyclonedds-loopback.xml", HAPSIM_BUILD_TREE_DDS_CONFIG)
#endif
#ifndef HAPSIM_SCENES_DIR
#define HAPSIM_SCENES_DIR ::hapsim::shipped_path("scenes", HAPSIM_BUILD_TREE_SCENES_DIR)
#endif
#ifndef HAPSIM_ASSESSMENT_REPORT_SCRIPT
#define HAPSIM_ASSESSMENT_REPORT_SCRIPT \
  ::hapsim::shipped_path("assessment_report.py", HAPSIM_BUILD_TREE_REPORT_SCRIPT)
#endif
