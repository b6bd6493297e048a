#include "cranioplan/algorithms/geometry/distance_transform.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <limits>

#include "cranioplan/model/parallel.h"

namespace cranioplan {

namespace {

constexpr double kFar = 1e30;

// d[q] = min over p of (q − p)² + f[p], for one line of n samples (squared distances in voxel
// units). v, z: scratch of n and n + 1 entries.
void lower_envelope(const double* f, double* d, int n, std::vector<int>& v,
                    std::vector<double>& z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kFar) continue;
    double s = 0.0;
    while (k >= 0) {
      const int p = v[k];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kFar : s;
    z[k + 1] = kFar;
  }
  if (k < 0) {
    std::fill(d, d + n, kFar);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double dq = q - v[j];
    d[q] = dq * dq + f[v[j]];
  }
}

}  // namespace

namespace {

// The squared distances (voxel units) of every voxel to the mask, in `T`: float when every
// squared distance in the grid is an integer float holds exactly (below 2^24), else double;
// the same values either way. Lines along x are contiguous; along y and z they are taken 16
// neighbours in x at a time, so each cache line read serves 16 lines.
template <class T>
std::vector<float> distance_in(const std::vector<uint8_t>& mask, const VoxelGrid& grid) {
  const int dims[3] = {grid.dims[0], grid.dims[1], grid.dims[2]};
  const T far = static_cast<T>(kFar);
  std::vector<T> sq(mask.size());
  for (size_t c = 0; c < mask.size(); ++c) sq[c] = mask[c] ? T(0) : far;
  const int longest = std::max({dims[0], dims[1], dims[2]});
  const size_t stride[3] = {1, static_cast<size_t>(dims[0]),
                            static_cast<size_t>(dims[0]) * dims[1]};
  constexpr int kTile = 16;
  for (int axis = 0; axis < 3; ++axis) {
    const int n = dims[axis];
    // The lines along the axis are independent: each thread takes a range of them, by the
    // dimension that is neither the axis nor x (by z for lines along x).
    const int across = axis == 2 ? 1 : 2;
    const int along_x = axis == 0 ? 1 : 0;  // the other dimension the lines are indexed by
    parallel_for(
        static_cast<size_t>(dims[across]),
        [&](size_t first, size_t last) {
          std::vector<double> line(longest), out(longest);
          std::vector<int> v(longest);
          std::vector<double> z(longest + 1);
          std::vector<T> tile(static_cast<size_t>(kTile) * longest);
          for (size_t o = first; o < last; ++o)
            for (int x0 = 0; x0 < dims[along_x]; x0 += kTile) {
              const int w = std::min(kTile, dims[along_x] - x0);
              const size_t base = o * stride[across] + x0 * stride[along_x];
              if (axis == 0) {
                // Contiguous lines of sites and empty voxels: the squared distance to the
                // nearest site on the line, by a forward and a backward sweep (the same
                // integers as the envelope).
                for (int t = 0; t < w; ++t) {
                  T* l = &sq[base + t * stride[along_x]];
                  int last = -1;
                  for (int q = 0; q < n; ++q) {
                    if (l[q] == T(0)) last = q;
                    out[q] = last < 0 ? -1.0 : double(q - last);
                  }
                  int next = -1;
                  for (int q = n - 1; q >= 0; --q) {
                    if (l[q] == T(0)) next = q;
                    double best = out[q];
                    if (next >= 0 && (best < 0.0 || next - q < best)) best = next - q;
                    l[q] = best < 0.0 ? far : static_cast<T>(best * best);
                  }
                }
                continue;
              }
              for (int q = 0; q < n; ++q) {
                const T* row = &sq[base + q * stride[axis]];
                for (int t = 0; t < w; ++t) tile[t * static_cast<size_t>(n) + q] = row[t];
              }
              for (int t = 0; t < w; ++t) {
                T* l = &tile[t * static_cast<size_t>(n)];
                // A line all of sites stays 0 and a line without one stays far (most lines of
                // a grid around a thin implant): only the others need their envelope.
                if (std::all_of(l, l + n, [&](T x) { return x == l[0]; }) &&
                    (l[0] == T(0) || l[0] == far))
                  continue;
                for (int q = 0; q < n; ++q) line[q] = l[q];
                lower_envelope(line.data(), out.data(), n, v, z);
                for (int q = 0; q < n; ++q) l[q] = static_cast<T>(out[q]);
              }
              for (int q = 0; q < n; ++q) {
                T* row = &sq[base + q * stride[axis]];
                for (int t = 0; t < w; ++t) row[t] = tile[t * static_cast<size_t>(n) + q];
              }
            }
        },
        4);
  }
  std::vector<float> d(mask.size());
  parallel_for(
      mask.size(),
      [&](size_t first, size_t last) {
        for (size_t c = first; c < last; ++c)
          d[c] = static_cast<double>(sq[c]) >= kFar
                     ? std::numeric_limits<float>::infinity()
                     : static_cast<float>(grid.spacing * std::sqrt(static_cast<double>(sq[c])));
      },
      1 << 16);
  return d;
}

}  // namespace

