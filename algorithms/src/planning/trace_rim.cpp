#include "cranioplan/algorithms/planning/trace_rim.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <numeric>
#include <optional>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Sectors of bearing around the axis the edge is found in (half a degree each).
constexpr int kSectors = 720;
// Rounds of the majority vote that evens out the tables' labels (about 0.4 mm each on a
// CT-resolution surface).
constexpr int kMajorityRounds = 3;
// Rounds of averaging over a vertex's neighbours that smooth the normals the probes go along.
constexpr int kNormalRounds = 2;
// A piece of table not reached from the seeds is the table too when it is this large, where it
// lies as far from the centre as the seed nearest its direction (Table::grow).
constexpr double kMinPieceMm2 = 50.0, kPieceRadiusMm = 15.0;
// Candidates for the edge kept in each sector: the boundary's clusters nearest the axis.
constexpr int kCandidates = 8;
constexpr double kClusterDeg = 1.5, kClusterMm = 3.0;

// Where a direction from the centre lies in the azimuthal equidistant projection around the
// axis: its angle from the axis, along its bearing around it (defined up to 180°).
struct Projection {
  Eigen::Vector3d axis, e1, e2;
  Eigen::Vector2d operator()(const Eigen::Vector3d& dir) const {
    const Eigen::Vector3d d = dir.normalized();
    const double theta = std::acos(std::clamp(d.dot(axis), -1.0, 1.0));
    const double phi = std::atan2(d.dot(e2), d.dot(e1));
    return theta * Eigen::Vector2d(std::cos(phi), std::sin(phi));
  }
  int sector(const Eigen::Vector2d& q) const {
    const double phi = std::atan2(q.y(), q.x());
    return std::clamp(static_cast<int>((phi + M_PI) / (2.0 * M_PI) * kSectors), 0, kSectors - 1);
  }
};

bool inside_polygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& q) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d &a = poly[i], &b = poly[j];
    if ((a.y() > q.y()) != (b.y() > q.y()) &&
        q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

// Unit normals at the vertices (the faces around each, weighted by area), averaged with their
// neighbours' a few rounds: a marching-cubes surface's own normals step by 45° across a slope.
std::vector<Eigen::Vector3d> smooth_vertex_normals(const SkullMesh& mesh) {
  std::vector<Eigen::Vector3d> n(mesh.n_vertices(), Eigen::Vector3d::Zero());
  for (auto fh : mesh.faces()) {
    const FaceCorners c = face_corners(mesh, fh);
    const Eigen::Vector3d w = c.cross();
    for (int id : c.ids) n[id] += w;
  }
  for (auto& v : n)
    if (v.norm() > 0.0) v.normalize();
  for (int round = 0; round < kNormalRounds; ++round) {
    std::vector<Eigen::Vector3d> next(n.size());
    parallel_for(n.size(), [&](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i) {
        Eigen::Vector3d sum = n[i];
        for (auto w : mesh.vv_range(mesh.vertex_handle(static_cast<unsigned>(i))))
          sum += n[w.idx()];
        next[i] = sum.norm() > 0.0 ? Eigen::Vector3d(sum.normalized()) : Eigen::Vector3d::Zero();
      }
    });
    n = std::move(next);
  }
  return n;
}

// For each face of `band`, the faces that share a corner with it (itself too), sorted: the
// neighbourhood the tables' majority vote counts, found once for both tables and every round.
// Flat: face i's are faces[start[i]] to faces[start[i + 1]].
struct FacesAround {
  std::vector<size_t> start;
  std::vector<int> faces;
};

FacesAround faces_around(const SkullMesh& mesh, const std::vector<int>& band) {
  auto gather = [&](int f, std::vector<int>& a) {
    a.clear();
    for (auto vh : mesh.fv_range(mesh.face_handle(f)))
      for (auto g : mesh.vf_range(vh)) a.push_back(g.idx());
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  };
  FacesAround out;
  out.start.assign(band.size() + 1, 0);
  parallel_for(band.size(), [&](size_t first, size_t last) {
    std::vector<int> a;
    for (size_t i = first; i < last; ++i) {
      gather(band[i], a);
      out.start[i + 1] = a.size();
    }
  });
  for (size_t i = 0; i < band.size(); ++i) out.start[i + 1] += out.start[i];
  out.faces.resize(out.start.back());
  parallel_for(band.size(), [&](size_t first, size_t last) {
    std::vector<int> a;
    for (size_t i = first; i < last; ++i) {
      gather(band[i], a);
      std::copy(a.begin(), a.end(), out.faces.begin() + static_cast<long>(out.start[i]));
    }
  });
  return out;
}

// One table of the skull near the opening (outer: facing away from the centre; inner: towards
// it): the faces whose bone has two tables, evened out by a majority vote and kept where they
// are connected to the seeds.
class Table {
 public:
  Table(const SkullMesh& mesh, const SurfaceLocator& bone, const std::vector<Eigen::Vector3d>& vn,
        const Eigen::Vector3d& center, bool outer, const TraceRimParams& params)
      : mesh_(mesh), bone_(bone), vn_(vn), center_(center), outer_(outer), params_(params) {}

