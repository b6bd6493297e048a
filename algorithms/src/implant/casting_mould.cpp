#include "cranioplan/algorithms/implant/casting_mould.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>

#include "cranioplan/algorithms/geometry/mesh_distance_field.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/model/parallel.h"

namespace cranioplan {

const char* status_name(MouldResult::Status status) {
  return status == MouldResult::Status::Made ? "made" : "failed";
}

namespace {

// The parting surface's grid over the plane across the axis, mm.
constexpr double kPartingStep = 0.5;

// Heights along the axis over a grid across it: the implant's top and bottom where a line along
// the axis meets it, and the parting surface (midway between them there; beyond the implant,
// that of the nearest cell over it, smoothed).
struct Parting {
  double u0 = 0, v0 = 0, step = kPartingStep;
  int nu = 0, nv = 0;
  std::vector<double> top, bottom, height;
  std::vector<uint8_t> over;  // a line there meets the implant

  size_t at(int i, int j) const { return static_cast<size_t>(j) * nu + i; }
  double sample(const std::vector<double>& m, double u, double v) const {
    const double fu = std::clamp((u - u0) / step, 0.0, nu - 1.0),
                 fv = std::clamp((v - v0) / step, 0.0, nv - 1.0);
    const int i = std::min(nu - 2, static_cast<int>(fu)),
              j = std::min(nv - 2, static_cast<int>(fv));
    const double a = fu - i, b = fv - j;
    return (1 - a) * (1 - b) * m[at(i, j)] + a * (1 - b) * m[at(i + 1, j)] +
           (1 - a) * b * m[at(i, j + 1)] + a * b * m[at(i + 1, j + 1)];
  }
};

// A pull direction's frame, parting surface and the implant's area it traps.
struct Pull {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ(), e1 = Eigen::Vector3d::UnitX(),
                  e2 = Eigen::Vector3d::UnitY();
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();  // local bounds
  Parting part;
  double undercut_mm2 = 0.0;
  std::vector<SkullMesh::FaceHandle> undercut;  // the faces
};

// How many times the line along `axis` through `x` crosses the surface (counted up to 8).
int crossings(const SurfaceLocator& self, const Eigen::Vector3d& x, const Eigen::Vector3d& axis,
              double reach) {
  Eigen::Vector3d from = x - reach * axis;
  const Eigen::Vector3d to = x + reach * axis;
  int n = 0;
  while (n < 8) {
    const auto hit = self.first_hit(from, to);
    if (!hit) break;
    ++n;
    from = hit->point + 1e-4 * axis;
  }
  return n;
}

Pull part_along(const SkullMesh& implant, const SurfaceLocator& self, const Eigen::Vector3d& c,
                const Eigen::Vector3d& axis, double wall_mm) {
  Pull out;
  out.axis = axis.normalized();
  out.e1 = out.axis.unitOrthogonal();
  out.e2 = out.axis.cross(out.e1);
  auto local = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d d = x - c;
    return Eigen::Vector3d(d.dot(out.e1), d.dot(out.e2), d.dot(out.axis));
  };
  auto world = [&](double u, double v, double h) {
    return c + u * out.e1 + v * out.e2 + h * out.axis;
  };
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (auto vh : implant.vertices()) {
    const Eigen::Vector3d q = local(to_eigen(implant.point(vh)));
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  out.lo = lo;
  out.hi = hi;
  Parting& part = out.part;
  part.u0 = lo.x() - wall_mm;
  part.v0 = lo.y() - wall_mm;
  part.nu = static_cast<int>(std::ceil((hi.x() - lo.x() + 2 * wall_mm) / part.step)) + 1;
  part.nv = static_cast<int>(std::ceil((hi.y() - lo.y() + 2 * wall_mm) / part.step)) + 1;
  const size_t cells = static_cast<size_t>(part.nu) * part.nv;
  part.top.assign(cells, 0.0);
  part.bottom.assign(cells, 0.0);
  part.height.assign(cells, 0.0);
  part.over.assign(cells, 0);
  parallel_for(cells, [&](size_t begin, size_t end) {
    for (size_t q = begin; q < end; ++q) {
      const double u = part.u0 + static_cast<double>(q % part.nu) * part.step,
                   v = part.v0 + static_cast<double>(q / part.nu) * part.step;
      const auto down = self.first_hit(world(u, v, hi.z() + 1.0), world(u, v, lo.z() - 1.0));
      if (!down) continue;
      const auto up = self.first_hit(world(u, v, lo.z() - 1.0), world(u, v, hi.z() + 1.0));
      part.top[q] = local(down->point).z();
      part.bottom[q] = up ? local(up->point).z() : part.top[q];
      part.height[q] = 0.5 * (part.top[q] + part.bottom[q]);
      part.over[q] = 1;
    }
  });
  // Beyond the implant: the nearest cell's over it (breadth first), then smoothed there.
  std::vector<uint8_t> set = part.over;
  std::deque<size_t> queue;
  for (size_t q = 0; q < cells; ++q)
    if (set[q]) queue.push_back(q);
  if (queue.empty()) {
    part.nu = 0;  // no line across the implant meets it
    return out;
  }
  while (!queue.empty()) {
    const size_t q = queue.front();
    queue.pop_front();
    const int i = static_cast<int>(q % part.nu), j = static_cast<int>(q / part.nu);
    const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      const int ii = i + di[k], jj = j + dj[k];
      if (ii < 0 || jj < 0 || ii >= part.nu || jj >= part.nv) continue;
      const size_t n = part.at(ii, jj);
      if (set[n]) continue;
      set[n] = 1;
      part.height[n] = part.height[q];
      queue.push_back(n);
    }
  }
  for (int it = 0; it < 40; ++it) {
    std::vector<double> next = part.height;
    for (int j = 1; j + 1 < part.nv; ++j)
      for (int i = 1; i + 1 < part.nu; ++i) {
        const size_t q = part.at(i, j);
        if (part.over[q]) continue;
        next[q] = 0.25 * (part.height[part.at(i + 1, j)] + part.height[part.at(i - 1, j)] +
                          part.height[part.at(i, j + 1)] + part.height[part.at(i, j - 1)]);
      }
    part.height = std::move(next);
  }
  // Undercuts: implant faces above the parting surface facing down, or below it facing up.
  const double slack = std::sin(2.0 * M_PI / 180.0);
  for (auto fh : implant.faces()) {
    Eigen::Vector3d q[3];
    int k = 0;
    for (auto vh : implant.fv_range(fh)) q[k++] = to_eigen(implant.point(vh));
    const Eigen::Vector3d cross = (q[1] - q[0]).cross(q[2] - q[0]);
    if (cross.norm() == 0) continue;
    const Eigen::Vector3d m = local((q[0] + q[1] + q[2]) / 3.0);
    const double facing = cross.normalized().dot(out.axis);
    const bool upper = m.z() > part.sample(part.height, m.x(), m.y());
    if ((upper && facing < -slack) || (!upper && facing > slack)) {
      out.undercut_mm2 += 0.5 * cross.norm();
      out.undercut.push_back(fh);
    }
  }
  return out;
}

}  // namespace

