#pragma once
// A statistical shape model of the normal skull vault: a template of two sheets (the outer and
// the inner table over the vault, one vertex per direction from the vault's centre), brought
// into dense correspondence with each skull of a collection (correspond_skull.h), aligned by
// similarity (generalised Procrustes) and reduced by principal component analysis. An instance
// is mean + components · b; b_k ~ N(0, variance_k).
//
// The file (.cpsm) is open and versioned: a text header of `key = value` lines that starts with
// `CRANIOPLAN-SHAPE-MODEL <version>` and ends with `end_header` (sizes, provenance, statistics),
// then little-endian arrays: the triangles (int32), the mean, the variances and the components
// (float64, column by column) (docs/SHAPE_MODEL.md).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "cranioplan/model/mesh.h"

namespace cranioplan {

/// Where a model comes from, recorded in its file.
struct ShapeModelProvenance {
  std::vector<std::string> skull_sha256;  ///< each skull's file, in build order
  std::vector<std::string> skull_names;   ///< their file names (no folders)
  std::string parameters_json;            ///< the build's parameters
  std::string program_version;
  std::string created_utc;  ///< ISO 8601
};

/// How well the model describes skulls (Styner et al. 2003's three measures).
struct ShapeModelStatistics {
  /// Cumulative share of the variance the first k+1 components hold.
  std::vector<double> compactness;
  /// Leave-one-out generalisation: the mean distance, mm, from each skull's vertices to a model
  /// built without it fitted to it (all components), averaged over skulls. 0 when not computed.
  double generalization_mm = 0.0;
  /// Specificity: the mean distance, mm, from random instances (b drawn from the prior) to the
  /// nearest training skull. 0 when not computed.
  double specificity_mm = 0.0;
};

struct ShapeModel {
  static constexpr int kFormatVersion = 1;
  /// The template's sheets: vertices [0, outer_count) are the outer table, the rest the inner.
  int outer_count = 0;
  std::vector<Eigen::Vector3i> triangles;  ///< outward from the bone (inner sheet: inward)
  Eigen::VectorXd mean;                    ///< 3N: x0 y0 z0 x1 ...
  Eigen::MatrixXd components;              ///< 3N × K, orthonormal columns
  Eigen::VectorXd variances;               ///< K, mm², decreasing
  ShapeModelProvenance provenance;
  ShapeModelStatistics statistics;

  int vertex_count() const { return static_cast<int>(mean.size() / 3); }
  int component_count() const { return static_cast<int>(variances.size()); }
  /// mean + components.leftCols(b.size()) · b, as 3×N points.
  Eigen::Matrix3Xd instance(const Eigen::VectorXd& b) const;
  /// The instance as a mesh of the two sheets (faces outward from the bone), so that rays from
  /// inside the vault cross the inner then the outer table as through bone.
  SkullMesh mesh(const Eigen::Matrix3Xd& points) const;
};

/// Writes `model` to `path` (a temporary file renamed). Throws InputError naming the file when
/// it cannot be written.
void write_shape_model(const ShapeModel& model, const std::string& path);
/// Reads a model. Throws InputError naming the file and the problem for anything that is not a
/// complete model of this format (another file, a truncated one, a newer version, sizes that
/// do not agree, values that are not finite).
ShapeModel read_shape_model(const std::string& path);
/// The same from a file's bytes already read (`path` names it in messages): a caller that
/// hashes the file reads it once, and the model is the one hashed.
ShapeModel parse_shape_model(const std::string& bytes, const std::string& path);

/// `points` (3×N) moved by the similarity `T` (scale × rotation, translation; 4×4).
Eigen::Matrix3Xd apply_similarity(const Eigen::Matrix4d& T, const Eigen::Matrix3Xd& points);

/// The median of `values` (the upper one of an even count), 0 when there are none.
double median_of(std::vector<double> values);

/// Corresponded skulls (3×N each, the template's vertex order), aligned by similarity.
struct ProcrustesResult {
  std::vector<Eigen::Matrix3Xd> aligned;
  Eigen::Matrix3Xd mean;
};
/// Generalised Procrustes alignment (rotation, translation and scale; the mean's size kept at
/// the first skull's).
ProcrustesResult generalised_procrustes(const std::vector<Eigen::Matrix3Xd>& shapes,
                                        int iterations = 10);

/// The similarity (s, R, t) minimising Σ w_i |s R a_i + t − b_i|² (Umeyama 1991, weighted);
/// `with_scale` false keeps s = 1. Returns a 4×4 matrix.
Eigen::Matrix4d similarity_between(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b,
                                   const Eigen::VectorXd& weights, bool with_scale);

struct ShapeModelBuildParams {
  /// Components kept: at most this many, and no more than hold `variance_kept` of the variance
  /// (at most skulls − 1).
  int max_components = 40;
  double variance_kept = 0.98;  ///< 0..1
};

/// The model from corresponded skulls (each 3×N in the template's vertex order; at least 3).
/// `with_statistics` also computes leave-one-out generalisation and specificity (a few seconds).
ShapeModel build_shape_model(const std::vector<Eigen::Matrix3Xd>& skulls, int outer_count,
                             const std::vector<Eigen::Vector3i>& triangles,
                             const ShapeModelBuildParams& params = {}, bool with_statistics = true);

}  // namespace cranioplan
