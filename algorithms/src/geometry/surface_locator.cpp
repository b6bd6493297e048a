#include "cranioplan/algorithms/geometry/surface_locator.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>
#include <thread>
#include <vector>

#include "cranioplan/model/parallel.h"

namespace cranioplan {

namespace {

constexpr int kLeafFaces = 4;
constexpr int kMaxDepth = 64;
// Trees over more faces are built on two threads.
constexpr int kParallelFaces = 20000;

// A box in float, rounded outward so that it still contains the double-precision geometry.
struct Box {
  std::array<float, 3> lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                          std::numeric_limits<float>::max()};
  std::array<float, 3> hi{-std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                          -std::numeric_limits<float>::max()};

  void add(const Eigen::Vector3d& p) {
    for (int k = 0; k < 3; ++k) {
      float l = static_cast<float>(p[k]), h = l;
      if (static_cast<double>(l) > p[k]) l = std::nextafter(l, -std::numeric_limits<float>::max());
      if (static_cast<double>(h) < p[k]) h = std::nextafter(h, std::numeric_limits<float>::max());
      lo[k] = std::min(lo[k], l);
      hi[k] = std::max(hi[k], h);
    }
  }
  void add(const Box& b) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
    }
  }
  double squared_distance(const Eigen::Vector3d& p) const {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max({static_cast<double>(lo[k]) - p[k], 0.0, p[k] - hi[k]});
      d2 += d * d;
    }
    return d2;
  }
  // Whether the segment o + t·d, t in [0, t_max], meets the box (slab test).
  bool meets(const Eigen::Vector3d& o, const Eigen::Vector3d& inv_d, double t_max) const {
    double t0 = 0.0, t1 = t_max;
    for (int k = 0; k < 3; ++k) {
      double a = (lo[k] - o[k]) * inv_d[k], b = (hi[k] - o[k]) * inv_d[k];
      if (std::isnan(a) || std::isnan(b)) {  // origin on a slab of a zero-direction axis
        if (o[k] < lo[k] || o[k] > hi[k]) return false;
        continue;
      }
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
      if (t0 > t1) return false;
    }
    return true;
  }
};

struct Node {
  Box box;
  int first = 0;  // leaf: first index into `order`; inner: index of the right child
  int count = 0;  // faces in a leaf; 0 for an inner node (its left child follows it)
};

// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return a;  // degenerate triangle: its vertices are still on it
  return a + ab * (vb / denom) + ac * (vc / denom);
}

// Parameter t in [0, 1] where the segment o + t·d crosses triangle abc, or a negative value.
// Barycentric tolerance so that a segment through a shared edge hits one of its faces.
double segment_triangle(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                        const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c) {
  constexpr double kEps = 1e-10;
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  const double scale = e1.norm() * h.norm();
  if (!(std::abs(det) > 1e-14 * scale)) return -1.0;  // parallel or degenerate
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = o - a;
  const double u = inv * s.dot(h);
  if (u < -kEps || u > 1.0 + kEps) return -1.0;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = inv * d.dot(q);
  if (v < -kEps || u + v > 1.0 + kEps) return -1.0;
  const double t = inv * e2.dot(q);
  return (t >= 0.0 && t <= 1.0) ? t : -1.0;
}

}  // namespace

struct SurfaceLocator::Tree {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> faces;  // by face index of the mesh
  std::vector<int> order;                 // faces in leaf order
  std::vector<Node> nodes;

  const Eigen::Vector3d& corner(int face, int k) const { return points[faces[face][k]]; }

  // A face and its centroid, side by side: the partitions read the centroids in order instead
  // of through the face numbers (the same comparisons, so the same partitions).
  struct Item {
    Eigen::Vector3f centroid;
    int face;
  };

