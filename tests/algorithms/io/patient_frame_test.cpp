// One patient frame for every volume format: an asymmetric phantom — a 12 mm ball near the
// patient's left-anterior-superior corner, a 7 mm ball near right-posterior-inferior — written
// in every format and pose, must read back with each ball at its true LPS position (x to the
// patient's left, y to the back, z to the head) within half a voxel. A reader that mirrors any
// axis moves a ball by 60 mm or more.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>

#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "support/dicom_writer.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

const Eigen::Vector3d kLeftAnteriorSuperior(35, -30, 40);
const Eigen::Vector3d kRightPosteriorInferior(-35, 30, -30);
constexpr double kBigRadius = 12.0, kSmallRadius = 7.0;

// The phantom on a grid of `dims` samples with the given directions, centred on the origin.
Volume phantom(const Eigen::Matrix3d& directions, int n = 80) {
  Volume v;
  v.dims = {n, n, n};
  v.directions = directions;
  v.origin = -directions * Eigen::Vector3d::Constant((n - 1) / 2.0);
  v.data.assign(v.size(), -1000.0f);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d p = v.world(Eigen::Vector3d(i, j, k));
        if ((p - kLeftAnteriorSuperior).norm() <= kBigRadius ||
            (p - kRightPosteriorInferior).norm() <= kSmallRadius)
          v.data[v.index(i, j, k)] = 1000.0f;
      }
  return v;
}

struct Blob {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  long long voxels = 0;
};

// The bright voxels' centroids on the patient's left (x > 0) and right, in world coordinates.
std::pair<Blob, Blob> blobs(const Volume& v) {
  Blob left, right;
  for (int k = 0; k < v.dims[2]; ++k)
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i) {
        if (v.at(i, j, k) < 0.0f) continue;
        const Eigen::Vector3d p = v.world(Eigen::Vector3d(i, j, k));
        Blob& b = p.x() > 0 ? left : right;
        b.centroid += p;
        ++b.voxels;
      }
  for (Blob* b : {&left, &right})
    if (b->voxels > 0) b->centroid /= static_cast<double>(b->voxels);
  return {left, right};
}

// Each ball where the patient has it, within half the smallest voxel side.
void expect_patient_true(const Volume& v, const std::string& what) {
  SCOPED_TRACE(what);
  const auto [left, right] = blobs(v);
  const double tol = 0.5 * v.spacing().minCoeff();
  ASSERT_GT(left.voxels, 0);
  ASSERT_GT(right.voxels, 0);
  EXPECT_GT(left.voxels, 3 * right.voxels) << "the big ball is not on the patient's left";
  EXPECT_LT((left.centroid - kLeftAnteriorSuperior).norm(), tol)
      << "left-anterior-superior ball at " << left.centroid.transpose();
  EXPECT_LT((right.centroid - kRightPosteriorInferior).norm(), tol)
      << "right-posterior-inferior ball at " << right.centroid.transpose();
}