  // `band`: the faces examined (near the opening, seen from the centre); `around`: for each,
  // the faces that share a corner with it (itself too), sorted (faces_around).
  void grow(const std::vector<int>& band, const FacesAround& around,
            const std::vector<int>& seeds) {
    in_.assign(mesh_.n_faces(), 0);
    std::vector<uint8_t> label(mesh_.n_faces(), 0), decided(band.size(), 0);
    parallel_for(band.size(), [&](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i) decided[i] = table(band[i]);
    });
    for (size_t i = 0; i < band.size(); ++i) label[band[i]] = decided[i];
    // The majority of the faces around each face's corners, a few rounds: a facet tipped the
    // other way, or a probe that met a channel in the diploë, is noise; a cut face is a band
    // as wide as the bone is thick.
    for (int round = 0; round < kMajorityRounds; ++round) {
      std::vector<uint8_t> next(band.size(), 0);
      parallel_for(band.size(), [&](size_t first, size_t last) {
        for (size_t i = first; i < last; ++i) {
          int on = 0;
          for (size_t k = around.start[i]; k < around.start[i + 1]; ++k)
            on += label[around.faces[k]];
          next[i] = 2 * on > static_cast<int>(around.start[i + 1] - around.start[i]);
        }
      });
      for (size_t i = 0; i < band.size(); ++i) label[band[i]] = next[i];
    }
    // The table's pieces (connected through labelled faces). A piece holding a seed is the
    // table; so are the faces of a piece of kMinPieceMm2 or more that lie as far from the centre
    // as the seed nearest their direction (within kPieceRadiusMm): the outer table below a
    // flap's lower edge may be cut off from the rest by bone the probes fail on (a suture, the
    // zygomatic root), while bone deep inside the head that the opening lays bare (a ridge of
    // the skull base) lies much nearer the centre than the rim beside it.
    std::vector<int> piece(mesh_.n_faces(), -1);
    std::vector<std::vector<int>> pieces;
    for (int f0 : band) {
      if (!label[f0] || piece[f0] >= 0) continue;
      const int id = static_cast<int>(pieces.size());
      std::vector<int> members{f0}, stack{f0};
      piece[f0] = id;
      while (!stack.empty()) {
        const int f = stack.back();
        stack.pop_back();
        for (auto g : mesh_.ff_range(mesh_.face_handle(f)))
          if (label[g.idx()] && piece[g.idx()] < 0) {
            piece[g.idx()] = id;
            members.push_back(g.idx());
            stack.push_back(g.idx());
          }
      }
      pieces.push_back(std::move(members));
    }
    std::vector<char> keep(pieces.size(), 0);
    std::vector<Eigen::Vector3d> seed_dirs;
    std::vector<double> seed_radii;
    for (int f : seeds)
      if (piece[f] >= 0) {
        keep[piece[f]] = 1;
        const Eigen::Vector3d d = centroid(f) - center_;
        seed_dirs.push_back(d.normalized());
        seed_radii.push_back(d.norm());
      }
    for (size_t k = 0; k < pieces.size(); ++k)
      if (keep[k])
        for (int f : pieces[k]) in_[f] = 1;
    if (seed_dirs.empty()) return;
    const PointIndex nearest_seed(seed_dirs);
    for (size_t k = 0; k < pieces.size(); ++k) {
      if (keep[k]) continue;
      double area = 0.0;
      for (int f : pieces[k])
        area += 0.5 * face_corners(mesh_, mesh_.face_handle(f)).cross().norm();
      if (area < kMinPieceMm2) continue;
      for (int f : pieces[k]) {
        const Eigen::Vector3d d = centroid(f) - center_;
        if (std::abs(d.norm() - seed_radii[nearest_seed.nearest(d.normalized())]) <= kPieceRadiusMm)
          in_[f] = 1;
      }
    }
  }

  bool in(int f) const { return f >= 0 && in_[f]; }
  bool raw(int f) const { return table(f); }

 private:
  Eigen::Vector3d centroid(int f) const {
    const FaceCorners c = face_corners(mesh_, mesh_.face_handle(f));
    return (c.p[0] + c.p[1] + c.p[2]) / 3.0;
  }
  Eigen::Vector3d normal(int f) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (auto vh : mesh_.fv_range(mesh_.face_handle(f))) sum += vn_[vh.idx()];
    return sum.norm() > 0.0 ? Eigen::Vector3d(sum.normalized()) : Eigen::Vector3d::Zero();
  }

  // The face faces the right way and has bone of two tables under it: a probe from it along
  // its normal, into the bone, leaves it through a surface facing back.
  bool table(int f) const {
    const FaceCorners c = face_corners(mesh_, mesh_.face_handle(f));
    const Eigen::Vector3d p = (c.p[0] + c.p[1] + c.p[2]) / 3.0;
    const Eigen::Vector3d n = normal(f);
    if (n.isZero()) return false;
    const double facing = n.dot((p - center_).normalized());
    if (outer_ ? facing < params_.min_facing : facing > -params_.min_facing) return false;
    const auto exit = bone_.first_hit(p - 1e-3 * n, p - params_.max_thickness_mm * n);
    if (!exit) return false;
    return normal(exit->face).dot(n) <= -std::cos(params_.table_angle_deg * kDeg);
  }

  const SkullMesh& mesh_;
  const SurfaceLocator& bone_;
  const std::vector<Eigen::Vector3d>& vn_;
  Eigen::Vector3d center_;
  bool outer_;
  const TraceRimParams& params_;
  std::vector<uint8_t> in_;
};

