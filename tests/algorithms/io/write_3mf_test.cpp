#include "cranioplan/algorithms/io/write_3mf.h"

#include <gtest/gtest.h>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

// Two named parts and the plan's metadata: lib3mf reads back the names, millimetres, every
// vertex (to the float the format stores) and triangle, closed; the same parts give the same
// bytes.
TEST(Write3mf, NamedPartsInMillimetresWithMetadataReadBack) {
  const SkullMesh a = test::make_symmetric_head(2);
  const SkullMesh b = build_mesh(test::box_soup({10, 20, 30}, {15.5, 21.25, 40}));
  const std::string bytes =
      encode_3mf({{"implant", &a}, {"mould outer", &b}},
                 {{"Application", "Cranioplan"}, {"Description", "plan ab12"}});
  EXPECT_EQ(bytes, encode_3mf({{"implant", &a}, {"mould outer", &b}},
                              {{"Application", "Cranioplan"}, {"Description", "plan ab12"}}))
      << "deterministic";
  test::TempDir dir;
  const std::string path = dir.path("plan.3mf");
  write_file_atomically(path, bytes);
  const Read3mf back = read_3mf(path);
  EXPECT_EQ(back.unit_mm, 1.0);
  EXPECT_EQ(back.metadata.at("Description"), "plan ab12");
  EXPECT_EQ(back.metadata.at("Application"), "Cranioplan");
  ASSERT_EQ(back.parts.size(), 2u);
  EXPECT_EQ(back.parts[0].first, "implant");
  EXPECT_EQ(back.parts[1].first, "mould outer");
  for (int k = 0; k < 2; ++k) {
    const SkullMesh& in = k == 0 ? a : b;
    const SkullMesh& out = back.parts[static_cast<size_t>(k)].second;
    ASSERT_EQ(out.n_vertices(), in.n_vertices());
    ASSERT_EQ(out.n_faces(), in.n_faces());
    for (auto vh : in.vertices())
      EXPECT_LT((to_eigen(out.point(vh)) - to_eigen(in.point(vh))).norm(), 1e-4);
    EXPECT_TRUE(report_mesh(out).watertight);
    EXPECT_NEAR(report_mesh(out).volume_mm3, report_mesh(in).volume_mm3,
                1e-5 * report_mesh(in).volume_mm3);
  }
  // Through write_mesh: a .3mf path writes the part "implant".
  write_mesh(b, dir.path("box.3mf"));
  const Read3mf one = read_3mf(dir.path("box.3mf"));
  ASSERT_EQ(one.parts.size(), 1u);
  EXPECT_EQ(one.parts[0].first, "implant");
}

TEST(Write3mf, AFileThatIsNoPackageIsNamed) {
  test::TempDir dir;
  const std::string path = dir.path("bad.3mf");
  write_file_atomically(path, "not a zip");
  try {
    read_3mf(path);
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.3mf"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cranioplan
