#include "cranioplan/algorithms/implant/trim_to_bone.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include "cranioplan/algorithms/geometry/distance_transform.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/model/parallel.h"
#include "stage_clock.h"

namespace cranioplan {

namespace {

using Mask = std::vector<uint8_t>;

// Calls f(k) for every slice k < nz on all threads, the slices dealt in a spread order (k = q ·
// step mod nz) so that each thread gets some of the implant's slices and some of the empty
// ones. f must write only its own slice's voxels.
template <class F>
void for_slices_spread(int nz, F&& f) {
  const size_t n = static_cast<size_t>(nz);
  size_t step = 1;
  for (size_t s : {7, 11, 13, 17, 19, 23})
    if (std::gcd(s, n) == 1) {
      step = s;
      break;
    }
  parallel_for(
      n,
      [&](size_t first, size_t last) {
        for (size_t q = first; q < last; ++q) f(static_cast<int>(q * step % n));
      },
      2);
}

// One step of 6-neighbour dilation (slices on all threads; each voxel written once).
Mask dilate(const Mask& in, const VoxelGrid& g) {
  Mask out(in.size(), 0);
  const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  const size_t sy = static_cast<size_t>(nx), sz = static_cast<size_t>(nx) * ny;
  parallel_for(
      static_cast<size_t>(nz),
      [&](size_t first, size_t last) {
        for (size_t k = first; k < last; ++k)
          for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
              const size_t c = k * sz + j * sy + i;
              out[c] = in[c] || (i > 0 && in[c - 1]) || (i + 1 < nx && in[c + 1]) ||
                       (j > 0 && in[c - sy]) || (j + 1 < ny && in[c + sy]) ||
                       (k > 0 && in[c - sz]) || (k + 1 < static_cast<size_t>(nz) && in[c + sz]);
            }
      },
      2);
  return out;
}

// Calls `f` with the index of every voxel whose centre lies beyond one of `ends` (planes whose
// normals point out of the scan).
template <class F>
void for_each_beyond(const VoxelGrid& grid, const std::vector<Plane>& ends, F&& f) {
  if (ends.empty()) return;
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const Eigen::Vector3d x = grid.center(i, j, k);
        if (std::any_of(ends.begin(), ends.end(),
                        [&](const Plane& end) { return end.signed_distance(x) > 0.0; }))
          f(grid.index(i, j, k));
      }
}

// Keeps the largest 6-connected piece (the first found, by its lowest voxel index, among
// pieces as large). Each piece is gathered as a list of its voxels; only the largest list is
// kept, so the work follows the mask's voxels rather than the grid's.
Mask largest_piece(const Mask& in, const VoxelGrid& g) {
  Mask seen(in.size(), 0);
  std::vector<size_t> best, piece;
  const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  const size_t sy = static_cast<size_t>(nx), sz = sy * ny;
  for (size_t seed = 0; seed < in.size(); ++seed) {
    if (!in[seed] || seen[seed]) continue;
    piece.clear();
    piece.push_back(seed);
    seen[seed] = 1;
    for (size_t next = 0; next < piece.size(); ++next) {
      const size_t c = piece[next];
      const int i = static_cast<int>(c % sy), j = static_cast<int>((c / sy) % ny),
                k = static_cast<int>(c / sz);
      auto visit = [&](size_t d) {
        if (in[d] && !seen[d]) {
          seen[d] = 1;
          piece.push_back(d);
        }
      };
      if (i > 0) visit(c - 1);
      if (i + 1 < nx) visit(c + 1);
      if (j > 0) visit(c - sy);
      if (j + 1 < ny) visit(c + sy);
      if (k > 0) visit(c - sz);
      if (k + 1 < nz) visit(c + sz);
    }
    if (piece.size() > best.size()) best.swap(piece);
  }
  Mask out(in.size(), 0);
  for (size_t c : best) out[c] = 1;
  return out;
}

// What `implant` and `bone` have on either side of voxel (i,j,k) along (di,dj,dk): 1 implant,
// 2 bone, 0 nothing within `reach` steps (the first non-empty voxel decides).
int first_along(const Mask& implant, const Mask& bone, const VoxelGrid& g, int i, int j, int k,
                int di, int dj, int dk, int reach) {
  for (int s = 1; s <= reach; ++s) {
    const int a = i + s * di, b = j + s * dj, c = k + s * dk;
    if (a < 0 || b < 0 || c < 0 || a >= g.dims[0] || b >= g.dims[1] || c >= g.dims[2]) return 0;
    const size_t v = g.index(a, b, c);
    if (implant[v]) return 1;
    if (bone[v]) return 2;
  }
  return 0;
}