std::vector<float> distance_to_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid) {
  const double largest = double(grid.dims[0]) * grid.dims[0] + double(grid.dims[1]) * grid.dims[1] +
                         double(grid.dims[2]) * grid.dims[2];
  return largest < double(1 << 24) ? distance_in<float>(mask, grid)
                                   : distance_in<double>(mask, grid);
}

namespace {

// What a row (along x) holds after a pass, as two spans: where its values are other than 0
// (outside it every voxel is in the mask) and where they are below the cap (outside it they are
// capped). A window's minimum is 0 outside its middle row's first span (that row's term is 0
// and none is below it) and capped outside the union of its rows' second spans; only what lies
// in both is summed: the same values as summing whole rows. A mask fills a shell of its grid:
// most rows are all in it or all far from it, and the others cross its surface in short spans.
struct Span {
  int lo = 1, hi = 0;  // empty
  bool empty() const { return lo > hi; }
  void add(int i) {
    if (empty()) lo = i;
    hi = i;
  }
};
struct Spans {
  Span nonzero, below_cap;
};

Spans spans_of(const float* row, int n, float capped) {
  Spans s;
  for (int i = 0; i < n; ++i) {
    if (row[i] != 0.0f) s.nonzero.add(i);
    if (row[i] < capped) s.below_cap.add(i);
  }
  return s;
}

// The union of the second spans of rows at(t), t in [lo, hi].
template <class At>
Span union_below_cap(int lo, int hi, const At& at) {
  Span u;
  for (int t = lo; t <= hi; ++t) {
    const Span& s = at(t).below_cap;
    if (s.empty()) continue;
    if (u.empty()) {
      u = s;
    } else {
      u.lo = std::min(u.lo, s.lo);
      u.hi = std::max(u.hi, s.hi);
    }
  }
  return u;
}

// Along x, and along y within each slice (slices on all threads): the squared distances within
// each slice into `sq`, each row's spans into `spans`.
void within_slices(const std::vector<uint8_t>& mask, const VoxelGrid& grid, int reach, float capped,
                   std::vector<float>& sq, std::vector<Spans>& spans) {
  const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  const size_t sy = static_cast<size_t>(nx), sz = sy * ny;
  parallel_for(
      static_cast<size_t>(nz),
      [&](size_t first, size_t last) {
        std::vector<float> slice(sz);
        std::vector<Spans> row_spans(static_cast<size_t>(ny));
        for (size_t k = first; k < last; ++k) {
          for (int j = 0; j < ny; ++j) {
            const uint8_t* in = &mask[k * sz + j * sy];
            float* out = &slice[j * sy];
            // A row all in the mask is all 0, one without any of it all capped.
            const bool none = std::none_of(in, in + nx, [](uint8_t v) { return v != 0; });
            if (none || std::all_of(in, in + nx, [](uint8_t v) { return v != 0; })) {
              std::fill(out, out + nx, none ? capped : 0.0f);
              row_spans[j] = Spans{};
              (none ? row_spans[j].nonzero : row_spans[j].below_cap) = Span{0, nx - 1};
              continue;
            }
            int gap = reach + 1;
            for (int i = 0; i < nx; ++i) {
              gap = in[i] ? 0 : std::min(gap + 1, reach + 1);
              out[i] = static_cast<float>(gap);
            }
            gap = reach + 1;
            for (int i = nx - 1; i >= 0; --i) {
              gap = in[i] ? 0 : std::min(gap + 1, reach + 1);
              const float g = std::min(out[i], static_cast<float>(gap));
              out[i] = g * g;
            }
            row_spans[j] = spans_of(out, nx, capped);
          }
          for (int j = 0; j < ny; ++j) {
            float* out = &sq[k * sz + j * sy];
            const int lo = std::max(-reach, -j), hi = std::min(reach, ny - 1 - j);
            const Span& middle = row_spans[j].nonzero;
            const Span u =
                union_below_cap(lo, hi, [&](int t) -> const Spans& { return row_spans[j + t]; });
            std::fill(out, out + nx, 0.0f);
            if (!middle.empty()) std::fill(out + middle.lo, out + middle.hi + 1, capped);
            const int from = std::max(middle.lo, u.lo), to = std::min(middle.hi, u.hi);
            if (!middle.empty() && !u.empty() && from <= to) {
              for (int t = lo; t <= hi; ++t) {
                const float step = static_cast<float>(t * t);
                const float* in = &slice[(j + t) * sy];
                for (int i = from; i <= to; ++i) out[i] = std::min(out[i], in[i] + step);
              }
            }
            spans[k * static_cast<size_t>(ny) + j] = spans_of(out, nx, capped);
          }
        }
      },
      2);
}

// Along z (slices on all threads), and the distance in mm: within the reach, +infinity beyond.
std::vector<float> along_z(const std::vector<float>& sq, const std::vector<Spans>& spans,
                           const VoxelGrid& grid, int reach, float capped) {
  const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  const size_t sy = static_cast<size_t>(nx), sz = sy * ny;
  std::vector<float> d(sq.size());
  const float limit = static_cast<float>(reach) * static_cast<float>(reach);
  parallel_for(
      static_cast<size_t>(nz),
      [&](size_t first, size_t last) {
        std::vector<float> row(sy);
        for (size_t k = first; k < last; ++k)
          for (int j = 0; j < ny; ++j) {
            float* out = &d[k * sz + j * sy];
            const int z = static_cast<int>(k);
            const int lo = std::max(-reach, -z), hi = std::min(reach, nz - 1 - z);
            auto at = [&](int t) -> const Spans& {
              return spans[static_cast<size_t>(z + t) * ny + j];
            };
            const Span& middle = at(0).nonzero;
            const Span u = union_below_cap(lo, hi, at);
            // Outside the middle row's span the minimum is 0 (0 mm); within it, outside the
            // union, capped (beyond the reach).
            std::fill(out, out + nx, 0.0f);
            if (middle.empty()) continue;
            std::fill(out + middle.lo, out + middle.hi + 1, std::numeric_limits<float>::infinity());
            const int from = std::max(middle.lo, u.lo), to = std::min(middle.hi, u.hi);
            if (u.empty() || from > to) continue;
            std::fill(row.begin() + from, row.begin() + to + 1, capped);
            for (int t = lo; t <= hi; ++t) {
              const float step = static_cast<float>(t * t);
              const float* in = &sq[static_cast<size_t>(z + t) * sz + j * sy];
              for (int i = from; i <= to; ++i) row[i] = std::min(row[i], in[i] + step);
            }
            for (int i = from; i <= to; ++i)
              out[i] =
                  row[i] <= limit
                      ? static_cast<float>(grid.spacing * std::sqrt(static_cast<double>(row[i])))
                      : std::numeric_limits<float>::infinity();
          }
      },
      2);
  return d;
}

// The squared distances (voxel units) within `reach` voxels, exact, by windows instead of
// envelopes: along x the nearest site on the line (capped at reach + 1), then along y and z the
// smallest of the 2·reach + 1 neighbours' values plus the squared step. A squared distance of at
// most reach² is made of steps of at most `reach` along each axis, so the window holds it; a
// larger one comes out larger than reach² (no term is ever below the true value). The same
// integers as the envelope, as floats, where they are at most reach²; +infinity beyond.
std::vector<float> distance_within(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                   int reach) {
  const float capped = static_cast<float>(reach + 1) * static_cast<float>(reach + 1);
  std::vector<float> sq(mask.size());
  std::vector<Spans> spans(static_cast<size_t>(grid.dims[1]) * grid.dims[2]);
  within_slices(mask, grid, reach, capped, sq, spans);
  return along_z(sq, spans, grid, reach, capped);
}

// The border layer of the grid and the voxels outside the mask: what depth_in_mask measures to.
std::vector<uint8_t> outside_of(const std::vector<uint8_t>& mask, const VoxelGrid& grid) {
  std::vector<uint8_t> out(mask.size());
  for (size_t c = 0; c < mask.size(); ++c) out[c] = !mask[c];
  // The grid's outermost layer stands for the outside beyond it.
  const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      uint8_t* row = &out[grid.index(0, j, k)];
      if (k == 0 || j == 0 || k == nz - 1 || j == ny - 1) {
        std::fill(row, row + nx, uint8_t{1});
      } else {
        row[0] = row[nx - 1] = 1;
      }
    }
  return out;
}

}  // namespace

