#include "cranioplan/algorithms/shape/shape_model.h"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include "cranioplan/algorithms/io/file_io.h"
#include "cranioplan/model/error.h"

namespace cranioplan {

Eigen::Matrix3Xd ShapeModel::instance(const Eigen::VectorXd& b) const {
  Eigen::VectorXd x = mean;
  const Eigen::Index k = std::min<Eigen::Index>(b.size(), components.cols());
  if (k > 0) x += components.leftCols(k) * b.head(k);
  return Eigen::Map<const Eigen::Matrix3Xd>(x.data(), 3, x.size() / 3);
}

SkullMesh ShapeModel::mesh(const Eigen::Matrix3Xd& points) const {
  TriangleSoup soup;
  soup.vertices.reserve(points.cols());
  for (Eigen::Index i = 0; i < points.cols(); ++i) soup.vertices.push_back(points.col(i));
  soup.triangles = triangles;
  return build_mesh(soup);
}

namespace {

constexpr const char* kMagic = "CRANIOPLAN-SHAPE-MODEL";

bool little_endian() {
  const std::uint16_t one = 1;
  unsigned char byte = 0;
  std::memcpy(&byte, &one, 1);
  return byte == 1;
}

template <class T>
void append(std::string& out, const T* data, size_t count) {
  out.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

// One line of text without line breaks (a header value).
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

}  // namespace

void write_shape_model(const ShapeModel& m, const std::string& path) {
  if (!little_endian())
    throw InputError(path, "shape models are written on little-endian machines");
  std::ostringstream h;
  h.precision(17);
  h << kMagic << ' ' << ShapeModel::kFormatVersion << '\n'
    << "vertices = " << m.vertex_count() << '\n'
    << "outer_vertices = " << m.outer_count << '\n'
    << "triangles = " << m.triangles.size() << '\n'
    << "components = " << m.component_count() << '\n'
    << "skulls = " << m.provenance.skull_sha256.size() << '\n';
  for (size_t i = 0; i < m.provenance.skull_sha256.size(); ++i)
    h << "skull = " << m.provenance.skull_sha256[i] << ' '
      << one_line(i < m.provenance.skull_names.size() ? m.provenance.skull_names[i] : "") << '\n';
  h << "parameters = " << one_line(m.provenance.parameters_json) << '\n'
    << "program_version = " << one_line(m.provenance.program_version) << '\n'
    << "created_utc = " << one_line(m.provenance.created_utc) << '\n'
    << "compactness =";
  for (double c : m.statistics.compactness) h << ' ' << c;
  h << '\n'
    << "generalization_mm = " << m.statistics.generalization_mm << '\n'
    << "specificity_mm = " << m.statistics.specificity_mm << '\n'
    << "end_header\n";
  std::string out = h.str();
  std::vector<std::int32_t> tri;
  tri.reserve(m.triangles.size() * 3);
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) tri.push_back(t[k]);
  append(out, tri.data(), tri.size());
  append(out, m.mean.data(), static_cast<size_t>(m.mean.size()));
  append(out, m.variances.data(), static_cast<size_t>(m.variances.size()));
  append(out, m.components.data(), static_cast<size_t>(m.components.size()));
  write_file_atomically(path, out);
}

namespace {

// The header's lines as key → values (a key may repeat: `skull`).
struct Header {
  int version = 0;
  std::multimap<std::string, std::string> values;
  size_t end = 0;  // byte offset of the arrays
};

Header parse_header(const std::string& bytes, const std::string& path) {
  Header h;
  const std::string magic = std::string(kMagic) + ' ';
  if (bytes.compare(0, magic.size(), magic) != 0)
    throw InputError(
        path, "not a Cranioplan shape model (it does not start with " + std::string(kMagic) + ")");
  size_t pos = 0;
  bool first = true;
  for (;;) {
    const size_t nl = bytes.find('\n', pos);
    if (nl == std::string::npos || nl - pos > 1'000'000)
      throw InputError(path, "the shape model's header has no end_header line (file cut short?)");
    const std::string line = bytes.substr(pos, nl - pos);
    pos = nl + 1;
    if (first) {
      first = false;
      try {
        h.version = std::stoi(line.substr(magic.size()));
      } catch (const std::exception&) {
        throw InputError(path, "the shape model's first line has no format version");
      }
      continue;
    }
    if (line == "end_header") break;
    const size_t eq = line.find(" = ");
    if (eq == std::string::npos) {
      if (line.size() > 2 && line.back() == '=') {  // a key with no values ("compactness =")
        h.values.emplace(line.substr(0, line.size() - 2), "");
        continue;
      }
      throw InputError(path, "the shape model's header line \"" + line.substr(0, 60) +
                                 "\" is not `key = value`");
    }
    h.values.emplace(line.substr(0, eq), line.substr(eq + 3));
  }
  h.end = pos;
  return h;
}

long long header_count(const Header& h, const std::string& key, const std::string& path,
                       long long max) {
  const auto it = h.values.find(key);
  if (it == h.values.end()) throw InputError(path, "the shape model's header has no " + key);
  long long v = -1;
  try {
    size_t used = 0;
    v = std::stoll(it->second, &used);
    if (used != it->second.size()) v = -1;
  } catch (const std::exception&) {
    v = -1;
  }
  if (v < 0 || v > max)
    throw InputError(path, "the shape model's " + key + " (" + it->second +
                               ") is not a count between 0 and " + std::to_string(max));
  return v;
}

std::string header_text(const Header& h, const std::string& key) {
  const auto it = h.values.find(key);
  return it == h.values.end() ? std::string() : it->second;
}

double header_number(const Header& h, const std::string& key) {
  try {
    return std::stod(header_text(h, key));
  } catch (const std::exception&) {
    return 0.0;
  }
}

}  // namespace

ShapeModel read_shape_model(const std::string& path) {
  return parse_shape_model(read_file_bytes(path), path);
}

ShapeModel parse_shape_model(const std::string& bytes, const std::string& path) {
  const Header h = parse_header(bytes, path);
  if (h.version < 1 || h.version > ShapeModel::kFormatVersion)
    throw InputError(path, "shape model format version " + std::to_string(h.version) +
                               "; this program reads version " +
                               std::to_string(ShapeModel::kFormatVersion) +
                               " (a newer program wrote it?)");
  if (!little_endian()) throw InputError(path, "shape models are read on little-endian machines");
  ShapeModel m;
  const long long n = header_count(h, "vertices", path, 10'000'000);
  m.outer_count = static_cast<int>(header_count(h, "outer_vertices", path, n));
  const long long t = header_count(h, "triangles", path, 40'000'000);
  const long long k = header_count(h, "components", path, 10'000);
  const long long skulls = header_count(h, "skulls", path, 1'000'000);
  if (n < 3 || t < 1)
    throw InputError(path, "the shape model has no surface (" + std::to_string(n) + " vertices, " +
                               std::to_string(t) + " triangles)");
  const size_t need = static_cast<size_t>(t) * 3 * 4 + static_cast<size_t>(3 * n) * 8 +
                      static_cast<size_t>(k) * 8 + static_cast<size_t>(3 * n * k) * 8;
  if (bytes.size() - h.end != need)
    throw InputError(path, "the shape model's arrays hold " + std::to_string(bytes.size() - h.end) +
                               " bytes where its header says " + std::to_string(need) +
                               " (file cut short or altered)");
  const char* p = bytes.data() + h.end;
  std::vector<std::int32_t> tri(static_cast<size_t>(t) * 3);
  std::memcpy(tri.data(), p, tri.size() * 4);
  p += tri.size() * 4;
  m.triangles.resize(static_cast<size_t>(t));
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const std::int32_t v = tri[3 * i + c];
      if (v < 0 || v >= n)
        throw InputError(path, "the shape model's triangle " + std::to_string(i) +
                                   " names vertex " + std::to_string(v) + " of " +
                                   std::to_string(n));
      m.triangles[i][c] = v;
    }
  }
  m.mean.resize(3 * n);
  std::memcpy(m.mean.data(), p, static_cast<size_t>(3 * n) * 8);
  p += static_cast<size_t>(3 * n) * 8;
  m.variances.resize(k);
  std::memcpy(m.variances.data(), p, static_cast<size_t>(k) * 8);
  p += static_cast<size_t>(k) * 8;
  m.components.resize(3 * n, k);
  std::memcpy(m.components.data(), p, static_cast<size_t>(3 * n * k) * 8);
  if (!m.mean.allFinite() || !m.variances.allFinite() || !m.components.allFinite())
    throw InputError(path, "the shape model holds values that are not finite numbers");
  if ((m.variances.array() <= 0.0).any())
    throw InputError(path, "the shape model holds a variance that is not positive");
  for (const auto& [key, value] : h.values) {
    if (key != "skull") continue;
    const size_t sp = value.find(' ');
    m.provenance.skull_sha256.push_back(value.substr(0, sp));
    m.provenance.skull_names.push_back(sp == std::string::npos ? "" : value.substr(sp + 1));
  }
  if (static_cast<long long>(m.provenance.skull_sha256.size()) != skulls)
    throw InputError(path, "the shape model's header names " +
                               std::to_string(m.provenance.skull_sha256.size()) +
                               " skulls where it says " + std::to_string(skulls));
  m.provenance.parameters_json = header_text(h, "parameters");
  m.provenance.program_version = header_text(h, "program_version");
  m.provenance.created_utc = header_text(h, "created_utc");
  std::istringstream c(header_text(h, "compactness"));
  for (double v; c >> v;) m.statistics.compactness.push_back(v);
  m.statistics.generalization_mm = header_number(h, "generalization_mm");
  m.statistics.specificity_mm = header_number(h, "specificity_mm");
  return m;
}

