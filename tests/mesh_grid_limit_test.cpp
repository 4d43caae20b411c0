// Issue 28: `sdfc mesh --resolution` advertises 4..1024 cells along the longest
// side; the cell limit once counted the padding around the region too, so
// 1021..1024 were refused on any roughly cubic scene.
#include <gtest/gtest.h>

#include "driver/compile.h"
#include "mesher.h"

namespace sdfc {
namespace {

CompiledScene checked(const std::string& text) {
  Diagnostics diags;
  CompileOptions options;
  CompiledScene c = checkSource("grid.sdf", text, options, diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format(false);
  return c;
}

TEST(MeshGridLimit, EveryAdvertisedResolutionIsAccepted) {
  const CompiledScene c = checked("scene { box(size: [2, 2, 2]) }\n");
  for (int resolution : {1020, 1021, 1024}) {
    MeshOptions options;
    options.resolution = resolution;
    const GridPlanResult r = planGrid(c.scene, options);
    EXPECT_EQ(r.error, "") << "--resolution " << resolution;
    EXPECT_GE(r.plan.cells.x, resolution);
  }
}

TEST(MeshGridLimit, MoreThan1024CubedCellsInTheRegionAreRefused) {
  const CompiledScene c = checked("scene { box(size: [2, 2, 2]) }\n");
  MeshOptions options;
  options.voxel_size = 2.0 / 1100;
  const GridPlanResult r = planGrid(c.scene, options);
  EXPECT_NE(r.error.find("more than the limit of 1024^3"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace sdfc
