#include "support/synthetic.h"

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "cranioplan/algorithms/shape/correspond_skull.h"
#include "cranioplan/algorithms/shape/shape_model.h"

namespace cranioplan::test {

ShapeModel stretched_head_model(const SkullMesh& head) {
  const ShapeTemplate t = make_shape_template(head, ShapeTemplateParams{4});
  std::vector<Eigen::Matrix3Xd> shapes;
  for (const Eigen::Vector3d& stretch :
       {Eigen::Vector3d(1.0, 1.0, 1.0), Eigen::Vector3d(1.03, 0.98, 1.0),
        Eigen::Vector3d(0.98, 1.02, 1.03)})
    shapes.push_back(stretch.asDiagonal() * t.points);
  return build_shape_model(shapes, t.outer_count, t.triangles, {}, false);
}
namespace {

// Icosphere with vertices symmetric under x ↦ −x.
TriangleSoup icosphere(int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleSoup s;
  s.vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : s.vertices) v.normalize();
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      s.vertices.push_back((s.vertices[a] + s.vertices[b]).normalized());
      const int id = static_cast<int>(s.vertices.size()) - 1;
      mid[key] = id;
      return id;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& tr : s.triangles) {
      const int a = midpoint(tr[0], tr[1]), b = midpoint(tr[1], tr[2]), c = midpoint(tr[2], tr[0]);
      next.emplace_back(tr[0], a, c);
      next.emplace_back(tr[1], b, a);
      next.emplace_back(tr[2], c, b);
      next.emplace_back(a, b, c);
    }
    s.triangles = std::move(next);
  }
  return s;
}

}  // namespace

// Radius of the head along unit direction u; even in u.x, so the head is symmetric in x.
Eigen::Vector3d head_surface_point(const Eigen::Vector3d& u) {
  const double x2 = u.x() * u.x();
  double r = 1.0 + 0.12 * u.y() + 0.08 * u.z() * u.z() - 0.06 * u.y() * u.z() + 0.05 * x2 * u.z();
  // Nose ridge at the front, on the midline, slightly below the equator.
  const double front = std::max(0.0, u.y());
  r += 0.10 * std::exp(-(x2 / 0.02) - std::pow(u.z() + 0.15, 2) / 0.05) * std::pow(front, 4);
  // Flattened back of the head.
  if (u.y() < -0.6) r -= 0.2 * std::pow(-u.y() - 0.6, 2);
  return Eigen::Vector3d(70.0 * u.x(), 85.0 * u.y(), 72.0 * u.z()) * r;
}

SkullMesh make_symmetric_head(int subdivisions) {
  TriangleSoup s = icosphere(subdivisions);
  for (auto& v : s.vertices) v = head_surface_point(v);
  return build_mesh(s);
}

Landmarks head_landmarks() {
  Landmarks lm;
  lm.nasion = head_surface_point(Eigen::Vector3d(0, 0.95, 0.05).normalized());
  lm.orbit_left = Eigen::Vector3d(-32, 78, 5);
  lm.orbit_right = Eigen::Vector3d(32, 78, 5);
  return lm;
}

SkullMesh mask_meshed_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return mask_meshed_boxes({{lo, hi}});
}

SkullMesh mask_meshed_boxes(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& boxes) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& [a, b] : boxes) {
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(2.25);
  const VoxelGrid g = VoxelGrid::covering(lo - margin, hi + margin, 0.5);
  std::vector<uint8_t> inside(g.size(), 0);
  for (const auto& [a, b] : boxes) {
    const std::vector<uint8_t> one = voxelize_mesh(build_mesh(box_soup(a, b)), g);
    for (size_t k = 0; k < inside.size(); ++k) inside[k] |= one[k];
  }
  ExtractBoneSurfaceParams mask;
  mask.threshold = 0.5;
  return extract_bone_surface(mask_volume(inside, g), mask).mesh;
}

long long genus(const SkullMesh& m) {
  const long long chi = static_cast<long long>(m.n_vertices()) -
                        static_cast<long long>(m.n_edges()) + static_cast<long long>(m.n_faces());
  return (2 - chi) / 2;
}

TriangleSoup box_soup(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleSoup s;
  for (int i = 0; i < 8; ++i)
    s.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                            i & 4 ? hi.z() : lo.z());
  s.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return s;
}