Eigen::Matrix3d oblique(const Eigen::Vector3d& spacing) {
  const Eigen::Matrix3d rot = (Eigen::AngleAxisd(20.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
  return rot * spacing.asDiagonal();
}

const Eigen::Vector3d kSpacing(1.6, 1.6, 2.0);

TEST(PatientFrame, NrrdInBothPatientSpacesAxialAndOblique) {
  test::TempDir dir;
  for (const bool tilted : {false, true}) {
    const Volume v = phantom(tilted ? oblique(kSpacing) : Eigen::Matrix3d(kSpacing.asDiagonal()));
    for (const std::string space : {"left-posterior-superior", "right-anterior-superior"}) {
      const std::string path = dir.path(space + (tilted ? "-oblique" : "") + ".nrrd");
      test::write_nrrd(v, path, true, space);
      const Volume r = read_volume(path);
      expect_patient_true(r, path);
      EXPECT_NE(r.frame.find(space), std::string::npos) << r.frame;
      EXPECT_TRUE(r.warnings.empty());
    }
  }
}

TEST(PatientFrame, NrrdWithoutASpaceIsReadAsLpsAndSaysSo) {
  test::TempDir dir;
  const Volume v = phantom(Eigen::Matrix3d(kSpacing.asDiagonal()));
  test::write_nrrd(v, dir.path("nospace.nrrd"), false, "");
  const Volume r = read_volume(dir.path("nospace.nrrd"));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("left and right are not known"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.frame.find("none declared"), std::string::npos) << r.frame;
}

TEST(PatientFrame, NiftiSformAndQformAreTurnedFromRas) {
  test::TempDir dir;
  // Oblique, and a grid whose k runs to the feet (NIfTI's qfac of -1 in RAS).
  Eigen::Matrix3d down = kSpacing.asDiagonal();
  down.col(2) *= -1.0;
  for (const auto& [name, directions] : std::vector<std::pair<std::string, Eigen::Matrix3d>>{
           {"oblique", oblique(kSpacing)}, {"feet-first", down}}) {
    const Volume v = phantom(directions);
    for (const test::NiftiForm form : {test::NiftiForm::Sform, test::NiftiForm::Qform}) {
      const std::string path =
          dir.path(name + (form == test::NiftiForm::Sform ? "-sform" : "-qform") + ".nii");
      test::write_nifti(v, path, form);
      const Volume r = read_volume(path);
      expect_patient_true(r, path);
      EXPECT_LT((r.directions - v.directions).norm(), 1e-4) << path;
      EXPECT_NE(r.frame.find("turned to LPS"), std::string::npos) << r.frame;
    }
  }
}

TEST(PatientFrame, APlanSavedBeforeThePatientFrameReadsNiftiAsItWas) {
  test::TempDir dir;
  const Volume v = phantom(Eigen::Matrix3d(kSpacing.asDiagonal()), 40);
  test::write_nifti(v, dir.path("v.nii"));
  ReadVolumeParams legacy;
  legacy.patient_frame = false;
  const Volume r = read_volume(dir.path("v.nii"), legacy);
  // As the file writes it: RAS numbers, x and y of the patient's frame negated.
  EXPECT_LT((r.origin - Eigen::Vector3d(-v.origin.x(), -v.origin.y(), v.origin.z())).norm(), 1e-4);
}

struct DicomCase {
  std::string name;
  Eigen::Matrix3d directions;
  test::DicomSeriesOptions options;
};

std::vector<DicomCase> dicom_cases() {
  using Options = test::DicomSeriesOptions;
  std::vector<DicomCase> cases;
  const Eigen::Matrix3d axial = kSpacing.asDiagonal();
  cases.push_back({"axial", axial, {}});
  Options reverse;
  reverse.order = Options::Order::Reverse;
  cases.push_back({"axial-stored-in-reverse", axial, reverse});
  Eigen::Matrix3d down = axial;
  down.col(2) *= -1.0;  // the first file is the top slice (feet-first tables, some exporters)
  cases.push_back({"top-slice-first", down, {}});
  Options shuffled;
  shuffled.order = Options::Order::Shuffled;
  cases.push_back({"oblique-shuffled", oblique(kSpacing), shuffled});
  Eigen::Matrix3d coronal;  // rows along the patient's left, columns towards the feet
  coronal.col(0) = Eigen::Vector3d(1.6, 0, 0);
  coronal.col(1) = Eigen::Vector3d(0, 0, -1.6);
  coronal.col(2) = Eigen::Vector3d(0, 2.0, 0);
  cases.push_back({"coronal", coronal, shuffled});
  return cases;
}

TEST(PatientFrame, DicomSeriesInEveryOrderAndOrientation) {
  test::TempDir dir;
  for (const DicomCase& c : dicom_cases()) {
    const std::string folder = dir.path(c.name);
    test::write_dicom_series(phantom(c.directions), folder, c.options);
    const Volume r = read_volume(folder);
    expect_patient_true(r, c.name);
    EXPECT_EQ(r.frame, "DICOM patient coordinates (LPS)");
    EXPECT_TRUE(r.warnings.empty()) << c.name << ": " << r.warnings.front();
    EXPECT_GT(r.directions.determinant(), 0.0) << c.name << ": slices not ordered along the normal";
  }
}

TEST(PatientFrame, DicomCompressedTransferSyntaxesDecode) {
  test::TempDir dir;
  const Volume v = phantom(Eigen::Matrix3d(kSpacing.asDiagonal()), 48);
  using C = test::DicomSeriesOptions::Compression;
  for (const C c : {C::RLE, C::JPEGLossless, C::JPEGLS}) {
    test::DicomSeriesOptions o;
    o.compression = c;
    const std::string folder = dir.path("c" + std::to_string(static_cast<int>(c)));
    test::write_dicom_series(v, folder, o);
    const Volume r = read_volume(folder);
    EXPECT_EQ(r.data, v.data) << "lossless syntax " << static_cast<int>(c);
  }
}

TEST(PatientFrame, DicomRescaleSlopeAndInterceptGiveHounsfieldUnits) {
  test::TempDir dir;
  const Volume v = phantom(Eigen::Matrix3d(kSpacing.asDiagonal()), 32);
  test::DicomSeriesOptions o;
  o.slope = 0.5;
  o.intercept = -2000.0;
  test::write_dicom_series(v, dir.path("s"), o);
  const Volume r = read_volume(dir.path("s"));
  EXPECT_EQ(r.data, v.data);
}

TEST(PatientFrame, GantryTiltIsFollowedExactly) {
  test::TempDir dir;
  Eigen::Matrix3d tilted = kSpacing.asDiagonal();
  tilted(1, 2) = 2.0 * std::tan(15.0 * M_PI / 180.0);  // each slice shifted along y
  const Volume v = phantom(tilted);
  test::write_dicom_series(v, dir.path("tilt"));
  const Volume r = read_volume(dir.path("tilt"));
  expect_patient_true(r, "gantry tilt");
  EXPECT_LT((r.directions - tilted).norm(), 1e-4);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("tilted 15.00 degrees"), std::string::npos) << r.warnings[0];
}

TEST(PatientFrame, UnevenSlicesAreResampledAndMissingOnesRefused) {
  test::TempDir dir;
  const Volume v = phantom(Eigen::Matrix3d(kSpacing.asDiagonal()));
  test::DicomSeriesOptions one_gap;
  one_gap.skip = {30};  // one slice gone: a 4 mm gap in a 2 mm series
  test::write_dicom_series(v, dir.path("gap"), one_gap);
  const Volume r = read_volume(dir.path("gap"));
  expect_patient_true(r, "one slice missing");
  EXPECT_EQ(r.dims[2], v.dims[2]);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("resampled"), std::string::npos) << r.warnings[0];

  test::DicomSeriesOptions hole;
  hole.skip = {30, 31, 32};
  test::write_dicom_series(v, dir.path("hole"), hole);
  try {
    read_volume(dir.path("hole"));
    ADD_FAILURE() << "a series with three slices missing was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("slices are missing: a gap of 8 mm"), std::string::npos)
        << e.what();
  }
}