// A place the edge may run through in a sector: a point of the table's boundary.
struct Candidate {
  Eigen::Vector3d point;
  double theta;    // angle from the axis, rad
  double radius;   // distance from the centre, mm
  bool at_border;  // the face beyond is the scan's end
};

// In each sector of bearing around the axis, the table's boundary as up to kCandidates
// clusters nearest the axis (each its point nearest the axis; a cluster spans kClusterDeg of
// angle from the axis and kClusterMm of distance from the centre: two tables' edges seen at one
// angle, as over a sinus the opening cuts through, are two). Inside the opening there is no
// table, so where the table was grown up to the opening its edge is the cluster nearest the
// axis; further ones are noise in the table or bone beyond it. Each boundary edge gives a point
// at every sector's middle bearing it spans (so that a sector narrower than the mesh's edges
// still has its point). Only edges between the table and a face examined and found not to be
// table, or the mesh's own border: where the examined band ends is not an edge of the bone.
std::vector<std::vector<Candidate>> edge_candidates(const SkullMesh& mesh, const Table& table,
                                                    const std::vector<uint8_t>& examined,
                                                    const Projection& project,
                                                    const Eigen::Vector3d& center,
                                                    const std::vector<ScanBorder>& borders) {
  auto on_cap = [&](SkullMesh::FaceHandle fh) {
    const FaceCorners c = face_corners(mesh, fh);
    const Eigen::Vector3d n = c.cross().normalized();
    const Eigen::Vector3d centroid = (c.p[0] + c.p[1] + c.p[2]) / 3.0;
    for (const ScanBorder& b : borders)
      if (n.dot(b.normal) > std::cos(10.0 * kDeg) &&
          std::abs(centroid.dot(b.normal) - b.offset) < 1.0)
        return true;
    return false;
  };
  const double sector_width = 2.0 * M_PI / kSectors;
  std::vector<std::vector<Candidate>> all(kSectors);
  for (auto h : mesh.halfedges()) {
    if (mesh.is_boundary(h) || !table.in(mesh.face_handle(h).idx())) continue;
    const auto opp = mesh.opposite_halfedge_handle(h);
    const bool mesh_border = mesh.is_boundary(opp);
    if (!mesh_border &&
        (table.in(mesh.face_handle(opp).idx()) || !examined[mesh.face_handle(opp).idx()]))
      continue;
    const bool at_border = mesh_border || on_cap(mesh.face_handle(opp));
    const Eigen::Vector3d a = to_eigen(mesh.point(mesh.from_vertex_handle(h)));
    const Eigen::Vector3d b = to_eigen(mesh.point(mesh.to_vertex_handle(h)));
    const Eigen::Vector2d qa = project(a - center), qb = project(b - center);
    const double pa = std::atan2(qa.y(), qa.x());
    const double span = std::remainder(std::atan2(qb.y(), qb.x()) - pa, 2.0 * M_PI);
    // The sectors whose middle bearing lies between the edge's ends, or the midpoint's.
    const double lo = std::min(pa, pa + span), hi = std::max(pa, pa + span);
    const int first = static_cast<int>(std::ceil((lo + M_PI) / sector_width - 0.5));
    const int last = static_cast<int>(std::floor((hi + M_PI) / sector_width - 0.5));
    auto add = [&](const Eigen::Vector3d& p, int k) {
      const Eigen::Vector2d q = project(p - center);
      all[((k % kSectors) + kSectors) % kSectors].push_back(
          {p, q.norm(), (p - center).norm(), at_border});
    };
    if (first > last) {
      const Eigen::Vector3d mid = 0.5 * (a + b);
      add(mid, project.sector(project(mid - center)));
      continue;
    }
    for (int k = first; k <= last; ++k) {
      const double phi = (k + 0.5) * sector_width - M_PI;
      const double t = std::abs(span) > 1e-12 ? std::clamp((phi - pa) / span, 0.0, 1.0) : 0.5;
      add((1.0 - t) * a + t * b, k);
    }
  }
  for (auto& sector : all) {
    std::sort(sector.begin(), sector.end(),
              [](const Candidate& a, const Candidate& b) { return a.theta < b.theta; });
    std::vector<Candidate> kept;
    for (const Candidate& c : sector) {
      const bool seen = std::any_of(kept.begin(), kept.end(), [&](const Candidate& k) {
        return c.theta - k.theta < kClusterDeg * kDeg && std::abs(c.radius - k.radius) < kClusterMm;
      });
      if (seen) continue;
      kept.push_back(c);
      if (static_cast<int>(kept.size()) == kCandidates) break;
    }
    sector = std::move(kept);
  }
  return all;
}

