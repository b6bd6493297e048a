#pragma once
// The quality report before printing.
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/implant/fixation_tabs.h"
#include "cranioplan/algorithms/implant/perforate.h"
#include "cranioplan/algorithms/implant/rim_gap.h"
#include "cranioplan/model/material.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/model/plane.h"

namespace cranioplan {

struct QualityParams {
  double min_thickness_mm = 1.0;  ///< thinner than this is not printable, mm (but see max_taper_mm)
  /// An implant fitted to the bone ends in a tapered edge where it meets the bone's outer
  /// surface at a grazing angle; that edge may be thinner than min_thickness over this width
  /// (the printer rounds it off), mm. Thin material elsewhere is never printable.
  double max_taper_mm = 2.0;
  /// Away from the bone, thin material may reach this far from the thick part: the tip of a
  /// corner (0.8 mm: corners of 45° and more at 1 mm, e.g. a free edge over an orbit), mm.
  double max_corner_mm = 0.8;
  double max_rim_gap_mm = 1.0;       ///< a larger gap to the bone is not printable, mm
  double max_penetration_mm3 = 5.0;  ///< more overlap with the skull is not printable, mm³
  double overlap_voxel_mm = 0.25;    ///< voxel size of the overlap measurement, mm
  /// A large implant's overlap grid is coarsened to at most this many voxels.
  double overlap_max_voxels = 8e6;
  /// The gap asked between the implant's edge and the bone, mm (0: none asked); with zones,
  /// the largest that holds a point of the edge (ClearanceZone). The rim gap is then judged as
  /// its excess over the clearance, and an edge nearer the bone than the clearance less
  /// `clearance_tolerance_mm` is not printable (it would not go in).
  double edge_clearance_mm = 0.0;
  std::vector<ClearanceZone> clearance_zones;
  double clearance_tolerance_mm = 0.2;  ///< mm
  double density_g_cm3 = 0.0;           ///< for the mass, g/cm³ (0: no mass)
  std::string material_name;            ///< as the report names it (empty: none)
  /// The perforations drilled (ImplantResult::holes): each must go through.
  std::vector<Hole> holes;
  /// The fixation tabs added (ImplantResult::tabs). Each must lie on the bone (its underside at
  /// most `max_tab_gap_mm` off it, and not in it by more), its screw holes go through, its screws
  /// into bone at least `tab_min_bone_mm` thick, and it keep `tab_midline_mm` from the
  /// midsagittal plane. The edge under a tab, which the tab bridges, is not judged by the rim
  /// gap and the clearance.
  std::vector<Tab> tabs;
  double max_tab_gap_mm = 0.2;   ///< mm
  double tab_min_bone_mm = 0.0;  ///< mm
  double tab_midline_mm = 0.0;   ///< mm (judged when the tabs were placed with the plane)
  /// Where the scan ended across the opening (ImplantParams::scan_ends): the edge along these
  /// planes is not judged against bone.
  std::vector<Plane> scan_ends;
};

/// The quality check a build with a material asks for: its minimum thickness, clearance,
/// clearance zones and density; the defaults without one.
QualityParams quality_params_for(const std::optional<Material>& material,
                                 const std::vector<ClearanceZone>& zones = {});

struct ImplantParams;
struct ImplantResult;
/// The quality check a build asks for: its material's and clearance zones' (above), the holes
/// it drilled and the tabs it added with their limits.
QualityParams quality_params_for(const ImplantParams& params, const ImplantResult& result);

struct QualityReport {
  bool watertight = false;
  bool manifold = false;
  bool outward = false;  ///< positive signed volume
  long long self_intersections = 0;
  long long pieces = 0;
  double volume_mm3 = 0.0;
  double area_mm2 = 0.0;
  double thickness_min_mm = 0.0, thickness_median_mm = 0.0, thickness_max_mm = 0.0;
  double thin_volume_mm3 = 0.0;    ///< material thinner than min_thickness_mm
  double thin_off_bone_mm3 = 0.0;  ///< of it, farther than its thinness from the bone
  /// How far thin material reaches from the thick part: on the bone (the tapered edge) and
  /// away from it (corners); −1 when no part is thick.
  double taper_reach_mm = 0.0, corner_reach_mm = 0.0;
  double rim_gap_mm = -1.0;  ///< −1 without a skull
  /// Where the rim gap is: the worst arc's side-wall point nearest the bone, and the bone point
  /// it faces (rim_gap_mm is their distance). Unset without a skull.
  std::optional<Eigen::Vector3d> rim_gap_at, rim_gap_bone;
  /// With a clearance asked: over every 5° arc of the rim, the arc's gap less the clearance
  /// asked there; the smallest and the largest over the arcs (0 and 0: every arc exactly as
  /// asked). Both 0 without a skull or without a clearance asked.
  double clearance_low_mm = 0.0, clearance_high_mm = 0.0;
  /// The worst arc's side-wall point for clearance_high_mm (unset without a clearance asked).
  std::optional<Eigen::Vector3d> clearance_high_at;
  bool clearance_asked = false;      ///< a clearance (or zone) was asked
  double mass_g = 0.0;               ///< volume × density (0 without a density)
  int holes = 0, holes_blocked = 0;  ///< perforations, and those that do not go through
  int tabs = 0, screws_blocked = 0;  ///< fixation tabs, and screw holes that do not go through
  /// The largest gap between a tab's underside and the bone, mm (negative: into the bone; 0
  /// without tabs), and the thinnest bone under a screw and the nearest tab to the midline
  /// (−1: none measured).
  double tab_gap_mm = 0.0, tab_bone_mm = -1.0, tab_midline_mm = -1.0;
  std::string material_name;
  double penetration_mm3 = -1.0;  ///< −1 without a skull
  bool printable = false;
  std::vector<std::string> reasons;  ///< why not printable, one sentence each
  /// The opening ran into the scan's end (QualityParams::scan_ends): the implant ends there,
  /// and the bone beyond it is unknown (no gap to bone is counted along it).
  bool ends_at_scan_end = false;
};

/// Checks an implant, optionally against the (defective) skull it is made for.
///
/// Thickness: from the centre of each face of the implant's two large surfaces (faces whose
/// normal is within 45° of the implant's thinnest principal axis; of an implant with more than
/// 60,000 faces, every k-th face so that about 60,000 are measured), along the inward normal to
/// the opposite surface, but at most the diameter of the deepest ball the ray passes (twice the
/// deepest voxel's depth on the grid below, plus a voxel): a facet of a voxel-trimmed curved
/// implant may have a normal that runs along the plate. Rim: the side wall (the other faces). Rim
/// gap: around the implant's axis, over every 5° arc (`worst_arc_gap`), the distance from the
/// arc's side-wall vertex nearest the bone to the bone; the largest over the arcs (a gap anywhere
/// along the rim 5° wide shows). Penetration: the volume inside both the implant and the skull, on
/// a voxel grid. Thin material: on the same grid, the implant minus its opening by a ball of
/// diameter min_thickness_mm (exact distance transforms; one voxel of slack). It is printable when
/// the implant has a thick part, its tapered edge on the bone is at most max_taper_mm wide and thin
/// material elsewhere (sharp corners) reaches at most max_corner_mm. (thickness_min_mm, measured
/// along face normals, goes to zero at any tapered edge and is reported but not judged.)
QualityReport check_implant(const SkullMesh& implant, const SkullMesh* skull,
                            const QualityParams& params = {});

/// Where a report's edge stands off the bone enough to show a person: the worst rim arc's point
/// when its gap is over kRimGapTargetMm, or, with a clearance asked, the arc furthest beyond the
/// clearance when that is over kRimGapTargetMm; nothing otherwise (the wizard's mark, the
/// report's row).
std::optional<Eigen::Vector3d> rim_gap_to_mark(const QualityReport& report);

class SurfaceLocator;
/// The same with the skull's locator built once by the caller (building it for a skull of two
/// million triangles costs more than the rest of the check).
QualityReport check_implant(const SkullMesh& implant, const SkullMesh* skull,
                            const SurfaceLocator* skull_locator, const QualityParams& params);

}  // namespace cranioplan
