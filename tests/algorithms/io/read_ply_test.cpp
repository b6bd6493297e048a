#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/read_mesh.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "io/mesh_formats.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

using test::TempDir;

// Expects the PLY reader to refuse `bytes` read as `path`, naming the file and `part`.
void expect_bad(const std::string& path, const std::string& part) {
  try {
    detail::read_ply(path, test::read_bytes(path));
    FAIL() << "expected an error for " << path;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
  }
}

// A PLY of the unit square (two triangles as one quad) with properties and an element the
// reader must read past: normals, a colour, a face flag and an edge element.
std::string square_ply(const std::string& encoding) {
  std::string s = "ply\r\nformat " + encoding +
                  " 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\n"
                  "property double y\nproperty float z\nproperty float nx\nproperty uchar red\n"
                  "element face 1\nproperty uchar flag\nproperty list uchar uint vertex_indices\n"
                  "element edge 1\nproperty int a\nproperty int b\nend_header\n";
  const float xs[4] = {0, 1, 1, 0};
  const double ys[4] = {0, 0, 1, 1};
  if (encoding == "ascii") {
    for (int i = 0; i < 4; ++i)
      s += std::to_string(xs[i]) + " " + std::to_string(ys[i]) + " 0 0.5 255\n";
    return s + "7 4 0 1 2 3\n0 1\n";
  }
  const bool big = encoding == "binary_big_endian";
  auto put = [&](const auto& value) {
    char b[sizeof(value)];
    std::memcpy(b, &value, sizeof(value));
    if (big) std::reverse(b, b + sizeof(value));
    s.append(b, sizeof(value));
  };
  for (int i = 0; i < 4; ++i) {
    put(xs[i]);
    put(ys[i]);
    put(0.0f);
    put(0.5f);
    put(static_cast<uint8_t>(255));
  }
  put(static_cast<uint8_t>(7));
  put(static_cast<uint8_t>(4));
  for (uint32_t v : {0u, 1u, 2u, 3u}) put(v);
  put(0);
  put(1);
  return s;
}

TEST(ReadPly, WhatWriteMeshWritesReadsBack) {
  TempDir dir;
  const SkullMesh head = test::make_symmetric_head(2);
  write_mesh(head, dir.path("head.ply"));
  const MeshFile f = read_mesh(dir.path("head.ply"));
  // Meshes are read in canonical order (make_canonical): the head's own soup put in that order.
  TriangleSoup expected = to_soup(head);
  make_canonical(expected);
  TriangleSoup got = to_soup(f.mesh);
  ASSERT_EQ(got.vertices.size(), expected.vertices.size());
  for (size_t i = 0; i < got.vertices.size(); ++i)
    EXPECT_LT((got.vertices[i] - expected.vertices[i]).norm(), 1e-4);  // rounded to float
  make_canonical(got);  // each triangle from its smallest corner, as the expected ones
  EXPECT_EQ(got.triangles, expected.triangles);
}

TEST(ReadPly, PlyInEveryEncodingWithOtherPropertiesAndElements) {
  TempDir dir;
  for (const char* encoding : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    const std::string p = dir.path(std::string(encoding) + ".ply");
    test::write_bytes(p, square_ply(encoding));
    const MeshFile f = read_mesh(p);
    EXPECT_EQ(f.format, "PLY");
    EXPECT_EQ(f.mesh.n_faces(), 2u) << encoding;
    EXPECT_EQ(f.mesh.n_vertices(), 4u) << encoding;
    EXPECT_NEAR(report_mesh(f.mesh).area_mm2, 1.0, 1e-9) << encoding;
  }
}

TEST(ReadPly, BadFilesGiveAMessageNotACrash) {
  TempDir dir;
  auto bad = [&](const std::string& name, const std::string& bytes, const std::string& part) {
    test::write_bytes(dir.path(name), bytes);
    expect_bad(dir.path(name), part);
  };
  const std::string ascii = square_ply("ascii");
  const std::string binary = square_ply("binary_little_endian");
  // Each of these crashed VTK's reader (segfault, abort) or was read as nothing.
  bad("truncated.ply", binary.substr(0, binary.size() - 30), "the file ends in item");
  const std::string head = ascii.substr(0, ascii.find("end_header") + 11);
  bad("long-face.ply", head + "0 0 0 0 0\n1 0 0 0 0\n1 1 0 0 0\n0 1 0 0 0\n7 200 0 1 2\n0 1\n",
      "the file ends in item 1 of 1 of element 'face'");
  bad("empty-header.ply", "ply\nformat ascii 1.0\nend_header\n", "no vertex element");
  bad("no-y.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n",
      "no y coordinate");
  bad("no-end.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
      "no 'end_header'");
  bad("no-format.ply", "ply\nelement vertex 0\nend_header\n", "no 'format' line");
  bad("keyword.ply", "ply\nformat ascii 1.0\nvertices 3\nend_header\n",
      "unknown header keyword 'vertices' on header line 3");
  bad("not-ply.ply", "PLY file\n", "does not start with 'ply'");
  bad("index.ply", head + "0 0 0 0 0\n1 0 0 0 0\n1 1 0 0 0\n0 1 0 0 0\n7 3 0 1 9\n0 1\n",
      "face 1 uses vertex 9 but the file has 4 vertices");
  bad("word.ply", head + "0 0 0 0 0\n1 x 0 0 0\n", "'x' is not a number, in item 2 of 4");
  bad("huge.ply",
      "ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n" +
          std::string(24, '\0'),
      "the file ends in item 3 of 2,000,000,000 of element 'vertex'");
}

}  // namespace
}  // namespace cranioplan
