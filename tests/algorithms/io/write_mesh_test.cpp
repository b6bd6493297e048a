#include "cranioplan/algorithms/io/write_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "cranioplan/model/error.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

TEST(WriteMesh, RefusesUnknownExtensionAndMissingFolder) {
  const SkullMesh head = test::make_symmetric_head(1);
  EXPECT_THROW(write_mesh(head, "/tmp/x.obj"), InputError);
  EXPECT_THROW(write_mesh(head, "/nonexistent-folder-xyz/x.stl"), InputError);
}

// A binary STL: an 80-byte header, the count, and 50 bytes per triangle (normal, three
// corners, attribute); the same mesh gives the same bytes every time.
TEST(WriteMesh, BinaryStlHasTheLayoutEveryReaderExpects) {
  const SkullMesh head = test::make_symmetric_head(1);
  const std::string bytes = encode_mesh(head, MeshFormat::BinarySTL);
  ASSERT_EQ(bytes.size(), 84 + 50 * head.n_faces());
  uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  EXPECT_EQ(count, head.n_faces());
  EXPECT_NE(bytes.substr(0, 5), "solid") << "a binary STL must not look like an ASCII one";
  EXPECT_EQ(encode_mesh(head, MeshFormat::BinarySTL), bytes);
  // The first triangle's normal is a unit vector.
  float n[3];
  std::memcpy(n, bytes.data() + 84, 12);
  EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-5);
}

TEST(WriteMesh, PlyNamesItsElementsAndTheFileIsReplacedWhole) {
  const SkullMesh head = test::make_symmetric_head(1);
  const std::string ply = encode_mesh(head, MeshFormat::BinaryPLY);
  EXPECT_EQ(ply.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(ply.find("element vertex " + std::to_string(head.n_vertices())), std::string::npos);
  EXPECT_NE(ply.find("element face " + std::to_string(head.n_faces())), std::string::npos);
  EXPECT_EQ(mesh_format_for_path("IMPLANT.PLY"), MeshFormat::BinaryPLY);
  test::TempDir dir;
  const std::string path = dir.path("implant.stl");
  test::write_bytes(path, "an older, longer file that the export replaces entirely ...........");
  write_mesh(head, path);
  EXPECT_EQ(test::read_bytes(path), encode_mesh(head, MeshFormat::BinarySTL));
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path(""))) ++files;
  EXPECT_EQ(files, 1u) << "no temporary file is left beside the export";
}

}  // namespace
}  // namespace cranioplan