SkullMesh cut_hole(const SkullMesh& mesh, const Eigen::Vector3d& center, double radius) {
  TriangleSoup s = to_soup(mesh);
  std::vector<Eigen::Vector3i> kept;
  for (const auto& t : s.triangles) {
    const Eigen::Vector3d c = (s.vertices[t[0]] + s.vertices[t[1]] + s.vertices[t[2]]) / 3.0;
    if ((c - center).norm() > radius) kept.push_back(t);
  }
  s.triangles = kept;
  return build_mesh(s);
}

SkullMesh scanned_padded(const SkullMesh& mesh, const Eigen::Vector3d& point,
                         const Eigen::Vector3d& up, double voxel_mm) {
  const auto [lo, hi] = mesh_bounds(mesh);
  const Eigen::Vector3d margin = Eigen::Vector3d::Constant(2.0 * voxel_mm);
  const VoxelGrid grid = VoxelGrid::covering(lo - margin, hi + margin, voxel_mm);
  std::vector<uint8_t> inside = voxelize_mesh(mesh, grid);
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i)
        if ((grid.center(i, j, k) - point).dot(up) < 0.0) inside[grid.index(i, j, k)] = 0;
  ExtractBoneSurfaceParams all;
  all.largest_piece_only = false;
  all.min_piece_triangles = 1;
  return extract_bone_surface(mask_volume(inside, grid), all).mesh;
}

SkullMesh cut_open(const SkullMesh& mesh, const Eigen::Vector3d& point, const Eigen::Vector3d& up) {
  TriangleSoup s = to_soup(mesh);
  std::vector<Eigen::Vector3i> kept;
  for (const auto& t : s.triangles) {
    bool above = true;
    for (int k = 0; k < 3; ++k) above = above && (s.vertices[t[k]] - point).dot(up) >= 0.0;
    if (above) kept.push_back(t);
  }
  s.triangles = kept;
  return build_mesh(s);
}

SkullMesh scaled(const SkullMesh& mesh, double factor) {
  SkullMesh out = mesh;
  for (auto vh : out.vertices()) out.set_point(vh, out.point(vh) * factor);
  return out;
}

SkullMesh transformed(const SkullMesh& mesh, const RigidTransform& t) {
  SkullMesh out = mesh;
  for (auto vh : out.vertices()) out.set_point(vh, to_point(t.apply(to_eigen(out.point(vh)))));
  return out;
}

Landmarks transformed(const Landmarks& lm, const RigidTransform& t) {
  Landmarks out = lm;
  if (out.nasion) out.nasion = t.apply(*out.nasion);
  if (out.orbit_left) out.orbit_left = t.apply(*out.orbit_left);
  if (out.orbit_right) out.orbit_right = t.apply(*out.orbit_right);
  for (auto& p : out.midline) p = t.apply(p);
  return out;
}

Plane transformed(const Plane& p, const RigidTransform& t) {
  return Plane::through(t.apply(p.normal * p.offset), t.apply_direction(p.normal));
}

Volume make_ball_volume(const Eigen::Vector3d& center_world, double radius, int n, double spacing,
                        bool as_ct) {
  Volume v;
  v.dims = {n, n, n};
  v.directions = Eigen::Matrix3d::Identity() * spacing;
  v.origin = center_world - Eigen::Vector3d::Constant(spacing * (n - 1) / 2.0);
  v.kind = as_ct ? VolumeKind::CT : VolumeKind::Mask;
  v.data.resize(v.size());
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const bool in = (v.world(Eigen::Vector3d(i, j, k)) - center_world).norm() <= radius;
        v.data[v.index(i, j, k)] = as_ct ? (in ? 1000.0f : -1000.0f) : (in ? 1.0f : 0.0f);
      }
  return v;
}

SkullMesh make_thick_head(double inner_scale, double voxel_mm) {
  const SkullMesh outer = make_symmetric_head(5);
  SkullMesh inner = outer;
  for (auto vh : inner.vertices()) inner.set_point(vh, inner.point(vh) * inner_scale);
  const auto [lo, hi] = mesh_bounds(outer);
  const VoxelGrid grid = VoxelGrid::covering(lo, hi, voxel_mm);
  std::vector<uint8_t> shell = voxelize_mesh(outer, grid);
  const std::vector<uint8_t> cavity = voxelize_mesh(inner, grid);
  for (size_t i = 0; i < shell.size(); ++i) shell[i] = shell[i] && !cavity[i];
  // The shell's boundary has two pieces, the outer and the inner wall: keep both.
  ExtractBoneSurfaceParams both;
  both.largest_piece_only = false;
  both.min_piece_triangles = 1;
  return extract_bone_surface(mask_volume(shell, grid), both).mesh;
}