  // Builds the subtree over items[first, first + count) at the end of `nodes`; returns its node
  // index. A large tree's two halves are built on two threads (their own ranges of `items`),
  // the right one's nodes then appended after the left's as one thread would have made them.
  int build(std::vector<Node>& nodes, int first, int count, std::vector<Item>& items, int depth) {
    const int index = static_cast<int>(nodes.size());
    nodes.emplace_back();
    if (count <= kLeafFaces || depth >= kMaxDepth - 2) {
      Box box;
      for (int i = first; i < first + count; ++i)
        for (int k = 0; k < 3; ++k) box.add(corner(items[i].face, k));
      nodes[index].box = box;
      nodes[index].first = first;
      nodes[index].count = count;
      return index;
    }
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f hi = -lo;
    for (int i = first; i < first + count; ++i) {
      lo = lo.cwiseMin(items[i].centroid);
      hi = hi.cwiseMax(items[i].centroid);
    }
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const int half = count / 2;
    std::nth_element(
        items.begin() + first, items.begin() + first + half, items.begin() + first + count,
        [axis](const Item& a, const Item& b) { return a.centroid[axis] < b.centroid[axis]; });
    int left = 0, right = 0;
    if (depth == 0 && count >= kParallelFaces && thread_count() > 1) {
      std::vector<Node> right_nodes;
      right_nodes.reserve(nodes.capacity() / 2);
      std::thread other([&] { build(right_nodes, first + half, count - half, items, depth + 1); });
      left = build(nodes, first, half, items, depth + 1);
      other.join();
      right = static_cast<int>(nodes.size());
      for (Node n : right_nodes) {
        if (n.count == 0) n.first += right;  // an inner node's right child
        nodes.push_back(n);
      }
    } else {
      left = build(nodes, first, half, items, depth + 1);
      right = build(nodes, first + half, count - half, items, depth + 1);
    }
    Box box = nodes[left].box;
    box.add(nodes[right].box);
    nodes[index].box = box;
    nodes[index].first = right;
    nodes[index].count = 0;
    return index;
  }

  // The one depth-first walk both queries make: a node `prune(node)` rejects is skipped; a
  // leaf's faces go to `visit(face)` in leaf order; an inner node's children (left at
  // index + 1, right at node.first) are pushed by `push_children(index, node, push)`, the one
  // to visit first pushed last.
  template <class Prune, class PushChildren, class Visit>
  void walk(const Prune& prune, const PushChildren& push_children, const Visit& visit) const {
    int stack[kMaxDepth];
    int top = 0;
    auto push = [&](int child) { stack[top++] = child; };
    if (!nodes.empty()) push(0);
    while (top > 0) {
      const int index = stack[--top];
      const Node& node = nodes[index];
      if (prune(node)) continue;
      if (node.count > 0) {
        for (int i = node.first; i < node.first + node.count; ++i) visit(order[i]);
        continue;
      }
      push_children(index, node, push);
    }
  }
};

SurfaceLocator::SurfaceLocator(const SkullMesh& mesh) {
  assert(mesh.n_faces() > 0 && "SurfaceLocator needs a mesh with faces");
  auto tree = std::make_shared<Tree>();
  // The mesh's points and faces, and the faces' centroids (both threads, each entry once).
  tree->points.resize(mesh.n_vertices(), Eigen::Vector3d::Zero());
  parallel_for(mesh.n_vertices(), [&](size_t first, size_t last) {
    for (size_t v = first; v < last; ++v)
      tree->points[v] = to_eigen(mesh.point(SkullMesh::VertexHandle(static_cast<int>(v))));
  });
  // Faces are numbered as the mesh's face range gives them, which skips deleted ones.
  std::vector<int> handle;
  for (auto fh : mesh.all_faces())
    if (mesh.status(fh).deleted()) {
      for (auto kept : mesh.faces()) handle.push_back(kept.idx());
      break;
    }
  const int n = static_cast<int>(handle.empty() ? mesh.n_faces() : handle.size());
  tree->faces.resize(static_cast<size_t>(n));
  std::vector<Tree::Item> items(static_cast<size_t>(n));
  parallel_for(static_cast<size_t>(n), [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i) {
      std::array<int, 3>& f = tree->faces[i];
      int k = 0;
      const int fh = handle.empty() ? static_cast<int>(i) : handle[i];
      for (auto vh : mesh.fv_range(SkullMesh::FaceHandle(fh))) {
        if (k == 3) break;
        f[k++] = vh.idx();
      }
      const int face = static_cast<int>(i);
      items[i] = {((tree->corner(face, 0) + tree->corner(face, 1) + tree->corner(face, 2)) / 3.0)
                      .cast<float>(),
                  face};
    }
  });
  tree->nodes.reserve(static_cast<size_t>(2 * n / kLeafFaces + 2));
  if (n > 0) tree->build(tree->nodes, 0, n, items, 0);
  tree->order.resize(n);
  for (int i = 0; i < n; ++i) tree->order[i] = items[i].face;
  tree->nodes.shrink_to_fit();
  tree_ = std::move(tree);
}