std::string mould_problem(const MouldParams& p) {
  if (std::string problem = range_problems("the mould's", p); !problem.empty()) return problem;
  const ParamSpec wall = spec_of<MouldParams>("wall_mm");
  if (p.key_diameter_mm + 2.0 > p.wall_mm)
    return wall.problem("the mould's", p.wall_mm, p.key_diameter_mm + 2.0, wall.max) +
           " for its keys";
  return {};
}

namespace {

// The pull: of the implant's thinnest principal axis (pointing away from the skull's inside)
// and the directions 10° and 20° around it, the one whose parting traps the least of the
// implant (the first of equals). A pull with `part.nu == 0` where no line across the implant
// meets it.
Pull choose_pull(const SkullMesh& implant, const SurfaceLocator& self, const Eigen::Vector3d& c,
                 const Eigen::Vector3d& inside, double wall_mm) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (auto vh : implant.vertices()) {
    const Eigen::Vector3d d = to_eigen(implant.point(vh)) - c;
    cov += d * d.transpose();
  }
  Eigen::Vector3d principal =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  if (principal.dot(c - inside) < 0) principal = -principal;
  std::vector<Eigen::Vector3d> pulls{principal};
  const Eigen::Vector3d p1 = principal.unitOrthogonal(), p2 = principal.cross(p1);
  for (const double tilt : {10.0, 20.0})
    for (int k = 0; k < 8; ++k) {
      const double t = tilt * M_PI / 180.0, az = k * M_PI / 4.0;
      pulls.push_back(std::cos(t) * principal +
                      std::sin(t) * (std::cos(az) * p1 + std::sin(az) * p2));
    }
  Pull best;
  for (const Eigen::Vector3d& pull : pulls) {
    Pull candidate = part_along(implant, self, c, pull, wall_mm);
    if (candidate.part.nu == 0) continue;  // no line along it meets the implant
    if (best.part.nu == 0 || candidate.undercut_mm2 < best.undercut_mm2 - 1e-9)
      best = std::move(candidate);
  }
  return best;
}

