#include "cranioplan/algorithms/quality/soft_tissue_check.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/slices.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"
#include "cranioplan/algorithms/io/write_labelmap.h"

namespace cranioplan {

namespace {

// The scalp's thickness over the intact bone around the defect: from points a few mm beyond the
// implant's side wall (`wall`), outward through the bone to the skin; the median, or the
// parameters' default where no such point reaches skin.
double scalp_thickness(const Volume& ct, const SurfaceSamples& all, const std::vector<char>& wall,
                       const Eigen::Vector3d& inside, const Eigen::Vector3d& centre, double step,
                       const SoftTissueParams& params) {
  std::vector<double> thickness;
  for (size_t i = 0; i < all.points.size(); i += std::max<size_t>(1, all.points.size() / 3000)) {
    if (!wall[i]) continue;
    const Eigen::Vector3d radial = (all.points[i] - inside).normalized();
    Eigen::Vector3d away = all.points[i] - centre;
    away -= away.dot(radial) * radial;
    if (away.norm() < 1e-6) continue;
    const Eigen::Vector3d from = all.points[i] + params.ring_mm * away.normalized();
    bool bone = false;
    double bone_end = 0.0;
    for (double t = -10.0; t < 40.0; t += step) {
      const double hu = sample_volume(ct, from + t * radial);
      if (!std::isfinite(hu)) break;
      if (hu >= params.bone_hu) {
        bone = true;
        bone_end = t;
      } else if (bone && hu < params.air_hu) {
        thickness.push_back(t - bone_end);
        break;
      }
    }
  }
  if (thickness.empty()) return params.default_scalp_mm;
  std::nth_element(thickness.begin(), thickness.begin() + thickness.size() / 2, thickness.end());
  return thickness[thickness.size() / 2];
}

std::string soft_tissue_message(const SoftTissueCheck& out, const SoftTissueParams& params) {
  char buf[320];
  if (out.intrusion_mm3 > 0.0)
    std::snprintf(buf, sizeof(buf),
                  "%.0f mm³ of the implant's inner half lie where the CT shows soft tissue "
                  "(%.0f–%.0f HU) deeper than the scalp: brain or dura reaching up to %.1f mm "
                  "above the implant's inner surface%s",
                  out.intrusion_mm3, params.soft_min_hu, params.soft_max_hu, out.intrusion_reach_mm,
                  out.finding ? "" : " (within the tolerance: dura and partial volume)");
  else if (std::isfinite(out.closest_mm))
    std::snprintf(buf, sizeof(buf), "soft tissue lies %.1f mm under the implant's inner surface",
                  out.closest_mm);
  else
    std::snprintf(buf, sizeof(buf), "no soft tissue within %.0f mm under the implant",
                  params.probe_mm);
  std::string message = buf;
  if (out.sunken_scalp_mm3 > 0.0) {
    std::snprintf(buf, sizeof(buf),
                  "; %.0f mm³ of it are scalp sunk into the defect (within the scalp's %.1f mm "
                  "under the skin), which the implant lifts",
                  out.sunken_scalp_mm3, out.scalp_mm);
    message += buf;
  }
  return message;
}

}  // namespace

SoftTissueCheck check_soft_tissue(const SkullMesh& implant, const Volume& ct,
                                  const Eigen::Vector3d& inside, const SoftTissueParams& params) {
  SoftTissueCheck out;
  if (ct.kind == VolumeKind::Mask || implant.n_faces() == 0) {
    out.message =
        ct.kind == VolumeKind::Mask ? "the volume is a mask: no tissue to check" : "no implant";
    return out;
  }
  out.checked = true;
  const auto in_range = [&](double hu) {
    return std::isfinite(hu) && hu >= params.soft_min_hu && hu <= params.soft_max_hu;
  };
  // Soft tissue at a point: in the range, and no bone among the 27 samples around it (where
  // bone meets fluid or air, the samples and their interpolation pass through the soft-tissue
  // range; a bone edge's partial volume is not tissue).
  const Eigen::Matrix3d to_index = ct.directions.inverse();
  const auto soft = [&](const Eigen::Vector3d& p) {
    if (!in_range(sample_volume(ct, p))) return false;
    const Eigen::Vector3d q = to_index * (p - ct.origin);
    const int ci = static_cast<int>(std::lround(q.x())), cj = static_cast<int>(std::lround(q.y())),
              ck = static_cast<int>(std::lround(q.z()));
    for (int k = std::max(0, ck - 1); k <= std::min(ct.dims[2] - 1, ck + 1); ++k)
      for (int j = std::max(0, cj - 1); j <= std::min(ct.dims[1] - 1, cj + 1); ++j)
        for (int i = std::max(0, ci - 1); i <= std::min(ct.dims[0] - 1, ci + 1); ++i)
          if (ct.at(i, j, k) >= params.bone_hu) return false;
    return true;
  };
  // The surface's points, each on the inner surface (its outward normal facing the cavity,
  // within 60°), on the outer (facing away from it) or on the side wall along the rim.
  const SurfaceSamples all = all_vertex_samples(implant);
  std::vector<char> inner(all.points.size()), wall(all.points.size());
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < all.points.size(); ++i) {
    const double facing = all.normals[i].dot((inside - all.points[i]).normalized());
    inner[i] = facing > 0.5;
    wall[i] = std::abs(facing) < 0.5;
    centre += all.points[i];
  }
  centre /= std::max<double>(1.0, static_cast<double>(all.points.size()));
  const double step = std::max(0.1, 0.25 * ct.spacing().minCoeff());
  const double voxel_mm = ct.spacing().maxCoeff();