SurfaceLocator::SurfaceLocator(std::shared_ptr<const Tree> tree, const RigidTransform& motion,
                               bool moved)
    : tree_(std::move(tree)), motion_(motion), moved_(moved) {}

SurfaceLocator::~SurfaceLocator() = default;
SurfaceLocator::SurfaceLocator(const SurfaceLocator&) = default;
SurfaceLocator& SurfaceLocator::operator=(const SurfaceLocator&) = default;
SurfaceLocator::SurfaceLocator(SurfaceLocator&&) noexcept = default;
SurfaceLocator& SurfaceLocator::operator=(SurfaceLocator&&) noexcept = default;

SurfaceLocator SurfaceLocator::moved(const RigidTransform& motion) const {
  return SurfaceLocator(tree_, motion * motion_, true);
}

SurfaceLocator::Closest SurfaceLocator::closest(const Eigen::Vector3d& world_query) const {
  return *closest_within(world_query, std::numeric_limits<double>::infinity());
}

std::optional<SurfaceLocator::Closest> SurfaceLocator::closest_within(
    const Eigen::Vector3d& world_query, double radius) const {
  const Tree& t = *tree_;
  const Eigen::Vector3d query = moved_ ? motion_.inverse().apply(world_query) : world_query;
  Closest best;
  double best_d2 = radius * radius;
  t.walk([&](const Node& node) { return node.box.squared_distance(query) >= best_d2; },
         [&](int index, const Node& node, const auto& push) {
           const int left = index + 1, right = node.first;
           const double dl = t.nodes[left].box.squared_distance(query);
           const double dr = t.nodes[right].box.squared_distance(query);
           // The nearer child is visited first (pushed last).
           if (dl <= dr) {
             if (dr < best_d2) push(right);
             if (dl < best_d2) push(left);
           } else {
             if (dl < best_d2) push(left);
             if (dr < best_d2) push(right);
           }
         },
         [&](int f) {
           const Eigen::Vector3d c =
               closest_on_triangle(query, t.corner(f, 0), t.corner(f, 1), t.corner(f, 2));
           const double d2 = (c - query).squaredNorm();
           if (d2 < best_d2) {
             best_d2 = d2;
             best.point = c;
             best.face = f;
           }
         });
  if (best.face < 0 && !std::isinf(radius)) return std::nullopt;
  best.distance = std::sqrt(best_d2);
  if (moved_) best.point = motion_.apply(best.point);
  return best;
}

void SurfaceLocator::faces_near(const Eigen::Vector3d& world_lo, const Eigen::Vector3d& world_hi,
                                double reach, std::vector<int>& faces) const {
  faces.clear();
  const Tree& t = *tree_;
  // The box in the tree's frame: the box around the moved corners.
  Eigen::Vector3d lo = world_lo, hi = world_hi;
  if (moved_ && !(lo.allFinite() && hi.allFinite())) {  // unbounded: every face
    for (const auto& n : t.nodes)
      for (int i = n.first; i < n.first + n.count; ++i) faces.push_back(t.order[i]);
    return;
  }
  if (moved_) {
    const RigidTransform to_tree = motion_.inverse();
    lo = hi = to_tree.apply(world_lo);
    for (int k = 1; k < 8; ++k) {
      const Eigen::Vector3d corner((k & 1) ? world_hi.x() : world_lo.x(),
                                   (k & 2) ? world_hi.y() : world_lo.y(),
                                   (k & 4) ? world_hi.z() : world_lo.z());
      const Eigen::Vector3d p = to_tree.apply(corner);
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const double reach2 = reach * reach;
  t.walk(
      [&](const Node& node) {
        double d2 = 0.0;
        for (int k = 0; k < 3; ++k) {
          const double d = std::max({static_cast<double>(node.box.lo[k]) - hi[k], 0.0,
                                     lo[k] - static_cast<double>(node.box.hi[k])});
          d2 += d * d;
        }
        return d2 > reach2;
      },
      [](int index, const Node& node, const auto& push) {
        push(node.first);
        push(index + 1);
      },
      [&](int f) { faces.push_back(f); });
}

std::optional<SurfaceLocator::Closest> SurfaceLocator::closest_within(
    const Eigen::Vector3d& world_query, double radius, const std::vector<int>& faces) const {
  const Tree& t = *tree_;
  const Eigen::Vector3d query = moved_ ? motion_.inverse().apply(world_query) : world_query;
  Closest best;
  double best_d2 = radius * radius;
  for (const int f : faces) {
    const Eigen::Vector3d &a = t.corner(f, 0), &b = t.corner(f, 1), &c = t.corner(f, 2);
    // The triangle's box first: no nearer than it.
    double box2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max(
          {std::min({a[k], b[k], c[k]}) - query[k], 0.0, query[k] - std::max({a[k], b[k], c[k]})});
      box2 += d * d;
    }
    // (With a margin far above the rounding of the closest point, so that a face skipped is
    // one the search below would not have taken.)
    if (box2 > best_d2 + 1e-12) continue;
    const Eigen::Vector3d p = closest_on_triangle(query, a, b, c);
    const double d2 = (p - query).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.point = p;
      best.face = f;
    }
  }
  if (best.face < 0) return std::nullopt;
  best.distance = std::sqrt(best_d2);
  if (moved_) best.point = motion_.apply(best.point);
  return best;
}