std::vector<float> distance_to_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                    double within_mm) {
  // Steps of up to `reach` voxels along an axis make every distance up to within_mm, and one
  // more keeps the float tests at within_mm exact (the next squared integer lies far from it).
  const double steps = std::floor(std::max(0.0, within_mm) / grid.spacing) + 1.0;
  const int longest = std::max({grid.dims[0], grid.dims[1], grid.dims[2]});
  // A window as long as the grid costs more than the envelope.
  if (steps * 4.0 > longest || steps > 1000.0) return distance_to_mask(mask, grid);
  return distance_within(mask, grid, static_cast<int>(steps));
}

std::vector<float> depth_in_mask(const std::vector<uint8_t>& mask, const VoxelGrid& grid) {
  return distance_to_mask(outside_of(mask, grid), grid);
}

std::vector<uint8_t> ball_centres(const std::vector<float>& depth, const VoxelGrid& grid,
                                  double radius) {
  const double need = radius + 0.5 * grid.spacing;
  std::vector<uint8_t> out(depth.size());
  for (size_t c = 0; c < depth.size(); ++c) out[c] = depth[c] >= need;
  return out;
}

std::vector<uint8_t> ball_centres(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                  double radius) {
  // Only depths up to the centres' decide.
  const double need = radius + 0.5 * grid.spacing;
  return ball_centres(distance_to_mask(outside_of(mask, grid), grid, need), grid, radius);
}

