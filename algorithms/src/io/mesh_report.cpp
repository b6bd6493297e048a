#include "cranioplan/algorithms/io/mesh_report.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <utility>

#include "cranioplan/algorithms/geometry/mesh_components.h"

namespace cranioplan {
namespace {

// The least span of a loop taken for a cut at the border (a scan's end crosses at least the
// vault's cap); a smaller loop is part of a cut only by lying in that cut's plane.
constexpr double kCutSpanMm = 30.0;
// A cut's plane lies this near the mesh's end along its normal (mm), and is taken as an axis's
// plane within this angle of it (degrees).
constexpr double kBorderReachMm = 2.0;
constexpr double kAxisSnapDeg = 1.0;

// The side a cut or cap faces, named by the patient's direction nearest its outward normal;
// within 1° of it, the normal is made that axis (a slice's plane, up to rounding).
std::string name_border(Eigen::Vector3d& outward) {
  int axis = 0;
  outward.cwiseAbs().maxCoeff(&axis);
  const double sign = outward[axis] < 0 ? -1.0 : 1.0;
  if (std::abs(outward[axis]) >= std::cos(kAxisSnapDeg * M_PI / 180.0))
    outward = sign * Eigen::Vector3d::Unit(axis);
  static const char* const kLow[3] = {"right", "front", "lower"};
  static const char* const kHigh[3] = {"left", "back", "upper"};
  return sign < 0 ? kLow[axis] : kHigh[axis];
}

// The chains of boundary edges (welded vertex ids), measured and placed.
std::vector<BoundaryLoop> boundary_loops(const TriangleSoup& welded,
                                         const std::vector<std::pair<int, int>>& edges) {
  std::unordered_map<int, int> parent;
  std::function<int(int)> find = [&](int a) {
    int r = a;
    while (parent[r] != r) r = parent[r];
    while (parent[a] != r) a = std::exchange(parent[a], r);
    return r;
  };
  for (const auto& [a, b] : edges) {
    parent.emplace(a, a);
    parent.emplace(b, b);
  }
  for (const auto& [a, b] : edges) parent[find(a)] = find(b);
  std::map<int, size_t> index;  // root -> loops[]
  std::vector<BoundaryLoop> loops;
  std::vector<std::vector<int>> members;
  for (const auto& [a, b] : edges) {
    const auto [it, fresh] = index.emplace(find(a), loops.size());
    if (fresh) {
      loops.emplace_back();
      members.emplace_back();
    }
    BoundaryLoop& l = loops[it->second];
    ++l.edges;
    l.length_mm += (welded.vertices[a] - welded.vertices[b]).norm();
    members[it->second].push_back(a);
    members[it->second].push_back(b);
  }
  for (size_t i = 0; i < loops.size(); ++i) {
    std::vector<int>& m = members[i];
    std::sort(m.begin(), m.end());
    m.erase(std::unique(m.begin(), m.end()), m.end());
    BoundaryLoop& l = loops[i];
    for (int v : m) l.centroid += welded.vertices[v];
    l.centroid /= static_cast<double>(m.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int v : m) {
      const Eigen::Vector3d d = welded.vertices[v] - l.centroid;
      cov += d * d.transpose();
    }
    l.normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
    for (int v : m)
      l.flatness_mm =
          std::max(l.flatness_mm, std::abs((welded.vertices[v] - l.centroid).dot(l.normal)));
    // At the border: flat, and its plane where the mesh ends along its normal, in any
    // orientation (a gantry tilt, a crop by an exporter, a skull that came in turned).
    Eigen::Vector3d a = l.centroid, b = l.centroid;
    for (int v : m) {
      a = a.cwiseMin(welded.vertices[v]);
      b = b.cwiseMax(welded.vertices[v]);
    }
    // A hole of a few millimetres on a curved surface is flat too: a cut spans a good part of
    // the head.
    const bool flat =
        l.flatness_mm <= std::max(1.0, 0.01 * l.length_mm) && (b - a).norm() >= kCutSpanMm;
    if (!flat) continue;
    double lowest = l.centroid.dot(l.normal), highest = lowest;
    for (const Eigen::Vector3d& p : welded.vertices) {
      lowest = std::min(lowest, p.dot(l.normal));
      highest = std::max(highest, p.dot(l.normal));
    }
    const double at = l.centroid.dot(l.normal);
    if (at - lowest <= kBorderReachMm)
      l.outward = -l.normal;
    else if (highest - at <= kBorderReachMm)
      l.outward = l.normal;
    else
      continue;
    l.at_border = true;
    l.border = name_border(l.outward);
  }
  auto outline = [&](size_t i) {
    std::vector<Eigen::Vector3d> points;
    for (int v : members[i]) points.push_back(welded.vertices[v]);
    loops[i].outline = hull_in_plane(std::move(points), loops[i].outward);
  };
  // The cut also leaves small loops in its plane (around islands of bone the plane crosses, in
  // the orbits or the nose): each lying within reach of a border's plane is part of that cut.
  std::vector<size_t> cuts;
  for (size_t i = 0; i < loops.size(); ++i)
    if (loops[i].at_border) {
      cuts.push_back(i);
      outline(i);
    }
  for (size_t i = 0; i < loops.size(); ++i) {
    BoundaryLoop& l = loops[i];
    if (l.at_border) continue;
    for (size_t c : cuts) {
      const BoundaryLoop& cut = loops[c];
      const double offset = cut.outward.dot(cut.centroid);
      const bool in_plane = std::all_of(members[i].begin(), members[i].end(), [&](int v) {
        return std::abs(cut.outward.dot(welded.vertices[v]) - offset) <= kBorderReachMm;
      });
      if (!in_plane) continue;
      l.at_border = true;
      l.border = cut.border;
      l.outward = cut.outward;
      outline(i);
      break;
    }
  }
  std::stable_sort(loops.begin(), loops.end(), [](const BoundaryLoop& a, const BoundaryLoop& b) {
    return a.length_mm > b.length_mm;
  });
  return loops;
}

// A cap: this much area at least, within a cut's reach of the mesh's end (kBorderReachMm: an
// importer's cap lies between the scan's last slice and the padding), its triangles facing out
// within this angle (degrees), and as wide as a cut through the head along both of its plane's
// principal axes (mm): a scan's end crosses the head's shell in a ring, 60 mm across at the
// least; a skull's own curve keeps a disc of only 38 mm within 2 mm of its end (at a 90 mm
// radius), and a defect's flat cut face is a band as narrow as the bone is thick. A scan's end
// covers a small part of its outline and leaves the head's inside open through it; a field of
// view that shaves the head's side across solid bone covers nearly all of its outline
// (measured: docs/AUTOPLAN.md).
constexpr double kCapMinAreaMm2 = 200.0;
constexpr double kCapFacingDeg = 30.0;
constexpr double kCapMajorMm = 60.0, kCapMinorMm = 30.0;
// A ring: at least this much of its outline open (mm²), and its triangles covering at most this
// fraction of it.
constexpr double kCapOpenMm2 = 1000.0, kCapCoverage = 0.5;

// Each triangle's unit normal and area (zero for a triangle without area).
struct Facets {
  std::vector<Eigen::Vector3d> normal;
  std::vector<double> area;
};

Facets facets_of(const TriangleSoup& welded) {
  const size_t nt = welded.triangles.size();
  Facets f{std::vector<Eigen::Vector3d>(nt, Eigen::Vector3d::Zero()), std::vector<double>(nt)};
  for (size_t t = 0; t < nt; ++t) {
    const Eigen::Vector3i& c = welded.triangles[t];
    const Eigen::Vector3d x = (welded.vertices[c[1]] - welded.vertices[c[0]])
                                  .cross(welded.vertices[c[2]] - welded.vertices[c[0]]);
    const double twice = x.norm();
    if (!(twice > 0.0)) continue;
    f.normal[t] = x / twice;
    f.area[t] = 0.5 * twice;
  }
  return f;
}

// A normal taken either way: the one whose largest coordinate is positive.
Eigen::Vector3d either_way(const Eigen::Vector3d& n) {
  int axis = 0;
  n.cwiseAbs().maxCoeff(&axis);
  return n[axis] < 0 ? Eigen::Vector3d(-n) : n;
}

// The directions to look for caps along: the axes (a volume's slices), and every direction that
// a quarter of a cap's least area of triangles share, either way (in cells of 0.005: an oblique
// volume's slices), more than kAxisSnapDeg from those before.
std::vector<Eigen::Vector3d> cap_directions(const Facets& f) {
  // Each triangle's direction cell, sorted so that a cell's triangles are a run.
  std::vector<std::pair<std::array<long, 3>, int>> cells;
  cells.reserve(f.area.size());
  for (size_t t = 0; t < f.area.size(); ++t) {
    if (!(f.area[t] > 0.0)) continue;
    const Eigen::Vector3d n = either_way(f.normal[t]);
    cells.push_back(
        {{std::lround(n.x() * 200.0), std::lround(n.y() * 200.0), std::lround(n.z() * 200.0)},
         static_cast<int>(t)});
  }
  std::sort(cells.begin(), cells.end());
  std::vector<Eigen::Vector3d> directions{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                          Eigen::Vector3d::UnitZ()};
  const double same = std::cos(kAxisSnapDeg * M_PI / 180.0);
  for (size_t i = 0; i < cells.size();) {
    size_t j = i;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double total = 0.0;
    for (; j < cells.size() && cells[j].first == cells[i].first; ++j) {
      const int t = cells[j].second;
      sum += f.area[t] * either_way(f.normal[t]);
      total += f.area[t];
    }
    i = j;
    const Eigen::Vector3d d = sum.normalized();
    if (total >= 0.25 * kCapMinAreaMm2 &&
        std::none_of(directions.begin(), directions.end(),
                     [&](const Eigen::Vector3d& e) { return std::abs(e.dot(d)) >= same; }))
      directions.push_back(d);
  }
  return directions;
}

// Each vertex's triangles, as a compressed list: those of vertex v are
// of_vertex[first[v]] .. of_vertex[first[v + 1] - 1].
struct VertexTriangles {
  std::vector<size_t> first;
  std::vector<int> of_vertex;
};

VertexTriangles vertex_triangles(const TriangleSoup& welded) {
  const size_t nv = welded.vertices.size(), nt = welded.triangles.size();
  VertexTriangles vt;
  vt.first.assign(nv + 1, 0);
  for (const Eigen::Vector3i& f : welded.triangles)
    for (int k = 0; k < 3; ++k) ++vt.first[static_cast<size_t>(f[k]) + 1];
  for (size_t v = 0; v < nv; ++v) vt.first[v + 1] += vt.first[v];
  vt.of_vertex.resize(vt.first[nv]);
  std::vector<size_t> at(vt.first.begin(), vt.first.end() - 1);
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) vt.of_vertex[at[welded.triangles[t][k]]++] = static_cast<int>(t);
  return vt;
}

// As wide as a cut through the head: the corners' extent along the two principal axes of their
// plane (across `out`, about `centroid`).
bool wide_as_a_cut(const std::vector<Eigen::Vector3d>& corners, const Eigen::Vector3d& centroid,
                   const Eigen::Vector3d& out) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : corners) {
    const Eigen::Vector3d q = (p - centroid) - (p - centroid).dot(out) * out;
    cov += q * q.transpose();
  }
  const Eigen::Matrix3d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
  double width[2] = {0.0, 0.0};
  for (int a = 0; a < 2; ++a) {
    const Eigen::Vector3d e = axes.col(a + 1);  // the two largest: in the plane
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Eigen::Vector3d& p : corners) {
      lo = std::min(lo, p.dot(e));
      hi = std::max(hi, p.dot(e));
    }
    width[a] = hi - lo;
  }
  return std::max(width[0], width[1]) >= kCapMajorMm && std::min(width[0], width[1]) >= kCapMinorMm;
}

