#include "cranioplan/algorithms/quality/soft_tissue_check.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cranioplan/algorithms/geometry/point_index.h"
#include "cranioplan/algorithms/geometry/slices.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"
#include "cranioplan/algorithms/io/write_labelmap.h"

namespace cranioplan {

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
  // within 60°) or not: the side wall along the rim faces sideways, towards the bone and the
  // scalp beside the defect, not down.
  const SurfaceSamples all = all_vertex_samples(implant);
  std::vector<char> inner(all.points.size());
  for (size_t i = 0; i < all.points.size(); ++i)
    inner[i] = all.normals[i].dot((inside - all.points[i]).normalized()) > 0.5;

  // Closest approach: from inner-surface points down along their normals.
  const double step = std::max(0.1, 0.25 * ct.spacing().minCoeff());
  const size_t stride =
      std::max<size_t>(1, all.points.size() / std::max<size_t>(1, params.samples));
  for (size_t i = 0; i < all.points.size(); i += stride) {
    if (!inner[i]) continue;
    for (double t = 0.0; t <= params.probe_mm && t < out.closest_mm; t += step)
      if (soft(all.points[i] + t * all.normals[i])) {
        out.closest_mm = t;
        break;
      }
  }

  // Intrusion: the implant's voxels on the CT's grid that are nearer its inner surface than its
  // outer, where the CT shows soft tissue.
  const std::vector<uint8_t> labels = labelmap_on_grid(implant, ct);
  const PointIndex index(all.points);
  long long count = 0;
  for (int k = 0; k < ct.dims[2]; ++k)
    for (int j = 0; j < ct.dims[1]; ++j)
      for (int i = 0; i < ct.dims[0]; ++i) {
        const size_t n = ct.index(i, j, k);
        if (!labels[n] || !in_range(ct.data[n])) continue;
        const Eigen::Vector3d p = ct.world(Eigen::Vector3d(i, j, k));
        if (!soft(p)) continue;
        if (!inner[static_cast<size_t>(index.nearest(p))]) continue;
        ++count;
        out.intrusion.push_back(p);
      }
  out.intrusion_mm3 = static_cast<double>(count) * std::abs(ct.directions.determinant());
  if (count > 0) out.closest_mm = 0.0;
  char buf[240];
  if (out.intrusion_mm3 > 0.0)
    std::snprintf(
        buf, sizeof(buf),
        "%.0f mm³ of the implant lie where the CT shows soft tissue (brain, dura or scalp, "
        "%.0f–%.0f HU) under its inner surface",
        out.intrusion_mm3, params.soft_min_hu, params.soft_max_hu);
  else if (std::isfinite(out.closest_mm))
    std::snprintf(buf, sizeof(buf), "soft tissue lies %.1f mm under the implant's inner surface",
                  out.closest_mm);
  else
    std::snprintf(buf, sizeof(buf), "no soft tissue within %.0f mm under the implant",
                  params.probe_mm);
  out.message = buf;
  return out;
}

}  // namespace cranioplan