std::vector<uint8_t> open_by_ball(const std::vector<uint8_t>& mask, const VoxelGrid& grid,
                                  double radius) {
  const double reach = radius + 0.5 * grid.spacing;
  const std::vector<float> to_centre =
      distance_to_mask(ball_centres(mask, grid, radius), grid, reach);
  std::vector<uint8_t> out(mask.size());
  for (size_t c = 0; c < mask.size(); ++c) out[c] = mask[c] && to_centre[c] <= reach;
  return out;
}

namespace {

// distance_to_mask's value for a squared distance in voxel units (the same float).
float distance_value(const VoxelGrid& g, long long squared) {
  return static_cast<float>(g.spacing * std::sqrt(static_cast<double>(squared)));
}

}  // namespace

std::vector<uint8_t> within_steps(const std::vector<uint8_t>& in, const VoxelGrid& g, int steps) {
  assert(steps >= 0 && steps <= 254 && "within_steps counts steps in a byte");
  const uint8_t cap = static_cast<uint8_t>(steps + 1);
  const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  const size_t sy = static_cast<size_t>(nx), sz = sy * ny;
  // Each row (along x) keeps the span outside which all its values are the cap (lo > hi: the
  // whole row is capped). A row relaxed from a neighbour changes only within the neighbour's span,
  // and a sweep along x only within steps of its own: the sweeps keep to the spans, and the values
  // are those of sweeping whole rows. A mask fills a shell of its grid; most rows stay capped.
  struct Span {
    int lo = 1, hi = 0;
    bool empty() const { return lo > hi; }
  };
  std::vector<uint8_t> d(in.size());
  std::vector<Span> held(static_cast<size_t>(ny) * nz);
  parallel_for(held.size(), [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      Span span;
      const uint8_t* from = &in[row * sy];
      uint8_t* to = &d[row * sy];
      for (int i = 0; i < nx; ++i) to[i] = from[i] ? 0 : cap;
      auto in_mask = [](uint8_t v) { return v != 0; };
      const uint8_t* lo = std::find_if(from, from + nx, in_mask);
      if (lo != from + nx) {
        span.lo = static_cast<int>(lo - from);
        span.hi = nx - 1 -
                  static_cast<int>(std::find_if(std::make_reverse_iterator(from + nx),
                                                std::make_reverse_iterator(lo), in_mask) -
                                   std::make_reverse_iterator(from + nx));
      }
      held[row] = span;
    }
  });
  auto one_more = [cap](uint8_t from) {
    return static_cast<uint8_t>(std::min<int>(from + 1, cap));
  };
  // Relaxes row `to` from its neighbour `from` within the neighbour's span; `to`'s span grows
  // by where it now holds a value below the cap.
  auto relax_row = [cap, one_more](uint8_t* to, Span& to_span, const uint8_t* from,
                                   const Span& from_span) {
    for (int i = from_span.lo; i <= from_span.hi; ++i) {
      to[i] = std::min(to[i], one_more(from[i]));
      if (to[i] < cap) {
        if (to_span.empty()) {
          to_span.lo = to_span.hi = i;
        } else {
          to_span.lo = std::min(to_span.lo, i);
          to_span.hi = std::max(to_span.hi, i);
        }
      }
    }
  };
  // Along x: each row by itself; along y: row by row within a slice (slices on all threads).
  parallel_for(
      static_cast<size_t>(nz),
      [&](size_t first, size_t last) {
        for (size_t k = first; k < last; ++k) {
          uint8_t* slice = &d[k * sz];
          Span* rows = &held[k * static_cast<size_t>(ny)];
          for (int j = 0; j < ny; ++j) {
            Span& span = rows[j];
            if (span.empty()) continue;
            uint8_t* row = slice + j * sy;
            const int hi = std::min(nx - 1, span.hi + steps), lo = std::max(0, span.lo - steps);
            for (int i = std::max(1, span.lo); i <= hi; ++i)
              row[i] = std::min(row[i], one_more(row[i - 1]));
            for (int i = std::min(nx - 2, span.hi); i >= lo; --i)
              row[i] = std::min(row[i], one_more(row[i + 1]));
            span = {lo, hi};
          }
          for (int j = 1; j < ny; ++j)
            if (!rows[j - 1].empty())
              relax_row(slice + j * sy, rows[j], slice + (j - 1) * sy, rows[j - 1]);
          for (int j = ny - 2; j >= 0; --j)
            if (!rows[j + 1].empty())
              relax_row(slice + j * sy, rows[j], slice + (j + 1) * sy, rows[j + 1]);
        }
      },
      2);
  // Along z: slice by slice, rows of y on all threads.
  parallel_for(
      static_cast<size_t>(ny),
      [&](size_t first, size_t last) {
        for (size_t j = first; j < last; ++j) {
          auto row_held = [&](int k) -> Span& { return held[k * static_cast<size_t>(ny) + j]; };
          for (int k = 1; k < nz; ++k)
            if (!row_held(k - 1).empty())
              relax_row(&d[k * sz + j * sy], row_held(k), &d[(k - 1) * sz + j * sy],
                        row_held(k - 1));
          for (int k = nz - 2; k >= 0; --k)
            if (!row_held(k + 1).empty())
              relax_row(&d[k * sz + j * sy], row_held(k), &d[(k + 1) * sz + j * sy],
                        row_held(k + 1));
        }
      },
      2);
  std::vector<uint8_t> out(in.size());
  parallel_for(held.size(), [&](size_t first, size_t last) {
    for (size_t row = first; row < last; ++row) {
      const Span& span = held[row];
      for (int i = span.lo; i <= span.hi; ++i) out[row * sy + i] = d[row * sy + i] <= steps;
    }
  });
  return out;
}

