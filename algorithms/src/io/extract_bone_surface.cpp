#include "cranioplan/algorithms/io/extract_bone_surface.h"

#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkQuadricDecimation.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cranioplan/algorithms/geometry/mesh_components.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "soup_building.h"

namespace cranioplan {

namespace {

// The surface built in `mesh` (result.mesh or another), the rest of the result in `result`.
void extract(const Volume& volume, const ExtractBoneSurfaceParams& params,
             ExtractBoneSurfaceResult& result, SkullMesh& mesh) {
  const auto t0 = std::chrono::steady_clock::now();
  mesh.clear();
  const double threshold =
      std::isnan(params.threshold) ? volume.default_threshold() : params.threshold;
  result.threshold_used = threshold;
  const auto [lo_it, hi_it] = std::minmax_element(volume.data.begin(), volume.data.end());
  if (volume.data.empty() || *hi_it < threshold || *lo_it >= threshold) {
    result.status = ExtractBoneSurfaceResult::Status::NoSurface;
    result.message = "threshold " + std::to_string(threshold) + " is outside the volume's range [" +
                     std::to_string(volume.data.empty() ? 0.0 : *lo_it) + ", " +
                     std::to_string(volume.data.empty() ? 0.0 : *hi_it) + "]: no surface";
    return;
  }

  // Pad by one sample below the threshold on every side so the surface is closed where bone
  // touches the edge of the scan. Index space: sample (i,j,k) of the volume sits at (i,j,k).
  // The padded copy of the volume and VTK's output are let go as soon as the triangles are out
  // (a SkullFix volume is 240 MB as floats): they are not needed while the mesh is built.
  TriangleSoup soup;
  {
    const int nx = volume.dims[0] + 2, ny = volume.dims[1] + 2, nz = volume.dims[2] + 2;
    const float pad = static_cast<float>(std::min<double>(*lo_it, threshold - 1.0));
    vtkNew<vtkFloatArray> scalars;
    scalars->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny * nz);
    float* dst = scalars->GetPointer(0);
    std::fill(dst, dst + static_cast<size_t>(nx) * ny * nz, pad);
    for (int k = 0; k < volume.dims[2]; ++k)
      for (int j = 0; j < volume.dims[1]; ++j)
        std::copy_n(&volume.data[volume.index(0, j, k)], volume.dims[0],
                    dst + ((static_cast<size_t>(k) + 1) * ny + j + 1) * nx + 1);
    vtkNew<vtkImageData> image;
    image->SetDimensions(nx, ny, nz);
    image->SetOrigin(-1, -1, -1);
    image->SetSpacing(1, 1, 1);
    image->GetPointData()->SetScalars(scalars);

    vtkNew<vtkFlyingEdges3D> fe;
    fe->SetInputData(image);
    fe->SetValue(0, threshold);
    fe->ComputeNormalsOff();
    fe->ComputeGradientsOff();
    fe->ComputeScalarsOff();
    fe->Update();
    soup = detail::soup_from_polydata("", fe->GetOutput());
  }
  for (auto& p : soup.vertices) p = volume.world(p);

  const SoupComponents comps = soup_components(soup);
  result.pieces_found = static_cast<long long>(comps.sizes.size());
  int keep = 1;
  if (!params.largest_piece_only) {
    keep = 0;
    while (keep < static_cast<int>(comps.sizes.size()) &&
           comps.sizes[keep] >= std::max<long long>(1, params.min_piece_triangles))
      ++keep;
    keep = std::max(keep, 1);
  }
  result.pieces_kept = keep;
  soup = keep_largest_pieces(soup, comps, keep);
  result.triangles_before_decimation = static_cast<long long>(soup.triangles.size());

  if (params.target_triangles > 0 &&
      params.target_triangles < static_cast<long long>(soup.triangles.size())) {
    const vtkSmartPointer<vtkPolyData> pd = detail::polydata_from_soup(soup);
    vtkNew<vtkQuadricDecimation> dec;
    dec->SetInputData(pd);
    dec->SetTargetReduction(1.0 - static_cast<double>(params.target_triangles) /
                                      static_cast<double>(soup.triangles.size()));
    dec->VolumePreservationOn();
    dec->Update();
    soup = detail::soup_from_polydata("", dec->GetOutput());
  }

  if (signed_volume(soup) < 0)
    for (auto& t : soup.triangles) std::swap(t[1], t[2]);
  if (params.canonical) make_canonical(soup);
  build_mesh(soup, mesh);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

ExtractBoneSurfaceResult extract_bone_surface(const Volume& volume,
                                              const ExtractBoneSurfaceParams& params) {
  ExtractBoneSurfaceResult result;
  extract(volume, params, result, result.mesh);
  return result;
}

ExtractBoneSurfaceResult extract_bone_surface(const Volume& volume,
                                              const ExtractBoneSurfaceParams& params,
                                              SkullMesh& mesh) {
  ExtractBoneSurfaceResult result;
  extract(volume, params, result, mesh);
  return result;
}

namespace {

// A field on a grid (0 outside, 1 inside) as a volume meshed at ½, largest piece, as meshed.
Volume field_volume(std::vector<float> field, const VoxelGrid& grid) {
  Volume volume = mask_volume({}, grid);
  volume.data = std::move(field);
  return volume;
}

ExtractBoneSurfaceParams field_surface() {
  ExtractBoneSurfaceParams surface;
  surface.threshold = 0.5;
  surface.largest_piece_only = true;
  surface.canonical = false;
  return surface;
}

// From 0 (outside) to 1 (inside), ½ on the surface. A value at or next to the iso-level puts a
// vertex on or next to a grid point, where the vertices of the edges meeting there fall
// together: triangles without area, whose neighbours then seem to cross. Values within kIsoGap
// of ½ are moved kIsoGap off it, on their side (the surface moves by at most a thousandth of a
// voxel). Without `iso_gap`, only a value exactly at ½ is moved, 1e-4 up (plans saved before).
std::vector<float> unit_field(std::vector<float> distance, const VoxelGrid& grid, bool iso_gap) {
  constexpr float kIsoGap = 1e-3f;
  const double h = grid.spacing;
  for (float& v : distance) {
    v = static_cast<float>(std::clamp(0.5 + v / h, 0.0, 1.0));
    if (!iso_gap) {
      if (v == 0.5f) v = 0.5f + 1e-4f;
    } else if (std::abs(v - 0.5f) < kIsoGap) {
      v = v < 0.5f ? 0.5f - kIsoGap : 0.5f + kIsoGap;
    }
  }
  return distance;
}

}  // namespace

ExtractBoneSurfaceResult surface_of_field(std::vector<float> field, const VoxelGrid& grid) {
  return extract_bone_surface(field_volume(std::move(field), grid), field_surface());
}

ExtractBoneSurfaceResult surface_of_field(std::vector<float> field, const VoxelGrid& grid,
                                          SkullMesh& mesh) {
  return extract_bone_surface(field_volume(std::move(field), grid), field_surface(), mesh);
}

ExtractBoneSurfaceResult surface_of_signed_distance(std::vector<float> distance,
                                                    const VoxelGrid& grid, bool iso_gap) {
  return surface_of_field(unit_field(std::move(distance), grid, iso_gap), grid);
}

ExtractBoneSurfaceResult surface_of_signed_distance(std::vector<float> distance,
                                                    const VoxelGrid& grid, SkullMesh& mesh,
                                                    bool iso_gap) {
  return surface_of_field(unit_field(std::move(distance), grid, iso_gap), grid, mesh);
}

}  // namespace cranioplan