// The edge all round: one candidate (or none) per sector, chosen together so that the edge runs
// on without jumps, near the axis, and through the rim the rays saw where they saw it: the least
// cost closed path through the sectors (dynamic programming, each candidate of a sector the rays
// saw tried as the start). Costs in millimetres at the rim's radius `scale`: the angle from the
// axis beyond the sector's nearest candidate (a little), the step from sector to sector in angle
// and in distance from the centre, the distance from the rim point the rays saw in the sector, and
// a sector passed without a point.
std::vector<int> choose_edge(const std::vector<std::vector<Candidate>>& candidates,
                             const std::vector<std::optional<Eigen::Vector3d>>& seen,
                             double scale) {
  constexpr double kNearAxis = 0.02, kStep = 1.0, kSeen = 0.0, kSkip = 5.0;
  const double inf = std::numeric_limits<double>::infinity();
  auto unary = [&](int k, int c) {
    if (c < 0) return kSkip;
    const Candidate& x = candidates[k][c];
    double cost = kNearAxis * (x.theta - candidates[k].front().theta) * scale;
    if (seen[k]) cost += kSeen * std::min((x.point - *seen[k]).norm(), 20.0);
    return cost;
  };
  // From state `a` in one sector to `b` in the next; a skipped sector carries the last point.
  auto step = [&](const Candidate* a, const Candidate* b) {
    if (!a || !b) return 0.0;
    return kStep * (std::abs(a->theta - b->theta) * scale + std::abs(a->radius - b->radius));
  };
  int start = -1;
  for (int k = 0; k < kSectors && start < 0; ++k)
    if (seen[k] && !candidates[k].empty()) start = k;
  if (start < 0) return {};
  double best_total = inf;
  std::vector<int> best;
  for (int c0 = 0; c0 < static_cast<int>(candidates[start].size()); ++c0) {
    // cost[k][s]: the least cost from the start to state s of sector start+k, where the state
    // says which candidate (the last one is "none"), and last[k][s] the last point on that path.
    std::vector<std::vector<double>> cost(kSectors);
    std::vector<std::vector<int>> from(kSectors);
    std::vector<std::vector<const Candidate*>> last(kSectors);
    cost[0].assign(candidates[start].size() + 1, inf);
    from[0].assign(cost[0].size(), -1);
    last[0].assign(cost[0].size(), nullptr);
    cost[0][c0] = unary(start, c0);
    last[0][c0] = &candidates[start][c0];
    for (int k = 1; k < kSectors; ++k) {
      const int sector = (start + k) % kSectors;
      const int n = static_cast<int>(candidates[sector].size());
      cost[k].assign(n + 1, inf);
      from[k].assign(n + 1, -1);
      last[k].assign(n + 1, nullptr);
      for (int s = 0; s <= n; ++s) {
        const Candidate* here = s < n ? &candidates[sector][s] : nullptr;
        const double u = unary(sector, s < n ? s : -1);
        for (size_t p = 0; p < cost[k - 1].size(); ++p) {
          if (cost[k - 1][p] == inf) continue;
          const double total = cost[k - 1][p] + u + step(last[k - 1][p], here);
          if (total < cost[k][s]) {
            cost[k][s] = total;
            from[k][s] = static_cast<int>(p);
            last[k][s] = here ? here : last[k - 1][p];
          }
        }
      }
    }
    // Back to the start's candidate.
    double total = inf;
    int end = -1;
    for (size_t p = 0; p < cost[kSectors - 1].size(); ++p) {
      if (cost[kSectors - 1][p] == inf) continue;
      const double t = cost[kSectors - 1][p] + step(last[kSectors - 1][p], &candidates[start][c0]);
      if (t < total) {
        total = t;
        end = static_cast<int>(p);
      }
    }
    if (end < 0 || total >= best_total) continue;
    best_total = total;
    best.assign(kSectors, -1);
    int s = end;
    for (int k = kSectors - 1; k >= 0; --k) {
      const int sector = (start + k) % kSectors;
      best[sector] = s < static_cast<int>(candidates[sector].size()) ? s : -1;
      s = from[k][s];
    }
  }
  return best;
}

// A narrow bay of the traced edge (the edge running out from the opening and back within
// kBayDeg of bearing, by more than kBayDepthDeg): the table grown along a ridge of bone that
// reaches into the opening or along crushed fragments, as along the orbit's rim below the
// sample's defect, not the vault's edge. Its sectors are left out, and the rim runs straight
// across them (a grey-scale opening of the edge's angle from the axis over the sectors).
constexpr int kBaySectors = 16;  // half the window: 8° of bearing
constexpr double kBayDepthDeg = 4.0;