Eigen::Matrix4d similarity_between(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b,
                                   const Eigen::VectorXd& w, bool with_scale) {
  const double total = w.sum();
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  if (!(total > 0.0)) return T;
  const Eigen::Vector3d ma = (a * w) / total, mb = (b * w) / total;
  const Eigen::Matrix3Xd ca = a.colwise() - ma, cb = b.colwise() - mb;
  const Eigen::Matrix3d cov = (cb * w.asDiagonal() * ca.transpose()) / total;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) S(2, 2) = -1.0;
  const Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  double s = 1.0;
  if (with_scale) {
    const double var_a = (ca.colwise().squaredNorm() * w)(0) / total;
    if (var_a > 0.0) s = (svd.singularValues().asDiagonal() * S).trace() / var_a;
  }
  T.topLeftCorner<3, 3>() = s * R;
  T.topRightCorner<3, 1>() = mb - s * R * ma;
  return T;
}

Eigen::Matrix3Xd apply_similarity(const Eigen::Matrix4d& T, const Eigen::Matrix3Xd& points) {
  return (T.topLeftCorner<3, 3>() * points).colwise() + T.topRightCorner<3, 1>();
}

double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

namespace {

double mean_distance(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return (a - b).colwise().norm().mean();
}

// PCA of the columns of X (3N × S, each a skull) about `mean`: components and variances, all
// S − 1 of them (fewer when the shapes span less).
void principal_components(const Eigen::MatrixXd& X, const Eigen::VectorXd& mean,
                          Eigen::MatrixXd& components, Eigen::VectorXd& variances) {
  const Eigen::MatrixXd C = X.colwise() - mean;
  const Eigen::Index s = C.cols();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(C.transpose() * C);
  const Eigen::VectorXd values = eig.eigenvalues().reverse();
  const Eigen::MatrixXd vectors = eig.eigenvectors().rowwise().reverse();
  Eigen::Index k = 0;
  while (k < std::max<Eigen::Index>(0, s - 1) && values(k) > 1e-9 * std::max(1.0, values(0))) ++k;
  components.resize(C.rows(), k);
  variances.resize(k);
  for (Eigen::Index j = 0; j < k; ++j) {
    components.col(j) = C * vectors.col(j) / std::sqrt(values(j));
    variances(j) = values(j) / static_cast<double>(std::max<Eigen::Index>(1, s - 1));
  }
}

Eigen::MatrixXd as_columns(const std::vector<Eigen::Matrix3Xd>& shapes) {
  Eigen::MatrixXd X(3 * shapes.front().cols(), static_cast<Eigen::Index>(shapes.size()));
  for (size_t i = 0; i < shapes.size(); ++i)
    X.col(static_cast<Eigen::Index>(i)) =
        Eigen::Map<const Eigen::VectorXd>(shapes[i].data(), shapes[i].size());
  return X;
}

Eigen::Matrix3Xd as_points(const Eigen::VectorXd& x) {
  return Eigen::Map<const Eigen::Matrix3Xd>(x.data(), 3, x.size() / 3);
}

}  // namespace