// A ring around the head's inside: the cap's outline encloses open space that its triangles do
// not cover. A cap across solid bone (a field of view that shaves the side of the head) covers
// most of its outline and closes no opening.
bool rings_the_inside(const BorderCap& cap) {
  double enclosed = 0.0;
  for (size_t i = 1; i + 1 < cap.outline.size(); ++i)
    enclosed += 0.5 * (cap.outline[i] - cap.outline[0])
                          .cross(cap.outline[i + 1] - cap.outline[0])
                          .dot(cap.outward);
  return enclosed - cap.area_mm2 >= kCapOpenMm2 && cap.area_mm2 <= kCapCoverage * enclosed;
}

// The cap facing `out` at the mesh's end (`end`: out · p there), if its triangles make one: those
// of the vertices within reach of the end (`seen`, `pass`: which triangles this pass has taken
// already) that lie within reach of it and face out through it.
std::optional<BorderCap> cap_at_end(const TriangleSoup& welded, const Facets& f,
                                    const VertexTriangles& vt, const Eigen::Vector3d& out,
                                    double end, std::vector<int>& seen, int pass) {
  const double facing = std::cos(kCapFacingDeg * M_PI / 180.0);
  BorderCap cap;
  cap.outward = out;
  cap.box_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  cap.box_max = -cap.box_min;
  std::vector<int> near_end;
  for (size_t v = 0; v < welded.vertices.size(); ++v) {
    if (end - welded.vertices[v].dot(out) > kBorderReachMm) continue;
    for (size_t i = vt.first[v]; i < vt.first[v + 1]; ++i)
      if (seen[vt.of_vertex[i]] != pass) {
        seen[vt.of_vertex[i]] = pass;
        near_end.push_back(vt.of_vertex[i]);
      }
  }
  std::sort(near_end.begin(), near_end.end());  // in the triangles' order, as every pass
  std::vector<Eigen::Vector3d> corners;
  for (const int t : near_end) {
    if (f.area[t] == 0.0 || f.normal[t].dot(out) < facing) continue;
    const Eigen::Vector3i& c = welded.triangles[t];
    bool at_end = true;
    for (int k = 0; k < 3 && at_end; ++k)
      at_end = end - welded.vertices[c[k]].dot(out) <= kBorderReachMm;
    if (!at_end) continue;
    cap.area_mm2 += f.area[t];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& p = welded.vertices[c[k]];
      cap.centroid += f.area[t] / 3.0 * p;
      cap.box_min = cap.box_min.cwiseMin(p);
      cap.box_max = cap.box_max.cwiseMax(p);
      corners.push_back(p);
    }
  }
  if (cap.area_mm2 < kCapMinAreaMm2) return std::nullopt;
  cap.centroid /= cap.area_mm2;
  if (!wide_as_a_cut(corners, cap.centroid, out)) return std::nullopt;
  cap.outline = hull_in_plane(std::move(corners), cap.outward);
  if (!rings_the_inside(cap)) return std::nullopt;
  cap.border = name_border(cap.outward);
  return cap;
}