// Of the undercut, what no parting could free: faces on a line along the pull that crosses the
// implant more than twice (mm²).
double trapped_area(const SkullMesh& implant, const SurfaceLocator& self, const Pull& pull,
                    double reach) {
  double area = 0.0;
  for (const auto fh : pull.undercut) {
    Eigen::Vector3d q[3];
    int k = 0;
    for (auto vh : implant.fv_range(fh)) q[k++] = to_eigen(implant.point(vh));
    if (crossings(self, (q[0] + q[1] + q[2]) / 3.0, pull.axis, reach) > 2)
      area += 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
  }
  return area;
}

// The pull's frame about the implant's centroid: (u, v) across the pull, h along it.
struct PullFrame {
  Eigen::Vector3d c, e1, e2, axis;
  Eigen::Vector3d local(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d d = x - c;
    return Eigen::Vector3d(d.dot(e1), d.dot(e2), d.dot(axis));
  }
  Eigen::Vector3d world(double u, double v, double h) const {
    return c + u * e1 + v * e2 + h * axis;
  }
};

// An opening through the outer half: a cylinder along the pull from this height up.
struct Opening {
  Eigen::Vector2d at;
  double radius, from;
};

// The pour channel over the implant's thickest cell; the vent over the cell of the implant
// farthest from it with the vent's width of implant around it. Their cells in `pour`, `vent`.
std::array<Opening, 2> pour_and_vent(const Parting& part, const MouldParams& p, size_t& pour,
                                     size_t& vent) {
  const size_t cells = static_cast<size_t>(part.nu) * part.nv;
  pour = 0;
  double thickest = -1.0;
  for (size_t q = 0; q < cells; ++q)
    if (part.over[q] && part.top[q] - part.bottom[q] > thickest)
      thickest = part.top[q] - part.bottom[q], pour = q;
  const auto uv = [&](size_t q) {
    return Eigen::Vector2d(part.u0 + static_cast<double>(q % part.nu) * part.step,
                           part.v0 + static_cast<double>(q / part.nu) * part.step);
  };
  vent = pour;
  double farthest = -1.0;
  const int rim = static_cast<int>(std::ceil((0.5 * p.vent_diameter_mm + 1.0) / part.step));
  for (size_t q = 0; q < cells; ++q) {
    if (!part.over[q]) continue;
    const int i = static_cast<int>(q % part.nu), j = static_cast<int>(q / part.nu);
    bool inside_rim = true;
    for (int dj = -rim; dj <= rim && inside_rim; ++dj)
      for (int di = -rim; di <= rim && inside_rim; ++di) {
        const int ii = i + di, jj = j + dj;
        inside_rim =
            ii >= 0 && jj >= 0 && ii < part.nu && jj < part.nv && part.over[part.at(ii, jj)];
      }
    const double d = (uv(q) - uv(pour)).norm();
    if (inside_rim && d > farthest) farthest = d, vent = q;
  }
  return {{{uv(pour), 0.5 * p.channel_diameter_mm, part.top[pour] - 0.5},
           {uv(vent), 0.5 * p.vent_diameter_mm, part.top[vent] - 0.5}}};
}

// The block in the pull's frame (the implant's bounds and the parting surface, a wall beyond),
// and the keys at its corners on the parting surface.
struct Block {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0, h0 = 0, h1 = 0;
  std::vector<Eigen::Vector3d> keys;
};