std::vector<Marker> round_defect_markers(const Eigen::Vector3d& center, double radius,
                                         double inner_scale, int edge_count, int surface_rings) {
  // Directions around the defect's axis; along each, the angle at which a surface leaves the
  // sphere is found by bisection.
  const Eigen::Vector3d axis = center.normalized();
  const Eigen::Vector3d t1 = axis.unitOrthogonal(), t2 = axis.cross(t1);
  auto direction = [&](double beta, double phi) {
    return Eigen::Vector3d(std::cos(beta) * axis +
                           std::sin(beta) * (std::cos(phi) * t1 + std::sin(phi) * t2));
  };
  auto rim_angle = [&](double scale, double phi) {
    double lo = 0.0, hi = 1.5;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      ((scale * head_surface_point(direction(mid, phi)) - center).norm() < radius ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  std::vector<Marker> markers;
  int id = 1;
  for (int layer = 0; layer < 2; ++layer) {
    const double scale = layer == 0 ? 1.0 : inner_scale;
    const MarkerType edge = layer == 0 ? MarkerType::OuterEdge : MarkerType::InnerEdge;
    const MarkerType surface = layer == 0 ? MarkerType::OuterSurface : MarkerType::InnerSurface;
    for (int e = 0; e < edge_count; ++e) {
      const double phi = 2.0 * M_PI * e / edge_count;
      markers.push_back({id++, edge,
                         scale * head_surface_point(direction(rim_angle(scale, phi), phi)),
                         MarkerSurface::Original});
    }
    for (int ring = 1; ring <= surface_rings; ++ring) {
      const int count = std::max(1, edge_count * ring / (surface_rings + 1));
      for (int e = 0; e < count; ++e) {
        const double phi = 2.0 * M_PI * (e + 0.5) / count;
        const double beta = rim_angle(scale, phi) * ring / (surface_rings + 1);
        markers.push_back({id++, surface, scale * head_surface_point(direction(beta, phi)),
                           MarkerSurface::Mirrored});
      }
    }
  }
  return markers;
}

Volume oblique_ball_volume(const Eigen::Vector3d& center) {
  Volume v = make_ball_volume(Eigen::Vector3d::Zero(), 10.0, 32, 1.0, false);
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  v.directions = rot * Eigen::Vector3d(0.9, 1.0, 1.3).asDiagonal();
  // The centre index (15.5, 15.5, 15.5) lands on `center`.
  v.origin = center - v.directions * Eigen::Vector3d::Constant(15.5);
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i)
        v.data[v.index(i, j, k)] = (v.world(Eigen::Vector3d(i, j, k)) - center).norm() <= 10.0;
  return v;
}

const ThickHeadDefect& thick_head_defect() {
  static const ThickHeadDefect c = [] {
    ThickHeadDefect k;
    k.intact = make_thick_head();
    InjectDefectParams p;
    p.center = head_surface_point(Eigen::Vector3d(0.7, 0.1, 0.7).normalized()) * 0.965;
    p.size_mm = 55;
    p.voxel_mm = 0.5;
    k.defective = inject_defect(k.intact, p).defective;
    k.defect = detect_defect(k.defective, SurfaceLocator(k.defective), Eigen::Vector3d::Zero());
    return k;
  }();
  return c;
}

::testing::AssertionResult on_the_patients_right_in_front(const Plane& plane,
                                                          const DefectRegion& defect) {
  const Eigen::Vector3d c = plane.project(defect.center);
  const double side = plane.signed_distance(c + 100.0 * defect.axis) * plane.normal.x();
  if (side >= 0.0)
    return ::testing::AssertionFailure()
           << "the defect lies on the patient's left (" << side << " mm along x from the plane)";
  if (defect.axis.y() >= 0.0)
    return ::testing::AssertionFailure()
           << "the defect faces the back (axis y " << defect.axis.y() << ")";
  return ::testing::AssertionSuccess();
}

}  // namespace cranioplan::test