// Fills the voxels of cracks narrower than twice `steps` voxels between implant and bone.
Mask bridge_cracks(const Mask& implant, const Mask& bone, const VoxelGrid& g, int steps) {
  // Candidates: within `steps` (6-neighbour steps) of both.
  const Mask near_implant = within_steps(implant, g, steps),
             near_bone = within_steps(bone, g, steps);
  static const int dirs[13][3] = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1}, {1, 1, 0},  {1, -1, 0},
                                  {1, 0, 1},  {1, 0, -1}, {0, 1, 1}, {0, 1, -1}, {1, 1, 1},
                                  {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}};
  // Steps along a diagonal are longer: the width is kept in millimetres.
  int reach[13];
  for (int n = 0; n < 13; ++n) {
    const int* d = dirs[n];
    const double len = std::sqrt(double(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    reach[n] = std::max(1, static_cast<int>(std::floor(steps / len + 1e-9)));
  }
  Mask out = implant;
  for_slices_spread(g.dims[2], [&](int k) {
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const size_t c = g.index(i, j, k);
        if (implant[c] || bone[c] || !near_implant[c] || !near_bone[c]) continue;
        for (int n = 0; n < 13; ++n) {
          const int* d = dirs[n];
          const int ahead = first_along(implant, bone, g, i, j, k, d[0], d[1], d[2], reach[n]);
          if (ahead == 0) continue;
          const int behind = first_along(implant, bone, g, i, j, k, -d[0], -d[1], -d[2], reach[n]);
          if (behind != 0 && behind != ahead) {
            out[c] = 1;
            break;
          }
        }
      }
  });
  return out;
}

// Separable Gaussian blur of a 0/1 mask along the three axes. Each row (along x) of a pass's
// input is zero outside a span [lo, hi] of it; the output is summed within the spans its taps
// reach and is zero elsewhere. A zero adds nothing to a sum of non-negative terms (x + 0 = x
// in floats), so every float is that of the whole sum, and the implant fills only a shell of
// its grid.
std::vector<float> blur(const Mask& in, const VoxelGrid& g, double sigma_voxels) {
  std::vector<float> a(in.begin(), in.end());
  if (sigma_voxels <= 0.05) return a;
  const int r = std::max(1, static_cast<int>(std::ceil(2.5 * sigma_voxels)));
  std::vector<float> w(2 * r + 1);
  float sum = 0;
  for (int t = -r; t <= r; ++t)
    sum += w[t + r] = std::exp(-0.5f * t * t / (sigma_voxels * sigma_voxels));
  for (auto& x : w) x /= sum;
  std::vector<float> b(a.size());
  const int dims[3] = {g.dims[0], g.dims[1], g.dims[2]};
  const size_t stride[3] = {1, static_cast<size_t>(dims[0]),
                            static_cast<size_t>(dims[0]) * dims[1]};
  // The span of each row (j, k) of the current input that may be other than zero; lo > hi:
  // none.
  struct Span {
    int lo, hi;
  };
  const size_t rows = static_cast<size_t>(dims[1]) * dims[2];
  std::vector<Span> held(rows), next(rows);
  parallel_for(rows, [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      const uint8_t* at = &in[row * stride[1]];
      Span span{dims[0], -1};
      for (int i = 0; i < dims[0]; ++i)
        if (at[i]) {
          span.lo = std::min(span.lo, i);
          span.hi = i;
        }
      held[row] = span;
    }
  });
  for (int axis = 0; axis < 3; ++axis) {
    // The output's spans: along x the input's widened by the taps; along y and z the union of
    // the rows' a tap reaches.
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j) {
        const size_t row = static_cast<size_t>(j) + static_cast<size_t>(k) * dims[1];
        Span span{dims[0], -1};
        if (axis == 0) {
          if (held[row].lo <= held[row].hi)
            span = {std::max(0, held[row].lo - r), std::min(dims[0] - 1, held[row].hi + r)};
        } else {
          const int pos = axis == 1 ? j : k;
          for (int t = -r; t <= r; ++t) {
            if (pos + t < 0 || pos + t >= dims[axis]) continue;
            const Span& s = held[static_cast<size_t>(axis == 1 ? j + t : j) +
                                 static_cast<size_t>(axis == 2 ? k + t : k) * dims[1]];
            span.lo = std::min(span.lo, s.lo);
            span.hi = std::max(span.hi, s.hi);
          }
        }
        next[row] = span;
      }
    // Slices on all threads; each voxel's sum is taken over the taps in order (the same
    // float operations however the loops run) and written once. Along y and z a whole row in
    // x has the same taps: it is summed tap by tap, each over its row's span.
    parallel_for(
        static_cast<size_t>(dims[2]),
        [&](size_t first, size_t last) {
          for (int k = static_cast<int>(first); k < static_cast<int>(last); ++k)
            for (int j = 0; j < dims[1]; ++j) {
              const size_t row = g.index(0, j, k);
              float* out = &b[row];
              std::fill(out, out + dims[0], 0.0f);
              const Span span = next[static_cast<size_t>(j) + static_cast<size_t>(k) * dims[1]];
              if (span.lo > span.hi) continue;
              if (axis == 0) {
                for (int i = span.lo; i <= span.hi; ++i) {
                  const float* at = &a[row + i];
                  float v = 0;
                  if (i >= r && i + r < dims[0]) {
                    for (int t = -r; t <= r; ++t) v += w[t + r] * at[t];
                  } else {
                    for (int t = -r; t <= r; ++t)
                      if (i + t >= 0 && i + t < dims[0]) v += w[t + r] * at[t];
                  }
                  out[i] = v;
                }
                continue;
              }
              const int pos = axis == 1 ? j : k;
              for (int t = -r; t <= r; ++t) {
                if (pos + t < 0 || pos + t >= dims[axis]) continue;
                const Span& s = held[static_cast<size_t>(axis == 1 ? j + t : j) +
                                     static_cast<size_t>(axis == 2 ? k + t : k) * dims[1]];
                if (s.lo > s.hi) continue;
                const float wt = w[t + r];
                const float* in = &a[row + static_cast<std::ptrdiff_t>(t) *
                                               static_cast<std::ptrdiff_t>(stride[axis])];
                for (int i = s.lo; i <= s.hi; ++i) out[i] += wt * in[i];
              }
            }
        },
        2);
    a.swap(b);
    held.swap(next);
  }
  return a;
}