Block block_around(const Pull& pull, const MouldParams& p) {
  const Parting& part = pull.part;
  Block b;
  b.u0 = pull.lo.x() - p.wall_mm;
  b.u1 = pull.hi.x() + p.wall_mm;
  b.v0 = pull.lo.y() - p.wall_mm;
  b.v1 = pull.hi.y() + p.wall_mm;
  b.h0 = pull.lo.z();
  b.h1 = pull.hi.z();
  const size_t cells = static_cast<size_t>(part.nu) * part.nv;
  for (size_t q = 0; q < cells; ++q) {
    b.h0 = std::min(b.h0, part.height[q]);
    b.h1 = std::max(b.h1, part.height[q]);
  }
  b.h0 -= p.wall_mm;
  b.h1 += p.wall_mm;
  const double inset = 0.5 * p.wall_mm;
  for (const double u : {b.u0 + inset, b.u1 - inset})
    for (const double v : {b.v0 + inset, b.v1 - inset})
      b.keys.emplace_back(u, v, part.sample(part.height, u, v));
  return b;
}

// The two halves as signed distances on a grid over the block (negative inside): the block cut
// by the parting surface, less the implant; the keys on the inner half, their sockets and the
// openings cut from the outer.
struct HalfFields {
  VoxelGrid grid;
  std::vector<float> outer, inner;
};

HalfFields half_fields(const SkullMesh& implant, const SurfaceLocator& self, const PullFrame& f,
                       const Parting& part, const Block& b, const std::array<Opening, 2>& openings,
                       const MouldParams& p) {
  Eigen::Vector3d wlo = Eigen::Vector3d::Constant(1e300), whi = -wlo;
  for (const double u : {b.u0, b.u1})
    for (const double v : {b.v0, b.v1})
      for (const double h : {b.h0, b.h1}) {
        const Eigen::Vector3d x = f.world(u, v, h);
        wlo = wlo.cwiseMin(x);
        whi = whi.cwiseMax(x);
      }
  HalfFields out{VoxelGrid::covering_at_most(wlo, whi, p.voxel_mm, p.max_voxels, 2), {}, {}};
  const VoxelGrid& g = out.grid;
  const std::vector<float> cavity =
      signed_distance_near_surface(self, voxelize_mesh(implant, g), g);
  out.outer.resize(g.size());
  out.inner.resize(g.size());
  const double rk = 0.5 * p.key_diameter_mm;
  parallel_for(g.size(), [&](size_t begin, size_t end) {
    for (size_t cc = begin; cc < end; ++cc) {
      const int i = static_cast<int>(cc % g.dims[0]),
                j = static_cast<int>((cc / g.dims[0]) % g.dims[1]),
                k = static_cast<int>(cc / (static_cast<size_t>(g.dims[0]) * g.dims[1]));
      const Eigen::Vector3d x = f.local(g.center(i, j, k));
      const double block = std::min(
          {x.x() - b.u0, b.u1 - x.x(), x.y() - b.v0, b.v1 - x.y(), x.z() - b.h0, b.h1 - x.z()});
      const double split = x.z() - part.sample(part.height, x.x(), x.y());
      const double not_implant = -static_cast<double>(cavity[cc]);
      double o = std::min({block, split, not_implant}), n = std::min({block, -split, not_implant});
      for (const Eigen::Vector3d& key : b.keys) {
        const double d = (x - key).norm();
        n = std::max(n, std::min(rk - d, block));        // the key on the inner half
        o = std::min(o, d - (rk + p.key_clearance_mm));  // its socket in the outer
      }
      for (const Opening& hole : openings) {
        const double radial = (x.head<2>() - hole.at).norm();
        o = std::min(o, -std::min(hole.radius - radial, x.z() - hole.from));
      }
      out.outer[cc] = static_cast<float>(o);
      out.inner[cc] = static_cast<float>(n);
    }
  });
  return out;
}