// The flat caps where a closed surface ends (welded soup): along each of cap_directions, either
// way, the triangles within 2 mm of the mesh's end and facing out through it form a cap if they
// cover enough, are as wide as a cut and ring the head's inside.
std::vector<BorderCap> border_caps(const TriangleSoup& welded) {
  const Facets f = facets_of(welded);
  const VertexTriangles vt = vertex_triangles(welded);
  std::vector<int> seen(welded.triangles.size(), -1);  // the pass that last took each triangle
  int pass = 0;
  std::vector<BorderCap> caps;
  for (const Eigen::Vector3d& d : cap_directions(f)) {
    double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
    for (const Eigen::Vector3d& p : welded.vertices) {
      lowest = std::min(lowest, p.dot(d));
      highest = std::max(highest, p.dot(d));
    }
    for (const double sign : {-1.0, 1.0}) {
      const double end = sign < 0 ? -lowest : highest;  // out · p at the mesh's end
      if (auto cap = cap_at_end(welded, f, vt, sign * d, end, seen, pass++))
        caps.push_back(std::move(*cap));
    }
  }
  std::stable_sort(caps.begin(), caps.end(),
                   [](const BorderCap& a, const BorderCap& b) { return a.area_mm2 > b.area_mm2; });
  return caps;
}

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), f, a, b, c);
  return buf;
}

