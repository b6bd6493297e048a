#include "cranioplan/algorithms/io/read_mesh.h"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>
#include <sstream>
#include <string_view>

#include "cranioplan/algorithms/geometry/mesh_components.h"
#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"
#include "file_bytes.h"
#include "mesh_formats.h"
#include "soup_building.h"

namespace cranioplan {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw InputError(path, problem);
}

void check_finite(const std::string& path, const Eigen::Vector3d& p, long long triangle) {
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
    fail(path, "triangle " + format_count(triangle + 1) +
                   " has a coordinate that is not a number (NaN or Inf)");
}

// The volume the triangles enclose, taken about the vertices' centroid (for a surface with
// holes, as a skull's base and defect are, a point inside keeps the open parts' share small).
double enclosed_volume(const TriangleSoup& soup) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& v : soup.vertices) c += v;
  return signed_volume(soup, c / static_cast<double>(std::max<size_t>(1, soup.vertices.size())));
}

// Drops the pieces that lie more than `far_mm` from the largest piece's bounding box.
void drop_far_pieces(const std::string& path, double far_mm, TriangleSoup& soup, MeshFile& out) {
  const SoupComponents comps = soup_components(soup);
  if (comps.sizes.size() < 2) return;
  const std::vector<PieceBox> boxes = piece_boxes(soup, comps);
  std::vector<bool> keep(comps.sizes.size(), true);
  double farthest = 0.0;
  for (size_t c = 1; c < keep.size(); ++c) {
    const double gap = boxes[c].gap_to(boxes[0]);
    if (gap <= far_mm) continue;
    keep[c] = false;
    ++out.pieces_dropped;
    out.triangles_dropped += comps.sizes[c];
    farthest = std::max(farthest, gap);
  }
  if (out.pieces_dropped == 0) return;
  soup = keep_pieces(soup, comps, keep);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.0f mm", farthest);
  out.warnings.push_back(
      path + ": " + format_count(out.pieces_dropped) + " piece" +
      (out.pieces_dropped == 1 ? "" : "s") + " of " + format_count(out.triangles_dropped) +
      " triangles lying apart from the skull (up to " + buf + " from it) " +
      (out.pieces_dropped == 1 ? "was" : "were") + " dropped; the skull is its largest piece (" +
      format_count(comps.sizes[0]) + " triangles) and what lies within " +
      std::to_string(static_cast<int>(far_mm)) + " mm of it");
}

}  // namespace

TriangleSoup read_mesh_soup(const std::string& path, std::string* format_out,
                            MeshSpace* space_out) {
  const std::string ext = detail::lower_extension(path);
  std::string format;
  MeshSpace space = MeshSpace::Undeclared;
  TriangleSoup soup;
  // A binary STL is parsed as it is read; the other formats from the whole file.
  const std::string bytes = ext == ".stl" ? std::string() : read_file_bytes(path);
  if (ext == ".stl") {
    soup = detail::read_stl(path, format, space);
  } else if (ext == ".off") {
    format = "OFF";
    soup = detail::read_off(path, bytes);
    space = detail::space_in_comments(bytes);
  } else if (ext == ".obj") {
    format = "OBJ";
    soup = detail::read_obj(path, bytes);
    space = detail::space_in_comments(bytes);
  } else if (ext == ".ply") {
    format = "PLY";
    soup = detail::read_ply(path, bytes);
    space = space_in_text(std::string_view(bytes).substr(0, bytes.find("end_header")));
  } else if (ext == ".vtk") {
    format = "VTK";
    soup = detail::read_legacy_vtk(path, bytes, space);
  } else if (ext == ".vtp") {
    format = "VTP";
    if (bytes.find("<VTKFile") == std::string::npos)
      fail(path, "not a VTP file (no <VTKFile> element)");
    soup = detail::read_vtp(path, bytes, space);
  } else {
    fail(path, "unknown mesh format '" + ext + "' (expected .stl, .ply, .obj, .off, .vtk or .vtp)");
  }
  if (soup.triangles.empty()) fail(path, "contains no triangles");
  if (format != "binary STL" && format != "ASCII STL")  // STL parsers check as they read
    for (size_t t = 0; t < soup.triangles.size(); ++t)
      for (int v = 0; v < 3; ++v)
        check_finite(path, soup.vertices[soup.triangles[t][v]], static_cast<long long>(t));
  if (format_out) *format_out = format;
  if (space_out) *space_out = space;
  return soup;
}