TEST(PatientFrame, AFolderOfSeveralSeriesReadsTheLargestCtOrTheOneNamed) {
  test::TempDir dir;
  const std::string folder = dir.path("study");
  test::DicomSeriesOptions big, small, mr;
  big.series_uid = "1.2.3.1";
  big.description = "head 2.0";
  small.series_uid = "1.2.3.2";
  small.file_prefix = "small";
  mr.series_uid = "1.2.3.3";
  mr.modality = "MR";
  mr.file_prefix = "mr";
  test::write_dicom_series(phantom(Eigen::Matrix3d(kSpacing.asDiagonal()), 40), folder, big);
  test::write_dicom_series(phantom(Eigen::Matrix3d(kSpacing.asDiagonal()), 24), folder, small);
  test::write_dicom_series(phantom(Eigen::Matrix3d(kSpacing.asDiagonal()), 60), folder + "/mr", mr);
  const std::vector<DicomSeries> listed = list_dicom_series(folder);
  ASSERT_EQ(listed.size(), 3u);
  const Volume r = read_volume(folder);
  EXPECT_EQ(r.dims[2], 40);  // the largest CT, not the larger MR
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("read 1.2.3.1 (CT, 'head 2.0', 40×40×40)"), std::string::npos)
      << r.warnings[0];
  ReadVolumeParams named;
  named.dicom_series = "1.2.3.2";
  EXPECT_EQ(read_volume(folder, named).dims[2], 24);
  named.dicom_series = "9.9";
  try {
    read_volume(folder, named);
    ADD_FAILURE() << "a series that is not there was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds no series 9.9"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1.2.3.3 (MR"), std::string::npos) << e.what();
  }
}