// Where a cut's or a cap's plane lies, for a person: "z = 0.0 mm", or "a plane tilted 20° from
// z = const, through z = 61.0 mm at its centre".
std::string plane_place(const Eigen::Vector3d& outward, const Eigen::Vector3d& through) {
  static const char* const kAxis = "xyz";
  int axis = 0;
  outward.cwiseAbs().maxCoeff(&axis);
  const double at = std::round(through[axis] * 10.0) / 10.0 + 0.0;  // no "-0.0"
  const double tilt = std::acos(std::min(1.0, std::abs(outward[axis]))) * 180.0 / M_PI;
  if (tilt == 0.0) return std::string(1, kAxis[axis]) + fmt(" = %.1f mm", at);
  return fmt("a plane tilted %.0f° from ", tilt) + kAxis[axis] + " = const, through " +
         kAxis[axis] + fmt(" = %.1f mm at its centre", at);
}

}  // namespace

// Andrew's monotone chain on the plane's coordinates.
std::vector<Eigen::Vector3d> hull_in_plane(std::vector<Eigen::Vector3d> points,
                                           const Eigen::Vector3d& normal) {
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  auto uv = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d(p.dot(u), p.dot(v)); };
  std::sort(points.begin(), points.end(), [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector2d x = uv(a), y = uv(b);
    return x.x() < y.x() || (x.x() == y.x() && x.y() < y.y());
  });
  if (points.size() < 3) return points;
  auto turn = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector2d p = uv(a) - uv(o), q = uv(b) - uv(o);
    return p.x() * q.y() - p.y() * q.x();
  };
  std::vector<Eigen::Vector3d> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);  // the last point is the first
  return hull;
}

