#include "hapsim/ui/panel_layer.h"

#include <gtest/gtest.h>

namespace hapsim {
namespace {

TEST(PanelDraw, SomeoneUsingThePanelsGetsThemDrawnEveryFrame) {
  PanelRedrawInput in;
  in.interacting = true;
  in.since_drawn_s = 0.001;  // fresh, yet a hover or a click must show at once
  EXPECT_EQ(choose_panel_draw(in), PanelDraw::kDirect);
  in.picture_due = true;
  EXPECT_EQ(choose_panel_draw(in), PanelDraw::kDirect);
}

TEST(PanelDraw, OtherwiseTheyAreRedrawnAtTheRefreshIntervalAndCopiedBetween) {
  PanelRedrawInput in;
  in.refresh_s = 0.05;
  in.since_drawn_s = -1.0;  // never drawn at this size
  EXPECT_EQ(choose_panel_draw(in), PanelDraw::kRefresh);
  in.since_drawn_s = 0.0;
  EXPECT_EQ(choose_panel_draw(in), PanelDraw::kCopy);
  in.since_drawn_s = 0.049;
  EXPECT_EQ(choose_panel_draw(in), PanelDraw::kCopy);
  in.since_drawn_s = 0.05;
  EXPECT_EQ(choose_panel_draw(in), PanelDraw::kRefresh);
}

TEST(PanelDraw, APictureShowsThisFramesFigures) {
  PanelRedrawInput in;
  in.since_drawn_s = 0.001;
  in.picture_due = true;
  EXPECT_EQ(choose_panel_draw(in), PanelDraw::kRefresh);
}

}  // namespace
}  // namespace hapsim