// The cavity against the implant: each implant vertex's distance to the nearer half, away from
// the openings (where the cavity is open to the top), into r's cavity figures.
void measure_cavity(const SkullMesh& implant, const SurfaceLocator& self, const PullFrame& f,
                    const std::array<Opening, 2>& openings, double reach, MouldResult& r) {
  const SurfaceLocator lo_half(r.inner), hi_half(r.outer);
  std::vector<double> gaps;
  for (auto vh : implant.vertices()) {
    const Eigen::Vector3d x = to_eigen(implant.point(vh));
    const Eigen::Vector3d q = f.local(x);
    bool open = false;
    for (const Opening& hole : openings)
      open = open || (q.head<2>() - hole.at).norm() < hole.radius + 1.0;
    if (open) continue;
    gaps.push_back(std::min(lo_half.closest(x).distance, hi_half.closest(x).distance));
    // Where the implant can be lifted out (its line along the pull crosses it twice).
    if (gaps.back() > r.cavity_free_max_mm && crossings(self, x, f.axis, reach) <= 2)
      r.cavity_free_max_mm = gaps.back();
  }
  std::sort(gaps.begin(), gaps.end());
  if (!gaps.empty()) {
    r.cavity_beyond_0_2 =
        static_cast<double>(gaps.end() - std::upper_bound(gaps.begin(), gaps.end(), 0.2)) /
        static_cast<double>(gaps.size());
    r.cavity_max_mm = gaps.back();
    r.cavity_p95_mm = gaps[static_cast<size_t>(0.95 * static_cast<double>(gaps.size() - 1))];
  }
}

std::string mould_message(const MouldResult& r, const Block& b) {
  char buf[300];
  std::snprintf(buf, sizeof(buf),
                "mould of %.0f × %.0f × %.0f mm in two halves; the cavity within %.2f mm of the "
                "implant (95 %% within %.2f mm, %.2f %% beyond 0.2 mm; within %.2f mm outside "
                "the folds)",
                b.u1 - b.u0, b.v1 - b.v0, b.h1 - b.h0, r.cavity_max_mm, r.cavity_p95_mm,
                100.0 * r.cavity_beyond_0_2, r.cavity_free_max_mm);
  std::string message = buf;
  if (r.undercut_mm2 > 1.0) {
    std::snprintf(buf, sizeof(buf),
                  "; %.0f mm² of the implant is undercut along the parting (%.0f mm² in folds: "
                  "where it folds back along the pull)",
                  r.undercut_mm2, r.trapped_mm2);
    message += buf;
  }
  return message;
}

}  // namespace

MouldResult make_casting_mould(const SkullMesh& implant, const Eigen::Vector3d& inside,
                               const MouldParams& p) {
  const auto t0 = std::chrono::steady_clock::now();
  MouldResult r;
  // Every return is of `r` itself, so that it is made where it is returned (a function that
  // returns anything else copies it, and the mould's halves with it).
  auto done = [&] {
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (const std::string problem = mould_problem(p); !problem.empty()) {
    r.message = problem;
    done();
    return r;
  }
  if (implant.n_faces() == 0) {
    r.message = "the implant has no triangles";
    done();
    return r;
  }
  const Eigen::Vector3d c = vertex_centroid(implant);
  const SurfaceLocator self(implant);
  const Pull best = choose_pull(implant, self, c, inside, p.wall_mm);
  if (best.part.nu == 0) {
    r.message = "no line across the implant meets it";
    done();
    return r;
  }
  const PullFrame frame{c, best.e1, best.e2, best.axis};
  const Parting& part = best.part;
  r.axis = best.axis;
  r.undercut_mm2 = best.undercut_mm2;
  const double reach = (best.hi - best.lo).norm() + 1.0;
  r.trapped_mm2 = trapped_area(implant, self, best, reach);

  size_t pour = 0, vent = 0;
  const std::array<Opening, 2> openings = pour_and_vent(part, p, pour, vent);
  r.pour = frame.world(openings[0].at.x(), openings[0].at.y(), part.top[pour]);
  r.vent = frame.world(openings[1].at.x(), openings[1].at.y(), part.top[vent]);
  const Block block = block_around(best, p);
  {
    HalfFields fields = half_fields(implant, self, frame, part, block, openings, p);
    // The halves meshed where the result keeps them.
    ExtractBoneSurfaceResult mo =
        surface_of_signed_distance(std::move(fields.outer), fields.grid, r.outer, p.iso_gap);
    ExtractBoneSurfaceResult mi =
        surface_of_signed_distance(std::move(fields.inner), fields.grid, r.inner, p.iso_gap);
    if (!mo.usable() || !mi.usable()) {
      r.message = "meshing the mould: " + (mo.usable() ? mi.message : mo.message);
      r.outer.clear();
      r.inner.clear();
      done();
      return r;
    }
  }
  measure_cavity(implant, self, frame, openings, reach, r);
  r.status = MouldResult::Status::Made;
  r.message = mould_message(r, block);
  done();
  return r;
}

}  // namespace cranioplan