std::vector<std::string> describe_openings(const MeshReport& report) {
  std::vector<std::string> out;
  for (const char* side : {"lower", "upper", "front", "back", "right", "left"}) {
    long long count = 0;
    double length = 0.0;
    const BoundaryLoop* first = nullptr;
    for (const BoundaryLoop& l : report.loops) {
      if (!l.at_border || l.border != side) continue;
      ++count;
      length += l.length_mm;
      if (!first) first = &l;
    }
    if (count == 0) continue;
    const std::string where = plane_place(first->outward, first->centroid);
    out.push_back(std::string("open along a flat cut at its ") + side + " border (" + where +
                  "): " + std::to_string(count) + (count == 1 ? " loop, " : " loops, ") +
                  fmt("%.0f mm", length) +
                  " long, where the scan ended; the bone's inside is taken by votes through it");
  }
  long long holes = 0;
  double total = 0.0;
  const BoundaryLoop* largest = nullptr;
  for (const BoundaryLoop& l : report.loops) {
    if (l.at_border) continue;
    ++holes;
    total += l.length_mm;
    if (!largest) largest = &l;  // longest first
  }
  if (largest)
    out.push_back(std::to_string(holes) + (holes == 1 ? " hole" : " holes") +
                  fmt(" in the surface, %.0f mm of open edge in all; the largest is %.0f mm around",
                      total, largest->length_mm) +
                  fmt(", at (%.0f, %.0f, %.0f) mm", largest->centroid.x(), largest->centroid.y(),
                      largest->centroid.z()) +
                  "; left open, the bone's inside taken by votes through them");
  return out;
}