// The faces of `mesh` whose bounding boxes meet [lo, hi].
SkullMesh faces_in_box(const SkullMesh& mesh, const Eigen::Vector3d& lo,
                       const Eigen::Vector3d& hi) {
  TriangleSoup soup;
  std::vector<int> index(mesh.n_vertices(), -1);
  for (auto fh : mesh.faces()) {
    Eigen::Vector3d a = Eigen::Vector3d::Constant(1e300), b = -a;
    for (auto vh : mesh.fv_range(fh)) {
      a = a.cwiseMin(to_eigen(mesh.point(vh)));
      b = b.cwiseMax(to_eigen(mesh.point(vh)));
    }
    if ((b.array() < lo.array()).any() || (a.array() > hi.array()).any()) continue;
    Eigen::Vector3i t;
    int n = 0;
    for (auto vh : mesh.fv_range(fh)) {
      int& id = index[vh.idx()];
      if (id < 0) {
        id = static_cast<int>(soup.vertices.size());
        soup.vertices.push_back(to_eigen(mesh.point(vh)));
      }
      t[n++] = id;
    }
    soup.triangles.push_back(t);
  }
  return build_mesh(soup);
}

// The implant's smooth field, held the clearance off the skull's surface to a fraction of the
// grid: the mask is blurred together with the bone it touches (so the blur does not pull the
// surface back from the bone), then capped by a field that crosses ½ exactly the clearance
// outside the skull's surface, from the distance to its triangles. The surface then follows the
// bone's own surface rather than its voxels. The clearance is `clearance` mm, or a zone's where
// the nearest bone lies in one. `locator`: the skull's triangles near the grid (none: no
// surface there). `to_bone`: distance_to_mask(bone) up to that band, needed for a clearance wider
// than a voxel.
std::vector<float> fit_against_bone(const Mask& mask, const Mask& bone, const VoxelGrid& g,
                                    const SurfaceLocator* locator, double sigma_voxels,
                                    double clearance, const std::vector<ClearanceZone>& zones,
                                    const std::vector<float>& to_bone, StageClock& clock) {
  const double h = g.spacing;
  double widest = clearance;
  for (const ClearanceZone& z : zones) widest = std::max(widest, z.clearance_mm);
  // Bone within two voxels of the implant joins the blur.
  const Mask near_implant = within_steps(mask, g, 2);
  Mask joined = mask;
  for (size_t c = 0; c < joined.size(); ++c) joined[c] = mask[c] || (bone[c] && near_implant[c]);
  clock.mark("bone joined");
  std::vector<float> field = blur(joined, g, sigma_voxels);
  Mask().swap(joined);
  clock.mark("blur");
  if (!locator) {  // no surface near the grid: its bone voxels stay empty
    for (size_t c = 0; c < field.size(); ++c)
      if (bone[c]) field[c] = 0.0f;
    return field;
  }
  // The cap is below 1 up to a voxel beyond the clearance: the bone grown by two voxels holds
  // that band while the clearance is at most a voxel; a wider one takes the distance to it.
  Mask near_bone;
  if (widest <= h) {
    near_bone = within_steps(bone, g, 2);
  } else {
    near_bone.resize(to_bone.size());
    const float band = static_cast<float>(widest + 2.0 * h);
    for (size_t c = 0; c < to_bone.size(); ++c) near_bone[c] = to_bone[c] <= band;
  }
  clock.mark("band");
  // Without zones the distances are asked within a bounded radius: the skull's faces near a
  // stretch of kStretch voxels of a row are found once, and each voxel there asks only those
  // (the same distances as asking the whole tree).
  constexpr int kStretch = 8;
  const double reach = 0.5 * h + clearance + 1e-6 * h;
  for_slices_spread(g.dims[2], [&](int k) {
    std::vector<int> faces;
    for (int j = 0; j < g.dims[1]; ++j) {
      int stretch_end = -1;  // the last voxel of the stretch whose faces are in `faces`
      for (int i = 0; i < g.dims[0]; ++i) {
        const size_t c = g.index(i, j, k);
        if (field[c] <= 0.0f || !near_bone[c]) continue;
        // Without zones only a surface nearer than half a voxel beyond the clearance (outside
        // the bone) or half a voxel short of it (inside) makes the cap other than 1 outside the
        // bone and 0 inside it: farther, the cap below is clamped to that. A millionth of a
        // voxel more keeps the rounding of the clamped values out of it.
        double cap = bone[c] ? 0.0 : 1.0;
        const double radius =
            !zones.empty() ? std::numeric_limits<double>::infinity()
                           : (bone[c] ? 0.5 * h - clearance : 0.5 * h + clearance) + 1e-6 * h;
        if (zones.empty() && radius > 0.0 && i > stretch_end) {
          stretch_end = std::min(g.dims[0] - 1, i + kStretch - 1);
          locator->faces_near(g.center(i, j, k), g.center(stretch_end, j, k), reach, faces);
        }
        const auto near = radius <= 0.0 ? std::nullopt
                          : zones.empty()
                              ? locator->closest_within(g.center(i, j, k), radius, faces)
                              : locator->closest_within(g.center(i, j, k), radius);
        if (near) {
          const double d = near->distance * (bone[c] ? -1.0 : 1.0);
          const double want =
              zones.empty() ? clearance : clearance_at(near->point, clearance, zones);
          cap = std::clamp(0.5 + (d - want) / h, 0.0, 1.0);
        }
        field[c] = std::min(field[c], static_cast<float>(cap));
      }
    }
  });
  clock.mark("cap");
  // Every bone voxel is in the band, and half a voxel or more inside the surface its cap is 0
  // (a distance to fewer triangles is never shorter), so the blur leaves nothing in the bone.
  return field;
}

}  // namespace

