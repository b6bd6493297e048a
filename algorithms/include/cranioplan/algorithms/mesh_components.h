#pragma once
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

}  // namespace cranioplan
