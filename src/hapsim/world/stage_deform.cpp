// Stage 5: deformable segments deflect under this step's contacts (eq. 1), the rest recover;
// sheets take this step's pushes (the Gaussian profile summed over them) and the imprint of the
// dynamic spheres resting on them.
#include "hapsim/world/world_model.h"
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

namespace hapsim::stage {

namespace {

// haptic path
void deform_sheet(const WorldModel& model, WorldState& state, const SegmentModel& seg,
                  SegmentState& sheet) noexcept {
  sheet.sheet->apply_contacts({sheet.sheet_pushes.data(), sheet.sheet_push_count});
  const Iso3& X_sheet_world = state.X_body_world(seg);
  for (std::size_t k = 0; k < state.body_contact_count; ++k) {
    const BodyContact& c = state.body_contacts[k];
    if (c.other_body != BodyIndex{seg.body}) {
      continue;
    }
    // A sphere resting on the sheet transcribes its lower cap (paper 000 §3.2.2, Fig. 2); a
    // mesh presses it through its pushes only.
    const std::size_t b = c.body.index();
    if (!model.bodies()[b].sphere) {
      continue;
    }
    const ExactSphere& sphere = *model.bodies()[b].sphere;
    sheet.sheet->imprint_sphere(X_sheet_world * (state.bodies[b].X_world_body * sphere.center_body),
                                sphere.radius_m);
  }
  sheet.sheet_dirty = true;
}

}  // namespace

// haptic path
void deform(const WorldModel& model, WorldState& state, double dt_s) noexcept {
  const std::vector<SegmentModel>& segs = model.segments();
  std::size_t sheet_index = 0;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    SegmentState& seg = state.segments[i];
    if (seg.sheet) {
      deform_sheet(model, state, segs[i], seg);
      state.sheet_depth_m[sheet_index++] = seg.sheet->max_depth_m();
      continue;
    }
    if (!seg.deflection) {
      continue;
    }
    seg.deflection->step({seg.pending.data(), seg.pending_count}, dt_s);
    if (!seg.deflection->moved_vertices().empty()) {
      seg.deformed_dirty = true;
    }
  }
}

}  // namespace hapsim::stage
