#pragma once
#include <limits>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

/// Connected pieces of an indexed soup (triangles sharing a vertex are connected).
struct SoupComponents {
  std::vector<int> label;        ///< per triangle, 0..count-1, largest piece first
  std::vector<long long> sizes;  ///< triangles per piece, descending
};
SoupComponents soup_components(const TriangleSoup& soup);

/// Keeps the pieces whose label is below `keep_count` (the largest ones), dropping unused
/// vertices.
TriangleSoup keep_largest_pieces(const TriangleSoup& soup, const SoupComponents& comps,
                                 int keep_count);

/// Keeps the pieces whose `keep[label]` is true, dropping unused vertices.
TriangleSoup keep_pieces(const TriangleSoup& soup, const SoupComponents& comps,
                         const std::vector<bool>& keep);

/// A piece's axis-aligned bounding box.
struct PieceBox {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  /// The distance between this box and `o` (0 when they overlap or touch), mm.
  double gap_to(const PieceBox& o) const;
};
/// Each piece's bounding box, by label.
std::vector<PieceBox> piece_boxes(const TriangleSoup& soup, const SoupComponents& comps);

}  // namespace cranioplan
