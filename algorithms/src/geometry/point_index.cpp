#include "cranioplan/algorithms/geometry/point_index.h"

#include <cassert>
#include <nanoflann.hpp>

namespace cranioplan {

struct PointIndex::Impl {
  struct Adaptor {
    const std::vector<Eigen::Vector3d>* pts;
    size_t kdtree_get_point_count() const { return pts->size(); }
    double kdtree_get_pt(size_t i, size_t dim) const { return (*pts)[i][static_cast<int>(dim)]; }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Adaptor>,
                                                   Adaptor, 3, int>;
  std::vector<Eigen::Vector3d> points;
  Adaptor adaptor;
  std::unique_ptr<Tree> tree;
};

PointIndex::PointIndex(std::vector<Eigen::Vector3d> points) : impl_(std::make_unique<Impl>()) {
  impl_->points = std::move(points);
  impl_->adaptor.pts = &impl_->points;
  impl_->tree = std::make_unique<Impl::Tree>(3, impl_->adaptor,
                                             nanoflann::KDTreeSingleIndexAdaptorParams(12));
  if (!impl_->points.empty()) impl_->tree->buildIndex();  // nanoflann refuses an empty set
}

PointIndex::~PointIndex() = default;
PointIndex::PointIndex(PointIndex&&) noexcept = default;
PointIndex& PointIndex::operator=(PointIndex&&) noexcept = default;

int PointIndex::nearest(const Eigen::Vector3d& query, double* squared_distance) const {
  assert(!impl_->points.empty() && "nearest() on an empty PointIndex");
  int index = -1;
  double d2 = 0.0;
  nanoflann::KNNResultSet<double, int> result(1);
  result.init(&index, &d2);
  impl_->tree->findNeighbors(result, query.data(), nanoflann::SearchParams(10));
  if (squared_distance) *squared_distance = d2;
  return index;
}

std::vector<int> PointIndex::within_radius(const Eigen::Vector3d& query, double radius) const {
  if (impl_->points.empty()) return {};
  std::vector<std::pair<int, double>> matches;
  nanoflann::SearchParams params;
  params.sorted = false;
  impl_->tree->radiusSearch(query.data(), radius * radius, matches, params);
  std::vector<int> out;
  out.reserve(matches.size());
  for (const auto& m : matches) out.push_back(m.first);
  return out;
}

const std::vector<Eigen::Vector3d>& PointIndex::points() const { return impl_->points; }

std::vector<size_t> thin_points(const std::vector<Eigen::Vector3d>& points, double spacing) {
  std::vector<size_t> kept;
  for (size_t i = 0; i < points.size(); ++i) {
    bool far = true;
    for (size_t k : kept)
      if ((points[k] - points[i]).squaredNorm() < spacing * spacing) {
        far = false;
        break;
      }
    if (far) kept.push_back(i);
  }
  return kept;
}

VertexCloud::VertexCloud(const SkullMesh& mesh)
    : samples(all_vertex_samples(mesh)), index(samples.points) {}

}  // namespace cranioplan