std::vector<char> narrow_bays(const std::vector<std::vector<Candidate>>& candidates,
                              const std::vector<int>& chosen) {
  const double none = std::numeric_limits<double>::infinity();
  std::vector<double> theta(kSectors, none);
  for (int k = 0; k < kSectors; ++k)
    if (chosen[k] >= 0) theta[k] = candidates[k][chosen[k]].theta;
  auto at = [&](const std::vector<double>& v, int k) {
    return v[((k % kSectors) + kSectors) % kSectors];
  };
  std::vector<double> eroded(kSectors, none), opened(kSectors, -none);
  for (int k = 0; k < kSectors; ++k)
    for (int j = -kBaySectors; j <= kBaySectors; ++j)
      eroded[k] = std::min(eroded[k], at(theta, k + j));
  for (int k = 0; k < kSectors; ++k)
    for (int j = -kBaySectors; j <= kBaySectors; ++j)
      if (at(eroded, k + j) < none) opened[k] = std::max(opened[k], at(eroded, k + j));
  std::vector<char> bay(kSectors, 0);
  for (int k = 0; k < kSectors; ++k)
    bay[k] = theta[k] < none && theta[k] > opened[k] + kBayDepthDeg * kDeg;
  return bay;
}

// The closed polyline `loop` resampled every `spacing` mm of its length, each point the mean of
// the polyline within `window` mm of it along it (the staircase of mesh edges made smooth), with
// the flag of the vertex each lies after.
void resample(const std::vector<Eigen::Vector3d>& loop, const std::vector<char>& flags,
              double spacing, double window, std::vector<Eigen::Vector3d>& points,
              std::vector<char>& out_flags) {
  const size_t n = loop.size();
  std::vector<double> s(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) s[i + 1] = s[i] + (loop[(i + 1) % n] - loop[i]).norm();
  const double length = s[n];
  if (!(length > 0.0)) return;
  auto at = [&](double t, size_t* vertex) {
    t = std::fmod(std::fmod(t, length) + length, length);
    const size_t i = static_cast<size_t>(std::upper_bound(s.begin(), s.end(), t) - s.begin()) - 1;
    const size_t k = std::min(i, n - 1);
    if (vertex) *vertex = k;
    const double seg = s[k + 1] - s[k];
    const double w = seg > 0.0 ? (t - s[k]) / seg : 0.0;
    return Eigen::Vector3d((1.0 - w) * loop[k] + w * loop[(k + 1) % n]);
  };
  const int count = std::max(8, static_cast<int>(std::round(length / spacing)));
  const double step = length / count;
  constexpr double kDelta = 0.25;  // mm between the points averaged
  const int half = std::max(0, static_cast<int>(std::round(0.5 * window / kDelta)));
  for (int k = 0; k < count; ++k) {
    const double t = k * step;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int j = -half; j <= half; ++j) sum += at(t + j * kDelta, nullptr);
    points.push_back(sum / (2 * half + 1));
    size_t vertex = 0;
    at(t, &vertex);
    out_flags.push_back(flags[vertex]);
  }
}

// The table's boundary lies short of the rim's crease where the probes from the outer table
// leave the bone through the cut face rather than the inner table (within about a bone's
// thickness of an oblique cut): each point is moved on over the outer surface towards the
// opening, in steps of kMarchStep, while the surface's normal stays within kCreaseDeg of the
// table's where the march began, up to kMarchMm.
constexpr double kMarchStep = 0.25, kMarchMm = 8.0, kCreaseDeg = 35.0, kBackMm = 2.0;

Eigen::Vector3d smoothed_normal_at(const SkullMesh& mesh, const std::vector<Eigen::Vector3d>& vn,
                                   int face) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (auto vh : mesh.fv_range(mesh.face_handle(face))) n += vn[vh.idx()];
  return n.norm() > 0.0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
}

Eigen::Vector3d onto_crease(const SurfaceLocator& bone, const std::vector<Eigen::Vector3d>& vn,
                            const SkullMesh& mesh, const Eigen::Vector3d& p,
                            const Eigen::Vector3d& towards) {
  // The table's normal where it is level, kBackMm back from the point (the boundary may lie on
  // the crease's rounding already).
  const SurfaceLocator::Closest at = bone.closest(p);
  Eigen::Vector3d n = smoothed_normal_at(mesh, vn, at.face);
  if (n.isZero()) return p;
  Eigen::Vector3d t = towards - towards.dot(n) * n;
  if (t.norm() < 1e-9) return p;
  const SurfaceLocator::Closest back = bone.closest(at.point - kBackMm * t.normalized());
  const Eigen::Vector3d n0 = smoothed_normal_at(mesh, vn, back.face);
  if (n0.isZero()) return p;
  const double crease = std::cos(kCreaseDeg * kDeg);
  Eigen::Vector3d here = back.point;
  n = n0;
  for (double s = kMarchStep; s <= kBackMm + kMarchMm + 1e-9; s += kMarchStep) {
    t = towards - towards.dot(n) * n;
    if (t.norm() < 1e-9) break;
    const SurfaceLocator::Closest next = bone.closest(here + kMarchStep * t.normalized());
    const Eigen::Vector3d nn = smoothed_normal_at(mesh, vn, next.face);
    if (nn.dot(n0) < crease) break;
    here = next.point;
    n = nn;
  }
  return here;
}