VoxelOffsets::VoxelOffsets(const VoxelGrid& grid, double mm) : grid_(grid) {
  const int r = static_cast<int>(std::ceil(mm / grid.spacing)) + 1;
  struct Entry {
    long long d2;
    int di, dj, dk;
  };
  std::vector<Entry> entries;
  for (int dk = -r; dk <= r; ++dk)
    for (int dj = -r; dj <= r; ++dj)
      for (int di = -r; di <= r; ++di) {
        const long long d2 = static_cast<long long>(di) * di + static_cast<long long>(dj) * dj +
                             static_cast<long long>(dk) * dk;
        if (distance_value(grid, d2) <= mm) entries.push_back({d2, di, dj, dk});
      }
  std::stable_sort(entries.begin(), entries.end(),
                   [](const Entry& a, const Entry& b) { return a.d2 < b.d2; });
  for (const Entry& e : entries) {
    offsets_.push_back({e.di, e.dj, e.dk});
    distance_.push_back(distance_value(grid, e.d2));
  }
}

LocalDistance::LocalDistance(const std::vector<uint8_t>& mask, const VoxelGrid& grid, float mm)
    : mask_(mask), offsets_(grid, mm), mm_(mm) {}

bool LocalDistance::farther(size_t voxel) const {
  // The first voxel of the mask met in order of distance decides: within `mm` or not.
  return !offsets_.first(
      voxel, [&](size_t v, int, int, int) { return mask_[v] != 0; },
      [&](float d) { return d <= mm_; });
}