ProcrustesResult generalised_procrustes(const std::vector<Eigen::Matrix3Xd>& shapes,
                                        int iterations) {
  ProcrustesResult r;
  r.aligned = shapes;
  if (shapes.empty()) return r;
  const Eigen::VectorXd w = Eigen::VectorXd::Ones(shapes.front().cols());
  r.mean = shapes.front();
  for (int it = 0; it < iterations; ++it) {
    for (size_t i = 0; i < shapes.size(); ++i)
      r.aligned[i] = apply_similarity(similarity_between(shapes[i], r.mean, w, true), shapes[i]);
    Eigen::Matrix3Xd next = Eigen::Matrix3Xd::Zero(3, r.mean.cols());
    for (const auto& a : r.aligned) next += a;
    next /= static_cast<double>(r.aligned.size());
    // Keep the mean's size and place at the first skull's: without it the mean shrinks a
    // little each round.
    next = apply_similarity(similarity_between(next, shapes.front(), w, true), next);
    const double moved = mean_distance(next, r.mean);
    r.mean = next;
    if (moved < 1e-4) break;
  }
  for (size_t i = 0; i < shapes.size(); ++i)
    r.aligned[i] = apply_similarity(similarity_between(shapes[i], r.mean, w, true), shapes[i]);
  return r;
}

