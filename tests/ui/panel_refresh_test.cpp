// When the viewer redraws its panels (ui/panel_refresh.h): at the start, at least every interval,
// on any event at or just off a panel, on keys and exposures, and while ImGui holds the input;
// never for the pointer working in the 3D view.
#include "hapsim/ui/panel_refresh.h"

#include <gtest/gtest.h>

#include <limits>

namespace hapsim {
namespace {

TEST(PanelRefresh, DueAtTheStartThenOnlyAfterTheInterval) {
  PanelRefresh r(0.05);
  EXPECT_TRUE(r.due(0.0, false));
  r.drawn(0.0);
  EXPECT_FALSE(r.due(0.01, false));
  EXPECT_FALSE(r.due(0.049, false));
  EXPECT_TRUE(r.due(0.05, false));
  r.drawn(0.06);
  EXPECT_FALSE(r.due(0.1, false));
  EXPECT_TRUE(r.due(0.11, false));
}

TEST(PanelRefresh, ThePointerInThe3dViewLeavesThemButOnOrJustOffAPanelDoesNot) {
  PanelRefresh r(1.0);
  r.drawn(0.0);
  r.pointer_event(false);  // orbiting or probing in the 3D view
  EXPECT_FALSE(r.due(0.1, false));
  r.pointer_event(true);  // onto a panel: hover highlights
  EXPECT_TRUE(r.due(0.1, false));
  r.drawn(0.1);
  r.pointer_event(false);  // just off it: the highlight must go
  EXPECT_TRUE(r.due(0.2, false));
  r.drawn(0.2);
  r.pointer_event(false);
  EXPECT_FALSE(r.due(0.3, false));
}

TEST(PanelRefresh, KeysExposuresAndImGuiHoldingTheInputDrawThemEveryFrame) {
  PanelRefresh r(1.0);
  r.drawn(0.0);
  r.other_event();
  EXPECT_TRUE(r.due(0.01, false));
  r.drawn(0.01);
  EXPECT_FALSE(r.due(0.02, false));
  EXPECT_TRUE(r.due(0.02, true));  // a slider dragged, a menu open
  EXPECT_TRUE(r.due(0.03, true));
}

TEST(PanelRefresh, ANanClockOrIntervalDrawsThemEveryFrame) {
  PanelRefresh nan_interval(std::numeric_limits<double>::quiet_NaN());
  nan_interval.drawn(0.0);
  EXPECT_TRUE(nan_interval.due(0.001, false));
  PanelRefresh r(0.05);
  r.drawn(0.0);
  EXPECT_TRUE(r.due(std::numeric_limits<double>::quiet_NaN(), false));
}

}  // namespace
}  // namespace hapsim
