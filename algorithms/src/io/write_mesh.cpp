#include "cranioplan/algorithms/io/write_mesh.h"

#include <Eigen/Geometry>
#include <cstdint>
#include <cstring>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/algorithms/io/write_3mf.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"

namespace cranioplan {
namespace {

template <class T>
void put(std::string& out, T value) {
  char buf[sizeof(T)];
  std::memcpy(buf, &value, sizeof(T));
  out.append(buf, sizeof(T));
}

std::string encode_stl(const SkullMesh& mesh) {
  std::string out;
  out.reserve(84 + 50 * mesh.n_faces());
  std::string header = "binary STL written by Cranioplan, units mm";
  header.resize(80, ' ');
  out += header;
  put<uint32_t>(out, static_cast<uint32_t>(mesh.n_faces()));
  for (auto fh : mesh.faces()) {
    const FaceCorners f = face_corners(mesh, fh);
    const auto& p = f.p;
    Eigen::Vector3d n = f.cross();
    if (n.norm() > 0) n.normalize();
    for (int c = 0; c < 3; ++c) put<float>(out, static_cast<float>(n[c]));
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) put<float>(out, static_cast<float>(p[v][c]));
    put<uint16_t>(out, 0);
  }
  return out;
}

std::string encode_ply(const SkullMesh& mesh) {
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment Cranioplan, units mm\n";
  out += "element vertex " + std::to_string(mesh.n_vertices()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  out += "element face " + std::to_string(mesh.n_faces()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  for (auto vh : mesh.vertices())
    for (int c = 0; c < 3; ++c) put<double>(out, mesh.point(vh)[c]);
  for (auto fh : mesh.faces()) {
    put<uint8_t>(out, 3);
    for (auto vh : mesh.fv_range(fh)) put<int32_t>(out, vh.idx());
  }
  return out;
}

}  // namespace

MeshFormat mesh_format_for_path(const std::string& path) {
  const std::string ext = detail::lower_extension(path);
  if (ext == ".stl") return MeshFormat::BinarySTL;
  if (ext == ".ply") return MeshFormat::BinaryPLY;
  if (ext == ".3mf") return MeshFormat::ThreeMF;
  throw InputError(path, "cannot write '" + ext + "' meshes (use .stl, .ply or .3mf)");
}

std::string encode_mesh(const SkullMesh& mesh, MeshFormat format) {
  switch (format) {
    case MeshFormat::BinarySTL:
      return encode_stl(mesh);
    case MeshFormat::BinaryPLY:
      return encode_ply(mesh);
    case MeshFormat::ThreeMF:
      return encode_3mf({{"implant", &mesh}}, {{"Application", "Cranioplan"}});
  }
  return {};
}

void write_mesh(const SkullMesh& mesh, const std::string& path, MeshFormat format) {
  write_file_atomically(path, encode_mesh(mesh, format));
}

}  // namespace cranioplan