// The seed points' faces.
std::vector<int> seed_faces(const SurfaceLocator& bone, const std::vector<Eigen::Vector3d>& seeds) {
  std::vector<int> faces;
  for (const Eigen::Vector3d& p : seeds) faces.push_back(bone.closest(p).face);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

// The faces whose centroid is seen from the centre within `band` (rad) of a ray through the
// opening.
std::vector<int> band_faces(const SkullMesh& mesh, const Eigen::Vector3d& center,
                            const std::vector<Eigen::Vector3d>& holes, double band) {
  const PointIndex index(holes);
  const double chord2 = std::pow(2.0 * std::sin(0.5 * band), 2);
  // A face further from the rays' mean direction than the widest ray and the band together has
  // no ray within the band (the triangle inequality on the sphere): no search for it.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& h : holes) mean += h;
  double reach = M_PI;
  if (mean.norm() > 1e-9) {
    mean.normalize();
    double widest = 0.0;
    for (const Eigen::Vector3d& h : holes)
      widest = std::max(widest, std::acos(std::clamp(h.dot(mean), -1.0, 1.0)));
    reach = widest + band;
  }
  const double min_cos = reach >= M_PI ? -2.0 : std::cos(reach) - 1e-9;
  std::vector<uint8_t> near(mesh.n_faces(), 0);
  parallel_for(mesh.n_faces(), [&](size_t first, size_t last) {
    for (size_t f = first; f < last; ++f) {
      const FaceCorners c = face_corners(mesh, mesh.face_handle(static_cast<int>(f)));
      const Eigen::Vector3d d = ((c.p[0] + c.p[1] + c.p[2]) / 3.0 - center).normalized();
      if (d.dot(mean) < min_cos) continue;
      double d2 = 0.0;
      index.nearest(d, &d2);
      near[f] = d2 <= chord2;
    }
  });
  std::vector<int> out;
  for (size_t f = 0; f < near.size(); ++f)
    if (near[f]) out.push_back(static_cast<int>(f));
  return out;
}

// Where the opening runs into the scan's end, no bone edges it: beyond the border's plane
// nothing was scanned, so the opening, seen from the centre, ends where the table would cross
// that plane. In each sector, the point at the table's distance from the centre where the
// sector's half-plane of directions meets the border's plane, on the side away from the axis:
// nearer the axis a ray reaches the table inside the scan, beyond it the scan ends first. The
// table's distance is that of the seeds (the bone the rays met next to the opening) at the
// same bearing around the axis, interpolated across bearings without seeds: across the
// opening's stretch along the scan's end, from the bone on either side of it. Kept where its
// direction lies within `band` (rad) of the opening's rays, as the faces examined do; the path
// chooses between these and the table's own edge (at the border's cap or cut the two coincide;
// across the opening only these exist).
constexpr int kBearingBins = 72;  // 5° of bearing each

// The mean of `values` by bearing (rad) in kBearingBins bins, bins without a value
// interpolated linearly (around the circle) from their nearest neighbours with one; empty when
// no bin has a value.
std::vector<double> by_bearing_bins(const std::vector<double>& bearings,
                                    const std::vector<double>& values) {
  std::vector<double> sum(kBearingBins, 0.0);
  std::vector<int> count(kBearingBins, 0);
  for (size_t i = 0; i < bearings.size(); ++i) {
    const int k = std::clamp(static_cast<int>((bearings[i] + M_PI) / (2.0 * M_PI) * kBearingBins),
                             0, kBearingBins - 1);
    sum[k] += values[i];
    ++count[k];
  }
  std::vector<int> filled;
  for (int k = 0; k < kBearingBins; ++k)
    if (count[k] > 0) {
      sum[k] /= count[k];
      filled.push_back(k);
    }
  if (filled.empty()) return {};
  for (size_t j = 0; j < filled.size(); ++j) {
    const int from = filled[j], to = filled[(j + 1) % filled.size()];
    const int gap = (to - from + kBearingBins - 1) % kBearingBins + 1;  // a full turn alone
    for (int step = 1; step < gap; ++step) {
      const double t = static_cast<double>(step) / gap;
      sum[(from + step) % kBearingBins] = (1.0 - t) * sum[from] + t * sum[to];
    }
  }
  return sum;
}

void add_scan_end_candidates(std::vector<std::vector<Candidate>>& all, const Projection& project,
                             const Eigen::Vector3d& center, const std::vector<ScanBorder>& borders,
                             const std::vector<Eigen::Vector3d>& seeds,
                             const std::vector<Eigen::Vector3d>& holes, double band) {
  if (borders.empty() || seeds.empty() || holes.empty()) return;
  std::vector<double> bearings, radii;
  for (const Eigen::Vector3d& p : seeds) {
    const Eigen::Vector2d q = project(p - center);
    if (q.norm() < 1e-9) continue;
    bearings.push_back(std::atan2(q.y(), q.x()));
    radii.push_back((p - center).norm());
  }
  const std::vector<double> bins = by_bearing_bins(bearings, radii);
  if (bins.empty()) return;
  auto radius_at = [&](double phi) {  // linear between the bins' middles
    const double x = (phi + M_PI) / (2.0 * M_PI) * kBearingBins - 0.5;
    const int k = static_cast<int>(std::floor(x));
    const double t = x - k;
    return (1.0 - t) * bins[(k % kBearingBins + kBearingBins) % kBearingBins] +
           t * bins[((k + 1) % kBearingBins + kBearingBins) % kBearingBins];
  };
  const PointIndex hole_index(holes);
  const double band_chord2 = std::pow(2.0 * std::sin(0.5 * band), 2);
  const double width = 2.0 * M_PI / kSectors;
  for (const ScanBorder& b : borders) {
    const double h = b.offset - b.normal.dot(center);  // the plane's distance from the centre
    if (!(h > 0.0)) continue;                          // the centre must lie inside the scan
    const double along = b.normal.dot(project.axis);
    for (int k = 0; k < kSectors; ++k) {
      const double phi = (k + 0.5) * width - M_PI;
      const Eigen::Vector3d u = std::cos(phi) * project.e1 + std::sin(phi) * project.e2;
      // n·d(θ) = A cos θ + B sin θ = ρ cos(θ − α) for d(θ) = cos θ axis + sin θ u.
      const double across = b.normal.dot(u);
      const double rho = std::hypot(along, across), alpha = std::atan2(across, along);
      const double radius = radius_at(phi);
      const double s = h / radius;
      if (rho < 1e-9 || s > rho) continue;
      const double theta = alpha - std::acos(std::clamp(s / rho, -1.0, 1.0));
      if (theta <= 0.0 || theta >= M_PI) continue;
      const Eigen::Vector3d d = std::cos(theta) * project.axis + std::sin(theta) * u;
      const Eigen::Vector3d point = center + radius * d;
      double d2 = 0.0;
      hole_index.nearest(d, &d2);
      if (d2 > band_chord2) continue;
      auto& sector = all[k];
      sector.push_back({point, theta, radius, true});
      std::sort(sector.begin(), sector.end(),
                [](const Candidate& x, const Candidate& y) { return x.theta < y.theta; });
    }
  }
}

// The edge of one table: its candidates per sector and the path chosen through them, as a
// closed polyline in order of bearing (empty when too little of it was found).
struct TableEdge {
  std::vector<Eigen::Vector3d> loop;
  std::vector<char> at_border;
  std::vector<int> sector;  // each point's sector
};

// The opening the edge goes round: the faces examined, and the rays through it (and beside it,
// closed by the scan's end) with the angle around them the faces were taken from.
struct Band {
  std::vector<int> faces;
  FacesAround around;  // faces_around(faces)
  const std::vector<Eigen::Vector3d>& rays;
  double angle;  // rad
};

TableEdge trace_table(const SkullMesh& mesh, const SurfaceLocator& bone,
                      const std::vector<Eigen::Vector3d>& vn, const Projection& project,
                      const Eigen::Vector3d& center, const Band& band,
                      const std::vector<Eigen::Vector3d>& seeds,
                      const std::vector<Eigen::Vector3d>& seen_rim,
                      const std::vector<ScanBorder>& borders, bool outer,
                      const TraceRimParams& params) {
  TableEdge e;
  Table table(mesh, bone, vn, center, outer, params);
  table.grow(band.faces, band.around, seed_faces(bone, seeds));
  std::vector<uint8_t> examined(mesh.n_faces(), 0);
  for (int f : band.faces) examined[f] = 1;
  auto candidates = edge_candidates(mesh, table, examined, project, center, borders);
  if (params.along_scan_end)
    add_scan_end_candidates(candidates, project, center, borders, seeds, band.rays, band.angle);
  std::vector<std::optional<Eigen::Vector3d>> seen(kSectors);
  double scale = 0.0;
  for (const Eigen::Vector3d& p : seen_rim) {
    seen[project.sector(project(p - center))] = p;
    scale += (p - center).norm();
  }
  scale /= std::max<size_t>(1, seen_rim.size());
  const std::vector<int> chosen = choose_edge(candidates, seen, scale);
  if (chosen.empty()) return e;
  const std::vector<char> bay = narrow_bays(candidates, chosen);
  for (int k = 0; k < kSectors; ++k)
    if (chosen[k] >= 0 && !bay[k]) {
      const Candidate& c = candidates[k][chosen[k]];
      e.loop.push_back(c.point);
      e.at_border.push_back(c.at_border);
      e.sector.push_back(k);
    }
  return e;
}

// The traced edge is given up when it has no point over this share of the sectors, or over a
// run of this many degrees of bearing.
constexpr double kMaxEmptyShare = 0.25;
constexpr double kMaxEmptyRunDeg = 30.0;

bool covers_enough(const std::vector<int>& sectors) {
  if (sectors.empty()) return false;
  if (static_cast<double>(sectors.size()) < (1.0 - kMaxEmptyShare) * kSectors) return false;
  int longest = 0;
  for (size_t i = 0; i < sectors.size(); ++i) {
    const int next = sectors[(i + 1) % sectors.size()];
    const int gap = (next - sectors[i] + kSectors) % kSectors - 1;
    longest = std::max(longest, gap);
  }
  return longest * 360.0 / kSectors <= kMaxEmptyRunDeg;
}

}  // namespace