std::vector<std::string> describe_caps(const MeshReport& report) {
  std::vector<std::string> out;
  for (const BorderCap& cap : report.caps) {
    const bool open_there =
        std::any_of(report.loops.begin(), report.loops.end(),
                    [&](const BoundaryLoop& l) { return l.at_border && l.border == cap.border; });
    if (open_there) continue;
    out.push_back("closed by a flat cap at its " + cap.border + " border (" +
                  plane_place(cap.outward, cap.centroid) +
                  fmt("): %.0f mm², where the scan ended; an opening through it is not a defect",
                      cap.area_mm2));
  }
  return out;
}

namespace {

// Identical positions as one vertex: each input vertex's id, ids in the order positions first
// appear, and the positions by id.
struct Welded {
  std::vector<int> id;
  std::vector<Eigen::Vector3d> positions;
};

Welded weld_positions(const std::vector<Eigen::Vector3d>& points) {
  const size_t n = points.size();
  auto key = [&](size_t i) {
    return std::array<double, 3>{points[i].x(), points[i].y(), points[i].z()};
  };
  Welded w;
  // A mesh in canonical form (every skull read or imported) has its positions distinct and in
  // order already: each vertex is its own.
  bool ascending = true;
  for (size_t i = 1; i < n && ascending; ++i) ascending = key(i - 1) < key(i);
  if (ascending) {
    w.id.resize(n);
    std::iota(w.id.begin(), w.id.end(), 0);
    w.positions = points;
    return w;
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  std::vector<int> first_of;  // each position's first vertex, in order of position
  std::vector<int> group(n);
  for (size_t r = 0; r < n; ++r) {
    if (r == 0 || key(order[r]) != key(order[r - 1])) first_of.push_back(order[r]);
    group[order[r]] = static_cast<int>(first_of.size()) - 1;
  }
  std::vector<int> by_appearance(first_of.size());
  std::iota(by_appearance.begin(), by_appearance.end(), 0);
  std::sort(by_appearance.begin(), by_appearance.end(),
            [&](int a, int b) { return first_of[a] < first_of[b]; });
  std::vector<int> rank(first_of.size());
  for (size_t k = 0; k < by_appearance.size(); ++k) rank[by_appearance[k]] = static_cast<int>(k);
  w.id.resize(n);
  for (size_t i = 0; i < n; ++i) w.id[i] = rank[group[i]];
  w.positions.resize(first_of.size());
  for (size_t g = 0; g < first_of.size(); ++g) w.positions[rank[g]] = points[first_of[g]];
  return w;
}

// Keys below 2^bits in ascending order by their digits, least significant first (12 bits a
// pass): the order std::sort gives, as the keys are plain values, in about half its time.
void radix_sort(std::vector<unsigned long long>& keys, int bits) {
  constexpr int kDigit = 12;
  constexpr unsigned long long kMask = (1ull << kDigit) - 1;
  std::vector<unsigned long long> other(keys.size());
  std::vector<size_t> start(size_t{1} << kDigit);
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::fill(start.begin(), start.end(), 0);
    for (const unsigned long long k : keys) ++start[(k >> shift) & kMask];
    size_t sum = 0;
    for (size_t& s : start) sum += std::exchange(s, sum);
    for (const unsigned long long k : keys) other[start[(k >> shift) & kMask]++] = k;
    keys.swap(other);
  }
}

// Every triangle's three undirected edges as (smaller id << 32 | larger id), sorted: an edge's
// triangles are a run.
std::vector<unsigned long long> sorted_edges(const std::vector<Eigen::Vector3i>& triangles,
                                             size_t vertices) {
  // Sorted packed as (smaller << b | larger), b the bits of the largest id, so that the digits
  // cover only bits the ids use; the same order.
  int b = 1;
  while (b < 32 && (size_t{1} << b) < vertices) ++b;
  std::vector<unsigned long long> edges;
  edges.reserve(triangles.size() * 3);
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      const unsigned long long a = static_cast<unsigned>(t[k]),
                               c = static_cast<unsigned>(t[(k + 1) % 3]);
      edges.push_back(std::min(a, c) << b | std::max(a, c));
    }
  radix_sort(edges, 2 * b);
  const unsigned long long low = (1ull << b) - 1;
  for (unsigned long long& e : edges) e = (e >> b) << 32 | (e & low);
  return edges;
}

}  // namespace

