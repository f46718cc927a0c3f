// Fixture for the include-layer test.
#pragma once