ShapeModel build_shape_model(const std::vector<Eigen::Matrix3Xd>& skulls, int outer_count,
                             const std::vector<Eigen::Vector3i>& triangles,
                             const ShapeModelBuildParams& params, bool with_statistics) {
  assert(skulls.size() >= 3 && "a shape model needs at least three skulls");
  ShapeModel m;
  m.outer_count = outer_count;
  m.triangles = triangles;
  const ProcrustesResult gpa = generalised_procrustes(skulls);
  const Eigen::MatrixXd X = as_columns(gpa.aligned);
  m.mean = X.rowwise().mean();
  Eigen::MatrixXd comps;
  Eigen::VectorXd vars;
  principal_components(X, m.mean, comps, vars);
  const double total = vars.sum();
  Eigen::Index keep = 0;
  double held = 0.0;
  for (; keep < vars.size() && keep < params.max_components; ++keep) {
    m.statistics.compactness.push_back(total > 0.0 ? (held + vars(keep)) / total : 1.0);
    held += vars(keep);
    if (total > 0.0 && held / total >= params.variance_kept) {
      ++keep;
      break;
    }
  }
  m.components = comps.leftCols(keep);
  m.variances = vars.head(keep);
  if (!with_statistics) return m;

  // Leave-one-out generalisation: each skull fitted by a model of the others (all their
  // components), after aligning it to their mean by similarity.
  const Eigen::VectorXd w = Eigen::VectorXd::Ones(skulls.front().cols());
  double general = 0.0;
  for (Eigen::Index i = 0; i < X.cols(); ++i) {
    Eigen::MatrixXd others(X.rows(), X.cols() - 1);
    for (Eigen::Index j = 0, c = 0; j < X.cols(); ++j)
      if (j != i) others.col(c++) = X.col(j);
    const Eigen::VectorXd mu = others.rowwise().mean();
    Eigen::MatrixXd P;
    Eigen::VectorXd v;
    principal_components(others, mu, P, v);
    const Eigen::Matrix3Xd target = as_points(X.col(i));
    Eigen::Matrix3Xd fit = as_points(mu);
    for (int round = 0; round < 3; ++round) {
      const Eigen::Matrix3Xd aligned =
          apply_similarity(similarity_between(target, fit, w, true), target);
      const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(aligned.data(), aligned.size());
      fit = as_points(mu + P * (P.transpose() * (x - mu)));
      if (round == 2) general += mean_distance(aligned, fit);
    }
  }
  m.statistics.generalization_mm = general / static_cast<double>(X.cols());

  // Specificity: random instances against the nearest training skull.
  std::mt19937 rng(12345);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int draws = 100;
  double spec = 0.0;
  for (int d = 0; d < draws; ++d) {
    Eigen::VectorXd b(m.component_count());
    for (Eigen::Index k = 0; k < b.size(); ++k) b(k) = normal(rng) * std::sqrt(m.variances(k));
    const Eigen::Matrix3Xd inst = m.instance(b);
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < X.cols(); ++j)
      best = std::min(best, mean_distance(inst, as_points(X.col(j))));
    spec += best;
  }
  m.statistics.specificity_mm = spec / draws;
  return m;
}

}  // namespace cranioplan
