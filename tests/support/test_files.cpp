#include "support/test_files.h"

#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace cranioplan::test {
namespace fs = std::filesystem;

TempDir::TempDir() {
  std::random_device rd;
  root_ = (fs::temp_directory_path() /
           ("cranioplan-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd())))
              .string();
  fs::create_directories(root_);
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(root_, ec);
}

std::string TempDir::path(const std::string& name) const {
  return (fs::path(root_) / name).string();
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string gzip(const std::string& bytes) {
  z_stream zs{};
  deflateInit2(&zs, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&zs, bytes.size()) + 64, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  zs.avail_in = static_cast<uInt>(bytes.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

void write_nrrd(const Volume& v, const std::string& path, bool gzip_encoding,
                const std::string& space, const std::string& extra_fields) {
  std::ostringstream h;
  h.precision(17);
  h << "NRRD0004\ntype: int16\ndimension: 3\n";
  h << "sizes: " << v.dims[0] << " " << v.dims[1] << " " << v.dims[2] << "\n";
  if (space.empty()) {
    const Eigen::Vector3d sp = v.spacing();
    h << "spacings: " << sp.x() << " " << sp.y() << " " << sp.z() << "\n";
  } else {
    const Eigen::Vector3d signs =
        space == "right-anterior-superior" ? Eigen::Vector3d(-1, -1, 1) : Eigen::Vector3d(1, 1, 1);
    const Eigen::Matrix3d d = signs.asDiagonal() * v.directions;
    const Eigen::Vector3d o = signs.asDiagonal() * v.origin;
    h << "space: " << space << "\nspace directions:";
    for (int c = 0; c < 3; ++c) h << " (" << d(0, c) << "," << d(1, c) << "," << d(2, c) << ")";
    h << "\nspace origin: (" << o.x() << "," << o.y() << "," << o.z() << ")\n";
  }
  h << "kinds: domain domain domain\nendian: little\n";
  h << "encoding: " << (gzip_encoding ? "gzip" : "raw") << "\n" << extra_fields << "\n";
  std::string data(v.size() * 2, '\0');
  for (size_t i = 0; i < v.size(); ++i) {
    const int16_t s = static_cast<int16_t>(v.data[i]);
    std::memcpy(&data[i * 2], &s, 2);
  }
  write_bytes(path, h.str() + (gzip_encoding ? gzip(data) : data));
}

void write_nifti(const Volume& v, const std::string& path, NiftiForm form) {
  std::string hdr(352, '\0');
  auto put = [&](size_t off, auto value) { std::memcpy(&hdr[off], &value, sizeof(value)); };
  put(0, int32_t{348});
  put(40, int16_t{3});
  for (int a = 0; a < 3; ++a) put(42 + 2 * a, static_cast<int16_t>(v.dims[a]));
  for (int a = 3; a < 8; ++a) put(42 + 2 * a, int16_t{1});
  put(70, int16_t{16});  // float32
  put(72, int16_t{32});
  const Eigen::Vector3d sp = v.spacing();
  // NIfTI's world is RAS: x and y of LPS negated.
  const Eigen::Matrix3d ras = Eigen::Vector3d(-1, -1, 1).asDiagonal() * v.directions;
  const Eigen::Vector3d origin = Eigen::Vector3d(-1, -1, 1).asDiagonal() * v.origin;
  const double qfac = ras.determinant() < 0 ? -1.0 : 1.0;
  put(76, static_cast<float>(qfac));
  for (int a = 0; a < 3; ++a) put(80 + 4 * a, static_cast<float>(sp[a]));
  put(108, 352.0f);
  put(112, 1.0f);
  if (form == NiftiForm::Sform) {
    put(254, int16_t{1});  // sform_code: scanner anatomical
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) put(280 + 16 * r + 4 * c, static_cast<float>(ras(r, c)));
      put(280 + 16 * r + 12, static_cast<float>(origin[r]));
    }
  } else {
    put(252, int16_t{1});  // qform_code
    Eigen::Matrix3d rot = ras * sp.cwiseInverse().asDiagonal();
    rot.col(2) *= qfac;
    Eigen::Quaterniond q(rot);
    if (q.w() < 0) q.coeffs() *= -1.0;
    put(256, static_cast<float>(q.x()));
    put(260, static_cast<float>(q.y()));
    put(264, static_cast<float>(q.z()));
    for (int a = 0; a < 3; ++a) put(268 + 4 * a, static_cast<float>(origin[a]));
  }
  std::memcpy(&hdr[344], "n+1\0", 4);
  std::string data(v.size() * 4, '\0');
  std::memcpy(data.data(), v.data.data(), data.size());
  write_bytes(path, hdr + data);
}

int run_command(const std::string& command, std::string* out) {
  FILE* pipe = ::popen((command + " 2>/dev/null").c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command);
  std::array<char, 4096> buf;
  std::string text;
  size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) text.append(buf.data(), n);
  const int status = ::pclose(pipe);
  if (out) *out = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace cranioplan::test
