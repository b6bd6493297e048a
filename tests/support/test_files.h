#pragma once
// Temporary folders and small file writers for IO tests.
#include <string>

#include "cranioplan/model/volume.h"

namespace cranioplan::test {

/// A fresh folder under the system temp folder, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  std::string path(const std::string& name) const;

 private:
  std::string root_;
};

void write_bytes(const std::string& path, const std::string& bytes);
std::string read_bytes(const std::string& path);
std::string gzip(const std::string& bytes);

/// Writes an int16 NRRD of the volume (LPS) with its directions and origin in `space`
/// ("left-posterior-superior" or "right-anterior-superior"; empty: no space field and
/// `spacings` only); gzip or raw. `extra_fields` (lines, each ending in a newline) go at the
/// header's end, e.g. a segmentation's "Segment0_ID:=bone" fields.
void write_nrrd(const Volume& v, const std::string& path, bool gzip_encoding,
                const std::string& space = "left-posterior-superior",
                const std::string& extra_fields = "");

enum class NiftiForm { Sform, Qform };
/// Writes a float32 NIfTI-1 of the volume (LPS) with its affine in NIfTI's RAS, as the sform,
/// or as the qform alone (the directions must then be a rotation times the spacings, with a
/// reflection allowed along k: qfac).
void write_nifti(const Volume& v, const std::string& path, NiftiForm form = NiftiForm::Sform);

/// Runs a command line; returns its exit code and fills stdout.
int run_command(const std::string& command, std::string* out = nullptr);

}  // namespace cranioplan::test