TEST(PatientFrame, AMissingFolderSaysItDoesNotExist) {
  try {
    read_volume("/nonexistent/dicom/series");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no such file or folder"), std::string::npos) << e.what();
  }
}

// InVesalius's layout (docs/FRAMES.md): the matrix's slices in IPPSorter order (k towards the
// head), each slice's rows reversed from DICOM's. The sample's matrix written back as the axial
// DICOM series InVesalius read it from must give the same bone surface as the project itself.
TEST(PatientFrame, TheSampleProjectAndItsDicomSeriesGiveTheSameMesh) {
  const std::string sample = sample_case_path();
  if (!std::filesystem::exists(sample)) GTEST_SKIP() << "sample case not installed";
  const Volume inv3 = read_volume(sample);
  // DICOM's grid: rows in DICOM order (j = 0 at the front), slices up, the first voxel at the
  // position the project implies.
  Volume dicom = inv3;
  dicom.directions = inv3.spacing().asDiagonal();
  dicom.origin = Eigen::Vector3d::Zero();
  for (int k = 0; k < inv3.dims[2]; ++k)
    for (int j = 0; j < inv3.dims[1]; ++j)
      for (int i = 0; i < inv3.dims[0]; ++i)
        dicom.data[dicom.index(i, j, k)] = inv3.at(i, inv3.dims[1] - 1 - j, k);
  test::TempDir dir;
  test::DicomSeriesOptions o;
  o.order = test::DicomSeriesOptions::Order::Shuffled;
  test::write_dicom_series(dicom, dir.path("series"), o);
  const Volume read = read_volume(dir.path("series"));
  ASSERT_EQ(read.dims, inv3.dims);
  // Voxel for voxel at the same place with the same value.
  long long differ = 0;
  double worst_place = 0.0;
  for (int k = 0; k < inv3.dims[2]; ++k)
    for (int j = 0; j < inv3.dims[1]; ++j)
      for (int i = 0; i < inv3.dims[0]; ++i) {
        const int jm = inv3.dims[1] - 1 - j;
        if (read.at(i, j, k) != inv3.at(i, jm, k)) ++differ;
        if ((i + j + k) % 97 == 0)
          worst_place = std::max(worst_place, (read.world(Eigen::Vector3d(i, j, k)) -
                                               inv3.world(Eigen::Vector3d(i, jm, k)))
                                                  .norm());
      }
  EXPECT_EQ(differ, 0);
  EXPECT_LT(worst_place, 1e-4);
  // The same bone surface; marching cubes splits a few ambiguous cubes the other way when the
  // rows run the other way, so the meshes agree to a few parts in a hundred thousand.
  const auto a = extract_bone_surface(inv3), b = extract_bone_surface(read);
  ASSERT_TRUE(a.usable() && b.usable());
  EXPECT_EQ(a.mesh.n_faces(), b.mesh.n_faces());
  EXPECT_NEAR(signed_volume(a.mesh), signed_volume(b.mesh), 1e-4 * signed_volume(a.mesh));
  const auto [alo, ahi] = mesh_bounds(a.mesh);
  const auto [blo, bhi] = mesh_bounds(b.mesh);
  EXPECT_LT((alo - blo).norm() + (ahi - bhi).norm(), 1e-3);
}

}  // namespace
}  // namespace cranioplan