std::vector<std::string> describe_repairs(const SoupRepair& done) {
  std::vector<std::string> out;
  if (done.repeated_dropped > 0)
    out.push_back(format_count(done.repeated_dropped) +
                  " triangles repeat another's three corners (the surface written twice there); "
                  "the copies were dropped");
  const SoupOrientation& o = done.orientation;
  if (o.triangles_turned > 0)
    out.push_back(format_count(o.triangles_turned) + " triangles in " +
                  format_count(o.patches_turned) + (o.patches_turned == 1 ? " patch" : " patches") +
                  " wound against their neighbours (inconsistent winding); they were turned to "
                  "agree");
  if (o.conflicts > 0)
    out.push_back(format_count(o.conflicts) + (o.conflicts == 1 ? " edge where" : " edges where") +
                  " the surface cannot wind one way (a twisted seam); left as read");
  const HoleClosing& h = done.holes;
  if (h.closed > 0) {
    char longest[32];
    std::snprintf(longest, sizeof(longest), "%.1f", h.largest_mm);
    out.push_back(format_count(h.closed) + (h.closed == 1 ? " small hole" : " small holes") +
                  " (up to " + longest + " mm of open edge) closed with " +
                  format_count(h.triangles_added) + " triangles");
  }
  return out;
}

namespace {

// The mesh built in `mesh` (out.mesh or another), the rest of what was read in `out`.
void read_into(const std::string& path, const ReadMeshParams& params, MeshFile& out,
               SkullMesh& mesh) {
  TriangleSoup soup = read_mesh_soup(path, &out.format, &out.space);
  out.triangles_in_file = static_cast<long long>(soup.triangles.size());
  // Into the patient's LPS: x and y negated, a turn about z that keeps the winding.
  if (params.space_from_header && negates_x_and_y(out.space)) {
    for (auto& v : soup.vertices) {
      v.x() = -v.x();
      v.y() = -v.y();
    }
    out.turned_to_lps = true;
  }
  assert(params.unit_mm > 0.0 && std::isfinite(params.unit_mm) && "validated by the caller");
  if (params.unit_mm != 1.0)
    for (auto& v : soup.vertices) v *= params.unit_mm;
  if (params.far_piece_mm > 0.0) drop_far_pieces(path, params.far_piece_mm, soup, out);
  const SoupRepair done = repair_soup(soup, params.repairs);
  out.repeated_dropped = done.repeated_dropped;
  out.triangles_turned = done.orientation.triangles_turned;
  out.patches_turned = done.orientation.patches_turned;
  out.holes_closed = done.holes.closed;
  for (const std::string& sentence : describe_repairs(done))
    out.warnings.push_back(path + ": " + sentence);
  if (params.orient_outward && enclosed_volume(soup) < 0.0) {
    for (auto& t : soup.triangles) std::swap(t[1], t[2]);
    out.turned_outward = true;
    out.warnings.push_back(path +
                           ": the surface was inside out (its triangles wind inward); it was "
                           "turned outward");
  }
  if (params.canonical) make_canonical(soup);

  BuildMeshStats stats;
  build_mesh(soup, mesh, &stats);
  out.degenerate_dropped = stats.degenerate_dropped;
  out.nonmanifold_split = stats.nonmanifold_split;
  if (mesh.n_faces() == 0)
    fail(path, "all " + format_count(out.triangles_in_file) +
                   " triangles have zero area; there is no surface to use");
  if (stats.degenerate_dropped > 0) {
    const std::string msg = format_count(stats.degenerate_dropped) + " of " +
                            format_count(out.triangles_in_file) +
                            " triangles have zero area or a repeated vertex";
    if (params.strict) fail(path, msg);
    out.warnings.push_back(path + ": " + msg + "; they were removed");
  }
  if (stats.nonmanifold_split > 0)
    out.warnings.push_back(path + ": " + format_count(stats.nonmanifold_split) +
                           " triangles share an edge with two or more others (non-manifold); "
                           "they were kept on separate vertices");
}

}  // namespace

MeshFile read_mesh(const std::string& path, const ReadMeshParams& params) {
  MeshFile out;
  read_into(path, params, out, out.mesh);
  return out;
}

MeshFile read_mesh(const std::string& path, const ReadMeshParams& params, SkullMesh& mesh) {
  MeshFile out;
  read_into(path, params, out, mesh);
  return out;
}

}  // namespace cranioplan