LocalOpening::LocalOpening(const std::vector<uint8_t>& mask, const VoxelGrid& grid, double radius)
    : mask_(mask),
      reach_(radius + 0.5 * grid.spacing),
      offsets_(grid, reach_),
      centre_(mask.size(), -1) {}

bool LocalOpening::is_centre(size_t v) {
  if (centre_[v] < 0) {
    // ball_centres: depth_in_mask ≥ radius + ½ voxel, the depth being the distance to the
    // nearest voxel outside the mask or on the grid's outermost layer.
    const VoxelGrid& g = offsets_.grid();
    const int nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
    const bool shallow = offsets_.first(
        v,
        [&](size_t u, int x, int y, int z) {
          return !mask_[u] || x == 0 || y == 0 || z == 0 || x == nx - 1 || y == ny - 1 ||
                 z == nz - 1;
        },
        [&](float d) { return d < reach_; });
    centre_[v] = !shallow;
  }
  return centre_[v] == 1;
}

bool LocalOpening::contains(size_t voxel) {
  // open_by_ball: within radius + ½ voxel of a centre (the same reach as the centres' depth).
  return mask_[voxel] && offsets_.first(
                             voxel, [&](size_t v, int, int, int) { return is_centre(v); },
                             [&](float d) { return d <= reach_; });
}

}  // namespace cranioplan
