// Stage 4: deformable segments deflect under this step's contacts (eq. 1); the rest recover.
#include "hapsim/world/world_stages.h"
#include "hapsim/world/world_state.h"

namespace hapsim::stage {

// haptic path
void deform(const WorldModel& /*model*/, WorldState& state, double dt_s) noexcept {
  for (SegmentState& seg : state.segments) {
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