namespace {

// A clearance wider than a voxel cut from `mask` to the voxels' resolution: voxels nearer the
// bone's than the clearance there (the zone's at the skull's closest point). Returns the
// distance to the bone's voxels it measured, asked against the clearances, the band beyond
// them and the fills' millimetre only.
std::vector<float> cut_wide_clearance(Mask& mask, const Mask& bone, const VoxelGrid& grid,
                                      const SurfaceLocator& locator, const TrimToBoneParams& params,
                                      double widest) {
  std::vector<float> to_bone =
      distance_to_mask(bone, grid, std::max(widest + 2.0 * grid.spacing, 1.0));
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const size_t c = grid.index(i, j, k);
        if (!mask[c] || to_bone[c] >= widest) continue;
        const double want = params.zones.empty()
                                ? *params.clearance_mm
                                : clearance_at(locator.closest(grid.center(i, j, k)).point,
                                               *params.clearance_mm, params.zones);
        if (to_bone[c] < want) mask[c] = 0;
      }
  return to_bone;
}

// What the fills (`bridged` beyond `mask`) leave thinner than the feature size away from the
// bone goes (a rod between the implant's edge and a fragment; a wall between the implant and a
// cut face is thick along the cut): what lies within a millimetre of the bone is the fill's
// contact. `to_bone`, when measured, is the distance to the bone's voxels.
void remove_thin_fills(Mask& bridged, const Mask& mask, const Mask& bone, const VoxelGrid& grid,
                       double radius_mm, const std::vector<float>& to_bone) {
  Mask far(bridged.size(), 0);
  bool any = false;
  const LocalDistance from_bone(bone, grid, 1.0f);
  for (size_t c = 0; c < bridged.size(); ++c)
    if (bridged[c] && !mask[c])
      any |= far[c] = to_bone.empty() ? from_bone.farther(c) : to_bone[c] > 1.0f;
  if (!any) return;
  // Whether each far fill lies in the fills' opening, from the voxels around it.
  LocalOpening opening(bridged, grid, radius_mm);
  std::vector<size_t> thin;
  for (size_t c = 0; c < bridged.size(); ++c)
    if (far[c] && !opening.contains(c)) thin.push_back(c);
  for (size_t c : thin) bridged[c] = 0;
}

