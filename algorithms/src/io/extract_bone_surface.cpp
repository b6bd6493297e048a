#include "cranioplan/algorithms/io/extract_bone_surface.h"

#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkQuadricDecimation.h>
#include <vtkShortArray.h>
#include <vtkSignedCharArray.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>

#include "cranioplan/algorithms/geometry/mesh_components.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/model/parallel.h"
#include "soup_building.h"

namespace cranioplan {

namespace {

struct SampleRange {
  float lo = 0.0f, hi = 0.0f;
  bool whole = true;  // every sample a whole number (CT values in HU, masks)
};

// The samples' range, and whether they are all whole numbers, on all threads.
SampleRange sample_range(const std::vector<float>& data) {
  SampleRange all;
  if (data.empty()) return all;
  all.lo = all.hi = data[0];
  std::mutex m;
  parallel_for(data.size(), [&](size_t begin, size_t end) {
    SampleRange part{data[begin], data[begin], true};
    for (size_t i = begin; i < end; ++i) {
      const float v = data[i];
      part.lo = std::min(part.lo, v);
      part.hi = std::max(part.hi, v);
      part.whole = part.whole && v == std::nearbyint(v);
    }
    const std::lock_guard<std::mutex> lock(m);  // min, max and "and" do not depend on order
    all.lo = std::min(all.lo, part.lo);
    all.hi = std::max(all.hi, part.hi);
    all.whole = all.whole && part.whole;
  });
  return all;
}

struct PaddedScalars {
  vtkSmartPointer<vtkDataArray> scalars;
  double scale = 1.0;  // the samples' factor in `scalars` (the threshold's too)
};

template <class Array, class T>
vtkSmartPointer<vtkDataArray> fill_padded(const Volume& volume, float pad, float scale) {
  const int nx = volume.dims[0] + 2, ny = volume.dims[1] + 2, nz = volume.dims[2] + 2;
  auto array = vtkSmartPointer<Array>::New();
  array->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny * nz);
  T* dst = array->GetPointer(0);
  const T padding = static_cast<T>(scale * pad);
  const size_t slice = static_cast<size_t>(nx) * ny;
  // Slice by slice on all threads: the copy, a sample for each of the volume's, is first
  // touched here, and faulting its pages in costs more than copying
  // (docs/decisions/0028-speed-history.md).
  parallel_for(
      static_cast<size_t>(nz),
      [&](size_t begin, size_t end) {
        for (size_t k = begin; k < end; ++k) {
          T* out = dst + k * slice;
          std::fill(out, out + slice, padding);
          if (k == 0 || k + 1 == static_cast<size_t>(nz)) continue;
          for (int j = 0; j < volume.dims[1]; ++j) {
            const float* in = &volume.data[volume.index(0, j, static_cast<int>(k) - 1)];
            T* row = out + (static_cast<size_t>(j) + 1) * nx + 1;
            for (int i = 0; i < volume.dims[0]; ++i) row[i] = static_cast<T>(scale * in[i]);
          }
        }
      },
      1);
  return array;
}

// The padded volume as flying edges reads it. Samples that are whole numbers (CT values,
// masks) are stored doubled as 8- or 16-bit integers when they, the padding and the
// threshold's double fit: doubling is exact in binary floating point, so every comparison with
// the threshold and every interpolation t = (threshold − s0) / (s1 − s0) gives the very same
// double as on the floats (the same surface, bit for bit), from a half or a quarter of the
// memory. Anything else stays float.
PaddedScalars padded_scalars(const Volume& volume, const SampleRange& range, float pad) {
  const double lo = 2.0 * std::min(range.lo, pad), hi = 2.0 * range.hi;
  const bool whole = range.whole && 2.0 * pad == std::nearbyint(2.0 * pad);
  if (whole && lo >= -128.0 && hi <= 127.0)
    return {fill_padded<vtkSignedCharArray, signed char>(volume, pad, 2.0f), 2.0};
  if (whole && lo >= -32768.0 && hi <= 32767.0)
    return {fill_padded<vtkShortArray, short>(volume, pad, 2.0f), 2.0};
  return {fill_padded<vtkFloatArray, float>(volume, pad, 1.0f), 1.0};
}

// The surface built in `mesh` (result.mesh or another), the rest of the result in `result`.
void extract(const Volume& volume, const ExtractBoneSurfaceParams& params,
             ExtractBoneSurfaceResult& result, SkullMesh& mesh) {
  const auto t0 = std::chrono::steady_clock::now();
  mesh.clear();
  const double threshold =
      std::isnan(params.threshold) ? volume.default_threshold() : params.threshold;
  result.threshold_used = threshold;
  const SampleRange range = sample_range(volume.data);
  if (volume.data.empty() || range.hi < threshold || range.lo >= threshold) {
    result.status = ExtractBoneSurfaceResult::Status::NoSurface;
    result.message = "threshold " + std::to_string(threshold) + " is outside the volume's range [" +
                     std::to_string(volume.data.empty() ? 0.0 : range.lo) + ", " +
                     std::to_string(volume.data.empty() ? 0.0 : range.hi) + "]: no surface";
    return;
  }

  // Pad by one sample below the threshold on every side so the surface is closed where bone
  // touches the edge of the scan. Index space: sample (i,j,k) of the volume sits at (i,j,k).
  // The padded copy of the volume and VTK's output are let go as soon as the triangles are out:
  // they are large, and not needed while the mesh is built (docs/BENCHMARKS.md, "Where the
  // memory goes, and what bounds it").
  TriangleSoup soup;
  {
    const float pad = static_cast<float>(std::min<double>(range.lo, threshold - 1.0));
    const PaddedScalars padded = padded_scalars(volume, range, pad);
    vtkNew<vtkImageData> image;
    image->SetDimensions(volume.dims[0] + 2, volume.dims[1] + 2, volume.dims[2] + 2);
    image->SetOrigin(-1, -1, -1);
    image->SetSpacing(1, 1, 1);
    image->GetPointData()->SetScalars(padded.scalars);

    vtkNew<vtkFlyingEdges3D> fe;
    fe->SetInputData(image);
    fe->SetValue(0, padded.scale * threshold);
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

// From 0 (outside) to 1 (inside), ½ on the surface, kept off the iso-level
// (keep_off_iso_level). Without `iso_gap`, only a value exactly at ½ is moved, 1e-4 up (plans
// saved before).
std::vector<float> unit_field(std::vector<float> distance, const VoxelGrid& grid, bool iso_gap) {
  const double h = grid.spacing;
  for (float& v : distance) {
    v = static_cast<float>(std::clamp(0.5 + v / h, 0.0, 1.0));
    if (!iso_gap && v == 0.5f) v = 0.5f + 1e-4f;
  }
  if (iso_gap) keep_off_iso_level(distance);
  return distance;
}

}  // namespace

void keep_off_iso_level(std::vector<float>& field) {
  constexpr float kIsoGap = 1e-3f;
  for (float& v : field)
    if (std::abs(v - 0.5f) < kIsoGap) v = v < 0.5f ? 0.5f - kIsoGap : 0.5f + kIsoGap;
}

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