std::vector<char> inside_loop(const std::vector<Eigen::Vector3d>& dirs,
                              const std::vector<Eigen::Vector3d>& loop,
                              const Eigen::Vector3d& center, const Eigen::Vector3d& axis,
                              const Eigen::Vector3d& e1) {
  const Projection project{axis, e1, axis.cross(e1)};
  std::vector<Eigen::Vector2d> poly;
  for (const Eigen::Vector3d& p : loop) poly.push_back(project(p - center));
  std::vector<char> in(dirs.size(), 0);
  for (size_t i = 0; i < dirs.size(); ++i) in[i] = inside_polygon(poly, project(dirs[i]));
  return in;
}

TracedRim trace_rim_on_bone(const SkullMesh& skull, const SurfaceLocator& bone,
                            const Eigen::Vector3d& center, const Eigen::Vector3d& axis,
                            const Eigen::Vector3d& e1,
                            const std::vector<Eigen::Vector3d>& hole_directions,
                            const std::vector<Eigen::Vector3d>& seen_rim,
                            const std::vector<Eigen::Vector3d>& seen_inner_rim,
                            const std::vector<Eigen::Vector3d>& outer_seeds,
                            const std::vector<Eigen::Vector3d>& inner_seeds,
                            const std::vector<ScanBorder>& borders, const TraceRimParams& params) {
  const auto t0 = std::chrono::steady_clock::now();
  TracedRim r;
  auto done = [&] {
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  };
  if (hole_directions.empty() || outer_seeds.empty() || seen_rim.empty() || skull.n_faces() == 0) {
    r.message = "no opening to trace";
    return done();
  }
  const Projection project{axis, e1, axis.cross(e1)};
  const double band_angle = std::clamp(params.band_deg, 5.0, 90.0) * kDeg;
  std::future<std::vector<Eigen::Vector3d>> normals =
      std::async(beside(), [&skull] { return smooth_vertex_normals(skull); });
  std::vector<int> faces = band_faces(skull, center, hole_directions, band_angle);
  FacesAround around = faces_around(skull, faces);
  const Band band{std::move(faces), std::move(around), hole_directions, band_angle};
  r.faces_examined = band.faces.size();
  const std::vector<Eigen::Vector3d> vn = normals.get();
  // The two tables are traced independently, the inner beside the outer (its edge is only
  // used when the outer one is found).
  const bool trace_inner = !inner_seeds.empty() && !seen_inner_rim.empty();
  std::future<TableEdge> inner_edge;
  if (trace_inner)
    inner_edge = std::async(beside(), [&] {
      return trace_table(skull, bone, vn, project, center, band, inner_seeds, seen_inner_rim,
                         borders, false, params);
    });
  const TableEdge outer = trace_table(skull, bone, vn, project, center, band, outer_seeds, seen_rim,
                                      borders, true, params);
  if (!covers_enough(outer.sector)) {
    r.message = "the outer table's edge was not found all around the opening";
    return done();
  }
  const double spacing = std::clamp(params.spacing_mm, 0.25, 5.0);
  resample(outer.loop, outer.at_border, spacing, 2.0, r.outer, r.at_scan_border);
  for (size_t i = 0; i < r.outer.size(); ++i) {
    if (r.at_scan_border[i]) continue;  // the scan's end, not a crease of the bone
    const double radius = (r.outer[i] - center).norm();
    r.outer[i] = onto_crease(bone, vn, skull, r.outer[i], center + radius * axis - r.outer[i]);
  }
  // From the point nearest −180° of bearing, in order of increasing bearing (the sectors').
  auto bearing = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d q = project(p - center);
    return std::atan2(q.y(), q.x());
  };
  size_t start = 0;
  for (size_t i = 1; i < r.outer.size(); ++i)
    if (bearing(r.outer[i]) < bearing(r.outer[start])) start = i;
  std::rotate(r.outer.begin(), r.outer.begin() + static_cast<long>(start), r.outer.end());
  std::rotate(r.at_scan_border.begin(), r.at_scan_border.begin() + static_cast<long>(start),
              r.at_scan_border.end());

  // The inner table's edge; each outer point paired with the inner one nearest it.
  if (trace_inner) {
    const TableEdge inner = inner_edge.get();
    if (inner.loop.size() >= 3) {
      const PointIndex index(inner.loop);
      for (const Eigen::Vector3d& p : r.outer) r.inner.push_back(inner.loop[index.nearest(p)]);
    }
  }
  r.status = TracedRim::Status::Traced;
  return done();
}

}  // namespace cranioplan