// The skull's triangles near the grid, which suffice for distances up to a few voxels beyond
// the widest clearance; none when no triangle lies near it.
std::unique_ptr<SurfaceLocator> locator_near_grid(const SkullMesh& skull, const VoxelGrid& grid,
                                                  double widest) {
  const double reach = 3.0 * grid.spacing + widest;
  const SkullMesh local =
      faces_in_box(skull, grid.origin - Eigen::Vector3d::Constant(reach),
                   grid.center(grid.dims[0] - 1, grid.dims[1] - 1, grid.dims[2] - 1) +
                       Eigen::Vector3d::Constant(reach));
  if (local.n_faces() == 0) return nullptr;
  return std::make_unique<SurfaceLocator>(local);
}

// trim_to_bone, meshed in `into` (the result's own mesh, or the caller's).
void trim_into(const SkullMesh& implant, const SkullMesh& skull,
               const SurfaceLocator* skull_locator, const TrimToBoneParams& params,
               TrimToBoneResult& result, SkullMesh& into) {
  assert(&into != &implant && "the fit is meshed into another mesh than the implant");
  const auto t0 = std::chrono::steady_clock::now();
  StageClock clock(result.stage_seconds);
  const auto [lo, hi] = mesh_bounds(implant);
  const VoxelGrid grid = VoxelGrid::covering_at_most(lo, hi, std::clamp(params.voxel_mm, 0.1, 1.0),
                                                     std::max(1e5, params.max_voxels), 4);
  const double h = grid.spacing;
  VoxelizeParams solid;
  solid.vote_through_holes = params.vote_through_holes;
  Mask mask = voxelize_mesh(implant, grid, solid);
  // The skull's faces over the grid's lines only, found by its locator when the caller has one.
  Mask bone = skull_locator ? voxelize_mesh(skull, grid, solid, *skull_locator)
                            : voxelize_mesh(skull, grid, solid);
  size_t before = 0;
  for (size_t c = 0; c < mask.size(); ++c) {
    before += mask[c];
    mask[c] = mask[c] && !bone[c];
  }
  // Beyond the scan's end the bone is unknown: the implant ends there.
  for_each_beyond(grid, params.scan_ends, [&](size_t c) { mask[c] = 0; });
  clock.mark("voxels");
  double widest = params.clearance_mm.value_or(0.0);
  for (const ClearanceZone& z : params.zones) widest = std::max(widest, z.clearance_mm);
  // The caller's locator of the whole skull gives the same distances as one of the triangles
  // near the grid: the nearest triangle is the same one, and where no triangle lies near the
  // grid, every distance asked is beyond the band (the caps are then 1 outside the bone and 0
  // inside, as without a locator).
  std::unique_ptr<SurfaceLocator> own;
  if (params.clearance_mm && !skull_locator) own = locator_near_grid(skull, grid, widest);
  const SurfaceLocator* locator = !params.clearance_mm ? nullptr
                                  : skull_locator      ? skull_locator
                                                       : own.get();
  // A clearance wider than a voxel is cut first (to the voxels' resolution; the surface is held
  // at it exactly below), so that the opening also takes what it leaves thin: a tongue of the
  // implant reaching between two pieces of bone narrows by the clearance from both sides.
  std::vector<float> to_bone;  // the distance to the bone's voxels, when a clearance needs it
  if (locator && widest > h) {
    to_bone = cut_wide_clearance(mask, bone, grid, *locator, params, widest);
    clock.mark("clearance cut");
  }
  // Opening by a ball: slivers thinner than the feature size (left on top of intact bone, and
  // the thin lip where the shell's outer surface grazes the bone's) disappear, so the implant
  // ends in an edge at least that thick instead of a feather.
  if (params.min_feature_mm > 0) mask = open_by_ball(mask, grid, 0.5 * params.min_feature_mm);
  // The opening must not give back bone.
  for (size_t c = 0; c < mask.size(); ++c) mask[c] = mask[c] && !bone[c];
  clock.mark("opening");
  // Bridging: where the implant stops short of the bone by less than twice the bridge width
  // (ragged thin bone, e.g. by an orbit), the crack between them is filled, so the implant
  // rests on the bone. A voxel is in a crack when, along one of 13 directions, the implant lies
  // on one side and the bone on the other, each within the width with nothing between; so a
  // concave corner where the implant's wall meets the top of the bone gets no fillet.
  const int bridge = static_cast<int>(std::lround(params.bridge_mm / h));
  if (bridge > 0) {
    Mask bridged = bridge_cracks(mask, bone, grid, bridge);
    clock.mark("cracks");
    if (params.thin_fills_removed && params.min_feature_mm > 0) {
      remove_thin_fills(bridged, mask, bone, grid, 0.5 * params.min_feature_mm, to_bone);
      clock.mark("thin fills");
    }
    mask = std::move(bridged);
  }
  mask = largest_piece(mask, grid);
  clock.mark("largest piece");
  size_t after = 0;
  for (uint8_t m : mask) after += m;
  result.removed_mm3 = static_cast<double>(before - std::min(before, after)) * grid.voxel_volume();
  result.volume_mm3 = static_cast<double>(after) * grid.voxel_volume();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (after == 0) {
    result.message = "nothing of the implant lies outside the bone";
    into = implant;
    result.seconds = elapsed();
    return;
  }
  std::vector<float> smooth;
  if (params.clearance_mm) {
    smooth = fit_against_bone(mask, bone, grid, locator, params.smoothing_mm / h,
                              std::max(0.0, *params.clearance_mm), params.zones, to_bone, clock);
    Mask().swap(mask);
    std::vector<float>().swap(to_bone);
  } else {
    // Without a clearance (build_implant commands before version 4): neither the grid nor the
    // smoothing may carry the surface into the
    // bone: the bone grown by one voxel stays outside (the surface then lies a fraction of a
    // voxel off the bone, up to a voxel and a half).
    smooth = blur(mask, grid, params.smoothing_mm / h);
    Mask().swap(mask);
    const Mask keep_out = dilate(bone, grid);
    for (size_t c = 0; c < smooth.size(); ++c)
      if (keep_out[c]) smooth[c] = 0.0f;
    clock.mark("blur");
  }
  Mask().swap(bone);
  // The bridge and the blur may carry the implant back over the scan's end: nothing beyond it
  // (the surface then ends within a voxel of it).
  for_each_beyond(grid, params.scan_ends, [&](size_t c) { smooth[c] = 0.0f; });
  if (params.iso_gap) keep_off_iso_level(smooth);
  // The implant as the meshing gives it: plans saved before meshes were made canonical replay
  // to their bytes.
  ExtractBoneSurfaceResult s = surface_of_field(std::move(smooth), grid, into);
  clock.mark("meshing");
  if (!s.usable()) {
    result.message = s.message;
    into = implant;
    result.seconds = elapsed();
    return;
  }
  result.status = TrimToBoneResult::Status::Trimmed;
  result.seconds = elapsed();
}

}  // namespace

TrimToBoneResult trim_to_bone(const SkullMesh& implant, const SkullMesh& skull,
                              const TrimToBoneParams& params) {
  TrimToBoneResult result;
  trim_into(implant, skull, nullptr, params, result, result.mesh);
  return result;
}

TrimToBoneResult trim_to_bone(const SkullMesh& implant, const SkullMesh& skull,
                              const TrimToBoneParams& params, SkullMesh& into,
                              const SurfaceLocator* skull_locator) {
  TrimToBoneResult result;
  trim_into(implant, skull, skull_locator, params, result, into);
  return result;
}

}  // namespace cranioplan
