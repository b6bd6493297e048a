#include "cranioplan/algorithms/quality/ct_agreement.h"

#include <algorithm>
#include <cstdio>

#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/surface_samples.h"

namespace cranioplan {

CtAgreement ct_agreement(const SkullMesh& mesh, const Volume& ct, const CtAgreementParams& params) {
  CtAgreement out;
  const ExtractBoneSurfaceResult bone = extract_bone_surface(ct, params.surface);
  if (!bone.usable() || bone.mesh.n_faces() == 0 || mesh.n_vertices() == 0) {
    out.message = "the CT has no bone surface at the plan's threshold";
    return out;
  }
  const SurfaceLocator locator(bone.mesh);
  const SurfaceSamples samples = subsample(all_vertex_samples(mesh), params.samples);
  std::vector<double> d;
  d.reserve(samples.points.size());
  for (const Eigen::Vector3d& p : samples.points) d.push_back(locator.closest(p).distance);
  const auto at = [&d](double q) {
    const size_t k = std::min(d.size() - 1, static_cast<size_t>(q * static_cast<double>(d.size())));
    std::nth_element(d.begin(), d.begin() + static_cast<long>(k), d.end());
    return d[k];
  };
  out.median_mm = at(0.5);
  out.p90_mm = at(0.9);
  out.agrees = out.median_mm <= params.max_median_mm && out.p90_mm <= params.max_p90_mm;
  char buf[300];
  std::snprintf(buf, sizeof(buf),
                "the skull lies %.2f mm (median) and %.2f mm (90%% of it) from the CT's bone "
                "surface%s",
                out.median_mm, out.p90_mm,
                out.agrees ? ""
                           : ": not this skull's CT, or not in its frame (at most 1 mm and "
                             "2.5 mm are accepted)");
  out.message = buf;
  return out;
}

}  // namespace cranioplan
