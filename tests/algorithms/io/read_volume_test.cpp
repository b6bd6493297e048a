#include "cranioplan/algorithms/io/read_volume.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

TEST(ReadVolume, AMissingFileIsAnInputErrorAndFormatsGoByExtension) {
  test::TempDir dir;
  EXPECT_THROW(read_volume(dir.path("missing.nrrd")), InputError);
  EXPECT_TRUE(is_volume_path("a/b/CT.NII.GZ"));
  EXPECT_TRUE(is_volume_path("x.nhdr"));
  EXPECT_TRUE(is_volume_path("case.inv3"));
  EXPECT_FALSE(is_volume_path("skull.stl"));
}

// A CT loaded as a skull holds its surface once: OpenMesh meshes cannot be moved, so a copy of
// the import would stay in `surface` beside `mesh` for the skull's whole life (about 300 MB on
// a SkullFix mask).
TEST(ReadVolume, ALoadedVolumeHoldsItsSurfaceOnce) {
  test::TempDir dir;
  const std::string p = dir.path("ball.nrrd");
  test::write_nrrd(test::oblique_ball_volume(Eigen::Vector3d(-120, 40, 17)), p, false);
  const LoadedSkull loaded = load_surface(p);
  EXPECT_EQ(loaded.source_kind, SkullSource::Volume);
  EXPECT_GT(loaded.mesh.n_faces(), 1000u);
  EXPECT_EQ(loaded.surface.mesh.n_vertices(), 0u);
  EXPECT_TRUE(loaded.surface.usable());
}

}  // namespace
}  // namespace cranioplan