  // How far the skin (air) lies outward from a point, looking away from the cavity; infinity
  // when no air comes within 60 mm.
  const auto to_skin = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d out = (p - inside).normalized();
    for (double t = 0.0; t < 60.0; t += step) {
      const double hu = sample_volume(ct, p + t * out);
      if (!std::isfinite(hu) || hu < params.air_hu) return t;
    }
    return std::numeric_limits<double>::infinity();
  };
  out.scalp_mm = scalp_thickness(ct, all, wall, inside, centre, step, params);
  // Tissue within the scalp's thickness under the skin (and a voxel's slack) is scalp: where
  // the implant's place holds some, the scalp has sunk into the defect. Deeper is brain or dura.
  const double scalp_reach = out.scalp_mm + voxel_mm;
  const auto scalp = [&](const Eigen::Vector3d& p) { return to_skin(p) <= scalp_reach; };

  // Closest approach: from inner-surface points down along their normals, to tissue other
  // than the scalp.
  const size_t stride =
      std::max<size_t>(1, all.points.size() / std::max<size_t>(1, params.samples));
  for (size_t i = 0; i < all.points.size(); i += stride) {
    if (!inner[i]) continue;
    for (double t = 0.0; t <= params.probe_mm && t < out.closest_mm; t += step)
      if (const Eigen::Vector3d x = all.points[i] + t * all.normals[i]; soft(x) && !scalp(x)) {
        out.closest_mm = t;
        break;
      }
  }

  // Intrusion: the implant's voxels on the CT's grid that are nearer its inner surface than its
  // outer, where the CT shows soft tissue.
  const std::vector<uint8_t> labels = labelmap_on_grid(implant, ct);
  const PointIndex index(all.points);
  long long count = 0, sunken = 0;
  std::vector<double> reach;
  for (int k = 0; k < ct.dims[2]; ++k)
    for (int j = 0; j < ct.dims[1]; ++j)
      for (int i = 0; i < ct.dims[0]; ++i) {
        const size_t n = ct.index(i, j, k);
        if (!labels[n] || !in_range(ct.data[n])) continue;
        const Eigen::Vector3d p = ct.world(Eigen::Vector3d(i, j, k));
        if (!soft(p)) continue;
        const auto nearest = static_cast<size_t>(index.nearest(p));
        if (!inner[nearest]) continue;
        if (scalp(p)) {
          ++sunken;
          continue;
        }
        ++count;
        out.intrusion.push_back(p);
        reach.push_back((p - all.points[nearest]).norm());
      }
  // How far above the implant's inner surface the brain or dura reaches (the 95th percentile
  // of the intruding voxels' depth into the implant, half a voxel added for the voxel's own).
  if (!reach.empty()) {
    std::nth_element(reach.begin(), reach.begin() + reach.size() * 95 / 100, reach.end());
    out.intrusion_reach_mm = reach[reach.size() * 95 / 100] + 0.5 * voxel_mm;
  }
  out.finding = out.intrusion_reach_mm > params.warn_reach_mm;
  const double voxel_mm3 = std::abs(ct.directions.determinant());
  out.intrusion_mm3 = static_cast<double>(count) * voxel_mm3;
  out.sunken_scalp_mm3 = static_cast<double>(sunken) * voxel_mm3;
  if (count > 0) out.closest_mm = 0.0;
  out.message = soft_tissue_message(out, params);
  return out;
}

}  // namespace cranioplan
