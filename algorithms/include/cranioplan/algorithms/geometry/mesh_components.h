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

/// Drops every triangle with the same three corners (by position) as one before it in the
/// soup, whichever way it winds: the copies that exporters write where pieces overlapped or a
/// surface was written twice. A copy is not a second surface: it would double every crossing
/// there, and a halfedge mesh can join only one of them. Returns how many were dropped.
long long drop_repeated_triangles(TriangleSoup& soup);

/// What orient_consistently did.
struct SoupOrientation {
  long long triangles_turned = 0;  ///< triangles whose winding was reversed
  long long patches_turned = 0;    ///< connected patches of them
  long long conflicts = 0;         ///< edges no orientation can agree on (a Möbius-like seam)
};
/// Makes neighbouring triangles wind alike: across every edge that two triangles share (their
/// corners compared by position, so unwelded copies count as one vertex), each must run the
/// edge the other way. Triangles are reached from neighbour to neighbour over such edges (not
/// over edges of three or more); in each patch reached, the triangles that disagree with the
/// larger part by area are turned. Which way the whole surface winds is left as it was.
SoupOrientation orient_consistently(TriangleSoup& soup);

/// What close_small_holes did.
struct HoleClosing {
  long long closed = 0;           ///< holes closed
  long long triangles_added = 0;  ///< triangles that close them
  double largest_mm = 0.0;        ///< the longest closed hole's open edge, mm
};
/// Closes every hole in the surface whose loop of open edges (edges of one triangle, corners
/// compared by position) is at most `max_length_mm` long: a triangle where three edges are
/// open, otherwise a fan from the loop's centroid (a vertex added there), wound as the triangles
/// around it. A skull's surface has no open edge of its own — a defect or a foramen is a
/// tunnel through the bone, not a gap in its surface — so such loops are triangles a program
/// lost; they are closed before anything asks what is inside the bone. Two holes that touch at
/// a corner (two lost triangles sharing a vertex) are told apart by turning about the corner
/// through the triangles there, and each is closed on its own. Longer loops (the scan's end, a
/// surface cropped or torn), loops through a corner where more than two holes meet or where
/// the triangles cannot be turned through (an edge of three triangles, patches wound against
/// each other), loops that pass a corner twice, and small loops in the plane (within 1 mm) of a
/// longer flat one (bone that the scan's end cuts across) are left.
HoleClosing close_small_holes(TriangleSoup& soup, double max_length_mm,
                              bool through_corners = true);

/// The three repairs above in one pass over the soup (corners compared by position once, the
/// edges listed once): repeated triangles dropped, then patches turned, then small holes
/// closed, each when asked for.
struct SoupRepairParams {
  bool drop_repeated = false;   ///< drop_repeated_triangles
  bool orient = false;          ///< orient_consistently
  double close_holes_mm = 0.0;  ///< close_small_holes; 0: none
  /// Two holes that touch at a corner are told apart and closed (close_small_holes); false:
  /// both left open, as load_skull 5 read them.
  bool through_corners = true;
};
struct SoupRepair {
  long long repeated_dropped = 0;
  SoupOrientation orientation;
  HoleClosing holes;
};
SoupRepair repair_soup(TriangleSoup& soup, const SoupRepairParams& params);

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
