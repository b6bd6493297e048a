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

// From the patient's LPS to `space`'s coordinates (x and y negated for RAS).
Eigen::Vector3d in_space(const Eigen::Vector3d& p, MeshSpace space) {
  return negates_x_and_y(space) ? Eigen::Vector3d(-p.x(), -p.y(), p.z()) : p;
}

std::string encode_stl(const SkullMesh& mesh, MeshSpace space) {
  std::string out;
  out.reserve(84 + 50 * mesh.n_faces());
  std::string header = "binary STL written by Cranioplan, units mm";
  if (negates_x_and_y(space)) header += std::string(", ") + space_tag(space);
  header.resize(80, ' ');
  out += header;
  put<uint32_t>(out, static_cast<uint32_t>(mesh.n_faces()));
  for (auto fh : mesh.faces()) {
    FaceCorners f = face_corners(mesh, fh);
    for (auto& corner : f.p) corner = in_space(corner, space);
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

std::string encode_ply(const SkullMesh& mesh, MeshSpace space) {
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment Cranioplan, units mm\n";
  if (negates_x_and_y(space)) out += std::string("comment ") + space_tag(space) + "\n";
  out += "element vertex " + std::to_string(mesh.n_vertices()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  out += "element face " + std::to_string(mesh.n_faces()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  for (auto vh : mesh.vertices()) {
    const Eigen::Vector3d p = in_space(to_eigen(mesh.point(vh)), space);
    for (int c = 0; c < 3; ++c) put<double>(out, p[c]);
  }
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

SkullMesh mesh_in_space(const SkullMesh& mesh, MeshSpace space) {
  SkullMesh out = mesh;
  if (negates_x_and_y(space))
    for (auto vh : out.vertices()) {
      auto& p = out.point(vh);
      p[0] = -p[0];
      p[1] = -p[1];
    }
  return out;
}

std::string encode_mesh(const SkullMesh& mesh, MeshFormat format, MeshSpace space) {
  switch (format) {
    case MeshFormat::BinarySTL:
      return encode_stl(mesh, space);
    case MeshFormat::BinaryPLY:
      return encode_ply(mesh, space);
    case MeshFormat::ThreeMF: {
      if (!negates_x_and_y(space))
        return encode_3mf({{"implant", &mesh}}, {{"Application", "Cranioplan"}});
      const SkullMesh turned = mesh_in_space(mesh, space);
      return encode_3mf({{"implant", &turned}}, {{"Application", "Cranioplan"}});
    }
  }
  return {};
}

void write_mesh(const SkullMesh& mesh, const std::string& path, MeshFormat format,
                MeshSpace space) {
  write_file_atomically(path, encode_mesh(mesh, format, space));
}

}  // namespace cranioplan