std::optional<SurfaceLocator::Hit> SurfaceLocator::first_hit(
    const Eigen::Vector3d& world_from, const Eigen::Vector3d& world_to) const {
  const Tree& t = *tree_;
  RigidTransform to_tree;
  if (moved_) to_tree = motion_.inverse();
  const Eigen::Vector3d o = moved_ ? to_tree.apply(world_from) : world_from;
  const Eigen::Vector3d d = (moved_ ? to_tree.apply(world_to) : world_to) - o;
  const Eigen::Vector3d inv_d = d.cwiseInverse();
  double best_t = 1.0;
  int best_face = -1;
  t.walk([&](const Node& node) { return !node.box.meets(o, inv_d, best_t); },
         [](int index, const Node& node, const auto& push) {
           push(node.first);  // right
           push(index + 1);   // left
         },
         [&](int f) {
           const double s = segment_triangle(o, d, t.corner(f, 0), t.corner(f, 1), t.corner(f, 2));
           if (s >= 0.0 && (s < best_t || (best_face < 0 && s <= best_t))) {
             best_t = s;
             best_face = f;
           }
         });
  if (best_face < 0) return std::nullopt;
  Hit h;
  h.point = world_from + best_t * (world_to - world_from);
  h.face = best_face;
  h.distance = (h.point - world_from).norm();
  return h;
}

std::vector<SurfaceLocator::Hit> SurfaceLocator::hits_along(const Eigen::Vector3d& from,
                                                            const Eigen::Vector3d& to) const {
  std::vector<Hit> hits;
  const double length = (to - from).norm();
  if (!(length > 0.0)) return hits;
  const Eigen::Vector3d along = (to - from) / length, step = 1e-4 * (to - from).normalized();
  Eigen::Vector3d at = from;
  while (auto hit = first_hit(at, to)) {
    at = hit->point + step;
    hit->distance = (hit->point - from).norm();
    hits.push_back(*hit);
    if ((at - from).dot(along) >= length) break;  // past the end: a segment back would loop
  }
  return hits;
}

Eigen::Vector3d SurfaceLocator::face_normal(int face) const {
  const Tree& t = *tree_;
  const Eigen::Vector3d n =
      (t.corner(face, 1) - t.corner(face, 0)).cross(t.corner(face, 2) - t.corner(face, 0));
  const double len = n.norm();
  if (!(len > 0)) return Eigen::Vector3d::Zero();
  return moved_ ? Eigen::Vector3d(motion_.apply_direction(n / len)) : Eigen::Vector3d(n / len);
}

size_t SurfaceLocator::memory_bytes() const {
  const Tree& t = *tree_;
  return t.points.capacity() * sizeof(Eigen::Vector3d) +
         t.faces.capacity() * sizeof(std::array<int, 3>) + t.order.capacity() * sizeof(int) +
         t.nodes.capacity() * sizeof(Node);
}

}  // namespace cranioplan
