// Fixture for the include-layer test: script (layer 5.0) including scene (5.2) must be reported.
#pragma once
#include "hapsim/scene/scene_file.h"
