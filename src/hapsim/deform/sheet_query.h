// The virtual sheet as a proximity query, so that tools and bodies meet it through the same
// contact code as every other segment (world stages). Answers against one of the sheet's height
// fields (the elastic one by default: a body lies exactly on its own imprint, so the imprinted
// surface would hide the sheet from it; see virtual_sheet.h). Above the sheet is outside; below
// it, over its square, is inside (a sphere pushed through is pushed back up). Reads the sheet
// live: nothing to refit after the sheet moves.
#pragma once

#include "hapsim/collision/proximity_query.h"
#include "hapsim/deform/virtual_sheet.h"

namespace hapsim {

class SheetQuery final : public ProximityQuery {
 public:
  /// Keeps a reference to `sheet`: it must outlive the query.
  explicit SheetQuery(const VirtualSheet& sheet, SheetLayer layer = SheetLayer::kElastic)
      : sheet_(&sheet), layer_(layer) {}

  /// SurfacePoint::triangle is kSdfSurface (found, not a mesh triangle). haptic path
  [[nodiscard]] SurfacePoint closest_point(const Vec3& p, QueryHint* hint = nullptr) const override;
  bool contact_within(const Vec3& p, double radius, SurfacePoint* out,
                      QueryHint* hint = nullptr) const override;
  void refit() override {}
  [[nodiscard]] std::size_t memory_bytes() const override { return sizeof(*this); }
  [[nodiscard]] std::string_view method_name() const override { return "sheet"; }

 private:
  const VirtualSheet* sheet_;
  SheetLayer layer_;
};

}  // namespace hapsim
