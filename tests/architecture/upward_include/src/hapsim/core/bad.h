// Fixture for the include-layer test: core including world must be reported.
#pragma once
#include "hapsim/world/world.h"