MeshReport report_mesh(const SkullMesh& mesh) {
  MeshReport r;
  TriangleSoup soup = to_soup(mesh);
  r.vertices = static_cast<long long>(soup.vertices.size());
  r.triangles = static_cast<long long>(soup.triangles.size());
  if (soup.vertices.empty()) return r;
  r.bbox_min = r.bbox_max = soup.vertices[0];
  for (const auto& p : soup.vertices) {
    r.bbox_min = r.bbox_min.cwiseMin(p);
    r.bbox_max = r.bbox_max.cwiseMax(p);
  }
  for (const auto& t : soup.triangles) {
    const auto &a = soup.vertices[t[0]], &b = soup.vertices[t[1]], &c = soup.vertices[t[2]];
    r.area_mm2 += 0.5 * (b - a).cross(c - a).norm();
  }
  r.volume_mm3 = signed_volume(soup);

  // Weld identical positions, then count triangles per undirected edge.
  Welded w = weld_positions(soup.vertices);
  for (auto& t : soup.triangles)
    for (int k = 0; k < 3; ++k) t[k] = w.id[t[k]];
  soup.vertices = std::move(w.positions);
  const std::vector<unsigned long long> edges = sorted_edges(soup.triangles, soup.vertices.size());
  std::vector<std::pair<int, int>> boundary;
  for (size_t e = 0; e < edges.size();) {
    size_t count = 1;
    while (e + count < edges.size() && edges[e + count] == edges[e]) ++count;
    if (count == 1) {
      ++r.boundary_edges;
      boundary.emplace_back(static_cast<int>(edges[e] >> 32),
                            static_cast<int>(edges[e] & 0xffffffffu));
    }
    if (count > 2) ++r.nonmanifold_edges;
    e += count;
  }
  // In the order of the welded ids: the same loops on any run.
  std::sort(boundary.begin(), boundary.end());
  r.loops = boundary_loops(soup, boundary);
  r.caps = border_caps(soup);
  r.pieces = static_cast<long long>(soup_components(soup).sizes.size());
  r.watertight = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
  return r;
}

std::vector<BorderCap> border_caps(const SkullMesh& mesh) { return border_caps(to_soup(mesh)); }

bool is_watertight(const SkullMesh& mesh) {
  // A halfedge mesh holds each edge once with at most two faces; with no boundary every edge
  // has two. When no two vertices share a position, welding changes nothing, and that is the
  // answer below without a copy, a weld and an edge sort (the fitted implant's commit waits
  // for this). Otherwise, the welded triangles decide.
  bool closed = mesh.faces().begin() != mesh.faces().end();  // a face not deleted
  for (auto he : mesh.halfedges())
    if (mesh.is_boundary(he)) {
      closed = false;
      break;
    }
  if (closed) {
    std::vector<std::array<double, 3>> at;
    at.reserve(mesh.n_vertices());
    for (auto vh : mesh.vertices()) {
      const auto& p = mesh.point(vh);
      at.push_back({p[0], p[1], p[2]});
    }
    std::sort(at.begin(), at.end());
    if (std::adjacent_find(at.begin(), at.end()) == at.end()) return true;
  }
  TriangleSoup soup = to_soup(mesh);
  if (soup.vertices.empty()) return false;
  const Welded w = weld_positions(soup.vertices);
  for (auto& t : soup.triangles)
    for (int k = 0; k < 3; ++k) t[k] = w.id[t[k]];
  // Every undirected edge of the welded triangles twice: no boundary, nothing non-manifold.
  const std::vector<unsigned long long> edges = sorted_edges(soup.triangles, soup.vertices.size());
  for (size_t e = 0; e < edges.size();) {
    size_t run = 1;
    while (e + run < edges.size() && edges[e + run] == edges[e]) ++run;
    if (run != 2) return false;
    e += run;
  }
  return !edges.empty();
}

}  // namespace cranioplan
